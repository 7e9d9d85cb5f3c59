// Where a media goes, as geometry. The scene's placements (Lua's on_marker, beside, billboard, screen) become a
// PlaceSpec; place() turns it, the marker's four detected corners and the media's aspect into a quad in image
// pixels plus the homography from the media's texture coordinates to the image. The workbench's renderer and
// `arwb render` both draw from this, so a media lands on the same pixels on screen and offline.
//
// The marker's own frame: corner 0 at (0,0), corner 1 at (1,0), corner 2 at (1,1), corner 3 at (0,1); one unit
// is the marker's side measured on its outer black edge (the detected corners). x runs to the marker's right
// (from corner 0 to corner 1), y downwards (from corner 0 to corner 3). A media's up is the marker's up, so it
// turns and tilts with the marker. The homography from this frame to the image is exact for a flat marker seen
// by a pinhole camera, so anything laid in the marker's plane (on_marker, beside) gets true perspective.
#pragma once

#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

enum class PlaceKind { on_marker, beside, billboard, screen };
enum class Fit { fit, fill, stretch };          // on_marker: keep the media's aspect inside, cover and crop, or stretch
enum class Side { right, left, top, bottom };   // beside: the marker's sides; billboard: screen sides
enum class ScreenCorner { top_left, top_right, bottom_left, bottom_right };

std::string_view place_kind_name(PlaceKind k);  // "on_marker", "beside", "billboard", "screen"
std::string_view fit_name(Fit f);
std::string_view side_name(Side s);
std::string_view screen_corner_name(ScreenCorner c);
// Parse the names above; false for anything else.
bool parse_fit(std::string_view s, Fit* out);
bool parse_side(std::string_view s, Side* out);
bool parse_screen_corner(std::string_view s, ScreenCorner* out);

struct PlaceSpec {
  PlaceKind kind = PlaceKind::on_marker;
  double opacity = 1.0;       // all kinds: 0..1
  // on_marker
  double scale = 1.0;         // > 0, about the marker's centre
  double rotate_deg = 0;      // in the marker's plane, clockwise as seen on an upright marker
  Fit fit = Fit::fit;
  // beside: side of the marker; billboard: side of the marker's bounding box on screen
  Side side = Side::right;
  double gap = 0.25;          // beside, billboard: from the marker's outer edge, in marker sides
  double size = 1.0;          // beside: media width for left/right, height for top/bottom, in marker sides;
                              // billboard: media height in marker sides (the marker's mean side in pixels);
                              // screen: media width as a fraction of the frame's width
  // beside, billboard: true lets a text or web card cover the cards placed before it; false (the default) moves
  // it to another side of its marker where it covers none (place_apart)
  bool overlap = false;
  // screen
  ScreenCorner corner = ScreenCorner::top_right;
  double margin_px = 16;
  // The defaults for a kind: what on_marker(), beside(), billboard() and screen() give with no options. They
  // differ only in size: 1 marker side beside, 0.6 for a billboard, a quarter of the frame's width on screen.
  static PlaceSpec defaults(PlaceKind k);
  // One line for tables: "on_marker fit", "beside right gap 0.25 size 1.5", "billboard top", "screen top_right".
  std::string describe() const;
  // Empty when every value is usable, else the first problem: "size must be a finite number > 0 (got nan)".
  std::string validate() const;
};

struct MediaQuad {
  // Image positions of the drawn part of the media: its top-left, top-right, bottom-right, bottom-left.
  std::array<cv::Point2d, 4> corners{};
  // Maps texture coordinates (u, v) in [0,1]^2 of the whole media to image pixels (homogeneous). For Fit::fill
  // only part of the media is drawn; uv_min and uv_max bound it.
  cv::Matx33d H = cv::Matx33d::eye();
  cv::Point2d uv_min{0, 0}, uv_max{1, 1};
  double opacity = 1.0;
  // on_marker and beside: texture coordinates to the marker's own frame (above), an affine map. What a flat
  // media drawn through the pose and the lens model (Overlay::solid) is laid on.
  cv::Matx33d uv_to_marker = cv::Matx33d::eye();
  bool in_marker_plane = false;
  // Whether an image point lies inside the drawn quad (for clicks on web cards).
  bool contains(cv::Point2d p) const;
};

// The homography from the marker's own frame (see above) to the image.
cv::Matx33d marker_homography(const Quad& corners);
// Mean length of the marker's four sides in pixels.
double marker_side_px(const Quad& corners);

// Places a media of aspect `media_aspect` (width / height, > 0) for a marker seen at `corners` in an image of
// size `frame`. Returns nullopt with *why set when it cannot be drawn: an invalid spec (validate()), a degenerate
// marker, or a beside placement reaching the marker plane's horizon (part of it would be behind the camera).
std::optional<MediaQuad> place(const PlaceSpec& spec, const Quad& corners, double media_aspect, cv::Size frame,
                               std::string* why = nullptr);

// The cards of one frame kept apart: place() for a card (beside or billboard, overlap false) whose box would
// cover a box in `taken` tries its marker's other sides, `kept` first (the side it had on the frame before, so
// that a card does not hop from side to side), then spec.side, right, left, top and bottom; the first that covers
// none, else the one that covers least. Its box is added to `taken` and *side gets the side used. Other kinds
// and overlap true are place() as is (their boxes not taken).
std::optional<MediaQuad> place_apart(const PlaceSpec& spec, const Quad& corners, double media_aspect, cv::Size frame,
                                     std::vector<cv::Rect2d>& taken, std::optional<Side> kept, Side* side,
                                     std::string* why = nullptr);

}  // namespace arwb
