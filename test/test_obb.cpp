// SPDX-License-Identifier: BSD-3-Clause
// detail/obb.h: the oriented box's separating-axis test (METHOD.md 8.3), with and without a
// margin, and the box fitted around Gaussian points. Oracles: boxes separated or overlapping by
// construction, an independent vertex-projection SAT, and sampled common points.
#include <pcl_probcollision/detail/obb.h>
#include <pcl_probcollision/uncertain_points.h>

#include <gtest/gtest.h>

#include "scenes.h"
#include "seeded_draws.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using detail::OrientedBox;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::randomPose;
using pcl_probcollision_test::randomRotation;
using pcl_probcollision_test::Shape;
using pcl_probcollision_test::shapeCloud;

namespace
{
// Vertex-projection separating-axis check in frame A: an independent implementation of the
// SAT over the 15 candidate axes. Returns the largest normalised gap over the axes (> 0:
// separated by that much; < 0: every axis overlaps by at least |gap|).
double
bruteSeparationGap (const OrientedBox& a, const OrientedBox& b_in_a)
{
  const Eigen::Matrix<double, 3, 8> ca = a.corners ();
  const Eigen::Matrix<double, 3, 8> cb = b_in_a.corners ();
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i)
  {
    axes.push_back (a.axes ().col (i));
    axes.push_back (b_in_a.axes ().col (i));
    for (int j = 0; j < 3; ++j)
    {
      const Eigen::Vector3d c = a.axes ().col (i).cross (b_in_a.axes ().col (j));
      if (c.norm () > 1e-6)
        axes.push_back (c.normalized ());
    }
  }
  double best = -std::numeric_limits<double>::infinity ();
  for (const auto& L : axes)
  {
    const Eigen::Matrix<double, 1, 8> pa = L.transpose () * ca;
    const Eigen::Matrix<double, 1, 8> pb = L.transpose () * cb;
    const double gap = std::max (pb.minCoeff () - pa.maxCoeff (), pa.minCoeff () - pb.maxCoeff ());
    best = std::max (best, gap);
  }
  return best;
}

OrientedBox
randomBox (std::mt19937_64& rng, bool allow_flat)
{
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  std::uniform_real_distribution<double> h (0.0, 1.0);
  OrientedBox b;
  b.center = draw3 (u, rng);
  b.setAxes (randomRotation (rng));
  b.setHalfExtents (draw3 (h, rng));
  if (allow_flat && h (rng) < 0.3)
    b.half_extents (static_cast<int> (3 * h (rng)) % 3) = 0.0;
  return b;
}
} // namespace

TEST (OrientedBox, KeepsTwoAxesAndImpliesTheThird)
{
  // The box stores the first two columns of its frame; axes() completes them to a rotation,
  // boxCoordinates() and transformed() agree with it, and a reflection given to setAxes() comes
  // back as the rotation with the same first two columns.
  std::mt19937_64 rng (17);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial)
  {
    Eigen::Matrix3d given = randomRotation (rng);
    if (trial % 2)
      given.col (2) = -given.col (2);
    OrientedBox b;
    b.center = draw3 (u, rng);
    b.setAxes (given);
    const Eigen::Matrix3d A = b.axes ();
    EXPECT_TRUE (A.leftCols<2> () == given.leftCols<2> ());
    EXPECT_NEAR ((A.transpose () * A - Eigen::Matrix3d::Identity ()).norm (), 0.0, 1e-14);
    EXPECT_NEAR (A.determinant (), 1.0, 1e-14);
    const Eigen::Vector3d p = draw3 (u, rng);
    EXPECT_NEAR ((b.boxCoordinates (p) - A.transpose () * (p - b.center)).norm (), 0.0, 1e-14);
    const Eigen::Isometry3d T = randomPose (rng, 1.0);
    EXPECT_NEAR ((b.transformed (T).axes () - T.linear () * A).norm (), 0.0, 1e-14);
  }
}

TEST (OrientedBox, SeparatedByConstructionAreDisjoint)
{
  std::mt19937_64 rng (11);
  std::uniform_real_distribution<double> gap_dist (1e-3, 0.5);
  std::normal_distribution<double> g (0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    Eigen::Isometry3d T = randomPose (rng, 1.0);
    // Push B along a random direction n until its support leaves A's by `gap`.
    const Eigen::Vector3d n = draw3 (g, rng).normalized ();
    const OrientedBox b_in_a = b.transformed (T);
    const double top_a = n.dot (a.center) + (a.axes ().transpose () * n).cwiseAbs ().dot (a.halfExtents ());
    const double bottom_b = n.dot (b_in_a.center) - (b_in_a.axes ().transpose () * n).cwiseAbs ().dot (b.halfExtents ());
    const double gap = gap_dist (rng);
    T.translation () += (top_a - bottom_b + gap) * n;
    EXPECT_TRUE (detail::disjoint (a, b, T)) << "trial " << trial;
    // Growing both boxes by m raises each support by at most sqrt(3) m.
    EXPECT_TRUE (detail::disjoint (a, b, T, gap / (4.0 * std::sqrt (3.0)))) << "trial " << trial;
    // Growing them past the gap along n makes them overlap on that axis; a large margin
    // overlaps on every axis.
    EXPECT_FALSE (detail::disjoint (a, b, T, 10.0)) << "trial " << trial;
    // Symmetry: B against A under the inverse pose.
    EXPECT_TRUE (detail::disjoint (b, a, T.inverse ())) << "trial " << trial;
  }
}

