// A picture that never changes as MediaContent, for the render tests (src/media's StillContent is above render
// in the house, so the tests have their own).
#pragma once

#include "track/media_spec.hpp"

#include <memory>
#include <utility>

namespace arwb::test {

class StillMedia : public MediaContent {
 public:
  explicit StillMedia(cv::Mat m, uint64_t version = 1)
      : m_(std::make_shared<const cv::Mat>(std::move(m))), version_(version) {}
  cv::Size size() const override { return m_->size(); }
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const override {
    if (version) *version = version_;
    return m_;
  }

 private:
  std::shared_ptr<const cv::Mat> m_;
  uint64_t version_;
};

}  // namespace arwb::test
