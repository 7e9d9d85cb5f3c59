// What a scene asks for its media (script::SceneRuntime): pictures, videos, cards and 3D models by what the scene
// wrote. The desktop's MediaStore (media_store.hpp) decodes and draws them; the phone player's core answers with
// sizes and paths and leaves the drawing to the page.
#pragma once

#include "track/media_spec.hpp"
#include "track/mesh.hpp"

#include <filesystem>
#include <memory>
#include <string>

namespace arwb::media {

// A video as a MediaContent whose picture follows a clock the scene sets: the time into the video it should
// show, and whether that time runs on by itself (live mode, between two of the scene's frames).
class VideoContent : public MediaContent {
 public:
  // Shows the frame at `position_s` seconds into the video (looping if the video loops, else holding the last
  // frame), and from then on, while `playing`, lets the picture advance with the wall clock (live mode only).
  // Offline, decodes up to that frame before returning and `playing` changes nothing. Negative or NaN: 0.
  // Going backwards seeks (CAP_PROP_POS_FRAMES, or reopening the file when the backend cannot seek), except that
  // live and playing, a clock at most a quarter second (2 frames at least) behind the picture is waited for: the
  // scene's clock wobbles against the wall clock, and a seek per wobble would stutter.
  virtual void set_clock(double position_s, bool playing) = 0;
  // Frame count / fps; 0 if the container does not say. Shrinks to what could really be decoded when decoding
  // ends early (a container that promised more, a truncated file).
  virtual double duration_s() const = 0;
  virtual double fps() const = 0;             // the container's rate, 25 when it gives none or an absurd one
  // Frames decoded so far, shown or skipped.
  virtual uint64_t frames_decoded() const = 0;
  // A decode failure after opening, "" if none: "<path>: cannot decode frame 18 of 40 (damaged or truncated
  // file); the video ends at frame 17". The last good frame stays shown.
  virtual std::string error() const = 0;
};

class MediaProvider {
 public:
  virtual ~MediaProvider() = default;
  // An image (a checked path, media_path.hpp). Null and *error set on failure; *error cleared on success.
  virtual std::shared_ptr<MediaContent> image(const std::string& path, std::string* error) = 0;
  // A new player for a video (each marker showing one has its own position). Null and *error set on failure.
  virtual std::shared_ptr<VideoContent> video(const std::string& path, bool loop, std::string* error) = 0;
  // A card with spec.text in spec.font_px, spec.colour on spec.background; never null.
  virtual std::shared_ptr<MediaContent> text_card(const MediaSpec& spec) = 0;
  // A card for the web link spec.url titled spec.title; never null.
  virtual std::shared_ptr<MediaContent> web_card(const MediaSpec& spec) = 0;
  // The 3D model `relative` (as the scene wrote it) inside `scene_dir`. Null and *error set on failure; *warning
  // (if given) gets what the load warned about.
  virtual std::shared_ptr<const Mesh> model(const std::filesystem::path& scene_dir, const std::string& relative,
                                            std::string* error, std::string* warning) = 0;
  // Forgets what no one holds (after a scene reload).
  virtual void trim() = 0;
};

}  // namespace arwb::media
