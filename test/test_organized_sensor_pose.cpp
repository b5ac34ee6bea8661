// SPDX-License-Identifier: BSD-3-Clause
// Where an organized cloud's sensor was, from its rows and columns (organizedSensorPose), and the
// model that takes it where a moved cloud left its VIEWPOINT behind.
#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/organized_sensor_pose.h>

#include <pcl/common/transforms.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>

using namespace pcl_probcollision;

namespace
{
const Eigen::Vector3d kSensor (0.6, -0.6, 0.7);
const Eigen::Vector3d kTarget (0.0, 0.0, 0.1);

/** \brief Where the ray from `from` along `d` first meets a 20 cm box standing on z = 0 or the
  * table around it (80 cm square) when table is set; infinity where it meets neither. */
double
hit (const Eigen::Vector3d& from, const Eigen::Vector3d& d, bool box, bool table)
{
  double t = std::numeric_limits<double>::infinity ();
  if (table && d.z () < 0.0)
  {
    const double s = -from.z () / d.z ();
    const Eigen::Vector3d p = from + s * d;
    if (std::abs (p.x ()) < 0.4 && std::abs (p.y ()) < 0.4)
      t = s;
  }
  if (box)
  {
    double enter = 0.0, leave = std::numeric_limits<double>::infinity ();
    for (int a = 0; a < 3; ++a)
    {
      const double lo = a < 2 ? -0.1 : 0.0, hi = a < 2 ? 0.1 : 0.2;
      const double t0 = (lo - from[a]) / d[a], t1 = (hi - from[a]) / d[a];
      enter = std::max (enter, std::min (t0, t1));
      leave = std::min (leave, std::max (t0, t1));
    }
    if (enter < leave && enter < t)
      t = enter;
  }
  return t;
}

/** \brief A pinhole depth image (64 x 48, 60 px focal length) from kSensor toward kTarget, with
  * noise_sigma of range noise along each ray; NaN where a ray meets nothing. Its VIEWPOINT is the
  * sensor's pose. */
pcl::PointCloud<pcl::PointXYZ>
pinholeImage (bool box = true, bool table = true, double noise_sigma = 0.002)
{
  const Eigen::Vector3d forward = (kTarget - kSensor).normalized ();
  const Eigen::Vector3d right = forward.cross (Eigen::Vector3d::UnitZ ()).normalized ();
  const Eigen::Vector3d down = forward.cross (right);
  pcl::PointCloud<pcl::PointXYZ> image (64, 48);
  std::mt19937 rng (3);
  std::normal_distribution<double> noise (0.0, noise_sigma);
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u)
    {
      const Eigen::Vector3d d = (forward + (u - 31.5) / 60.0 * right + (v - 23.5) / 60.0 * down).normalized ();
      const double t = hit (kSensor, d, box, table);
      const double range = t + noise (rng);
      image.at (u, v).getVector3fMap () = std::isfinite (t) ? Eigen::Vector3f ((kSensor + range * d).cast<float> ())
                                                            : Eigen::Vector3f::Constant (std::numeric_limits<float>::quiet_NaN ());
    }
  image.is_dense = false;
  image.sensor_origin_ = Eigen::Vector4f (float (kSensor.x ()), float (kSensor.y ()), float (kSensor.z ()), 0.0f);
  Eigen::Matrix3f r;
  r << right.cast<float> (), down.cast<float> (), forward.cast<float> ();
  image.sensor_orientation_ = Eigen::Quaternionf (r);
  return image;
}

/** \brief A turn about a slanted axis and a shift, as a robot's base frame is from its camera's. */
Eigen::Affine3f
baseFromCamera ()
{
  return Eigen::Translation3f (0.3f, -1.2f, 0.8f) * Eigen::AngleAxisf (2.0f, Eigen::Vector3f (1.0f, 2.0f, 0.5f).normalized ());
}
} // namespace

TEST (OrganizedSensorPose, APinholeImageGivesItsSensorWhereverTheCloudWasMoved)
{
  const auto image = pinholeImage ();
  const std::optional<SensorPose> pose = organizedSensorPose (image);
  ASSERT_TRUE (pose.has_value ());
  EXPECT_LT ((pose->origin - kSensor).norm (), 1e-4) << pose->origin.transpose ();
  EXPECT_GT (pose->axis.dot ((kTarget - kSensor).normalized ()), 0.9999) << pose->axis.transpose ();
  // Moved as a camera's cloud into a robot's base frame: the points move, the VIEWPOINT does not.
  pcl::PointCloud<pcl::PointXYZ> moved;
  pcl::transformPointCloud (image, moved, baseFromCamera ());
  ASSERT_EQ (moved.sensor_origin_, image.sensor_origin_);
  const std::optional<SensorPose> after = organizedSensorPose (moved);
  ASSERT_TRUE (after.has_value ());
  const Eigen::Affine3d T = baseFromCamera ().cast<double> ();
  EXPECT_LT ((after->origin - T * kSensor).norm (), 1e-4) << after->origin.transpose ();
  EXPECT_GT (after->axis.dot (T.linear () * (kTarget - kSensor).normalized ()), 0.9999);
}

