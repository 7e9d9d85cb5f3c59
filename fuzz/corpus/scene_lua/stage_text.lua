marker(ids(0, 1), { media = stage "adaptive_threshold", place = billboard { side = "bottom" } })
marker(2, { media = text(42, { size = 0, colour = "#ff000080", background = "#00000000" }), place = "beside" })
