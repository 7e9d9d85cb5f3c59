// What a scene shows on or beside a marker: the description an author wrote (MediaSpec) and the pixels it has
// right now (MediaContent). The decoders behind MediaContent (images, video players, text and web cards) live in
// src/media; the core only carries them from the scene to whoever draws, so Frame stays free of decoders.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>

namespace arwb {

// stage: the current frame's picture of one pipeline stage (trace_view.hpp), by its stage name.
// cube, axes, model: 3D media (mesh.hpp), drawn in the marker's frame through its pose.
enum class MediaKind { none, image, video, web, text, stage, cube, axes, model };
bool is_solid(MediaKind k);   // cube, axes, model
// The kind as the scene API names it: "image", "video", "web", "text", "stage", "cube", "axes", "model"; "none".
const char* media_kind_name(MediaKind k);

struct MediaSpec {
  MediaKind kind = MediaKind::none;
  std::string source;        // as the author wrote it: a path relative to the scene's folder, a URL, or the text
  std::string path;          // image, video: the resolved path (inside the scene's folder, checked)
  std::string url;           // web: http or https only
  std::string title;         // web: the card's title (default: the URL's host)
  std::string text;          // text: what it shows on this frame (a computed text is evaluated each frame)
  std::string stage;         // stage: a stage name from detect/trace.hpp ("adaptive_threshold", "bit_grid", ...)
  bool loop = false;         // video: start again at the end instead of holding the last frame
  double font_px = 32;       // text: glyph height in the card's own pixels (the card is scaled with its placement)
  cv::Scalar colour{255, 255, 255, 255};       // text: BGRA
  cv::Scalar background{40, 40, 40, 200};      // text: BGRA card behind the text (alpha 0: none)
  // cube, axes, model: the size in marker sides (a cube's edge, the axes' length, a model's largest extent),
  // where its base's centre stands in the marker's frame (marker sides: x right, y up, z out of the marker) and
  // its rotation (degrees about x, then y, then z); lit by the lamp or flat colour.
  double size = 1.0;
  cv::Vec3d offset{0, 0, 0};
  cv::Vec3d rotate_deg{0, 0, 0};
  bool lit = true;
  double thickness = 0.04;                     // axes: the bars' thickness in marker sides
  // cube: per face (mesh.hpp's CubeFace order: right left back front top bottom) a BGRA colour, or an image
  // (the resolved path; the colour then tints it). face_source is what the author wrote.
  std::array<cv::Scalar, 6> face_colour{{{235, 180, 70, 255}, {235, 180, 70, 255}, {235, 180, 70, 255},
                                         {235, 180, 70, 255}, {235, 180, 70, 255}, {235, 180, 70, 255}}};
  std::array<std::string, 6> face_image{};
  std::array<std::string, 6> face_source{};
  // One line for tables and logs: "image media/painting.png", "video media/clip.mp4 (loop)", "web https://...",
  // "text \"ID 7\"", "cube size 1", "axes", "model models/house.obj size 1.5".
  std::string describe() const;
};

// The pixels a media shows now. Implementations are thread-safe: the scene sets them up on the worker, the UI
// thread reads them every frame to update textures, and video players decode on their own thread.
class MediaContent {
 public:
  virtual ~MediaContent() = default;
  // Width and height in pixels, known before the first picture is decoded (from the header or the container).
  virtual cv::Size size() const = 0;
  // The newest picture, CV_8UC3 BGR or CV_8UC4 BGRA (straight alpha), and its version. The version changes
  // whenever the pixels do (a video's frame number, plus one per reload), so a texture uploads only then.
  // May return null while a video's first frame is still being decoded.
  virtual std::shared_ptr<const cv::Mat> current(uint64_t* version) const = 0;
};

}  // namespace arwb
