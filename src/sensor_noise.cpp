// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/sensor_noise.h>
#include <pcl_probcollision/detail/input_checks.h>

#include <pcl/exceptions.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pcl_probcollision
{
namespace
{
constexpr double kHalfPi = 1.57079632679489661923;

void
requireNonNegative (double value, const char* what)
{
  if (!(std::isfinite (value) && value >= 0.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel] " << what << " = " << value
                                                                  << " must be finite and >= 0");
}

void
requirePositive (double value, const char* what)
{
  if (!(std::isfinite (value) && value > 0.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel] " << what << " = " << value
                                                                  << " must be finite and > 0");
}
} // namespace

SensorPose
SensorPose::fromViewpoint (const Eigen::Vector4f& sensor_origin,
                           const Eigen::Quaternionf& sensor_orientation)
{
  SensorPose pose;
  pose.origin = sensor_origin.head<3> ().cast<double> ();
  Eigen::Quaterniond q = sensor_orientation.cast<double> ();
  // A non-finite orientation is no viewing axis: NaN, which sensorPoseError names (it was
  // taken for the identity without a word). A zero one is PCL's unset orientation: the identity.
  if (!q.coeffs ().allFinite ())
  {
    pose.axis = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
    return pose;
  }
  if (!(q.norm () > 0.0))
    q = Eigen::Quaterniond::Identity ();
  pose.axis = (q.normalized () * Eigen::Vector3d::UnitZ ()).normalized ();
  return pose;
}

std::string
SensorNoiseModel::sensorPoseError (const SensorPose& sensor) const
{
  if (!usesSensorPose () || (sensor.origin.allFinite () && sensor.axis.allFinite ()))
    return std::string ();
  std::ostringstream out;
  out.precision (9);
  if (!sensor.origin.allFinite ())
    out << "sensor origin (" << sensor.origin.x () << ", " << sensor.origin.y () << ", " << sensor.origin.z ()
        << ") is not finite: the " << name () << " noise model measures each point's depth from it";
  else
    out << "sensor orientation is not finite (viewing axis (" << sensor.axis.x () << ", " << sensor.axis.y () << ", "
        << sensor.axis.z () << ")): the " << name () << " noise model measures each point's depth along it";
  return out.str ();
}

SensorNoiseModel
SensorNoiseModel::isotropic (double sigma)
{
  requireNonNegative (sigma, "isotropic sigma");
  // Beyond the coordinate range a deviation means nothing, and its variance would overflow the
  // single-precision covariances, every point then read as non-finite (found in review).
  if (!(sigma <= detail::kMaxCoordinate))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel] isotropic sigma = "
                             << sigma << " must be at most 1e15, the supported coordinate range");
  SensorNoiseModel m;
  m.type_ = Type::Isotropic;
  m.sigma_ = sigma;
  return m;
}

SensorNoiseModel
SensorNoiseModel::anisotropic (const Eigen::Matrix3d& covariance)
{
  if (!covariance.allFinite ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel::anisotropic] covariance is not finite");
  if (!covariance.isApprox (covariance.transpose (), 1e-9) &&
      (covariance - covariance.transpose ()).norm () > 1e-12)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel::anisotropic] covariance is not symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (covariance, Eigen::EigenvaluesOnly);
  const double smallest = eig.eigenvalues ()(0);
  if (smallest < -1e-12 * std::max (1.0, eig.eigenvalues ()(2)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel::anisotropic] covariance has a negative eigenvalue "
                             << smallest);
  SensorNoiseModel m;
  m.type_ = Type::Anisotropic;
  m.fixed_ = 0.5 * (covariance + covariance.transpose ());
  return m;
}

SensorNoiseModel
SensorNoiseModel::kinect (const KinectParams& params)
{
  requirePositive (params.fx, "kinect fx");
  requirePositive (params.min_depth, "kinect min_depth");
  if (!(params.max_angle > 0.0 && params.max_angle < kHalfPi))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SensorNoiseModel::kinect] max_angle = " << params.max_angle
                                                                                      << " must be in (0, pi/2)");
  SensorNoiseModel m;
  m.type_ = Type::KinectV1;
  m.kinect_ = params;
  return m;
}

