-- 3D on markers: the paper's cube, the marker frame's axes and two models, each standing in its marker's 3D
-- frame and drawn through the marker's pose with the camera's lens model (the default values, or the
-- calibration loaded with --calib / File > Load calibration). Works on the built-in synthetic source (ids 0, 1, 2)
-- and on printed ARUCO_ORIGINAL markers (`arwb markers --ids 0-3 --pdf models.pdf`).
-- The house is a hand-written OBJ with its material library; the post a glTF made by make_gltf.py.
dictionary "ARUCO_ORIGINAL"

-- The paper's cube, one face showing which way is up, and the axes through it (x red, y green, z blue).
marker(0, { name = "cube", media = cube { colour = "#46b4eb", faces = { top = "#f0c040", front = "#e05050" } } })
marker(0, { name = "axes", media = axes { length = 1.4, offset = {0, 0, 0.01} } })

-- A model on the marker, turned a little so two of its walls face the camera.
marker(1, { name = "house", media = model("house.obj", { size = 1.2, rotate = {0, 0, 30} }) })

-- A model beside its marker, and a caption that appears when the camera comes close.
marker(2, { name = "post", media = model("marker_post.gltf", { size = 1 }), place = beside { side = "right", gap = 0.1 } })
marker(2, {
  name = "distance",
  media = text(function(m)
    -- In marker sides, or in the unit of --marker-size (the Pose panel's "marker side") when one is given.
    if m.pose then return string.format("distance %.1f", m.pose.distance) end
    return "no pose"
  end, { size = 28 }),
  place = beside { side = "bottom", gap = 0.1, size = 0.4 },
})

-- Marker 3 shows the cube only while it is seen nearly from the front (tilt under 30 degrees).
marker(3, {
  name = "front only",
  on_update = function(m)
    if m.pose and m.pose.tilt < 30 then return { media = cube { size = 0.5 } } end
    return { media = false }
  end,
})
