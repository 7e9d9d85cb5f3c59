// coarse_search: the whole frame searched again, coarser, for large markers; its contours join the first search's.
#include "detect/pipeline.hpp"

namespace arwb::stages {

std::vector<std::vector<cv::Point>> coarse_search(const cv::Mat& search, const cv::Mat& block_means, int factor,
                                                  const DetectorParams& p, cv::Mat* binary) {
  const bool from_blocks = p.coarse_factor % 2 == 0 && !block_means.empty();
  *binary = adaptive_threshold(
      from_blocks ? decimate(block_means, p.coarse_factor / 2) : decimate(search, p.coarse_factor), p);
  return find_contours(*binary, p.coarse_min_perimeter_px, nullptr, nullptr, factor);
}

}  // namespace arwb::stages
