// The phone player core's media (recording_media.hpp).
#include "recording_media.hpp"

#include "capture/image_header.hpp"
#include "media/media_store.hpp"

namespace arwb::web {

void RecordingMedia::set_video(const std::string& path, cv::Size size, double duration_s) {
  videos_[path] = {size, duration_s};
}

std::shared_ptr<MediaContent> RecordingMedia::image(const std::string& path, std::string* error) {
  std::string reason;
  const std::optional<ImageHeader> h = read_image_header(path, &reason);
  if (!h) {
    if (error) *error = path + ": " + reason;
    return nullptr;
  }
  if (error) error->clear();
  return std::make_shared<SizedContent>(cv::Size(h->width, h->height), path);
}

std::shared_ptr<media::VideoContent> RecordingMedia::video(const std::string& path, bool loop, std::string* error) {
  const auto it = videos_.find(path);
  if (it == videos_.end() || it->second.size.width <= 0 || it->second.size.height <= 0) {
    if (error) *error = path + ": the page has not said the video's size (it reads it before the scene starts)";
    return nullptr;
  }
  if (error) error->clear();
  return std::make_shared<RecordedVideo>(it->second.size, it->second.duration_s, loop);
}

std::shared_ptr<MediaContent> RecordingMedia::text_card(const MediaSpec& spec) {
  return std::make_shared<CardContent>(media::layout_text_card(spec));
}

std::shared_ptr<MediaContent> RecordingMedia::web_card(const MediaSpec&) {
  return std::make_shared<SizedContent>(
      cv::Size(media::MediaStore::kWebCardWidth, media::MediaStore::kWebCardHeight));
}

// The desktop's loader and checks (media/model_file.hpp); its textures stay encoded (model_texture.cpp here).
std::shared_ptr<const Mesh> RecordingMedia::model(const std::filesystem::path& scene_dir, const std::string& relative,
                                                  std::string* error, std::string* warning) {
  return models_.get(scene_dir, relative, error, warning);
}

}  // namespace arwb::web
