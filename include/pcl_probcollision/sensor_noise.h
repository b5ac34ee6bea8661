// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>

namespace pcl_probcollision
{
/** \brief Where the sensor is, in the cloud's frame: its optical centre and its optical axis
  * (unit vector). From a PCL cloud: origin = sensor_origin_.head<3>(),
  * axis = sensor_orientation_ * (0, 0, 1). */
struct SensorPose
{
  /** \brief The optical centre (default the origin). */
  Eigen::Vector3d origin = Eigen::Vector3d::Zero ();
  /** \brief The optical axis, a unit vector (default +z). */
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ ();

  /** \brief From PCL's viewpoint fields (sensor_origin_, sensor_orientation_). A zero
    * orientation (unset) is the identity; a non-finite one gives a NaN axis, which
    * SensorNoiseModel::sensorPoseError refuses for a depth model. */
  static SensorPose fromViewpoint (const Eigen::Vector4f& sensor_origin,
                                   const Eigen::Quaternionf& sensor_orientation);
};

/** \brief Kinect v1 constants (Nguyen et al. 2012): sigma_a = 0.0012 + 0.0019 (z - 0.4)^2
  * + 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2 metres and
  * sigma_l = (0.8 + 0.035 theta / (pi/2 - theta)) z / fx metres, z clamped to >= min_depth,
  * theta (ray-to-normal angle) clamped to <= max_angle. */
struct KinectNoiseParams
{
  double fx = 585.0;                          ///< focal length, pixels
  double min_depth = 0.4;                     ///< metres; the model's valid range starts here
  double max_angle = 70.0 * 3.14159265358979323846 / 180.0;  ///< radians
};

/** \brief Stereo triangulation: sigma_a = z^2 sigma_d / (f b), sigma_l = z sigma_px / f.
  * Defaults describe a PR2-like wide stereo pair (f = 395 px, b = 0.09 m) with sigma_d chosen
  * so that sigma_a = 1.5 cm at 1.5 m, the PR2 range error the thesis reports; set them from
  * your calibration. */
struct StereoNoiseParams
{
  double focal_px = 395.0;   ///< f, pixels
  double baseline = 0.09;    ///< b, metres
  double disparity_sigma_px = 0.237;  ///< sigma_d, pixels
  double pixel_sigma_px = 0.5;        ///< sigma_px, pixels (lateral)
};

/** \brief Lidar: sigma_a = range_sigma, sigma_l = range * angle_sigma (illustrative). */
struct LidarNoiseParams
{
  double range_sigma = 0.01;      ///< metres
  double angle_sigma = 0.0022;    ///< radians
};

/** \brief Sensor (position) noise Sigma_i of a measured point, added to the discretisation
  * covariance (METHOD.md 3.3).
  *
  * Every model but Anisotropic is built from an axial standard deviation sigma_a along the
  * viewing ray u and a lateral one sigma_l across it:
  * Sigma = sigma_l^2 (I - u u^T) + sigma_a^2 u u^T. Lengths in metres for the depth models
  * (their published constants are in metres); Isotropic and Anisotropic use the data's units.
  *
  * \note The depth z = |axis^T (x - origin)|: its sign is ignored because some PCD writers store
  * the viewpoint rotated by 180 degrees about x (PCL's own stereo test scan does) while the
  * points stay in the optical frame.
  */
class SensorNoiseModel
{
public:
  /** \brief The kind of noise model. */
  enum class Type
  {
    None,         ///< no sensor noise
    Isotropic,    ///< sigma^2 I
    Anisotropic,  ///< one fixed covariance for every point
    KinectV1,     ///< structured light, Nguyen, Izadi and Lovell 2012
    Stereo,       ///< triangulation, Khoshelham and Oude Elberink 2012
    Lidar         ///< range sigma_r, angular sigma_phi
  };

