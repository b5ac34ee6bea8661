// SPDX-License-Identifier: BSD-3-Clause
// detail/leakage.h: the probability that a Gaussian point lies outside a box (METHOD.md 8.4,
// 11.7), its tabulated normal tail, the leakage a hierarchy node stores (the area-weighted
// mean over its points) and the build's per-point passes that compute it (detail/node_kernels.h).
// Oracles: closed forms in Phi from std::erfc.
#include <pcl_probcollision/detail/leakage.h>
#include <pcl_probcollision/detail/node_kernels.h>
#include <pcl_probcollision/detail/obb.h>
#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/probabilistic_bvh.h>

#include <gtest/gtest.h>

#include "scenes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace pcl_probcollision;
using detail::OrientedBox;
using pcl_probcollision_test::Phi;
using pcl_probcollision_test::randomPose;

TEST (Leakage, PointOracles)
{
  // Box [-0.05, 0.05]^3, isotropic sigma = 0.01 (METHOD.md 11.7). The box keeps its half
  // extents in float: h = 0.05f, and the exact forms below use h.
  OrientedBox box;
  box.half_extents = Eigen::Vector3f::Constant (0.05f);
  const double h = box.half_extents (0);
  const Eigen::Matrix3d cov = Eigen::Matrix3d::Identity () * 1e-4;
  // Centre: 2 Phi(-5) = 5.733e-7 (exact form; relative accuracy).
  const double centre = detail::pointOutsideProbability (box, Eigen::Vector3d::Zero (), cov);
  EXPECT_NEAR (centre, 2.0 * Phi (-h / 0.01), 1e-15);
  EXPECT_NEAR (centre, 5.733e-7, 1e-10);
  // 0.01 inside a face: Phi(-1) + Phi(-9) = 0.158655.
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0, 0.04), cov), 0.158655, 1e-6);
  // On a face: 0.5 + Phi(-10) ~ 0.5.
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (h, 0, 0), cov), 0.5, 1e-12);
  // Union bound at the centre: 3 * 2 Phi(-5).
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d::Zero (), cov, detail::LeakageBound::UnionBound),
               6.0 * Phi (-h / 0.01), 1e-15);
  // Rotating box and point together changes nothing.
  std::mt19937_64 rng (3);
  Eigen::Isometry3d T = randomPose (rng, 2.0);
  const OrientedBox moved = box.transformed (T);
  EXPECT_NEAR (detail::pointOutsideProbability (moved, T * Eigen::Vector3d (0, 0, 0.04),
                                                T.linear () * cov * T.linear ().transpose ()),
               0.158655, 1e-6);
  // Zero covariance: the indicator of being outside.
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0.05, 0, 0), Eigen::Matrix3d::Zero ()), 0.0);
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0.0501, 0, 0), Eigen::Matrix3d::Zero ()), 1.0);
  // Degenerate along one axis only: that slab is an indicator, the others are Gaussian.
  Eigen::Matrix3d flat = Eigen::Vector3d (1e-4, 1e-4, 0.0).asDiagonal ();
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0.04, 0.0), flat), 0.158655, 1e-6);
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0, 0.06), flat), 1.0);
}

// The build's tabulated tail against erfc: absolute error below 1e-11 everywhere.
TEST (Leakage, TabulatedTailMatchesErfc)
{
  double worst = 0.0;
  for (int i = -20000; i <= 24000; ++i)
  {
    const double z = i * 5.123e-4;  // not on the table's grid
    const double exact = normalCdf (-z);
    const double tab = detail::normalTailTabulated (z);
    worst = std::max (worst, std::abs (tab - exact));
    ASSERT_GE (tab, -1e-11) << z;
    ASSERT_LE (tab, 1.0 + 1e-11) << z;
  }
  EXPECT_LT (worst, 1e-11);
  EXPECT_GT (worst, 0.0);  // it is an approximation: the test would notice erfc in its place
  EXPECT_EQ (detail::normalTailTabulated (0.0), 0.5);
  EXPECT_EQ (detail::normalTailTabulated (10.0), 0.0);
  EXPECT_EQ (detail::normalTailTabulated (1e300), 0.0);
  EXPECT_EQ (detail::normalTailTabulated (-1e300), 1.0);
  EXPECT_TRUE (std::isnan (detail::normalTailTabulated (std::numeric_limits<double>::quiet_NaN ())));
}

