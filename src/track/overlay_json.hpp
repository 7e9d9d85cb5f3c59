// A frame's overlays as JSON: what each medium is and where it is drawn, at full precision. `arwb render
// --overlays` writes it for every frame, and the phone player's core hands it to the page, which draws from it:
// the same fields from the same Overlay, so the two can be compared number for number.
#pragma once

#include "track/overlay.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace arwb {

// {"marker","track","mapping","kind","source"[,"url","title"][,"text"],"place","quad":{"corners":[[x,y] x4],
// "H":[9, row-major],"uv_min":[u,v],"uv_max":[u,v],"opacity"}[,"size":[w,h]][,"solid":{"mesh_to_marker":[16],
// "rvec":[3],"tvec":[3]}]}. "source" is what the scene wrote (a path relative to the scene's folder for pictures
// and videos); "size" is the medium's own, in pixels, when it has pictures.
nlohmann::ordered_json overlay_json(const Overlay& o);
nlohmann::ordered_json overlays_json(const std::vector<Overlay>& overlays);

}  // namespace arwb
