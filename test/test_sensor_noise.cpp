// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/exceptions.h>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>

using pcl_probcollision::SensorNoiseModel;
using pcl_probcollision::SensorPose;

namespace
{
// Variance of a covariance along a unit direction.
double
varianceAlong (const Eigen::Matrix3d& c, const Eigen::Vector3d& u)
{
  return u.dot (c * u);
}
} // namespace

TEST (SensorNoiseModel, NoneIsZeroAndIsotropicIsSigmaSquaredIdentity)
{
  const SensorPose sensor;
  const Eigen::Vector3d p (0.3, -0.2, 1.4);
  EXPECT_TRUE (SensorNoiseModel ().covariance (p, Eigen::Vector3d::Zero (), sensor).isZero (0.0));
  const Eigen::Matrix3d c = SensorNoiseModel::isotropic (0.004).covariance (p, Eigen::Vector3d::Zero (), sensor);
  EXPECT_TRUE (c.isApprox (0.004 * 0.004 * Eigen::Matrix3d::Identity (), 1e-15));
}

TEST (SensorNoiseModel, AnisotropicReturnsTheGivenCovarianceAndRejectsIndefinite)
{
  Eigen::Matrix3d m;
  m << 4e-6, 1e-6, 0, 1e-6, 2e-6, 0, 0, 0, 1e-6;
  EXPECT_TRUE (SensorNoiseModel::anisotropic (m).covariance (Eigen::Vector3d::Ones (), Eigen::Vector3d::Zero (), SensorPose ()).isApprox (m));
  Eigen::Matrix3d bad = m;
  bad (2, 2) = -1e-6;
  EXPECT_THROW (SensorNoiseModel::anisotropic (bad), pcl::BadArgumentException);
  bad = m;
  bad (0, 2) = 1e-6;  // not symmetric
  EXPECT_THROW (SensorNoiseModel::anisotropic (bad), pcl::BadArgumentException);
}

TEST (SensorNoiseModel, StereoAxialGrowsWithDepthSquaredAlongTheRayLateralLinearly)
{
  const SensorNoiseModel::StereoParams params;
  const SensorNoiseModel model = SensorNoiseModel::stereo (params);
  const SensorPose sensor;
  const Eigen::Vector3d dir = Eigen::Vector3d (0.1, -0.05, 1.0).normalized ();
  for (double z : {0.5, 1.0, 1.5, 3.0})
  {
    const Eigen::Vector3d p = dir * (z / dir.z ());
    const Eigen::Matrix3d c = model.covariance (p, Eigen::Vector3d::Zero (), sensor);
    const double sa = z * z * params.disparity_sigma_px / (params.focal_px * params.baseline);
    const double sl = z * params.pixel_sigma_px / params.focal_px;
    EXPECT_NEAR (varianceAlong (c, dir), sa * sa, 1e-12 * sa * sa + 1e-18);
    const Eigen::Vector3d across = dir.cross (Eigen::Vector3d::UnitX ()).normalized ();
    EXPECT_NEAR (varianceAlong (c, across), sl * sl, 1e-12);
    // The viewing ray is the principal axis once axial noise dominates.
    if (sa > sl)
    {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (c);
      EXPECT_NEAR (std::abs (eig.eigenvectors ().col (2).dot (dir)), 1.0, 1e-9);
    }
  }
  // The documented calibration: 1.5 cm axial at 1.5 m.
  double sa = 0, sl = 0;
  model.sigmas (Eigen::Vector3d (0, 0, 1.5), Eigen::Vector3d::Zero (), sensor, sa, sl);
  EXPECT_NEAR (sa, 0.015, 1e-4);
}

