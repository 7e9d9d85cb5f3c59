// OpenGL textures made from OpenCV images, uploaded only when a panel that is drawn asks for them and only when
// their content changed (a version number, usually the frame index, says so).
//
// Needs a current OpenGL context (3.3 core); every function here is called on the UI thread.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <unordered_map>

namespace arwb::render {

class Texture {
 public:
  Texture() = default;
  ~Texture();
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  Texture(Texture&& o) noexcept;
  Texture& operator=(Texture&& o) noexcept;

  // Uploads `image` (CV_8UC1, CV_8UC3 BGR or CV_8UC4 BGRA) unless `version` is the one already uploaded.
  // `nearest` picks nearest-neighbour magnification, so pixels stay square when a user zooms in.
  // `mipmaps` builds the mipmap chain and filters trilinearly: media drawn much smaller than their pixels
  // (a 1920-wide video on a 60 px marker) would shimmer otherwise.
  // True when it uploaded (the version or size changed).
  bool upload(const cv::Mat& image, uint64_t version, bool nearest = true, bool mipmaps = false);
  unsigned id() const { return id_; }
  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return id_ == 0 || width_ == 0; }

 private:
  unsigned id_ = 0;
  int width_ = 0, height_ = 0;
  uint64_t version_ = UINT64_MAX;
};

// Textures by name ("frame", "stage:otsu", "warp:12"...). Textures not asked for during a number of UI frames
// are freed, so a closed panel costs no GPU memory.
class TextureCache {
 public:
  Texture& get(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest = true,
              bool mipmaps = false);
  // Call once per UI frame, after drawing.
  void end_frame(int keep_frames = 120);
  size_t size() const { return entries_.size(); }
  // What the uploads cost since the cache was made: how many, their bytes, and the time spent in them (glTexImage
  // copies the pixels; a software renderer converts them too).
  struct Uploads {
    int64_t count = 0;
    double bytes = 0, ms = 0;
  };
  const Uploads& uploads() const { return uploads_; }

 private:
  struct Entry {
    Texture texture;
    uint64_t last_used = 0;
  };
  std::unordered_map<std::string, Entry> entries_;
  uint64_t frame_ = 0;
  Uploads uploads_;
};

// The current framebuffer's pixels (the window's back buffer after drawing), BGR, top row first.
cv::Mat read_framebuffer(int width, int height);

}  // namespace arwb::render
