dictionary "ARUCO_ORIGINAL"
marker(0, { media = image "media/tile.png", place = on_marker { fit = "fill" } })
marker(1, { media = image("media/tile.png"), place = beside { side = "right", gap = 0.25, size = 1.5 } })
marker({0, 2}, { media = text(function(m) return "exhibit " .. m.id end), place = billboard() })
marker(2, { media = web "https://example.com/", place = on_marker() })
marker(1, {
  on_enter = function(m) print("hello " .. m.id) end,
  on_update = function(m, dt) return { place = beside { side = "left" } } end,
  on_leave = function(m) print("bye", m.id) end,
})
