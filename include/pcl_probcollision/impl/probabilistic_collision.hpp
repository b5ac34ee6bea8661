// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/covariance_estimation.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
template <typename PointT>
ProbabilisticCollision<PointT>::ProbabilisticCollision ()
  : classifier_ (request_.classifier)
{
  this->filter_name_ = "ProbabilisticCollision";
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setKSearch (int k)
{
  if (k < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::setKSearch] k = " << k << " must be >= 1");
  k_ = k;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setRequest (const CollisionRequest& request)
{
  request.validate ();
  request_ = request;
  // The classifier holds the random-feature draw of these parameters.
  classifier_ = RobustClassifier (request_.classifier);
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setThresholds (double free_below, double collision_above)
{
  CollisionRequest r = request_;
  r.free_below = free_below;
  r.collision_above = collision_above;
  if (!(free_below <= collision_above))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::setThresholds] free_below "
                             << free_below << " exceeds collision_above " << collision_above);
  r.validate ();
  request_ = r;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setHierarchyParams (const BVHParams& params)
{
  params.validate ();
  request_.hierarchy = params;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setProbabilityThreshold (double p)
{
  if (!(p >= 0.0 && p <= 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::setProbabilityThreshold] threshold "
                             << p << " outside [0, 1]");
  probability_threshold_ = p;
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::buildHierarchy (const PointCloudConstPtr& cloud, const pcl::IndicesConstPtr& indices,
                                                const CovarianceCloudConstPtr& covariances,
                                                const SensorNoiseModel& noise, const char* which,
                                                std::shared_ptr<const ProbabilisticBVH>& bvh,
                                                std::size_t& skipped, std::string& message) const
{
  std::ostringstream err;
  if (!cloud)
  {
    message = std::string ("no ") + which + " cloud given";
    return false;
  }
  if (covariances && covariances->size () != cloud->size ())
  {
    err << which << " covariances have " << covariances->size () << " entries for " << cloud->size () << " points";
    message = err.str ();
    return false;
  }
  for (const int i : indices ? *indices : pcl::Indices ())
    if (i < 0 || static_cast<std::size_t> (i) >= cloud->size ())
    {
      err << which << " index " << i << " outside the cloud of " << cloud->size () << " points";
      message = err.str ();
      return false;
    }

  // Finite but absurd coordinates (beyond 1e15 units) overflow the float arithmetic of the kd-tree:
  // FLANN's middle split computes (min + max) / 2 = inf for two values above FLT_MAX / 2 and
  // aborts on an assertion (found by fuzz/fuzz_collide). Refuse them with the point named.
  {
    constexpr float kMaxCoordinate = 1e15f;
    const std::size_t count = indices ? indices->size () : cloud->size ();
    for (std::size_t j = 0; j < count; ++j)
    {
      const int i = indices ? (*indices)[j] : static_cast<int> (j);
      const PointT& p = (*cloud)[i];
      if (pcl::isXYZFinite (p) &&
          !(std::abs (p.x) <= kMaxCoordinate && std::abs (p.y) <= kMaxCoordinate && std::abs (p.z) <= kMaxCoordinate))
      {
        err.precision (9);
        err << which << " point " << i << " at (" << p.x << ", " << p.y << ", " << p.z
            << ") is beyond the supported coordinate range of +-1e15";
        message = err.str ();
        return false;
      }
    }
  }

  // Estimate what the caller did not give: covariances and the neighbour radii (area weights).
  pcl::PointCloud<Covariance> estimated;
  std::vector<float> radii;
  std::vector<Eigen::Vector3d> displacements;
  if (!covariances)
  {
    CovarianceEstimation<PointT> estimation;
    estimation.setInputCloud (cloud);
    if (indices)
      estimation.setIndices (indices);
    estimation.setKSearch (k_);
    estimation.setSensorNoise (noise);
    estimation.setSurfaceProjection (project_);
    estimation.compute (estimated);
    radii = estimation.getNeighbourRadii ();
    displacements = estimation.getSurfaceDisplacements ();
  }

  UncertainCloud points;
  skipped = 0;
  const std::size_t n = indices ? indices->size () : cloud->size ();
  points.means.reserve (n);
  points.covariances.reserve (n);
  points.source_indices.reserve (n);
  if (!radii.empty ())
    points.area_weights.reserve (n);
  for (std::size_t j = 0; j < n; ++j)
  {
    const int i = indices ? (*indices)[j] : static_cast<int> (j);
    const PointT& p = (*cloud)[i];
    const Covariance& c = covariances ? (*covariances)[i] : (estimated.size () == n ? estimated[j] : Covariance::nan ());
    if (!pcl::isXYZFinite (p) || !c.isFinite ())
    {
      ++skipped;
      continue;
    }
    points.means.emplace_back (p.getVector3fMap ().template cast<double> ());
    if (!displacements.empty ())
      points.means.back () += displacements[j];
    points.covariances.push_back (c.matrix ());
    points.source_indices.push_back (i);
    if (!radii.empty ())
      points.area_weights.push_back (static_cast<double> (radii[j]) * radii[j]);
  }
  if (points.empty ())
  {
    err << which << " cloud has no finite point (" << n << " given, " << skipped << " non-finite)";
    message = err.str ();
    return false;
  }
  auto built = std::make_shared<ProbabilisticBVH> ();
  built->build (std::move (points), request_.hierarchy);  // no copy of the cloud
  bvh = built;
  return true;
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::prepare (CollisionResult& result)
{
  if (!this->input_)
    result.message = "no input cloud given (setInputCloud)";
  else if (!pcl::PCLBase<PointT>::initCompute ())
    result.message = "input cloud or indices unusable";
  else
  {
    const bool built = buildHierarchies (result);
    this->deinitCompute ();
    if (built)
      return true;
  }
  result.status = CollisionResult::Status::InvalidInput;
  return false;
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::buildHierarchies (CollisionResult& result)
{
  const auto start = std::chrono::steady_clock::now ();
  std::string message;
  Source input_now {this->input_.get (), this->indices_.get (), input_covariances_.get (), k_, request_.hierarchy};
  Source target_now {target_.get (), target_indices_.get (), target_covariances_.get (), k_, request_.hierarchy};
  // PCLBase replaces missing indices by "all points" with a fresh vector each time; compare
  // against what the user set.
  if (!this->use_indices_)
    input_now.indices = nullptr;
  bool built = false;
  try
  {
    if (input_dirty_ || !input_bvh_ || !(input_now == input_source_))
    {
      input_bvh_.reset ();
      if (!buildHierarchy (this->input_, this->use_indices_ ? this->indices_ : pcl::IndicesConstPtr (),
                           input_covariances_, input_noise_, "input", input_bvh_, input_skipped_, message))
      {
        result.message = message;
        return false;
      }
      input_source_ = input_now;
      input_dirty_ = false;
      built = true;
    }
    if (target_dirty_ || !target_bvh_ || !(target_now == target_source_))
    {
      target_bvh_.reset ();
      if (!buildHierarchy (target_, target_indices_, target_covariances_, target_noise_, "target", target_bvh_,
                           target_skipped_, message))
      {
        result.message = message;
        return false;
      }
      target_source_ = target_now;
      target_dirty_ = false;
      built = true;
    }
  }
  catch (const pcl::PCLException& e)
  {
    result.message = e.what ();
    return false;
  }
  result.build_ms = built ? std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count () : 0.0;
  return true;
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::checkPose (const Eigen::Isometry3d& T_target_input, CollisionResult& result)
{
  const Eigen::Matrix3d R = T_target_input.linear ();
  if (T_target_input.matrix ().allFinite () && (R.transpose () * R).isIdentity (1e-6) && R.determinant () >= 0.0)
    return true;
  result.message = "pose T_target_input is not a finite rotation plus translation";
  return false;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::finishResult (const Eigen::Isometry3d& T_target_input, double build_ms,
                                              CollisionResult& result) const
{
  result.points_skipped_nonfinite = input_skipped_ + target_skipped_;
  if (request_.enable_timings)
    result.build_ms = build_ms;
  // Report the witness in the target's frame, where the pose puts A.
  if (result.witness_side != 0)
  {
    result.witness_point = T_target_input * result.witness_point;
    result.witness_normal = T_target_input.linear () * result.witness_normal;
  }
  // Per-point values: from hierarchy order to the caller's clouds.
  if (request_.per_point)
  {
    auto scatter = [] (const std::vector<float>& in, const ProbabilisticBVH& bvh, std::size_t size) {
      std::vector<float> out (size, std::numeric_limits<float>::quiet_NaN ());
      for (std::size_t j = 0; j < in.size (); ++j)
        out[bvh.sourceIndex (static_cast<int> (j))] = in[j];
      return out;
    };
    result.probabilities_a = scatter (result.probabilities_a, *input_bvh_, this->input_->size ());
    result.probabilities_b = scatter (result.probabilities_b, *target_bvh_, target_->size ());
  }
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::compute (const Eigen::Isometry3d& T_target_input, CollisionResult& result)
{
  result = CollisionResult ();
  if (checkPose (T_target_input, result) && prepare (result))
  {
    const double build_ms = result.build_ms;
    // collide() works in A's frame: B is mapped there by the inverse pose.
    if (collide (*input_bvh_, *target_bvh_, T_target_input.inverse (), request_, result, &classifier_))
    {
      finishResult (T_target_input, build_ms, result);
      return true;
    }
  }
  PCL_ERROR ("[pcl_probcollision::%s::compute] %s\n", this->getClassName ().c_str (), result.message.c_str ());
  return false;
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input,
                                              std::vector<CollisionResult>& results, int threads)
{
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::computeBatch] threads = "
                             << threads << " must be >= 0 (0: one per hardware thread)");
  const std::size_t count = T_target_input.size ();
  results.assign (count, CollisionResult ());
  // Poses compute() would refuse fail here; the others become queries in A's frame.
  std::vector<std::size_t> posed;
  std::vector<Eigen::Isometry3d> T_input_target;
  for (std::size_t i = 0; i < count; ++i)
    if (checkPose (T_target_input[i], results[i]))
    {
      posed.push_back (i);
      T_input_target.push_back (T_target_input[i].inverse ());
    }
  // Like compute(), build only when some pose gets that far; every such pose shares the outcome.
  CollisionResult prepared;
  if (!posed.empty ())
  {
    if (prepare (prepared))
    {
      std::vector<CollisionResult> answers;
      collideBatch (*input_bvh_, *target_bvh_, T_input_target, request_, answers, threads, &classifier_);
      for (std::size_t k = 0; k < posed.size (); ++k)
        results[posed[k]] = std::move (answers[k]);
    }
    else
      for (const std::size_t i : posed)
        results[i] = prepared;
  }

  std::size_t failed = 0;
  for (std::size_t i = 0; i < count; ++i)
  {
    CollisionResult& result = results[i];
    if (result.ok ())
    {
      finishResult (T_target_input[i], prepared.build_ms, result);
      continue;
    }
    result.message = "pose " + std::to_string (i) + ": " + result.message;
    if (failed++ == 0)
      PCL_ERROR ("[pcl_probcollision::%s::computeBatch] %s\n", this->getClassName ().c_str (), result.message.c_str ());
  }
  if (failed > 1)
    PCL_ERROR ("[pcl_probcollision::%s::computeBatch] %zu of %zu poses failed\n", this->getClassName ().c_str (),
               failed, count);
  return failed == 0;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::applyFilter (pcl::Indices& indices)
{
  indices.clear ();
  this->removed_indices_->clear ();
  const CollisionRequest saved = request_;
  request_.per_point = true;
  request_.exhaustive = true;
  CollisionResult result;
  const bool ok = compute (result);
  request_ = saved;
  if (!ok)
    return;  // compute() printed the error; the output stays empty

  const std::vector<float>& p = result.probabilities_a;
  const pcl::Indices& candidates = *this->indices_;
  indices.reserve (candidates.size ());
  for (const int i : candidates)
  {
    // Never reached by the traversal (NaN) means far from B: probability 0.
    const bool hit = !std::isnan (p[i]) && p[i] >= probability_threshold_;
    if (hit != this->negative_)
      indices.push_back (i);
    else if (this->extract_removed_indices_)
      this->removed_indices_->push_back (i);
  }
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_ProbabilisticCollision(T) template class PCL_EXPORTS pcl_probcollision::ProbabilisticCollision<T>;
