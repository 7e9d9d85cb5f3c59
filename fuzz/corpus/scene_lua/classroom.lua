-- A classroom: each marker shows one stage of the detection pipeline, live, on the marker itself. Hold up
-- marker 3 to show the adaptive threshold, 4 for the contours, 12 for the bit grids... The pictures are the
-- workbench's own stage views of the current frame, so the class sees exactly what the detector sees.
-- Stage names are the pipeline's (see docs/scene-api.md); a title sits above each marker.
dictionary "ARUCO_ORIGINAL"

local stages = {
  "acquisition", "search_regions", "decimation", "adaptive_threshold", "contours", "coarse_search", "size_filter",
  "quad_fit", "nested_filter", "corner_refinement", "perspective_removal", "otsu", "bit_grid", "border_check",
  "identification", "fine_search", "duplicates",
}

for i, name in ipairs(stages) do
  local id = i - 1
  marker(id, { name = name, media = stage(name), place = beside { side = "right", gap = 0.2, size = 2.0 } })
  marker(id, { media = text(string.format("%d. %s", id, (name:gsub("_", " "))), { size = 30 }),
               place = billboard { side = "top", size = 0.35 } })
end
