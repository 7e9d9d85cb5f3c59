// Synthetic frames with exact ground truth: markers rendered through a homography with supersampling, and
// photograph-like images for the benchmark (perspective, scale, rotation, blur, noise, light, shadows, JPEG,
// clutter that looks like markers, and images with no marker at all).
//
// Corners use the detector's convention: pixel centres at integer coordinates; a marker's corners are the
// outer corners of its black border, its own top-left first, then clockwise.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

struct TruthMarker {
  int id = -1;
  std::string dict;
  Quad corners{};
};

// Draws marker `id` so that its outer black corners land on `corners`, with a white quiet zone of
// `quiet_cells` cells around it, anti-aliased by rendering at `supersample` times the resolution.
// `black` and `white` are the grey levels printed. canvas: CV_8UC1 or CV_8UC3.
void draw_marker(cv::Mat& canvas, const Dictionary& dict, int id, const Quad& corners, double quiet_cells = 1.0,
                 int supersample = 4, int black = 0, int white = 255);

// The corners of a square marker of side `side_px` centred at `centre`, turned `roll_deg` in the image plane and
// tilted `tilt_x_deg`/`tilt_y_deg` out of it, seen by a pinhole camera of focal length `focal_px`.
Quad project_square(cv::Point2d centre, double side_px, double roll_deg, double tilt_x_deg, double tilt_y_deg,
                    double focal_px);

// False when marker `id` reads the same as itself turned, or as another marker in some rotation: its id or
// orientation cannot be told, so synthetic frames skip it.
bool unambiguous(const Dictionary& dict, int id);

// The harder bench's conditions (`arwb synth --set hard`, `arwb bench --set hard`): each is what detectors were seen
// to miss on photographs they had never seen. An image of a hard set has one of them.
enum class Hardship {
  none,          // the photographs above
  low_contrast,  // large markers (100 px up to 0.6 of the frame) printed grey on grey, with a soft-edged shadow and a
                 // steep light gradient across them
  tiny,          // markers of 10 to 24 px
  low_light,     // a dim scene: strong sensor noise and the blur of a long exposure
  crossed,       // thin dark lines across markers' borders: a large marker (190 to 265 px) half in a soft shadow
                 // band with a line through it, and a marker of about 37 px and one of about 55 px, each with a line
                 // that crosses its quiet zone and ends on its border
};
constexpr Hardship kHardships[] = {Hardship::low_contrast, Hardship::tiny, Hardship::low_light, Hardship::crossed};
std::string_view hardship_name(Hardship h);

struct SynthOptions {
  cv::Size size{640, 480};
  std::vector<Dictionary> dictionaries;   // markers are drawn from these, in turn
  double empty_fraction = 0.1;            // share of images with no marker
  int max_markers = 5;
  double min_side_px = 24;                // marker sides, log-uniform in [min, max_side_rate x shorter image side]
  double max_side_rate = 0.6;
  double max_tilt_deg = 55;
  bool effects = true;                    // blur, noise, light, shadow, JPEG, clutter; false: clean renders
  Hardship hardship = Hardship::none;     // with effects: the sizes, contrast and light of that condition instead
};

struct SynthImage {
  cv::Mat image;                          // BGR
  std::vector<TruthMarker> markers;
  std::string notes;                      // the effects applied, for humans reading truth.jsonl
};

// Image `index` of the set seeded by `seed`: the same pair gives the same image.
SynthImage synth_photo(const SynthOptions& opt, uint64_t seed, int index);

}  // namespace arwb
