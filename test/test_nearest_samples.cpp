// SPDX-License-Identifier: BSD-3-Clause
// src/nearest_samples.h, private to the library: the nearest sample of a hierarchy to a point
// must be the one a pass over every mean finds, index included (the depth of a deep point and
// the normal it reports come from it).
#include "nearest_samples.h"

#include "scenes.h"

#include <pcl_probcollision/probabilistic_bvh.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using namespace pcl_probcollision_test;

namespace
{
/** \brief The pass over every mean in index order that nearestSample() replaces. */
detail::NearestSample
bruteForce (const ProbabilisticBVH& bvh, const Eigen::Vector3d& x)
{
  detail::NearestSample out;
  double best2 = std::numeric_limits<double>::infinity ();
  for (std::size_t i = 0; i < bvh.means ().size (); ++i)
    if (const double d2 = (bvh.means ()[i] - x).squaredNorm (); d2 < best2)
    {
      best2 = d2;
      out.index = static_cast<int> (i);
    }
  out.distance = std::sqrt (best2);
  return out;
}
} // namespace

// Queries inside, beside and far from three shapes, and on samples themselves: the same index
// and the same distance to the last bit.
TEST (NearestSample, EqualsThePassOverEveryMean)
{
  std::mt19937_64 rng (5);
  std::normal_distribution<double> normal (0.0, 1.0);
  for (const Shape shape : {Shape::Box, Shape::Sphere, Shape::NoisyPlane})
  {
    const ProbabilisticBVH bvh (shapeCloud (shape, 3000, 17));
    ASSERT_EQ (bvh.means ().size (), 3000u);
    for (int q = 0; q < 600; ++q)
    {
      const double scale = q < 200 ? 0.3 : q < 400 ? 1.0 : 20.0;
      Eigen::Vector3d x (normal (rng), normal (rng), normal (rng));
      x *= scale;
      if (q % 50 == 0)
        x = bvh.means ()[static_cast<std::size_t> (q)];  // on a sample: distance 0
      const detail::NearestSample expected = bruteForce (bvh, x);
      const detail::NearestSample found = detail::nearestSample (bvh, x);
      EXPECT_EQ (found.index, expected.index) << shapeName (shape) << " query " << q;
      EXPECT_EQ (found.distance, expected.distance) << shapeName (shape) << " query " << q;
    }
  }
}

// Equal distances: a grid of duplicated samples (each point twice, at indices i and i + n) and
// queries at grid points and at the centres between them, where several samples are exactly as
// near. The lowest index among them is the one reported, as the pass over the means reports it.
TEST (NearestSample, TiesGoToTheLowestIndex)
{
  UncertainCloud grid = jitteredGrid (20, 0.01, 0.001, 3);
  const std::size_t n = grid.means.size ();
  for (std::size_t i = 0; i < n; ++i)
  {
    grid.means.push_back (grid.means[i]);
    grid.covariances.push_back (grid.covariances[i]);
    grid.source_indices.push_back (static_cast<int> (n + i));
  }
  const ProbabilisticBVH bvh (grid);
  ASSERT_EQ (bvh.means ().size (), 2 * n);
  int ties = 0;
  for (int ix = 2; ix < 17; ++ix)
    for (int iy = 2; iy < 17; ++iy)
      for (const double offset : {0.0, 0.005})
      {
        const Eigen::Vector3d x = bvh.means ()[static_cast<std::size_t> (ix * 20 + iy)] + Eigen::Vector3d (offset, offset, 0.0);
        const detail::NearestSample expected = bruteForce (bvh, x);
        const detail::NearestSample found = detail::nearestSample (bvh, x);
        EXPECT_EQ (found.index, expected.index) << ix << " " << iy << " " << offset;
        EXPECT_EQ (found.distance, expected.distance);
        const double best2 = (bvh.means ()[static_cast<std::size_t> (expected.index)] - x).squaredNorm ();
        int equally_near = 0;
        for (const Eigen::Vector3d& m : bvh.means ())
          equally_near += (m - x).squaredNorm () == best2 ? 1 : 0;
        ties += equally_near >= 2 ? 1 : 0;
      }
  EXPECT_EQ (ties, 2 * 15 * 15);  // every query has a sample and its copy equally near
}

TEST (NearestSample, AnEmptyHierarchyHasNone)
{
  const ProbabilisticBVH bvh;
  const detail::NearestSample found = detail::nearestSample (bvh, Eigen::Vector3d::Zero ());
  EXPECT_EQ (found.index, -1);
  EXPECT_EQ (found.distance, std::numeric_limits<double>::infinity ());
}