TEST (SensorNoiseModel, KinectMatchesNguyenAtNormalIncidenceAndGrowsTowardGrazing)
{
  const SensorNoiseModel model = SensorNoiseModel::kinect ();
  const SensorPose sensor;
  double sa = 0, sl = 0;
  // Fronto-parallel surface at z = 1 m: theta = 0.
  model.sigmas (Eigen::Vector3d (0, 0, 1.0), Eigen::Vector3d (0, 0, -1), sensor, sa, sl);
  EXPECT_NEAR (sa, 0.0012 + 0.0019 * 0.36, 1e-12);
  EXPECT_NEAR (sl, 0.8 * 1.0 / 585.0, 1e-12);
  double sa2 = 0, sl2 = 0;
  model.sigmas (Eigen::Vector3d (0, 0, 2.0), Eigen::Vector3d (0, 0, -1), sensor, sa2, sl2);
  EXPECT_GT (sa2, sa);
  EXPECT_NEAR (sl2, 2.0 * sl, 1e-12);
  // Tilted 60 degrees: larger axial and lateral noise.
  const double t = 60.0 * M_PI / 180.0;
  double sa3 = 0, sl3 = 0;
  model.sigmas (Eigen::Vector3d (0, 0, 1.0), Eigen::Vector3d (std::sin (t), 0, -std::cos (t)), sensor, sa3, sl3);
  const double g = t / (M_PI / 2 - t);
  EXPECT_NEAR (sa3, 0.0012 + 0.0019 * 0.36 + 0.0001 * g * g, 1e-12);
  EXPECT_GT (sl3, sl);
  // Depth below the model's range is clamped to 0.4 m.
  model.sigmas (Eigen::Vector3d (0, 0, 0.1), Eigen::Vector3d (0, 0, -1), sensor, sa, sl);
  EXPECT_NEAR (sa, 0.0012, 1e-12);
}

TEST (SensorNoiseModel, DepthUsesTheSensorPoseAndIgnoresTheAxisSign)
{
  const SensorNoiseModel model = SensorNoiseModel::stereo ();
  SensorPose moved;
  moved.origin = Eigen::Vector3d (1, 2, 3);
  const Eigen::Matrix3d at_origin = model.covariance (Eigen::Vector3d (0, 0, 1.2), Eigen::Vector3d::Zero (), SensorPose ());
  const Eigen::Matrix3d shifted = model.covariance (Eigen::Vector3d (1, 2, 4.2), Eigen::Vector3d::Zero (), moved);
  EXPECT_TRUE (at_origin.isApprox (shifted, 1e-12));
  // PCL's stereo scan stores a 180 degree rotation about x while its points look down +z.
  const SensorPose flipped = SensorPose::fromViewpoint (Eigen::Vector4f::Zero (), Eigen::Quaternionf (0, 1, 0, 0));
  EXPECT_NEAR (flipped.axis.z (), -1.0, 1e-7);
  const Eigen::Matrix3d with_flip = model.covariance (Eigen::Vector3d (0, 0, 1.2), Eigen::Vector3d::Zero (), flipped);
  EXPECT_TRUE (at_origin.isApprox (with_flip, 1e-6));
}

TEST (SensorNoiseModel, BadParametersThrowNamingTheParameter)
{
  EXPECT_THROW (SensorNoiseModel::isotropic (-1.0), pcl::BadArgumentException);
  EXPECT_THROW (SensorNoiseModel::isotropic (std::nan ("")), pcl::BadArgumentException);
  EXPECT_THROW (SensorNoiseModel::isotropic (1e20), pcl::BadArgumentException);  // beyond the coordinate range
  EXPECT_NO_THROW (SensorNoiseModel::isotropic (1e15));
  SensorNoiseModel::StereoParams stereo;
  stereo.baseline = 0.0;
  try
  {
    SensorNoiseModel::stereo (stereo);
    FAIL () << "no exception";
  }
  catch (const pcl::BadArgumentException& e)
  {
    EXPECT_NE (std::string (e.what ()).find ("baseline"), std::string::npos) << e.what ();
  }
  SensorNoiseModel::KinectParams kinect;
  kinect.max_angle = 2.0;
  EXPECT_THROW (SensorNoiseModel::kinect (kinect), pcl::BadArgumentException);
  EXPECT_THROW (SensorNoiseModel::fromName ("sonar"), pcl::BadArgumentException);
  EXPECT_EQ (SensorNoiseModel::fromName ("kinect").type (), SensorNoiseModel::Type::KinectV1);
}
