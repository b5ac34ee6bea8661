// SPDX-License-Identifier: BSD-3-Clause
// Plain data of uncertain_points.h: UncertainCloud's size, PackedCovariance (round trip through
// its six entries, symmetrisation, the quadratic form) and PointSetView's sizes.
#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace pcl_probcollision;

namespace
{
/** \brief A random symmetric positive definite matrix: R diag(s^2) R^T, s in [0.001, 0.1]. */
Eigen::Matrix3d
randomSpd (std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> sd (0.001, 0.1), angle (-M_PI, M_PI);
  const double sx = sd (rng);  // one draw per statement: argument order is unspecified
  const double sy = sd (rng);
  const double sz = sd (rng);
  const double az = angle (rng);
  const double ay = angle (rng);
  const double ax = angle (rng);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd (az, Eigen::Vector3d::UnitZ ()) *
                             Eigen::AngleAxisd (ay, Eigen::Vector3d::UnitY ()) *
                             Eigen::AngleAxisd (ax, Eigen::Vector3d::UnitX ()))
                                .toRotationMatrix ();
  return R * Eigen::Vector3d (sx * sx, sy * sy, sz * sz).asDiagonal () * R.transpose ();
}
} // namespace

TEST (UncertainCloud, SizeAndEmptyFollowTheMeans)
{
  UncertainCloud c;
  EXPECT_TRUE (c.empty ());
  EXPECT_EQ (c.size (), 0u);
  c.means.assign (3, Eigen::Vector3d::Zero ());
  c.covariances.assign (3, Eigen::Matrix3d::Identity ());
  EXPECT_FALSE (c.empty ());
  EXPECT_EQ (c.size (), 3u);
}

TEST (PackedCovariance, DefaultIsZero)
{
  EXPECT_TRUE (PackedCovariance ().matrix ().isZero (0.0));
  EXPECT_EQ (PackedCovariance ().quadratic (Eigen::Vector3d (1.0, 2.0, 3.0)), 0.0);
}

TEST (PackedCovariance, RoundTripsASymmetricMatrixExactly)
{
  Eigen::Matrix3d s;
  s << 4.0, 0.5, -0.25,  //
      0.5, 9.0, 0.125,   //
      -0.25, 0.125, 16.0;
  const PackedCovariance p (s);
  EXPECT_EQ (p.xx, 4.0);
  EXPECT_EQ (p.xy, 0.5);
  EXPECT_EQ (p.xz, -0.25);
  EXPECT_EQ (p.yy, 9.0);
  EXPECT_EQ (p.yz, 0.125);
  EXPECT_EQ (p.zz, 16.0);
  EXPECT_EQ (p.matrix (), s);  // exact: each entry is copied, and (a + a) / 2 = a in binary

  // Any other matrix is kept to single precision: each entry is the nearest float.
  std::mt19937_64 rng (3);
  for (int i = 0; i < 100; ++i)
  {
    const Eigen::Matrix3d c = randomSpd (rng);
    const Eigen::Matrix3d symmetric = 0.5 * (c + c.transpose ());  // bitwise symmetric
    const Eigen::Matrix3d rounded = symmetric.cast<float> ().cast<double> ();
    EXPECT_EQ (PackedCovariance (symmetric).matrix (), rounded) << i;
    EXPECT_LE ((rounded - symmetric).cwiseAbs ().maxCoeff (), 0x1p-24 * symmetric.cwiseAbs ().maxCoeff ()) << i;
    EXPECT_EQ (PackedCovariance (rounded).matrix (), rounded) << i;  // float entries round-trip exactly
  }
}

TEST (PackedCovariance, KeepsTheSymmetricPartOfAnAsymmetricMatrix)
{
  Eigen::Matrix3d s;
  s << 1.0, 2.0, 3.0,  //
      4.0, 5.0, 6.0,   //
      7.0, 8.0, 9.0;
  const Eigen::Matrix3d m = PackedCovariance (s).matrix ();
  EXPECT_EQ (m, Eigen::Matrix3d (0.5 * (s + s.transpose ())));
  EXPECT_EQ (m (0, 1), 3.0);
  EXPECT_EQ (m (0, 2), 5.0);
  EXPECT_EQ (m (1, 2), 7.0);
  EXPECT_EQ (m, m.transpose ());
}

