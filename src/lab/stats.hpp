// Rates with their uncertainty: the Wilson score interval, which stays inside [0, 1] and behaves at 0 and 100 %
// (where the normal approximation's interval collapses to a point).
#pragma once

#include <utility>

namespace arwb::lab {

// The 95 % Wilson interval (z = 1.96) of `successes` out of `trials`; (0, 1) for no trials.
std::pair<double, double> wilson_interval(int successes, int trials, double z = 1.959964);

}  // namespace arwb::lab