  /** \brief Parameters of kinect(). */
  using KinectParams = KinectNoiseParams;
  /** \brief Parameters of stereo(). */
  using StereoParams = StereoNoiseParams;
  /** \brief Parameters of lidar(). */
  using LidarParams = LidarNoiseParams;

  /** \brief No sensor noise (the default). */
  SensorNoiseModel () = default;

  /** \brief sigma^2 I; sigma >= 0 in data units. Throws pcl::BadArgumentException otherwise. */
  static SensorNoiseModel isotropic (double sigma);
  /** \brief The same covariance for every point; must be symmetric positive semi-definite
    * and finite (throws otherwise). */
  static SensorNoiseModel anisotropic (const Eigen::Matrix3d& covariance);
  /** \brief A Kinect v1's depth noise (KinectParams), growing with depth and the surface's tilt
    * to the line of sight; needs the sensor pose and the surface normal. */
  static SensorNoiseModel kinect (const KinectParams& params = KinectParams ());
  /** \brief A stereo camera's depth noise (StereoParams), growing with depth squared along the
    * line of sight; needs the sensor pose. */
  static SensorNoiseModel stereo (const StereoParams& params = StereoParams ());
  /** \brief A lidar's range and angular noise (LidarParams); needs the sensor pose. */
  static SensorNoiseModel lidar (const LidarParams& params = LidarParams ());
  /** \brief The sigma fromName() gives "isotropic" when none is given (data units). */
  static constexpr double kDefaultIsotropicSigma = 0.005;
  /** \brief Parses "none", "isotropic", "kinect", "stereo" or "lidar" with default parameters
    * (isotropic uses sigma); throws pcl::BadArgumentException naming the value otherwise. */
  static SensorNoiseModel fromName (const std::string& name, double sigma = kDefaultIsotropicSigma);

  /** \brief Which model this is. */
  Type type () const { return type_; }
  /** \brief Its name as fromName() reads it ("none", "isotropic", "kinect", ...). */
  const char* name () const;
  /** \brief True when the model depends on the sensor pose (the depth models). */
  bool usesSensorPose () const;
  /** \brief Whether this model can work from that sensor pose: empty when it can (a model that
    * uses no sensor pose can work from any), otherwise why not, as "sensor origin (nan, 0, 1) is
    * not finite: the kinect noise model measures each point's depth from it", or a non-finite
    * viewing axis (SensorPose::fromViewpoint of a non-finite orientation). The one rule:
    * buildCloudModel() (naming the cloud) and CovarianceEstimation::initCompute() call it, so a
    * NaN sensor_origin_ is named as such instead of every covariance coming out NaN. */
  std::string sensorPoseError (const SensorPose& sensor) const;
  /** \brief True when the model depends on the surface normal (KinectV1). */
  bool usesNormal () const { return type_ == Type::KinectV1; }

  /** \brief Axial and lateral standard deviations at a point (metres for the depth models).
    * \param[in] point the measured point in the cloud's frame
    * \param[in] normal unit surface normal (only KinectV1 reads it; zero means facing the ray)
    * \param[in] sensor the sensor pose in the cloud's frame
    * \param[out] sigma_axial standard deviation along the viewing ray (0 for None and
    *             Anisotropic, sigma for Isotropic)
    * \param[out] sigma_lateral standard deviation across the viewing ray (likewise) */
  void sigmas (const Eigen::Vector3d& point, const Eigen::Vector3d& normal, const SensorPose& sensor,
               double& sigma_axial, double& sigma_lateral) const;

  /** \brief The covariance Sigma_i at a point (see sigmas()). */
  Eigen::Matrix3d covariance (const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                              const SensorPose& sensor) const;

private:
  Type type_ = Type::None;
  double sigma_ = 0.0;
  Eigen::Matrix3d fixed_ = Eigen::Matrix3d::Zero ();
  KinectParams kinect_;
  StereoParams stereo_;
  LidarParams lidar_;
};
} // namespace pcl_probcollision
