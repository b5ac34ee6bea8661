// SPDX-License-Identifier: BSD-3-Clause
// normal_distribution.h: normalCdf against references to 17 digits and in the far lower tail,
// normalQuantile against normalCdf (relative accuracy on the smaller tail) and at the ends.
#include <pcl_probcollision/normal_distribution.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace pcl_probcollision;

TEST (NormalFunctions, CdfMatchesErfcAndTails)
{
  EXPECT_EQ (normalCdf (0.0), 0.5);
  // references to 17 digits; erfc is good to a few ulp, hence 1e-15 relative
  EXPECT_NEAR (normalCdf (-1.0) / 0.15865525393145705, 1.0, 1e-15);
  EXPECT_NEAR (normalCdf (-2.0) / 0.022750131948179207, 1.0, 1e-15);
  EXPECT_NEAR (normalCdf (1.0) + normalCdf (-1.0), 1.0, 1e-16);
  // the lower tail keeps its relative precision (1 - Phi(z) would round to 0)
  EXPECT_NEAR (normalCdf (-10.0) / 7.6198530241604696e-24, 1.0, 1e-14);
  EXPECT_NEAR (normalCdf (-30.0) / 4.906713927148187e-198, 1.0, 1e-13);
  EXPECT_EQ (normalCdf (std::numeric_limits<double>::infinity ()), 1.0);
  EXPECT_EQ (normalCdf (-std::numeric_limits<double>::infinity ()), 0.0);
}

TEST (NormalFunctions, QuantileInvertsCdf)
{
  // reference: Phi^-1(0.9) = 1.2815515655446004 (gamma of the default confidence)
  EXPECT_NEAR (normalQuantile (0.9), 1.2815515655446004, 1e-15);
  EXPECT_EQ (normalQuantile (0.5), 0.0);
  for (double p : {1e-300, 1e-100, 1e-20, 1e-9, 1e-3, 0.02425, 0.1, 0.3, 0.5, 0.7, 0.97575, 0.999, 1.0 - 1e-12})
  {
    const double x = normalQuantile (p);
    // relative accuracy on the smaller tail probability; 1e-13 covers erfc's and one ulp of x
    const double tail = p < 0.5 ? p : 1.0 - p;
    const double back = p < 0.5 ? normalCdf (x) : normalCdf (-x);
    EXPECT_NEAR (back / tail, 1.0, 1e-13) << "p = " << p;
    if (1.0 - (1.0 - p) == p)  // symmetry, where 1 - p is exact
    {
      EXPECT_NEAR (normalQuantile (1.0 - p), -x, 1e-13 * std::max (1.0, std::abs (x))) << "p = " << p;
    }
  }
  EXPECT_EQ (normalQuantile (0.0), -std::numeric_limits<double>::infinity ());
  EXPECT_EQ (normalQuantile (1.0), std::numeric_limits<double>::infinity ());
  EXPECT_TRUE (std::isnan (normalQuantile (1.5)));
  EXPECT_TRUE (std::isnan (normalQuantile (-0.1)));
  EXPECT_TRUE (std::isnan (normalQuantile (std::numeric_limits<double>::quiet_NaN ())));
}
