// The phone player core's media (media::MediaProvider): it decodes and draws nothing, since the page draws every
// medium from the bundle's own files, and answers the scene with what placing them needs: each one's size (an
// image's from its header, a video's as the page's <video> read it, a web card's fixed one, a text card's from the
// desktop's layout) and, for videos, the clock the scene sets, which the page's <video> then follows.
#pragma once
#include "media/card_layout.hpp"
#include "media/media_provider.hpp"
#include "media/model_cache.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace arwb::web {

// What every medium here answers for its pixels: none, at version 0 (the page draws it from the bundle's files).
template <class Content>
class DrawnByPage : public Content {
 public:
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const final {
    if (version) *version = 0;
    return nullptr;
  }
};

// A medium the page draws: only its size is known here, and for a picture its path in the core's file system
// (a cube face's, which the page finds by it).
class SizedContent final : public DrawnByPage<MediaContent> {
 public:
  explicit SizedContent(cv::Size size, std::string path = {}) : size_(size), path_(std::move(path)) {}
  cv::Size size() const override { return size_; }
  const std::string& path() const { return path_; }

 private:
  cv::Size size_;
  std::string path_;
};

// A model's texture the page decodes (web/core/model_texture.cpp): the picture file's bytes, checked here as the
// desktop checks them before decoding (its header, its size within the limits, a format browsers show).
class EncodedPicture final : public DrawnByPage<MediaContent> {
 public:
  EncodedPicture(cv::Size size, std::vector<uint8_t> bytes) : size_(size), bytes_(std::move(bytes)) {}
  cv::Size size() const override { return size_; }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  cv::Size size_;
  std::vector<uint8_t> bytes_;
};

// A text card the page draws: laid out as the desktop lays it out (media/card_layout.hpp), so of the same size.
class CardContent final : public DrawnByPage<MediaContent> {
 public:
  explicit CardContent(media::CardLayout layout) : layout_(std::move(layout)) {}
  cv::Size size() const override { return {layout_.width, layout_.height}; }
  const media::CardLayout& layout() const { return layout_; }

 private:
  media::CardLayout layout_;
};

// A video the page plays: the scene's clock, recorded for the page.
class RecordedVideo final : public DrawnByPage<media::VideoContent> {
 public:
  RecordedVideo(cv::Size size, double duration_s, bool loop) : size_(size), duration_s_(duration_s), loop_(loop) {}
  cv::Size size() const override { return size_; }
  void set_clock(double position_s, bool playing) override {
    position_s_ = position_s >= 0 ? position_s : 0;   // negative or NaN: 0, as the desktop's player
    playing_ = playing;
  }
  double duration_s() const override { return duration_s_; }
  double fps() const override { return 25; }   // the page's <video> does not say; the scene does not ask
  uint64_t frames_decoded() const override { return 0; }
  std::string error() const override { return ""; }
  double position_s() const { return position_s_; }
  bool playing() const { return playing_; }
  bool loop() const { return loop_; }

 private:
  cv::Size size_;
  double duration_s_ = 0, position_s_ = 0;
  bool loop_ = false, playing_ = false;
};

class RecordingMedia final : public media::MediaProvider {
 public:
  // A video's size and length as the page's <video> element read them, by its path in the core's file system.
  void set_video(const std::string& path, cv::Size size, double duration_s);

  std::shared_ptr<MediaContent> image(const std::string& path, std::string* error) override;
  std::shared_ptr<media::VideoContent> video(const std::string& path, bool loop, std::string* error) override;
  std::shared_ptr<MediaContent> text_card(const MediaSpec& spec) override;
  std::shared_ptr<MediaContent> web_card(const MediaSpec& spec) override;
  std::shared_ptr<const Mesh> model(const std::filesystem::path& scene_dir, const std::string& relative,
                                    std::string* error, std::string* warning) override;
  void trim() override { models_.trim(); }

 private:
  struct VideoInfo {
    cv::Size size;
    double duration_s = 0;
  };
  std::map<std::string, VideoInfo> videos_;
  media::ModelCache models_;
};

}  // namespace arwb::web