TEST (OrganizedSensorPose, NoPoseWhereTheRowsDoNotSayIt)
{
  // Not organized: the same points in one row.
  auto image = pinholeImage ();
  pcl::PointCloud<pcl::PointXYZ> flat = image;
  flat.width = static_cast<std::uint32_t> (flat.size ());
  flat.height = 1;
  EXPECT_FALSE (organizedSensorPose (flat).has_value ());
  // A table alone, without noise: each row meets its one plane in a line. (With range noise its
  // points leave the line along their rays, within the row's plane, and give it.)
  EXPECT_FALSE (organizedSensorPose (pinholeImage (false, true, 0.0)).has_value ());
  const std::optional<SensorPose> noisy = organizedSensorPose (pinholeImage (false, true, 0.002));
  ASSERT_TRUE (noisy.has_value ());
  EXPECT_LT ((noisy->origin - kSensor).norm (), 1e-3) << noisy->origin.transpose ();
  // A lidar's rings (rows at fixed elevations, columns at fixed azimuths) over the table and the
  // box: a ring over the table alone lies in the table's plane, one over both is no plane.
  for (const bool box : {false, true})
  {
    SCOPED_TRACE (box ? "table and box" : "table");
    pcl::PointCloud<pcl::PointXYZ> rings (90, 16);
    const Eigen::Vector3d lidar (0.5, -0.5, 0.6);
    for (int v = 0; v < 16; ++v)
      for (int u = 0; u < 90; ++u)
      {
        const double elevation = -0.3 - 0.04 * v, azimuth = 2.0 + 0.02 * u;
        const Eigen::Vector3d d (std::cos (elevation) * std::cos (azimuth), std::cos (elevation) * std::sin (azimuth), std::sin (elevation));
        const double t = hit (lidar, d, box, true);
        rings.at (u, v).getVector3fMap () = std::isfinite (t) ? Eigen::Vector3f ((lidar + t * d).cast<float> ())
                                                              : Eigen::Vector3f::Constant (std::numeric_limits<float>::quiet_NaN ());
      }
    const std::optional<SensorPose> pose = organizedSensorPose (rings);
    EXPECT_FALSE (pose.has_value ()) << pose->origin.transpose ();
  }
}

// A single view moved into another frame with pcl::transformPointCloud keeps its old VIEWPOINT.
// Refused (it hides the scan's points behind one another), it left the scan two-sided, and a
// ball deep in the box read free; a depth model measured every point's depth from it. The
// model now takes the pose the rows and columns give, with a warning, and answers as the cloud
// whose VIEWPOINT moved along.
TEST (OrganizedSensorPose, AModelTakesTheSensorAMovedCloudLeftItsViewpointBehind)
{
  const auto image = pinholeImage ();
  pcl::PointCloud<pcl::PointXYZ> stale, along;
  pcl::transformPointCloud (image, stale, baseFromCamera ());
  along = stale;
  const Eigen::Affine3d T = baseFromCamera ().cast<double> ();
  along.sensor_origin_.head<3> () = (T * kSensor).cast<float> ();
  along.sensor_orientation_ = Eigen::Quaternionf (baseFromCamera ().linear ()) * image.sensor_orientation_;
  CloudModelParams params;
  params.surface = true;
  params.noise = SensorNoiseModel::kinect ();
  const auto from_stale = buildCloudModel (stale, params);
  const auto from_along = buildCloudModel (along, params);
  EXPECT_NE (from_stale->warning ().find ("where the planes of its rows and columns of points meet, not at its VIEWPOINT"),
             std::string::npos)
      << from_stale->warning ();
  EXPECT_EQ (from_along->warning (), "");
  ASSERT_TRUE (from_stale->surface ().seenFromViewpoint ());
  EXPECT_LT ((from_stale->surface ().viewpoint () + from_stale->origin () - T * kSensor).norm (), 1e-4);
  // The kinect model's covariances: as the moved-along cloud's.
  ASSERT_EQ (from_stale->size (), from_along->size ());
  const auto& a = from_stale->hierarchy ().covariances ();
  const auto& b = from_along->hierarchy ().covariances ();
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size (); ++i)
    for (const Eigen::Vector3d e : {Eigen::Vector3d::UnitX (), Eigen::Vector3d::UnitY (), Eigen::Vector3d::UnitZ ()})
      worst = std::max (worst, std::abs (std::sqrt (a[i].quadratic (e)) - std::sqrt (b[i].quadratic (e))));
  EXPECT_LT (worst, 1e-5);  // metres of standard deviation
  // A ball 6 cm inside the box, in the base frame: not free.
  pcl::PointCloud<pcl::PointXYZ> ball;
  for (int i = 0; i < 200; ++i)
  {
    const double z = 1.0 - (2.0 * i + 1.0) / 200.0, phi = 2.39996322972865332 * i, r = std::sqrt (1.0 - z * z);
    ball.push_back (pcl::PointXYZ (float (0.02 * r * std::cos (phi)), float (0.02 * r * std::sin (phi)), float (0.02 * z)));
  }
  CloudModelParams ball_params;
  ball_params.surface = true;
  const auto ball_model = buildCloudModel (ball, ball_params);
  CollisionRequest request;
  request.surface = true;
  const Eigen::Isometry3d T_ball (Eigen::Translation3d (T * Eigen::Vector3d (0.0, 0.0, 0.08)));
  for (const auto* scene : {&from_stale, &from_along})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (**scene, *ball_model, T_ball, request, r));  // T_a_b: the ball in the scene's frame
    EXPECT_NE (r.verdict, Verdict::Free) << "P " << r.probability;
  }
}
