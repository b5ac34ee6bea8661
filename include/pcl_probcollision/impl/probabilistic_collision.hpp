// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/error_message.h>
#include <pcl_probcollision/probabilistic_collision.h>
#include <pcl_probcollision/detail/input_checks.h>

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>
// The base class's one out-of-line member (FilterIndices::applyFilter(PointCloud &)) is
// instantiated with ours, so no binary needs libpcl_filters and libpcl_sample_consensus at run
// time: loading them was 13-14 ms of every process start (docs/PERFORMANCE.md, `-threads`).
#include <pcl/filters/impl/filter_indices.hpp>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
template <typename PointT>
ProbabilisticCollision<PointT>::ProbabilisticCollision (bool extract_removed_indices)
  : pcl::FilterIndices<PointT> (extract_removed_indices), classifier_ (request_.classifier)
{
  this->filter_name_ = "ProbabilisticCollision";
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setInputCloud (const PointCloudConstPtr& cloud)
{
  pcl::FilterIndices<PointT>::setInputCloud (cloud);
  markInput ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setIndices (const pcl::IndicesPtr& indices)
{
  pcl::FilterIndices<PointT>::setIndices (indices);
  markInput ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setIndices (const pcl::IndicesConstPtr& indices)
{
  pcl::FilterIndices<PointT>::setIndices (indices);
  markInput ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setIndices (const pcl::PointIndicesConstPtr& indices)
{
  pcl::FilterIndices<PointT>::setIndices (indices);
  markInput ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setIndices (std::size_t row_start, std::size_t col_start, std::size_t nb_rows,
                                            std::size_t nb_cols)
{
  // PCLBase's version prints an error for a block that does not fit and keeps the indices it had
  // (so a query silently used every point), and dereferences a null input: refuse both here.
  const auto* cloud = this->input_.get ();
  const std::string block = "rows " + std::to_string (row_start) + " + " + std::to_string (nb_rows) + ", columns " +
                            std::to_string (col_start) + " + " + std::to_string (nb_cols);
  if (!cloud)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::ProbabilisticCollision::setIndices] "
                                                        << block << ": no input cloud (call setInputCloud first)");
  if (nb_rows > cloud->height || row_start > cloud->height - nb_rows || nb_cols > cloud->width ||
      col_start > cloud->width - nb_cols)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::setIndices] "
                             << block << " outside the input cloud of width " << cloud->width << ", height "
                             << cloud->height << " (an unorganized cloud has height 1); the indices are unchanged");
  pcl::FilterIndices<PointT>::setIndices (row_start, col_start, nb_rows, nb_cols);
  markInput ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setKSearch (int k)
{
  if (k < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::setKSearch] k = " << k << " must be >= 1");
  input_params_.k = target_params_.k = k;
  markForRebuild ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setSurfaceProjection (bool project)
{
  input_params_.surface_projection = target_params_.surface_projection = project;
  markForRebuild ();
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::setHierarchyParams (const BVHParams& params)
{
  params.validate ();
  input_params_.hierarchy = target_params_.hierarchy = params;
  markForRebuild ();
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
  r.validate ();  // its ranges, (0, 0.5] and [0.5, 1), also keep the two in order; a NaN is named
  request_ = r;
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
ProbabilisticCollision<PointT>::prepare (CollisionResult& result)
{
  const auto start = std::chrono::steady_clock::now ();
  bool built = false;
  // A surface request (CollisionRequest::surface) needs both models' surface model: a model this
  // filter built without one is rebuilt with it, once. The separators answer alike either way
  // (the surface model adds to the hierarchy, it changes none of it); a prebuilt model is the
  // caller's (CollisionResult::answered_by then says who answered).
  auto build = [&] (const PointCloudConstPtr& cloud, const pcl::IndicesConstPtr& indices,
                    const CovarianceCloudConstPtr& covariances, CloudModelParams params, const char* which,
                    CloudModel::ConstPtr& model, bool& dirty) {
    params.surface = params.surface || request_.surface;
    if (!dirty && model && (!params.surface || model->params ().surface))
    {
      // Reused: the cloud may have been resized in place since (filter()'s rule too).
      result.message = cloud ? staleModelError (*model, *cloud, which) : std::string ();
      return result.message.empty ();
    }
    model.reset ();
    if (!cloud)
    {
      result.message = std::string ("no ") + which + " cloud given (" +
                       (which == std::string ("input") ? "setInputCloud" : "setTargetCloud") + ")";
      return false;
    }
    try
    {
      model = buildCloudModel (*cloud, params, indices.get (), covariances.get (), which);
    }
    catch (const pcl::PCLException& e)
    {
      result.message = errorMessage (e);
      return false;
    }
    dirty = false;
    built = true;
    return true;
  };
  // PCLBase replaces missing indices by "all points": pass only what the user set.
  const pcl::IndicesConstPtr input_indices = this->use_indices_ ? pcl::IndicesConstPtr (this->indices_) : nullptr;
  // A prebuilt model needs no cloud, but one set beside it must be the cloud it was built from
  // (filter() and the per-point values index it): a cloud of another size set after the model
  // was answered for by the old model (a probe, 2026-12-06).
  const auto prebuilt = [&] (const PointCloudConstPtr& cloud, const CloudModel::ConstPtr& model, const char* which) {
    result.message = cloud && model ? staleModelError (*model, *cloud, which) : std::string ();
    return result.message.empty ();
  };
  const bool ok = (input_prebuilt_ ? prebuilt (this->input_, input_model_, "input")
                                   : build (this->input_, input_indices, input_covariances_, input_params_, "input",
                                            input_model_, input_dirty_)) &&
                  (target_prebuilt_ ? prebuilt (target_, target_model_, "target")
                                    : build (target_, target_indices_, target_covariances_, target_params_, "target",
                                             target_model_, target_dirty_));
  if (!ok)
  {
    result.status = CollisionResult::Status::InvalidInput;
    return false;
  }
  result.build_ms = built ? std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count () : 0.0;
  return true;
}

template <typename PointT>
std::string
ProbabilisticCollision<PointT>::staleModelError (const CloudModel& model, const PointCloud& cloud, const char* which)
{
  if (model.sourceSize () == cloud.size ())
    return std::string ();
  const std::string setter = which == std::string ("input") ? "setInputModel" : "setTargetModel";
  return std::string ("the ") + which + " model was built from a cloud of " + std::to_string (model.sourceSize ()) +
         " points, the " + which + " cloud has " + std::to_string (cloud.size ()) +
         " (a cloud changed in place needs to be set again, or markForRebuild(); a model given by " + setter +
         "() needs the cloud it was built from, or " + setter + " (nullptr) to build one from the cloud)";
}

template <typename PointT>
std::string
ProbabilisticCollision<PointT>::changedCloudError (const CloudModel& model, const PointCloud& cloud) const
{
  if (const std::string stale = staleModelError (model, cloud, "input"); !stale.empty ())
    return stale;
  // A model built from points directly has no fingerprint to compare. PCLBase stands "all
  // points" in for indices never set: the model was built without them then.
  const pcl::Indices* indices = this->use_indices_ ? this->indices_.get () : nullptr;
  if (model.sourceFingerprint () == 0 || model.sourceFingerprint () == cloudFingerprint (cloud, indices))
    return std::string ();
  return std::string ("the input model was built from other points than the input cloud's ") +
         (indices ? "within its indices" : "(all of them: no setIndices)") + " (" +
         (input_prebuilt_ ? "a model given by setInputModel() needs the cloud and indices it was built from, or "
                            "setInputModel (nullptr) to build one from the cloud"
                          : "a cloud changed in place needs to be set again, or markForRebuild()") +
         ")";
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::finishResult (const Eigen::Isometry3d& T_target_input, double build_ms,
                                              CollisionResult& result) const
{
  result.build_ms = request_.enable_timings ? build_ms : std::numeric_limits<double>::quiet_NaN ();
  // collide() answers in its query frame, A's; compute()'s query frame is the target's.
  mapResultPoints (result, T_target_input);
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::compute (const Eigen::Isometry3d& T_target_input, CollisionResult& result)
{
  result = CollisionResult ();
  result.message = detail::poseError (T_target_input, "T_target_input");
  if (result.message.empty () && prepare (result))
  {
    const double build_ms = result.build_ms;
    // collide() works in A's frame: B is mapped there by the inverse pose, of a rotation (a
    // rounded one is taken to the nearest: its transpose would not invert it).
    const Eigen::Isometry3d T = detail::rigidPose (T_target_input);
    if (collide (*input_model_, *target_model_, T.inverse (), request_, result, &classifier_))
    {
      finishResult (T, build_ms, result);
      return true;
    }
  }
  PCL_ERROR ("[pcl_probcollision::%s::compute] %s\n", this->getClassName ().c_str (), result.message.c_str ());
  return false;
}

template <typename PointT>
void
ProbabilisticCollision<PointT>::finishBatchResult (std::size_t i, const Eigen::Isometry3d& T_target_input,
                                                   double build_ms, CollisionResult& result, std::size_t& failed) const
{
  if (result.ok ())
  {
    finishResult (T_target_input, build_ms, result);
    return;
  }
  result.message = "pose " + std::to_string (i) + ": " + result.message;
  if (failed++ == 0)
    PCL_ERROR ("[pcl_probcollision::%s::computeBatch] %s\n", this->getClassName ().c_str (), result.message.c_str ());
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input,
                                              std::vector<CollisionResult>& results, int threads)
{
  return computeBatch (T_target_input, results, threads, {});
}

template <typename PointT>
bool
ProbabilisticCollision<PointT>::computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input,
                                              std::vector<CollisionResult>& results, int threads,
                                              const std::function<void (std::size_t)>& ready)
{
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticCollision::computeBatch] threads = "
                             << threads << " must be >= 0 (0: one per hardware thread)");
  const std::size_t count = T_target_input.size ();
  results.assign (count, CollisionResult ());
  // Poses compute() would refuse fail here; the others become queries in A's frame, each of a
  // rotation (rigidPose, once a pose: T_query keeps it for finishing the result; a refused pose
  // keeps what was given, which its failed result never reads).
  std::vector<std::size_t> posed;
  std::vector<Eigen::Isometry3d> T_query (T_target_input), T_input_target;
  for (std::size_t i = 0; i < count; ++i)
  {
    results[i].message = detail::poseError (T_target_input[i], "T_target_input");
    if (results[i].message.empty ())
    {
      posed.push_back (i);
      T_query[i] = detail::rigidPose (T_target_input[i]);
      T_input_target.push_back (T_query[i].inverse ());
    }
  }
  // Every pose is finished and handed over in pose order: those up to `end` once results hold them.
  CollisionResult prepared;
  std::size_t handed = 0, failed = 0;
  auto handOverUpTo = [&] (std::size_t end) {
    for (; handed < end; ++handed)
    {
      finishBatchResult (handed, T_query[handed], prepared.build_ms, results[handed], failed);
      if (ready)
        ready (handed);
    }
  };
  // Like compute(), build only when some pose gets that far; every such pose shares the outcome.
  if (!posed.empty ())
  {
    if (prepare (prepared))
    {
      std::vector<CollisionResult> answers;
      collideBatch (*input_model_, *target_model_, T_input_target, request_, answers, threads, &classifier_,
                    [&] (std::size_t k) {
                      handOverUpTo (posed[k]);  // the refused poses before it
                      results[posed[k]] = std::move (answers[k]);
                      handOverUpTo (posed[k] + 1);
                    });
    }
    else
      for (const std::size_t i : posed)
        results[i] = prepared;
  }
  handOverUpTo (count);
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
  // Every point's own answer. A cap stops where it stops (a planner's max_leaf_fits = 8 kept no
  // point, with setNegative every point: a probe, 2026-12-07); the ladder picks one rung for the
  // whole pair, so wherever the separators read collision every point got their values, which do
  // not see deep into an object (METHOD.md 10.1): its surface layer answers each point instead.
  request_.max_leaf_fits = 0;
  request_.max_surface_pairs = 0;
  request_.surface_ladder = false;
  CollisionResult result;
  const bool ok = compute (result);
  request_ = saved;
  if (!ok)
    return;  // compute() printed the error; filter() leaves the output empty

  const std::vector<float>& p = result.probabilities_a;
  // compute() checked the model's size against the input cloud; the indices kept below name the
  // cloud's points, so here the points themselves must be the model's (a prebuilt model's cloud
  // moved 1 m kept 53 points a metre from anything: a probe, 2026-12-06).
  if (const std::string stale = changedCloudError (*input_model_, *this->input_); !stale.empty ())
  {
    PCL_ERROR ("[pcl_probcollision::%s::applyFilter] %s\n", this->getClassName ().c_str (), stale.c_str ());
    return;
  }
  const pcl::Indices& candidates = *this->indices_;
  indices.reserve (candidates.size ());
  const PointCloud& cloud = *this->input_;
  for (const int i : candidates)
  {
    // A non-finite point is never kept, negative or not, as PCL's own filters do (setNegative
    // returned the 97,920 NaN pixels of a stereo scan: a probe, 2026-12-06).
    if (!pcl::isXYZFinite (cloud[static_cast<std::size_t> (i)]))
    {
      if (this->extract_removed_indices_)
        this->removed_indices_->push_back (i);
      continue;
    }
    // Never reached by the traversal (NaN) means far from B: probability 0 (kept at a threshold
    // of 0, as every other point is).
    const float pi = std::isnan (p[i]) ? 0.0f : p[i];
    const bool hit = pi >= probability_threshold_;
    if (hit != this->negative_)
      indices.push_back (i);
    else if (this->extract_removed_indices_)
      this->removed_indices_->push_back (i);
  }
  filter_failed_ = false;
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_ProbabilisticCollision(T) template class PCL_EXPORTS pcl_probcollision::ProbabilisticCollision<T>;
