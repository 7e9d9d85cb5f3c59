marker(0, { on_enter = function(m) while true do end end })
marker(1, { on_update = function(m) local t = {} for i = 1, 1e7 do t[i] = i end end })
marker(2, { on_enter = function(m) return string.rep("x", 1e9) end, on_update = function() error("every frame") end })
