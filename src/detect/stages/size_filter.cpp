// size_filter: drop contours too short or too long.
#include "detect/pipeline.hpp"

#include "detect/stages/rejection.hpp"

namespace arwb::stages {

std::optional<Rejection> size_filter(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                     bool explain, int factor) {
  const double perimeter = contour_length(contour, factor);
  if (perimeter < p.min_perimeter_px)
    return reject(Stage::size_filter, "min_perimeter_px", perimeter, p.min_perimeter_px,
                  explain ? fmt("perimeter %.0f px < min_perimeter_px %.0f px", perimeter, p.min_perimeter_px) : "");
  const double max_px = p.max_perimeter_rate * std::max(image.width, image.height);
  if (perimeter > max_px)
    return reject(Stage::size_filter, "max_perimeter_rate", perimeter, max_px,
                  explain ? fmt("perimeter %.0f px > max_perimeter_rate x frame = %.0f px", perimeter, max_px) : "");
  return std::nullopt;
}

}  // namespace arwb::stages
