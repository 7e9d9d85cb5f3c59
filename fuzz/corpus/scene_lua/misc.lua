marker(0, { media = video("media/tile.png", { loop = true }), place = screen { corner = "top_left" } })
print(tostring(setmetatable({}, {__tostring = function() return "t" end})))
