#include "media/contents.hpp"

#include <atomic>

namespace arwb::media {

uint64_t next_version() {
  static std::atomic<uint64_t> versions{0};
  return ++versions;
}

}  // namespace arwb::media
