// A model's texture in the phone player's core (media/model_loader.hpp's Context::decode_texture; the desktop's is
// src/media/model_texture.cpp): the core has no image decoders, so the bytes are kept for the page, whose browser
// decodes them. They are checked first as the desktop checks them before decoding, with the same messages.
#include "media/model_loader.hpp"

#include "capture/image_header.hpp"
#include "media/media_path.hpp"
#include "recording_media.hpp"

namespace arwb::media::model {

std::shared_ptr<MediaContent> Context::decode_texture(std::span<const uint8_t> bytes, const std::string& shown,
                                                      const std::string& what) {
  const auto warn = [&](const std::string& reason) {
    warnings.push_back(name + ": " + what + ": " + shown + ": " + reason);
    return nullptr;
  };
  if (bytes.empty()) return warn("empty file (0 bytes)");
  std::string reason;
  const std::optional<ImageHeader> header = parse_image_header(bytes, &reason);
  if (!header) return warn(reason);
  if (!(reason = image_limit_error(*header, kMaxMediaPixels)).empty()) return warn(reason);
  if (!(reason = phone_picture_problem(*header)).empty()) return warn(reason);
  return std::make_shared<web::EncodedPicture>(cv::Size(header->width, header->height),
                                               std::vector<uint8_t>(bytes.begin(), bytes.end()));
}

}  // namespace arwb::media::model