TEST (OrientedBox, OverlappingByConstructionAreNotDisjoint)
{
  std::mt19937_64 rng (12);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    // A point of B (its local coordinates) placed on a point of A: they share it.
    const Eigen::Vector3d pa = a.center + a.axes () * draw3 (u, rng).cwiseProduct (a.halfExtents ());
    const Eigen::Vector3d pb = b.center + b.axes () * draw3 (u, rng).cwiseProduct (b.halfExtents ());
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
    T.linear () = randomRotation (rng);
    T.translation () = pa - T.linear () * pb;
    ASSERT_TRUE (a.contains (T * pb, 1e-12));
    EXPECT_FALSE (detail::disjoint (a, b, T)) << "trial " << trial;
    EXPECT_FALSE (detail::disjoint (b, a, T.inverse ())) << "trial " << trial;
  }
  // Degenerate: two zero-thickness squares crossing at right angles, and two collinear
  // segments sharing a piece.
  OrientedBox sq_a, sq_b;
  sq_a.setHalfExtents (Eigen::Vector3d (1, 1, 0));
  sq_b.setHalfExtents (Eigen::Vector3d (1, 1, 0));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.linear () = Eigen::AngleAxisd (M_PI / 2, Eigen::Vector3d::UnitX ()).toRotationMatrix ();
  EXPECT_FALSE (detail::disjoint (sq_a, sq_b, T));
  OrientedBox seg;
  seg.setHalfExtents (Eigen::Vector3d (1, 0, 0));
  T = Eigen::Isometry3d::Identity ();
  T.translation () = Eigen::Vector3d (1.5, 0, 0);
  EXPECT_FALSE (detail::disjoint (seg, seg, T));
  T.translation () = Eigen::Vector3d (2.5, 0, 0);
  EXPECT_TRUE (detail::disjoint (seg, seg, T));
}

TEST (OrientedBox, AgreesWithVertexProjectionOracle)
{
  // Random poses near contact; compared with an independent vertex-projection SAT wherever the
  // decision is clear by more than 1e-6 (near-ties are not a property of either algorithm).
  std::mt19937_64 rng (13);
  int separated = 0, overlapping = 0;
  for (int trial = 0; trial < 5000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    const Eigen::Isometry3d T = randomPose (rng, 1.5);
    const double gap = bruteSeparationGap (a, b.transformed (T));
    const bool sat = detail::disjoint (a, b, T);
    if (gap > 1e-6)
    {
      ++separated;
      EXPECT_TRUE (sat) << "trial " << trial << " gap " << gap;
    }
    else if (gap < -1e-6)
    {
      ++overlapping;
      EXPECT_FALSE (sat) << "trial " << trial << " gap " << gap;
      // A sampled point of B inside A can only happen for overlapping boxes.
    }
    // Margin m is the same as growing the boxes.
    OrientedBox ag = a, bg = b;
    ag.setHalfExtents (ag.halfExtents ().array () + 0.1);
    bg.setHalfExtents (bg.halfExtents ().array () + 0.1);
    const double gap_m = bruteSeparationGap (ag, bg.transformed (T));
    if (std::abs (gap_m) > 1e-6)
    {
      EXPECT_EQ (detail::disjoint (a, b, T, 0.1), gap_m > 0) << "trial " << trial;
    }
  }
  EXPECT_GT (separated, 500);
  EXPECT_GT (overlapping, 500);
}

TEST (OrientedBox, SampledCommonPointImpliesOverlap)
{
  // Dense sampling can only prove overlap: any sample of B inside A forbids "disjoint".
  std::mt19937_64 rng (14);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  int proven = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const OrientedBox a = randomBox (rng, false);
    const OrientedBox b = randomBox (rng, false);
    const Eigen::Isometry3d T = randomPose (rng, 1.5);
    bool common = false;
    for (int s = 0; s < 400 && !common; ++s)
    {
      const Eigen::Vector3d pb = b.center + b.axes () * draw3 (u, rng).cwiseProduct (b.halfExtents ());
      common = a.contains (T * pb);
    }
    if (common)
    {
      ++proven;
      EXPECT_FALSE (detail::disjoint (a, b, T)) << "trial " << trial;
    }
  }
  EXPECT_GT (proven, 50);
}

TEST (OrientedBox, FitContainsInflatedPoints)
{
  std::mt19937_64 rng (15);
  const UncertainCloud c = shapeCloud (Shape::Sphere, 200, 16, 0.01);
  const Eigen::Matrix3d axes = randomRotation (rng);
  const OrientedBox box = detail::fitOrientedBox (axes, c.means.data (), c.covariances.data (), nullptr, c.size (), 2.0);
  for (std::size_t j = 0; j < c.size (); ++j)
    for (int k = 0; k < 3; ++k)
    {
      const Eigen::Vector3d a = axes.col (k);
      const double s = std::sqrt (a.dot (c.covariances[j] * a));
      EXPECT_LE (std::abs (a.dot (c.means[j] - box.center)) + 2.0 * s, box.half_extents (k) + 1e-12);
    }
  // Tight: on each axis some point touches each face.
  for (int k = 0; k < 3; ++k)
  {
    double top = -1e300;
    for (std::size_t j = 0; j < c.size (); ++j)
    {
      const Eigen::Vector3d a = axes.col (k);
      top = std::max (top, a.dot (c.means[j] - box.center) + 2.0 * std::sqrt (a.dot (c.covariances[j] * a)));
    }
    // Tight up to the float the extent is stored in (rounded up: OrientedBox::setHalfExtents).
    EXPECT_NEAR (top, box.half_extents (k), 1e-12 + std::ldexp (std::abs (top), -22));
  }
}
