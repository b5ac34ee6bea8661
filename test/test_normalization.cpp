// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/normalization.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <random>

using namespace pcl_probcollision;

namespace
{
UncertainCloud
randomCloud (std::size_t n, unsigned seed, double spread)
{
  std::mt19937 rng (seed);
  std::uniform_real_distribution<double> u (-spread, spread);
  UncertainCloud c;
  for (std::size_t i = 0; i < n; ++i)
  {
    const double x = u (rng);  // one draw per statement: argument order is unspecified
    const double y = u (rng);
    c.means.emplace_back (x + 3.0, y - 7.0, u (rng) + 100.0);
    Eigen::Matrix3d a = Eigen::Matrix3d::NullaryExpr ([&] () { return u (rng) * 1e-2; });
    c.covariances.push_back (a * a.transpose ());
  }
  return c;
}
} // namespace

TEST (Normalization, UniformMapsIntoTheUnitCubeAndRoundTrips)
{
  UncertainCloud a = randomCloud (50, 1, 2.0), b = randomCloud (30, 2, 0.5);
  const UnitCubeTransform t = computeUnitCubeTransform ({&a, &b});
  EXPECT_DOUBLE_EQ (t.scale.x (), t.scale.y ());
  EXPECT_DOUBLE_EQ (t.scale.x (), t.scale.z ());
  double farthest = 0.0;
  for (const UncertainCloud* c : {&a, &b})
    for (std::size_t i = 0; i < c->size (); ++i)
    {
      const Eigen::Vector3d y = t.apply (c->means[i]);
      EXPECT_TRUE ((y.array () >= 0.0).all () && (y.array () <= 1.0).all ());
      farthest = std::max (farthest, (y - Eigen::Vector3d::Constant (0.5)).norm ());
      EXPECT_TRUE (t.applyInverse (y).isApprox (c->means[i], 1e-12));
      const Eigen::Matrix3d s = t.applyToCovariance (c->covariances[i]);
      const Eigen::Matrix3d expected = t.scale.asDiagonal () * c->covariances[i] * t.scale.asDiagonal ();
      EXPECT_TRUE (s.isApprox (expected, 1e-14));
      EXPECT_TRUE (t.applyInverseToCovariance (s).isApprox (c->covariances[i], 1e-12));
    }
  EXPECT_NEAR (farthest, 0.5, 1e-12);  // the farthest point lands on the ball of radius 1/2
}

TEST (Normalization, UniformIsEquivariantUnderRigidMotion)
{
  UncertainCloud a = randomCloud (40, 3, 1.0), b = randomCloud (40, 4, 1.0);
  const Eigen::Isometry3d T = Eigen::Translation3d (5, -2, 1) * Eigen::AngleAxisd (0.7, Eigen::Vector3d (1, 2, 3).normalized ());
  UncertainCloud a2 = a, b2 = b;
  for (UncertainCloud* c : {&a2, &b2})
    for (std::size_t i = 0; i < c->size (); ++i)
    {
      c->means[i] = T * c->means[i];
      c->covariances[i] = T.linear () * c->covariances[i] * T.linear ().transpose ();
    }
  const UnitCubeTransform t1 = computeUnitCubeTransform ({&a, &b});
  const UnitCubeTransform t2 = computeUnitCubeTransform ({&a2, &b2});
  EXPECT_NEAR (t1.scale.x (), t2.scale.x (), 1e-12);
  // Normalised points differ by the rotation about the cube centre only.
  for (std::size_t i = 0; i < a.size (); ++i)
  {
    const Eigen::Vector3d y1 = t1.apply (a.means[i]) - Eigen::Vector3d::Constant (0.5);
    const Eigen::Vector3d y2 = t2.apply (a2.means[i]) - Eigen::Vector3d::Constant (0.5);
    EXPECT_TRUE ((T.linear () * y1 - y2).norm () < 1e-12);
  }
}

TEST (Normalization, PerAxisUsesTheBoundingBoxAndGuardsFlatExtents)
{
  UncertainCloud flat;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
    {
      flat.means.emplace_back (i * 0.5, j * 0.25, 2.0);
      flat.covariances.push_back (Eigen::Matrix3d::Identity () * 1e-4);
    }
  const UnitCubeTransform t = computeUnitCubeTransform ({&flat}, Scaling::PerAxis);
  EXPECT_NEAR (t.scale.x (), 1.0 / 2.0, 1e-15);
  EXPECT_NEAR (t.scale.y (), 1.0 / 1.0, 1e-15);
  EXPECT_NEAR (t.scale.z (), 1.0 / (1e-9 * 2.0), 1e-3);  // zero extent raised to 1e-9 max
  applyUnitCubeTransform (t, flat);
  EXPECT_TRUE (flat.means.back ().isApprox (Eigen::Vector3d (1, 1, 0), 1e-12));
  EXPECT_NEAR (flat.covariances[0] (0, 0), 1e-4 / 4.0, 1e-18);
}

TEST (Normalization, DegenerateInputsGiveAWellDefinedMap)
{
  UncertainCloud empty;
  const UnitCubeTransform t0 = computeUnitCubeTransform ({&empty});
  EXPECT_TRUE (t0.scale.isOnes ());
  UncertainCloud single;
  single.means.emplace_back (1, 2, 3);
  single.means.emplace_back (std::nan (""), 0, 0);  // non-finite means are ignored
  single.covariances.assign (2, Eigen::Matrix3d::Identity ());
  const UnitCubeTransform t1 = computeUnitCubeTransform ({&single});
  EXPECT_TRUE (t1.scale.isOnes ());
  EXPECT_TRUE (t1.apply (single.means[0]).isApprox (Eigen::Vector3d::Constant (0.5)));
}
