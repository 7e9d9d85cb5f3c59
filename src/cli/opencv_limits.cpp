#include "cli/opencv_limits.hpp"

#include "capture/image_io.hpp"

#include <cstdlib>
#include <string>
#include <utility>

namespace arwb {

bool set_opencv_image_limits() {
  const std::string side = std::to_string(kMaxImageSide), pixels = std::to_string(kDefaultMaxPixels);
  bool set = false;
  for (const auto& [name, value] : {std::pair{"OPENCV_IO_MAX_IMAGE_WIDTH", &side},
                                    std::pair{"OPENCV_IO_MAX_IMAGE_HEIGHT", &side},
                                    std::pair{"OPENCV_IO_MAX_IMAGE_PIXELS", &pixels}})
    if (!std::getenv(name) && setenv(name, value->c_str(), 0) == 0) set = true;
  return set;
}

}  // namespace arwb
