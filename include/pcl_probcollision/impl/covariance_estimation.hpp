// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/covariance_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_probcollision
{
template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::setKSearch (int k)
{
  if (k < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CovarianceEstimation::setKSearch] k = " << k
                                                                                      << " must be >= 1");
  this->k_ = k;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::setScale (double tau)
{
  if (!(std::isfinite (tau) && tau > 0.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CovarianceEstimation::setScale] tau = " << tau
                                                                                      << " must be finite and > 0");
  tau_ = tau;
}

template <typename PointInT, typename PointOutT>
double
CovarianceEstimation<PointInT, PointOutT>::getScale () const
{
  return tau_ ? *tau_ : 2.0 * std::sqrt (static_cast<double> (this->k_));
}

template <typename PointInT, typename PointOutT>
SensorPose
CovarianceEstimation<PointInT, PointOutT>::getSensorPose () const
{
  if (sensor_pose_)
    return *sensor_pose_;
  if (this->input_)
    return SensorPose::fromViewpoint (this->input_->sensor_origin_, this->input_->sensor_orientation_);
  return SensorPose ();
}

template <typename PointInT, typename PointOutT>
bool
CovarianceEstimation<PointInT, PointOutT>::initCompute ()
{
  radii_.clear ();
  if (this->search_radius_ != 0.0)
  {
    PCL_ERROR ("[pcl_probcollision::%s::initCompute] radius search (%g) is not supported: the "
               "covariance is defined on the k nearest neighbours; call setRadiusSearch (0).\n",
               this->getClassName ().c_str (), this->search_radius_);
    return false;
  }
  if (this->k_ < 1)
  {
    PCL_ERROR ("[pcl_probcollision::%s::initCompute] k = %d must be >= 1.\n",
               this->getClassName ().c_str (), this->k_);
    return false;
  }
  // pcl::Feature would pick OrganizedNeighbor (a projective, camera-model search) for organized
  // clouds; Pauly et al. define the neighbourhood in Euclidean space.
  if (!this->tree_)
    this->tree_.reset (new pcl::search::KdTree<PointInT> (false));
  return pcl::Feature<PointInT, PointOutT>::initCompute ();
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::computeFeature (PointCloudOut& output)
{
  const auto& input = *this->input_;
  const auto& surface = *this->surface_;
  const auto& indices = *this->indices_;
  const bool same_cloud = this->input_ == this->surface_;
  const SensorPose sensor = getSensorPose ();
  const double tau = getScale ();

  std::size_t finite_surface = 0;
  for (const auto& p : surface.points)
    finite_surface += pcl::isXYZFinite (p) ? 1 : 0;

  radii_.assign (indices.size (), std::numeric_limits<float>::quiet_NaN ());
  pcl::Indices nn_indices;
  std::vector<float> nn_sqr_dists;
  bool dense = true;

  for (std::size_t out = 0; out < indices.size (); ++out)
  {
    const int index = indices[out];
    const PointInT& query = input[index];
    if (!pcl::isXYZFinite (query))
    {
      output[out] = PointOutT (Covariance::nan ());
      dense = false;
      continue;
    }
    const Eigen::Vector3d xi = query.getVector3fMap ().template cast<double> ();

    // Ask one more than k: the query itself comes back when it is part of the surface.
    const int k_ask = static_cast<int> (std::min<std::size_t> (this->k_ + 1, finite_surface));
    int found = 0;
    if (k_ask > 0)
      found = this->tree_->nearestKSearch (input, index, k_ask, nn_indices, nn_sqr_dists);

    // Keep at most k neighbours other than the query point itself.
    std::size_t kept = 0;
    double r = 0.0;
    for (int j = 0; j < found && kept < static_cast<std::size_t> (this->k_); ++j)
    {
      if (same_cloud && nn_indices[j] == index)
        continue;
      if (!pcl::isXYZFinite (surface[nn_indices[j]]))
        continue;
      nn_indices[kept] = nn_indices[j];
      ++kept;
      r = std::max (r, std::sqrt (static_cast<double> (nn_sqr_dists[j])));
    }
    radii_[out] = static_cast<float> (r);

    Eigen::Matrix3d psi = Eigen::Matrix3d::Zero ();
    if (kept > 0 && r > 0.0)
    {
      const double tau_i = tau * r / std::sqrt (static_cast<double> (kept));
      const double inv_tau2 = 1.0 / (tau_i * tau_i);
      double weight_sum = 0.0;
      for (std::size_t j = 0; j < kept; ++j)
      {
        // Differences in double: exact for float inputs even far from the origin.
        const Eigen::Vector3d d = surface[nn_indices[j]].getVector3fMap ().template cast<double> () - xi;
        const double w = std::exp (-d.squaredNorm () * inv_tau2);
        psi.noalias () += w * d * d.transpose ();
        weight_sum += w;
      }
      if (weight_sum > 0.0)
        psi /= weight_sum;
    }

    Eigen::Matrix3d total = use_discretization_ ? psi : Eigen::Matrix3d::Zero ();
    if (noise_.type () != SensorNoiseModel::Type::None)
    {
      Eigen::Vector3d normal = Eigen::Vector3d::Zero ();
      if (noise_.usesNormal () && kept >= 2 && psi.trace () > 0.0)
      {
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (psi);
        normal = eig.eigenvectors ().col (0);
      }
      total += noise_.covariance (xi, normal, sensor);
    }
    total = 0.5 * (total + total.transpose ());
    output[out] = PointOutT (Covariance (total));
  }
  output.is_dense = dense;
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_CovarianceEstimation(T) \
  template class PCL_EXPORTS pcl_probcollision::CovarianceEstimation<T, pcl_probcollision::Covariance>;