TEST (Leakage, SinglePointNodeOracle)
{
  // One point, isotropic sigma, box inflated by k_sigma = 1: the point sits at the centre of a
  // cube of half extent sigma, so leakage = 1 - (Phi(1) - Phi(-1)) = 2 Phi(-1) = 0.317311.
  // sigma = 2^-7, so that the variance is exact in the float the hierarchy keeps.
  constexpr double sigma = 0x1p-7;
  UncertainCloud c;
  c.means.push_back (Eigen::Vector3d (1, 2, 3));
  c.covariances.push_back (Eigen::Matrix3d::Identity () * sigma * sigma);
  ProbabilisticBVH bvh (c);
  ASSERT_EQ (bvh.nodes ().size (), 1u);
  // The node keeps its leakage in single precision (ProbabilisticBVH::Node).
  EXPECT_FLOAT_EQ (bvh.node (0).leakage, static_cast<float> (2.0 * Phi (-1.0)));
  // (The extents one float step above sigma: stored rounded up, OrientedBox::setHalfExtents.)
  EXPECT_NEAR (bvh.node (0).box.half_extents.maxCoeff (), sigma, std::ldexp (sigma, -22));
  EXPECT_NEAR (bvh.node (0).box.half_extents.minCoeff (), sigma, std::ldexp (sigma, -22));
  EXPECT_GE (bvh.node (0).box.half_extents.minCoeff (), sigma);
  // k_sigma = 3: 2 Phi(-h / sigma), h = 3 sigma rounded up to the next float: 2 Phi(-3) to
  // within 2e-6 of its value.
  BVHParams p;
  p.k_sigma = 3.0;
  bvh.build (c, p);
  const double h = bvh.node (0).box.half_extents (0);
  EXPECT_FLOAT_EQ (bvh.node (0).leakage, static_cast<float> (2.0 * Phi (-h / sigma)));
  EXPECT_NEAR (bvh.node (0).leakage, 2.0 * Phi (-3.0), 2e-6 * 2.0 * Phi (-3.0));
}

TEST (Leakage, AreaWeightsWeightTheMean)
{
  // Two points in one leaf: one exact (P_x = 0), one noisy; weights move the node's leakage.
  UncertainCloud c;
  c.means = {Eigen::Vector3d (0, 0, 0), Eigen::Vector3d (1, 0, 0)};
  c.covariances = {Eigen::Matrix3d::Zero (), Eigen::Matrix3d::Identity () * 0x1p-14};  // exact in float
  ProbabilisticBVH equal (c);
  const double p_noisy = detail::pointOutsideProbability (equal.node (0).box, c.means[1], c.covariances[1]);
  EXPECT_GT (p_noisy, 0.1);
  EXPECT_FLOAT_EQ (equal.node (0).leakage, static_cast<float> (0.5 * p_noisy));
  c.area_weights = {3.0, 1.0};
  ProbabilisticBVH weighted (c);
  EXPECT_FLOAT_EQ (weighted.node (0).leakage, static_cast<float> (0.25 * p_noisy));
  c.area_weights = {0.0, 0.0};  // no area information: equal weights
  ProbabilisticBVH zero (c);
  EXPECT_FLOAT_EQ (zero.node (0).leakage, static_cast<float> (0.5 * p_noisy));
}

