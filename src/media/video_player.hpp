// The media store's video players (MediaStore::video): capture's VideoReader behind a clock the scene sets.
// Live mode decodes on the player's own thread, paced by the video's rate; offline mode decodes in set_clock.
#pragma once

#include "media/media_store.hpp"

#include <memory>
#include <string>

namespace arwb::media {

// See MediaStore::video.
std::shared_ptr<VideoContent> open_video_player(const std::string& path, bool loop, StoreMode mode,
                                                std::string* error);

}  // namespace arwb::media
