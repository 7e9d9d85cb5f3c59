#include "lab/stats.hpp"

#include <algorithm>
#include <cmath>

namespace arwb::lab {

std::pair<double, double> wilson_interval(int successes, int trials, double z) {
  if (trials <= 0) return {0.0, 1.0};
  const double n = trials, p = std::clamp(double(successes) / n, 0.0, 1.0), z2 = z * z;
  const double centre = (p + z2 / (2 * n)) / (1 + z2 / n);
  const double half = z / (1 + z2 / n) * std::sqrt(p * (1 - p) / n + z2 / (4 * n * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

}  // namespace arwb::lab