TEST (Leakage, NodeKernelsMatchTheirDefinitions)
{
  // detail::nodeProjections and nodeOutside (the build's vectorised per-point passes, in the
  // clone this machine runs) against their definitions point by point: 1,003 points (not a
  // multiple of the lanes), every eleventh with a zero covariance, some repeated.
  std::mt19937_64 rng (17);
  std::normal_distribution<double> g;
  const std::size_t m = 1003;
  std::vector<Eigen::Vector3d> means;
  std::vector<PackedCovariance> covariances;
  std::vector<int> points;
  for (std::size_t i = 0; i < m; ++i)
  {
    means.push_back (i % 13 == 5 ? means.back () : Eigen::Vector3d (g (rng), 0.3 * g (rng), 0.01 * g (rng)));
    Eigen::Matrix3d a;
    for (int r = 0; r < 9; ++r)
      a (r / 3, r % 3) = 0.01 * g (rng);
    covariances.emplace_back (i % 11 == 0 ? Eigen::Matrix3d::Zero () : Eigen::Matrix3d (a * a.transpose ()));
    points.push_back (static_cast<int> (i));
  }
  std::shuffle (points.begin (), points.end (), rng);
  const Eigen::Vector3d mean (0.1, -0.2, 0.05);
  const Eigen::Matrix3d axes = Eigen::Quaterniond (0.9, 0.2, -0.3, 0.1).normalized ().toRotationMatrix ();
  const double k_sigma = 1.5;
  std::vector<double> q[3], s[3];
  for (int k = 0; k < 3; ++k)
  {
    q[k].resize (m);
    s[k].resize (m);
  }
  detail::NodeExtents e;
  detail::nodeProjections (m, points.data (), means.data ()->data (), covariances.data (), mean, axes, k_sigma,
                           q[0].data (), q[1].data (), q[2].data (), s[0].data (), s[1].data (), s[2].data (), e);
  for (int k = 0; k < 3; ++k)
  {
    double lo = std::numeric_limits<double>::infinity (), hi = -lo, q_min = lo, q_max = -lo, s_max = 0.0;
    for (std::size_t i = 0; i < m; ++i)
    {
      const std::size_t p = static_cast<std::size_t> (points[i]);
      EXPECT_NEAR (q[k][i], axes.col (k).dot (means[p] - mean), 1e-14);
      EXPECT_EQ (s[k][i], std::sqrt (std::max (0.0, covariances[p].quadratic (axes.col (k)))));
      lo = std::min (lo, q[k][i] - k_sigma * s[k][i]);
      hi = std::max (hi, q[k][i] + k_sigma * s[k][i]);
      q_min = std::min (q_min, q[k][i]);
      q_max = std::max (q_max, q[k][i]);
      s_max = std::max (s_max, s[k][i]);
    }
    EXPECT_EQ (e.lo[k], lo);
    EXPECT_EQ (e.hi[k], hi);
    EXPECT_EQ (e.q_min[k], q_min);
    EXPECT_EQ (e.q_max[k], q_max);
    EXPECT_EQ (e.s_max[k], s_max);
    EXPECT_GT (s_max, 0.0);
  }
  // P_x per point: per axis Phi(-z_lo) + Phi(-z_hi) from erfc, the maximum over the axes
  // (MinSlab) or their sum (UnionBound); the table's tails are within 1e-11 of erfc's.
  for (const auto bound : {detail::LeakageBound::MinSlab, detail::LeakageBound::UnionBound})
  {
    std::vector<double> out (m);
    detail::nodeOutside (m, q[0].data (), q[1].data (), q[2].data (), s[0].data (), s[1].data (), s[2].data (), e.lo,
                         e.hi, bound, out.data ());
    std::size_t exact = 0;
    for (std::size_t i = 0; i < m; ++i)
    {
      double axis[3];
      for (int k = 0; k < 3; ++k)
        axis[k] = s[k][i] > 0.0 ? std::min (1.0, Phi (-(q[k][i] - e.lo[k]) / s[k][i]) + Phi (-(e.hi[k] - q[k][i]) / s[k][i]))
                                : 0.0;
      const double expected = bound == detail::LeakageBound::MinSlab ? std::max ({axis[0], axis[1], axis[2]})
                                                                     : std::min (1.0, axis[0] + axis[1] + axis[2]);
      EXPECT_NEAR (out[i], expected, 1e-10) << "point " << i;
      exact += out[i] == 0.0;
    }
    EXPECT_GE (exact, m / 11);  // the points without a deviation: P_x = 0
  }
}
