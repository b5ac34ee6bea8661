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
  displacements_.clear ();
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
bool
CovarianceEstimation<PointInT, PointOutT>::projectOntoSurface (const Eigen::Vector3d& mean_offset,
                                                             const Eigen::Matrix3d& second_moment, double k_eff,
                                                             const Eigen::Matrix3d& sensor_cov,
                                                             Eigen::Vector3d& displacement, Eigen::Matrix3d& psi,
                                                             Eigen::Vector3d& normal, double& shrink)
{
  // Scatter of the neighbours (the point itself excluded, so that its own error does not pull
  // the plane) about their weighted centroid; its weakest direction is the local normal.
  const Eigen::Matrix3d scatter = second_moment - mean_offset * mean_offset.transpose ();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (0.5 * (scatter + scatter.transpose ()));
  const Eigen::Vector3d n = eig.eigenvectors ().col (0);
  const double lambda = std::max (eig.eigenvalues ()(0), 0.0);
  const double s2 = n.dot (sensor_cov * n);
  if (!(s2 > 0.0) || !(k_eff > 1.0))
    return false;
  // The sensor explains the scatter across the plane on a flat patch (alpha = 1; a factor 2
  // absorbs the sampling spread of lambda over about ten neighbours); at an edge or corner
  // the scatter is geometry, and the point keeps most of its measured position.
  constexpr double kTolerance = 2.0;
  const double alpha = lambda > kTolerance * s2 ? kTolerance * s2 / lambda : 1.0;
  // x_i sits at the origin of the moments, so the centroid is at mean_offset.
  displacement = alpha * n * n.dot (mean_offset);
  // The discretisation term about the new position, sum w (d - delta)(d - delta)^T / sum w,
  // along the normal only: sliding a sample along its own surface does not move the surface,
  // and a tangential spread of the sample spacing, seen by a leaf separator that is tilted
  // against the surface, read as a crossing (docs/RESULTS.md).
  const Eigen::Matrix3d about_moved = second_moment - mean_offset * displacement.transpose () -
                                      displacement * mean_offset.transpose () + displacement * displacement.transpose ();
  psi = n.dot (about_moved * n) * n * n.transpose ();
  // Variance of the shrunk position along n, as a share of the measured point's: the measured
  // part weighs (1 - alpha), the plane's offset (error s2 / k_eff, independent of x_i) alpha.
  shrink = (1.0 - alpha) * (1.0 - alpha) + alpha * alpha / k_eff;
  normal = n;
  return true;
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
  if (project_)
    displacements_.assign (indices.size (), Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ()));
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
    // Weighted mean offset of the neighbours and their effective number (surface projection).
    Eigen::Vector3d first = Eigen::Vector3d::Zero ();
    double k_eff = 0.0, weight_sq_sum = 0.0;
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
        first += w * d;
        weight_sum += w;
        weight_sq_sum += w * w;
      }
      if (weight_sum > 0.0)
      {
        psi /= weight_sum;
        first /= weight_sum;
        k_eff = weight_sum * weight_sum / weight_sq_sum;
      }
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
      const Eigen::Matrix3d sensor_cov = noise_.covariance (xi, normal, sensor);
      Eigen::Vector3d delta, n;
      Eigen::Matrix3d psi_moved;
      double shrink = 1.0;
      if (project_ && kept >= 2 && projectOntoSurface (first, psi, k_eff, sensor_cov, delta, psi_moved, n, shrink))
      {
        displacements_[out] = delta;
        total = (use_discretization_ ? psi_moved : Eigen::Matrix3d::Zero ()) + sensor_cov;
        const Eigen::Matrix3d A = Eigen::Matrix3d::Identity () - (1.0 - std::sqrt (shrink)) * n * n.transpose ();
        total = A * total * A.transpose ();
      }
      else
        total += sensor_cov;
    }
    if (project_ && !displacements_[out].allFinite ())
      displacements_[out].setZero ();
    total = 0.5 * (total + total.transpose ());
    output[out] = PointOutT (Covariance (total));
  }
  output.is_dense = dense;
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_CovarianceEstimation(T) \
  template class PCL_EXPORTS pcl_probcollision::CovarianceEstimation<T, pcl_probcollision::Covariance>;
