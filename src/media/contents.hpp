// A still picture as MediaContent (an image, a card, a frame's stage picture), and the one counter the media
// store's versions come from.
#pragma once

#include "track/media_spec.hpp"

#include <cstdint>
#include <memory>
#include <utility>

namespace arwb::media {

// Every picture any content of the store publishes takes the next number: versions grow within a content and
// are never shared between contents, so a texture cache keyed by a content's address cannot take a new content
// allocated at a recycled address (a new card, a new player) for the old one.
uint64_t next_version();

// One picture that never changes.
class StillContent final : public MediaContent {
 public:
  // An image or a card: a new version from next_version().
  explicit StillContent(cv::Mat pixels)
      : pixels_(std::make_shared<const cv::Mat>(std::move(pixels))), version_(next_version()) {}
  // A picture versioned by its owner (a frame's stage picture keeps the frame's version, so a texture of it is
  // uploaded once per frame, however often the scene asks).
  StillContent(std::shared_ptr<const cv::Mat> pixels, uint64_t version)
      : pixels_(std::move(pixels)), version_(version) {}
  cv::Size size() const override { return pixels_->size(); }
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const override {
    if (version) *version = version_;
    return pixels_;
  }

 private:
  std::shared_ptr<const cv::Mat> pixels_;
  uint64_t version_;
};

}  // namespace arwb::media