SensorNoiseModel
SensorNoiseModel::stereo (const StereoParams& params)
{
  requirePositive (params.focal_px, "stereo focal_px");
  requirePositive (params.baseline, "stereo baseline");
  requireNonNegative (params.disparity_sigma_px, "stereo disparity_sigma_px");
  requireNonNegative (params.pixel_sigma_px, "stereo pixel_sigma_px");
  SensorNoiseModel m;
  m.type_ = Type::Stereo;
  m.stereo_ = params;
  return m;
}

SensorNoiseModel
SensorNoiseModel::lidar (const LidarParams& params)
{
  requireNonNegative (params.range_sigma, "lidar range_sigma");
  requireNonNegative (params.angle_sigma, "lidar angle_sigma");
  SensorNoiseModel m;
  m.type_ = Type::Lidar;
  m.lidar_ = params;
  return m;
}

SensorNoiseModel
SensorNoiseModel::fromName (const std::string& name, double sigma)
{
  if (name == "none")
    return SensorNoiseModel ();
  if (name == "isotropic")
    return isotropic (sigma);
  if (name == "kinect")
    return kinect ();
  if (name == "stereo")
    return stereo ();
  if (name == "lidar")
    return lidar ();
  PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                       "[pcl_probcollision::SensorNoiseModel::fromName] unknown sensor model '"
                           << name << "' (expected none, isotropic, kinect, stereo or lidar)");
}

const char*
SensorNoiseModel::name () const
{
  switch (type_)
  {
    case Type::None: return "none";
    case Type::Isotropic: return "isotropic";
    case Type::Anisotropic: return "anisotropic";
    case Type::KinectV1: return "kinect";
    case Type::Stereo: return "stereo";
    case Type::Lidar: return "lidar";
  }
  return "unknown";
}

bool
SensorNoiseModel::usesSensorPose () const
{
  return type_ == Type::KinectV1 || type_ == Type::Stereo || type_ == Type::Lidar;
}

void
SensorNoiseModel::sigmas (const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                          const SensorPose& sensor, double& sigma_axial, double& sigma_lateral) const
{
  const Eigen::Vector3d ray = point - sensor.origin;
  const double depth = std::abs (sensor.axis.dot (ray));
  switch (type_)
  {
    case Type::None:
    case Type::Anisotropic:
      sigma_axial = sigma_lateral = 0.0;
      return;
    case Type::Isotropic:
      sigma_axial = sigma_lateral = sigma_;
      return;
    case Type::KinectV1:
    {
      const double z = std::max (depth, kinect_.min_depth);
      double theta = 0.0;  // angle between the viewing ray and the surface normal
      const double ray_norm = ray.norm ();
      if (normal.squaredNorm () > 0.0 && ray_norm > 0.0)
        theta = std::acos (std::min (1.0, std::abs (normal.normalized ().dot (ray / ray_norm))));
      theta = std::min (theta, kinect_.max_angle);
      const double grazing = theta / (kHalfPi - theta);
      sigma_axial = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) + 0.0001 / std::sqrt (z) * grazing * grazing;
      sigma_lateral = (0.8 + 0.035 * grazing) * z / kinect_.fx;
      return;
    }
    case Type::Stereo:
      sigma_axial = depth * depth * stereo_.disparity_sigma_px / (stereo_.focal_px * stereo_.baseline);
      sigma_lateral = depth * stereo_.pixel_sigma_px / stereo_.focal_px;
      return;
    case Type::Lidar:
      sigma_axial = lidar_.range_sigma;
      sigma_lateral = ray.norm () * lidar_.angle_sigma;
      return;
  }
  sigma_axial = sigma_lateral = 0.0;
}

Eigen::Matrix3d
SensorNoiseModel::covariance (const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                              const SensorPose& sensor) const
{
  if (type_ == Type::None)
    return Eigen::Matrix3d::Zero ();
  if (type_ == Type::Anisotropic)
    return fixed_;
  if (type_ == Type::Isotropic)
    return sigma_ * sigma_ * Eigen::Matrix3d::Identity ();
  double sa = 0.0, sl = 0.0;
  sigmas (point, normal, sensor, sa, sl);
  const Eigen::Vector3d ray = point - sensor.origin;
  const double n = ray.norm ();
  // A point at the sensor origin has no ray direction: use the optical axis.
  const Eigen::Vector3d u = n > 0.0 ? Eigen::Vector3d (ray / n) : sensor.axis;
  return sl * sl * (Eigen::Matrix3d::Identity () - u * u.transpose ()) + sa * sa * (u * u.transpose ());
}
} // namespace pcl_probcollision
