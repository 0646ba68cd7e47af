// viz/viewer_hud: the live plots' axes end on round numbers, so that their
// grid lines are labelled 0, 20, 40 rather than 0, 12.05, 24.09 (issue 31).
// No window: the arithmetic only.
#include "viz/viewer_hud.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vmh::viz {
namespace {

// every grid line (top / intervals * k) a multiple of 1, 2, 2.5 or 5 times a
// power of ten, the top at or above the data and less than 2.5 times it
TEST(ViewerHud, AxisTopsAreRoundAndHoldTheData) {
  for (double max : {36.14, 24.09, 0.011, 0.021, 3.3, 1.0, 7.0, 1234.5, 9.99e-4}) {
    for (int n : {2, 4, 5}) {
      SCOPED_TRACE(std::to_string(max) + " over " + std::to_string(n));
      const double top = round_axis_top(max, n);
      EXPECT_GE(top, max);
      EXPECT_LT(top, 2.5 * max);
      const double step = top / n;
      const double p = std::pow(10.0, std::floor(std::log10(step) + 1e-9));
      const double m = step / p;
      EXPECT_TRUE(std::abs(m - 1) < 1e-9 || std::abs(m - 2) < 1e-9 ||
                  std::abs(m - 2.5) < 1e-9 || std::abs(m - 5) < 1e-9)
          << "step " << step;
    }
  }
  EXPECT_EQ(round_axis_top(36.14, 4), 40.0);
  EXPECT_EQ(round_axis_top(36.14, 2), 40.0);
  EXPECT_EQ(round_axis_top(0.0, 4), 1.0);
  EXPECT_EQ(round_axis_top(std::nan(""), 4), 1.0);
}

}  // namespace
}  // namespace vmh::viz
