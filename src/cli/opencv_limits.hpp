// OpenCV's own image limits (OPENCV_IO_MAX_IMAGE_WIDTH, _HEIGHT, _PIXELS), a second fence behind load_image's
// header checks with the same values (src/capture/image_io.hpp), for any decoding that does not pass through it.
#pragma once

namespace arwb {

// Sets the variables the user has not set to capture's limits (kMaxImageSide, kDefaultMaxPixels); a user's own
// values are kept. True when it set any: OpenCV reads them once, as its library is loaded, so the process must
// start again for them to count.
bool set_opencv_image_limits();

}  // namespace arwb
