-- A museum room: each exhibit's marker shows its painting on the marker, a caption beside it, and marker 2
-- plays a short film next to itself. Works on the built-in synthetic source (ids 0, 1, 2) and on printed
-- ARUCO_ORIGINAL markers (`arwb markers --ids 0-5 --pdf museum.pdf`). The media were painted by
-- `arwb make-media`.
dictionary "ARUCO_ORIGINAL"

local captions = {
  [0] = "Composition in red, blue and yellow\nworkbench collection, 2026",
  [1] = "Sunset over the bay\noil on canvas (procedural)",
  [2] = "Orbit\n3 s film, loops",
}

marker(0, { name = "composition", media = image "media/composition.png", place = on_marker { fit = "fill" } })
marker(1, { name = "sunset", media = image "media/sunset.png", place = on_marker { scale = 1.2 } })
marker(2, { name = "film", media = video("media/orbit.mp4", { loop = true }),
            place = beside { side = "right", gap = 0.25, size = 1.5 } })

-- Captions under every exhibit, in the marker's plane, so they tilt with the wall.
marker({from = 0, to = 2}, {
  name = "caption",
  media = text(function(m) return captions[m.id] or ("exhibit " .. m.id) end, { size = 28 }),
  place = beside { side = "bottom", gap = 0.1, size = 0.45 },
})

-- Visitors' counter: how long each exhibit has been looked at this visit.
marker({from = 0, to = 2}, {
  on_enter = function(m) print("visitor looks at exhibit " .. m.id) end,
  on_leave = function(m) print(string.format("exhibit %d left after %.1f s", m.id, m.seconds)) end,
})
