-- A lab bench: every marker is a station and gets a label beside it, upright on screen so it stays readable
-- however the station turns. Labels are computed each frame: the station's name, how long it has been in view
-- and how large it appears. Marker 0 carries a flask icon on it.
dictionary "ARUCO_ORIGINAL"

local stations = { [0] = "Reagents", [1] = "Centrifuge", [2] = "Microscope", [3] = "Balance", [4] = "Fume hood" }

marker(0, { media = image "media/flask.png", place = on_marker { scale = 0.8, opacity = 0.9 } })

marker({from = 0, to = 1023}, {
  name = "station label",
  media = text(function(m)
    local name = stations[m.id] or ("Station " .. m.id)
    return string.format("%s\n%.0f s in view, %d px", name, m.seconds, math.floor(m.side + 0.5))
  end, { size = 26, colour = "#ffffff", background = "#203040d0" }),
  place = billboard { side = "top", gap = 0.2, size = 0.5 },
})

-- A warning beside the fume hood once it has been in view for five seconds.
marker(4, {
  on_update = function(m, dt)
    if m.seconds > 5 then
      return { media = text("Close the sash!", { colour = "#ffffff", background = "#c02020e0" }),
               place = beside { side = "right", size = 1.2 } }
    end
  end,
})
