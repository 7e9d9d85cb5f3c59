// The pictures of text and web cards, drawn with cairo (MediaStore::text_card and web_card cache them).
#pragma once

#include "track/media_spec.hpp"

#include <opencv2/core.hpp>

namespace arwb::media {

// The text in spec.font_px, spec.colour on spec.background, as BGRA; see MediaStore::text_card.
cv::Mat draw_text_card(const MediaSpec& spec);
// The globe, the title and the URL, kWebCardWidth x kWebCardHeight BGRA; see MediaStore::web_card.
cv::Mat draw_web_card(const MediaSpec& spec);

}  // namespace arwb::media
