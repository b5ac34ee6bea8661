// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/point_types.h>
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/features/feature.h>

#include <optional>
#include <vector>

namespace pcl_probcollision
{
/** \brief Per-point covariance of a point cloud: the k-nearest-neighbour discretisation
  * covariance of Pauly, Mitra and Guibas (2004) plus a sensor noise model (METHOD.md 3).
  *
  * For each point x_i with neighbours N_i (its k nearest, itself excluded):
  * Psi_i = sum_j w_ij (x_j - x_i)(x_j - x_i)^T / sum_j w_ij, w_ij = exp(-|x_i - x_j|^2 / tau_i^2),
  * tau_i = tau r_i / sqrt(k), r_i the distance to the k-th neighbour. The output is
  * Psi_i + Sigma_i, with Sigma_i from the SensorNoiseModel (none by default).
  *
  * Defaults: k = 10, tau = 2 sqrt(k) (so tau_i = 2 r_i, the authors' reference code), the
  * discretisation term on, no sensor noise, Euclidean k-d tree search
  * (pcl::search::KdTree) unless setSearchMethod() gives another.
  *
  * \note Output is index-aligned with the input (or its indices); an organized input keeps its
  * width and height. A non-finite input point gets an all-NaN covariance and the output is then
  * not dense. Every finite point gets a finite, symmetric positive semi-definite covariance.
  * \note Degenerate neighbourhoods give well-defined results: fewer than k finite neighbours
  * use the ones there are (k' = finite points - 1); a point with no neighbour, or whose
  * neighbours all coincide with it (r_i = 0), gets Psi_i = 0; collinear or coplanar
  * neighbourhoods give a singular Psi_i (zero variance across the line or plane), which is the
  * exact answer for noise-free samples. Add a sensor noise model to regularise it.
  * \note Radius search is not supported (the method is defined on k neighbours): compute()
  * fails with a PCL_ERROR and an empty output when a radius is set.
  */
template <typename PointInT, typename PointOutT = Covariance>
class CovarianceEstimation : public pcl::Feature<PointInT, PointOutT>
{
public:
  using Ptr = pcl::shared_ptr<CovarianceEstimation<PointInT, PointOutT>>;
  using ConstPtr = pcl::shared_ptr<const CovarianceEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename pcl::Feature<PointInT, PointOutT>::PointCloudOut;

  CovarianceEstimation ()
  {
    this->feature_name_ = "CovarianceEstimation";
    this->k_ = 10;
  }

  /** \brief Number of nearest neighbours k >= 1 (default 10). Throws
    * pcl::BadArgumentException otherwise. */
  void setKSearch (int k);
  int getKSearch () const { return this->k_; }

  /** \brief Global kernel scale tau > 0 (tau_i = tau r_i / sqrt(k)); unset means 2 sqrt(k).
    * Throws pcl::BadArgumentException for a non-positive or non-finite value. */
  void setScale (double tau);
  /** \brief The scale in use: the one set, or 2 sqrt(k). */
  double getScale () const;

  /** \brief Whether Psi_i (the discretisation term) is added (default true). */
  void setUseDiscretization (bool use) { use_discretization_ = use; }
  bool getUseDiscretization () const { return use_discretization_; }

  /** \brief The sensor noise added to every point (default none). */
  void setSensorNoise (const SensorNoiseModel& model) { noise_ = model; }
  const SensorNoiseModel& getSensorNoise () const { return noise_; }

  /** \brief Sensor pose in the input cloud's frame for the depth models; unset means the
    * input's sensor_origin_ and sensor_orientation_. */
  void setSensorPose (const SensorPose& pose) { sensor_pose_ = pose; }
  SensorPose getSensorPose () const;

  /** \brief After compute(): r_i, the distance of each output point to its k-th neighbour
    * (NaN for non-finite points, 0 without neighbours), index-aligned with the output. The
    * hierarchy uses r_i^2 as the surface area a point stands for. */
  const std::vector<float>& getNeighbourRadii () const { return radii_; }

protected:
  bool initCompute () override;
  void computeFeature (PointCloudOut& output) override;

private:
  std::optional<double> tau_;
  bool use_discretization_ = true;
  SensorNoiseModel noise_;
  std::optional<SensorPose> sensor_pose_;
  std::vector<float> radii_;
};
} // namespace pcl_probcollision

#ifdef PCL_NO_PRECOMPILE
#include <pcl_probcollision/impl/covariance_estimation.hpp>
#endif
