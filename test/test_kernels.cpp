// SPDX-License-Identifier: BSD-3-Clause
// detail/kernels.h, the hot loops of the classifier: sinCos against std::sin and std::cos over
// many quadrants and beyond its reduction range. The other loops are checked through the fits
// they compute (test_robust_classifier, test_separator_fit, test_point_probabilities).
#include <pcl_probcollision/detail/kernels.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace pcl_probcollision;

TEST (Kernels, VectorisedSinCosMatchesTheLibrary)
{
  std::vector<double> z, s, c;
  for (int k = -200000; k <= 200000; ++k)
    z.push_back (k * 1e-3 + 1e-7 * k);  // |z| up to ~200, covers many quadrants
  z.push_back (3e5);                      // beyond the reduction range: library path
  z.push_back (-1e6);
  s.resize (z.size ());
  c.resize (z.size ());
  detail::sinCos (z.data (), s.data (), c.data (), z.size ());
  double worst = 0.0;
  for (std::size_t i = 0; i < z.size (); ++i)
    worst = std::max ({worst, std::abs (s[i] - std::sin (z[i])), std::abs (c[i] - std::cos (z[i]))});
  EXPECT_LT (worst, 4.5e-16);  // a few ulp of numbers below 1
}
