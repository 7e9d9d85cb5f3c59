-- Links: markers that open web pages, as the paper's web applications do. Each marker gets a card with the
-- page's title and address beside it; click the card in the workbench's live view to open the page in the
-- system's browser (http and https only, started without a shell).
dictionary "ARUCO_ORIGINAL"

marker(0, { media = web("https://opencv.org", { title = "OpenCV" }), place = beside { side = "top" } })
marker(1, { media = web("https://www.lua.org/manual/5.4/", { title = "Lua 5.4 manual" }),
            place = beside { side = "right", size = 1.8 } })
marker(2, { media = web("https://github.com/ocornut/imgui", { title = "Dear ImGui" }),
            place = beside { side = "bottom", size = 0.8 } })
