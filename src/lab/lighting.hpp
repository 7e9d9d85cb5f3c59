// The light on the wall, beyond its level: what the paper blames for the losses its table shows outdoors (section
// 5.2: "shadows created by users on the surfaces where markers are applied" at 0.5 m, "reflection phenomena" at
// 2 m) and finds much weaker indoors, where "the uniform diffusion of the natural light ... reduces shadows and
// reflections" (5.3). Both need the sun: the share of the light that arrives straight from it says whether there
// is any (none in the evening), how dark a shadow is and how bright a glint; how often each happens is geometry:
//
//   shadow: the user stands between the sun and the wall and casts a shadow as wide as their shoulders; one of its
//     two edges crosses the marker when the sun's azimuth puts it there. Inside it only the diffuse light remains
//     (1 - direct share of the level). With the azimuth uniform over the half-plane the wall faces, an edge at
//     x = d tan(azimuth) +- w/2 from the marker crosses a marker of side s with chance 2 s d / (pi (d^2 + w^2/4))
//     (shadow_edge_chance): geometry alone, nothing fitted. The edge's penumbra is the occluder's distance times
//     the sun's angular diameter, which in pixels is the same at any distance (f x 0.0093 rad, about 5 px at
//     640x480).
//   glare: a semi-glossy print mirrors the sun into the camera as a lobe of a few degrees; the camera is inside it
//     when the sun stands within the lobe of the camera's mirror direction: the lobe's solid angle over the
//     half-sky's, 1 - cos(lobe) (glint_chance). The lobe's footprint on the print grows with the distance while
//     the marker's image shrinks, so near the camera a glint is a spot on the marker and at 2 m it washes out
//     much of it; in pixels its radius is f x tan(lobe) at any distance.
//
// The paper's three conditions are the model's three environments, by level: outdoors in sunlight (1000 lx and
// above), indoors in natural light (850 lx and above), and the evening's diffuse light (below). Every constant is
// in docs/lab.md with why it has its value.
#pragma once

#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <random>
#include <string>

namespace arwb::lab {

struct SceneLight {
  double direct_outdoor = 0.75;         // share of the light straight from the sun, at 1000 lx and above
  double direct_indoor = 0.3;           // at 850 lx and above (sunlight through windows, mostly diffused)
  double direct_evening = 0.0;          // below 850 lx
  double body_width_m = 0.43;           // the user's shoulders (bideltoid breadth), whose shadow's edges cross
  double shadow_chance = -1;            // a frame's chance of a shadow edge when there is sun; -1: from the geometry
                                        // (shadow_edge_chance). Tests set 0 or more than 1.
  double sun_diameter_rad = 0.0093;     // the penumbra's angle
  double glare_chance = -1;             // a frame's chance of a glint when there is sun; -1: from the lobe
                                        // (glint_chance)
  double glare_lobe_deg = 4;            // the glint's half-width (semi-glossy paper)
  double glare_peak = 1.6;              // the glint's peak radiance over the paper's diffuse white
};

double direct_share(const SceneLight& light, double lux);
// The chance that an edge of the user's shadow crosses a marker of side `side_m` seen from `distance_m` (the
// model above); light.shadow_chance instead when it is set.
double shadow_edge_chance(const SceneLight& light, double side_m, double distance_m);
// The chance that the camera is inside the sun's mirror lobe: 1 - cos(lobe); light.glare_chance when set.
double glint_chance(const SceneLight& light);

struct LightEvents {
  bool shadow = false;
  bool glare = false;
  std::string text() const;   // "a shadow edge across the marker", "a glint", both, or ""
};

// Puts a shadow edge and a glint on `levels` (synth/marker_view.hpp's grey levels, level / 255 the reflectance,
// the glint above 255) as chance has it for a marker with image corners `corners` at `distance_m` under `lux`
// through a focal length of `focal_px` pixels. `rng` is the frame's own lighting generator.
LightEvents apply_scene_light(cv::Mat1f& levels, const SceneLight& light, double distance_m, double lux,
                              double focal_px, const Quad& corners, std::mt19937& rng);

}  // namespace arwb::lab
