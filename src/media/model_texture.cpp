// A model's texture decoded into pixels for the desktop (model_loader.hpp's Context::decode_texture). The phone
// player's core compiles its own definition instead (web/core/model_texture.cpp), which keeps the bytes for the
// page's browser to decode: that core has no image decoders.
#include "media/model_loader.hpp"

#include "capture/image_io.hpp"
#include "capture/pixels.hpp"
#include "media/contents.hpp"
#include "media/media_path.hpp"

namespace arwb::media::model {

// decode_image checks the signature, the header and the limits before OpenCV allocates anything.
std::shared_ptr<MediaContent> Context::decode_texture(std::span<const uint8_t> bytes, const std::string& shown,
                                                      const std::string& what) {
  LoadedImage image = decode_image(bytes, shown, cv::IMREAD_UNCHANGED, kMaxMediaPixels);
  if (!image.ok()) {
    warnings.push_back(name + ": " + what + ": " + image.error);
    return nullptr;
  }
  return std::make_shared<StillContent>(to_bgr8(image.image, Alpha::keep));
}

}  // namespace arwb::media::model