TEST (PackedCovariance, QuadraticIsTheVarianceAlongADirection)
{
  // Axis-aligned: a^T Sigma a picks a diagonal entry.
  Eigen::Matrix3d d = Eigen::Vector3d (1.0, 4.0, 9.0).asDiagonal ();
  const PackedCovariance diag (d);
  EXPECT_EQ (diag.quadratic (Eigen::Vector3d::UnitX ()), 1.0);
  EXPECT_EQ (diag.quadratic (Eigen::Vector3d::UnitY ()), 4.0);
  EXPECT_EQ (diag.quadratic (Eigen::Vector3d::UnitZ ()), 9.0);
  // Off-diagonal terms count twice: (1, 1, 0) on [[1, 0.5], [0.5, 4]] gives 1 + 4 + 2 * 0.5.
  d (0, 1) = d (1, 0) = 0.5;
  EXPECT_EQ (PackedCovariance (d).quadratic (Eigen::Vector3d (1.0, 1.0, 0.0)), 6.0);

  // Against the full product of the stored (float-rounded) matrix on random matrices and
  // directions; both sides sum at most nine terms of size |a|^2 |Sigma|, so a few ulps of the
  // largest is the tolerance.
  std::mt19937_64 rng (5);
  std::normal_distribution<double> n (0.0, 1.0);
  for (int i = 0; i < 200; ++i)
  {
    const Eigen::Matrix3d c = randomSpd (rng).cast<float> ().cast<double> ();
    const double x = n (rng);
    const double y = n (rng);
    const double z = n (rng);
    const Eigen::Vector3d a (x, y, z);
    const double expected = a.dot (c * a);
    const double tolerance = 16.0 * std::numeric_limits<double>::epsilon () * a.squaredNorm () * c.cwiseAbs ().maxCoeff () * 3.0;
    EXPECT_NEAR (PackedCovariance (c).quadratic (a), expected, tolerance) << i;
    EXPECT_GT (PackedCovariance (c).quadratic (a), 0.0) << i;  // positive definite
  }
}

TEST (PointSetView, DefaultIsEmpty)
{
  const PointSetView v;
  EXPECT_EQ (v.size, 0u);
  EXPECT_EQ (v.means, nullptr);
  EXPECT_EQ (v.covariances, nullptr);
}

TEST (PointSetView, SizeIsTheShorterOfTheTwoVectors)
{
  const std::vector<Eigen::Vector3d> m (5, Eigen::Vector3d::Ones ());
  const std::vector<Eigen::Matrix3d> c4 (4, Eigen::Matrix3d::Identity ()), c5 (5, Eigen::Matrix3d::Identity ()),
      c7 (7, Eigen::Matrix3d::Identity ());
  EXPECT_EQ (PointSetView (m, c4).size, 4u);
  EXPECT_EQ (PointSetView (m, c5).size, 5u);
  EXPECT_EQ (PointSetView (m, c7).size, 5u);
  const PointSetView v (m, c7);
  EXPECT_EQ (v.means, m.data ());
  EXPECT_EQ (v.covariances, c7.data ());
}

TEST (PointSetView, PointerConstructorAndCloudViewDoNotCopy)
{
  UncertainCloud cloud;
  for (int i = 0; i < 6; ++i)
  {
    cloud.means.emplace_back (i, 2.0 * i, 3.0 * i);
    cloud.covariances.push_back ((i + 1.0) * Eigen::Matrix3d::Identity ());
  }
  const PointSetView whole (cloud);
  EXPECT_EQ (whole.size, 6u);
  EXPECT_EQ (whole.means, cloud.means.data ());
  EXPECT_EQ (whole.covariances, cloud.covariances.data ());
  EXPECT_EQ (whole.means[5], Eigen::Vector3d (5.0, 10.0, 15.0));

  const PointSetView tail (cloud.means.data () + 2, cloud.covariances.data () + 2, 3);
  EXPECT_EQ (tail.size, 3u);
  EXPECT_EQ (tail.means[0], cloud.means[2]);
  EXPECT_EQ (tail.covariances[2], cloud.covariances[4]);

  cloud.covariances.pop_back ();  // the cloud view is as long as the shorter vector
  EXPECT_EQ (PointSetView (cloud).size, 5u);
}
