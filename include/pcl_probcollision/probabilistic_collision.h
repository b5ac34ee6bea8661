// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/point_types.h>
#include <pcl_probcollision/robust_classifier.h>
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/filters/filter_indices.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace pcl_probcollision
{
/** \brief Probability that the object sampled by the input cloud (A) collides with the object
  * sampled by the target cloud (B), after Pan, Chitta and Manocha (ISRR 2011); see METHOD.md.
  *
  * The PCL face of the library: a thin adaptor that builds one CloudModel per cloud
  * (buildCloudModel) and queries them with collide(). Each point is a Gaussian: given
  * covariances, or estimated with CovarianceEstimation (k = 10) plus the cloud's
  * SensorNoiseModel. The default noise model is none, right for exact samples (meshes, CAD);
  * for sensor data set the sensor's model (CloudModelParams says which, and why pcd_collision
  * assumes 5 mm instead).
  *
  * Models are built at the first query and reused for every pose. Like
  * pcl::Registration::setInputTarget, every setter of something a model is built from
  * (setInputCloud, setIndices, setTargetCloud, setTargetIndices, the covariances, noise models,
  * k, surface projection and hierarchy parameters) marks that model for rebuild, even when it
  * is given the same pointer again. A cloud changed in place (pcl::transformPointCloud (*a, *a,
  * T)) is NOT noticed by compute() until it is set again or markForRebuild() is called: until
  * then the old model answers. One resized in place is refused: compute() and filter() fail
  * naming both sizes (their per-point results would not be index-aligned with it). Prebuilt
  * models (setInputModel, setTargetModel) are used as they are; a cloud set beside one must have
  * the size of the cloud it was built from (compute() fails otherwise: set the model to nullptr
  * to build from a new cloud). filter(), whose output names the input cloud's points, also
  * checks that the input model was built from those very points (CloudModel::sourceFingerprint(),
  * an O(n) hash) and fails otherwise.
  *
  * As a filter (pcl::FilterIndices), it keeps the points of A whose collision probability
  * reaches setProbabilityThreshold() (default 0.5); setNegative() keeps the others and
  * setKeepOrganized() keeps an organized layout, as in pcl::CropBox. Filtering runs an
  * exhaustive query so that every point near B is evaluated, without the request's caps
  * (max_leaf_fits, max_surface_pairs) and, for surface_ladder, with the surface layer answering
  * every point (the ladder picks one rung for the whole pair); points the traversal never came
  * near count as probability 0. It answers at the identity pose: move B's cloud first.
  * For robot self-filtering (B a robot part, A a scan; setNegative() removes the part's points):
  * the separators' per-point P falls inside B, deepest lowest (points 3-5 mm inside a 1 cm
  * finger read under 0.5: METHOD.md 10.1), so build B with its outward normals (a mesh's
  * samples as pcl::PointNormal, CloudModelParams::surface) and set request.surface; and a point
  * on B's surface reads P near 0.5 by design (half its spread lies inside), so a scan of the
  * part itself needs a lower threshold (0.2) or B padded by the scan's noise.
  *
  * \note Non-finite points are skipped (and counted in the result). The two clouds must be in
  * the same units: covariances, noise sigmas and distances are in those units (the hierarchy's
  * thresholds, BVHParams::sigma_max and epsilon, are ratios: the same for metres and millimetres).
  * \note Not thread-safe (a PCL filter object). computeBatch() spreads many poses over
  * threads; for concurrent queries from the caller's own threads build the models once
  * (buildCloudModel, or getInputModel() after a compute) and call collide() from each thread.
  */
template <typename PointT>
class ProbabilisticCollision : public pcl::FilterIndices<PointT>
{
public:
  /** \brief Shared pointer to a ProbabilisticCollision. */
  using Ptr = pcl::shared_ptr<ProbabilisticCollision<PointT>>;
  /** \brief Shared pointer to a const ProbabilisticCollision. */
  using ConstPtr = pcl::shared_ptr<const ProbabilisticCollision<PointT>>;
  /** \brief The type of both clouds. */
  using PointCloud = pcl::PointCloud<PointT>;
  /** \brief Shared pointer to a const cloud. */
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  /** \brief Shared pointer to a const cloud of per-point covariances. */
  using CovarianceCloudConstPtr = pcl::PointCloud<Covariance>::ConstPtr;

  /** \brief No clouds yet; both models' parameters and the request are their defaults
    * (CloudModelParams, CollisionRequest). Each getter below returns what its setter set.
    * extract_removed_indices: filter() lists the points it did not keep (getRemovedIndices()),
    * as PCL's filters take it. */
  explicit ProbabilisticCollision (bool extract_removed_indices = false);

  /** \brief Object A; marks its model for rebuild (even for the same pointer). */
  void setInputCloud (const PointCloudConstPtr& cloud) override;
  /** \brief Restricts A to these indices; marks its model for rebuild. */
  void setIndices (const pcl::IndicesPtr& indices) override;
  /** \brief Restricts A to these indices; marks its model for rebuild. */
  void setIndices (const pcl::IndicesConstPtr& indices) override;
  /** \brief Restricts A to these indices; marks its model for rebuild. */
  void setIndices (const pcl::PointIndicesConstPtr& indices) override;
  /** \brief Restricts A to a block of the input cloud (nb_rows rows from row_start, nb_cols
    * columns from col_start; an unorganized cloud is one row); marks its model for rebuild.
    * \throws pcl::BadArgumentException naming the block and the cloud's width and height when
    *         there is no input cloud yet or the block does not fit it (PCL's own version prints
    *         an error and keeps the previous indices, all points by default); the indices are
    *         then unchanged. */
  void setIndices (std::size_t row_start, std::size_t col_start, std::size_t nb_rows, std::size_t nb_cols) override;

  /** \brief Object B; marks its model for rebuild (even for the same pointer). */
  void setTargetCloud (const PointCloudConstPtr& target) { target_ = target; markTarget (); }
  /** \brief Object B (null before setTargetCloud()). */
  PointCloudConstPtr getTargetCloud () const { return target_; }
  /** \brief Restricts B to these indices (all points by default); marks its model for rebuild. */
  void setTargetIndices (const pcl::IndicesConstPtr& indices) { target_indices_ = indices; markTarget (); }
  /** \brief B's indices (null: all points). */
  pcl::IndicesConstPtr getTargetIndices () const { return target_indices_; }

  /** \brief Covariances of A, index-aligned with the whole input cloud (not its indices);
    * unset means estimated. A non-finite covariance drops its point. */
  void setInputCovariances (const CovarianceCloudConstPtr& covariances) { input_covariances_ = covariances; markInput (); }
  /** \brief Covariances of B, index-aligned with the whole target cloud; unset means estimated. */
  void setTargetCovariances (const CovarianceCloudConstPtr& covariances) { target_covariances_ = covariances; markTarget (); }

  /** \brief Sensor noise added to A's estimated covariances (CloudModelParams::noise, default
    * none). The depth models read the input cloud's sensor_origin_ / sensor_orientation_. */
  void setInputNoise (const SensorNoiseModel& noise) { input_params_.noise = noise; markInput (); }
  /** \brief A's sensor noise model. */
  const SensorNoiseModel& getInputNoise () const { return input_params_.noise; }
  /** \brief Sensor noise added to B's estimated covariances (default none). */
  void setTargetNoise (const SensorNoiseModel& noise) { target_params_.noise = noise; markTarget (); }
  /** \brief B's sensor noise model. */
  const SensorNoiseModel& getTargetNoise () const { return target_params_.noise; }

  /** \brief k of the covariance estimation for both clouds, >= 1 (CloudModelParams::k);
    * throws otherwise. */
  void setKSearch (int k);
  /** \brief k of A's model parameters (setKSearch() sets both clouds'). */
  int getKSearch () const { return input_params_.k; }
  /** \brief Locally denoised point positions for both clouds
    * (CloudModelParams::surface_projection, default on). */
  void setSurfaceProjection (bool project);
  /** \brief Surface projection of A's model parameters (setSurfaceProjection() sets both
    * clouds'). */
  bool getSurfaceProjection () const { return input_params_.surface_projection; }
  /** \brief Hierarchy parameters, used for both clouds (CloudModelParams::hierarchy); validated. */
  void setHierarchyParams (const BVHParams& params);
  /** \brief Hierarchy parameters of A's model parameters (setHierarchyParams() sets both
    * clouds'). */
  const BVHParams& getHierarchyParams () const { return input_params_.hierarchy; }
  /** \brief Everything a model of A is built from but the cloud; validated. */
  void setInputModelParams (const CloudModelParams& params) { params.validate (); input_params_ = params; markInput (); }
  /** \brief Everything a model of A is built from but the cloud. */
  const CloudModelParams& getInputModelParams () const { return input_params_; }
  /** \brief Everything a model of B is built from but the cloud; validated. */
  void setTargetModelParams (const CloudModelParams& params) { params.validate (); target_params_ = params; markTarget (); }
  /** \brief Everything a model of B is built from but the cloud. */
  const CloudModelParams& getTargetModelParams () const { return target_params_; }

  /** \brief Uses a prebuilt model of A instead of building one from the input cloud (null:
    * build from the input cloud again). filter() still needs the input cloud it came from (its
    * points are checked: changedCloudError()). */
  void setInputModel (const CloudModel::ConstPtr& model) { input_model_ = model; input_prebuilt_ = static_cast<bool> (model); input_dirty_ = !model; }
  /** \brief Uses a prebuilt model of B instead of building one from the target cloud. */
  void setTargetModel (const CloudModel::ConstPtr& model) { target_model_ = model; target_prebuilt_ = static_cast<bool> (model); target_dirty_ = !model; }
  /** \brief The models of the last successful compute (null before): share them with
    * collide() from other threads. */
  CloudModel::ConstPtr getInputModel () const { return input_model_; }
  /** \brief B's counterpart of getInputModel(). */
  CloudModel::ConstPtr getTargetModel () const { return target_model_; }
  /** \brief Rebuilds the models built from clouds at the next query: for clouds changed in place
    * without being set again. Prebuilt models are kept. */
  void markForRebuild () { markInput (); markTarget (); }

  /** \brief Every query parameter at once; validated (throws pcl::BadArgumentException). With
    * request.surface on, the next query builds both clouds' surface model
    * (CloudModelParams::surface) if they lack it; a model set by setInputModel() or setTargetModel()
    * is used as given. */
  void setRequest (const CollisionRequest& request);
  /** \brief The query parameters. */
  const CollisionRequest& getRequest () const { return request_; }
  /** \brief Verdict thresholds on P: Free below free_below, InCollision above collision_above. */
  void setThresholds (double free_below, double collision_above);
  /** \brief Seed of the stochastic traversal (and of nothing else). */
  void setSeed (std::uint64_t seed) { request_.seed = seed; }

  /** \brief Minimum P_i kept by filter(), in [0, 1] (default 0.5); throws otherwise. */
  void setProbabilityThreshold (double p);
  /** \brief The minimum P_i filter() keeps. */
  double getProbabilityThreshold () const { return probability_threshold_; }

  /** \brief Query with both clouds in their own frames as given (identity pose). */
  bool compute (CollisionResult& result) { return compute (Eigen::Isometry3d::Identity (), result); }
  /** \brief Query with A moved by a rigid pose: A's point p is tested at T_target_input * p in
    * B's frame. Models are reused across calls (see the class comment for when they are
    * rebuilt). The witness is in the query frame, here the target's (CollisionResult).
    * \return false, with result.status and message set and a PCL_ERROR, when the inputs are
    * unusable (no cloud, no finite point, a non-rigid or non-finite pose). */
  bool compute (const Eigen::Isometry3d& T_target_input, CollisionResult& result);
  /** \brief compute() for many poses, spread over threads (collideBatch()).
    *
    * results[i] is what compute (T_target_input[i], results[i]) gives (timings aside),
    * whatever the thread count, except that a failed pose's message starts with "pose <i>: ".
    * A bad pose fails alone; the others are still answered. Models are (re)built once, before
    * the threads start; with request.enable_timings every result's build_ms is the time this
    * call spent on them (0 when they were reused), so do not sum it over the results.
    * \param[in] T_target_input rigid poses of A in B's frame, as for compute()
    * \param[out] results resized to T_target_input.size()
    * \param[in] threads worker threads: 0 = std::thread::hardware_concurrency(), never more
    *            than poses; negative throws pcl::BadArgumentException
    * \return true when every pose succeeded (true for no pose); a PCL_ERROR names the first
    *         failure otherwise. */
  bool computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input, std::vector<CollisionResult>& results,
                     int threads = 0);
  /** \brief computeBatch() that hands each result over while the later poses are answered
    * (collideBatch()'s overload with `ready`): ready (i) is called once for every pose, in pose
    * order, as soon as results[i] is final (failed poses included, with their "pose <i>: "
    * message). The calls never overlap and run on the batch's threads; ready may move from or
    * clear results[i], and must not change this object. An exception from ready stops the batch
    * and is rethrown here. pcd_collision -poses prints its answers so. */
  bool computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input, std::vector<CollisionResult>& results,
                     int threads, const std::function<void (std::size_t)>& ready);

  /** \brief Like pcl::Filter::filter, in place too (output the input cloud), but a failed call
    * leaves the output empty, so it never holds stale points: not even with setKeepOrganized(),
    * where PCL's base class would return the whole input cloud (a probe, 2026-12-07). */
  void
  filter (PointCloud& output)
  {
    // In place, PCL filters into a copy and assigns it: clearing the output first emptied the input
    // before the query (a 307,200-point scan read "no finite point").
    const bool in_place = &output == this->input_.get ();
    if (!in_place)
      output.clear ();
    filter_failed_ = true;  // until applyFilter() succeeds: PCL skips it without an input cloud
    pcl::FilterIndices<PointT>::filter (output);
    if (filter_failed_)
      output.clear ();
    if (in_place)
      markInput ();  // the input cloud changed: its model is rebuilt at the next query
  }
  /** \brief Like pcl::Filter::filter for indices, with indices cleared first (empty after a failed
    * call). */
  void
  filter (pcl::Indices& indices)
  {
    indices.clear ();
    filter_failed_ = true;
    pcl::FilterIndices<PointT>::filter (indices);
    if (filter_failed_)
      indices.clear ();
  }

protected:
  /** \brief Runs an exhaustive per-point query and keeps the indices of A whose P_i reaches
    * the probability threshold (the others with setNegative()); empty, with a PCL_ERROR, when
    * the query fails or the input model is not the input cloud's (its size or its points:
    * changedCloudError()). */
  void applyFilter (pcl::Indices& indices) override;
  using pcl::FilterIndices<PointT>::applyFilter;

private:
  void markInput () { input_dirty_ = true; }
  void markTarget () { target_dirty_ = true; }
  /** \brief Builds whichever model is marked for rebuild; false with result's status and
    * message on bad input, build_ms set to the time spent. */
  bool prepare (CollisionResult& result);
  /** \brief The staleness rule, compute()'s (for a model it built and reuses) and filter()'s
    * (for any input model): empty when the model's per-point results are index-aligned with the
    * cloud (model.sourceSize() == cloud.size()), otherwise why not, naming `which` cloud. */
  static std::string staleModelError (const CloudModel& model, const PointCloud& cloud, const char* which);
  /** \brief filter()'s rule: staleModelError(), and then that the model's
    * CloudModel::sourceFingerprint() is the cloud's (cloudFingerprint()), so the indices filter()
    * keeps name the points the model answered for; empty when they do. */
  std::string changedCloudError (const CloudModel& model, const PointCloud& cloud) const;
  /** \brief Turns collide()'s answer (A's frame) into compute()'s: the witness in the
    * target's frame and, with timings, build_ms. */
  void finishResult (const Eigen::Isometry3d& T_target_input, double build_ms, CollisionResult& result) const;
  /** \brief computeBatch()'s last step for pose i: finishResult() for an answer, the pose's
    * number before a failure's message (and a PCL_ERROR for the first failure, counted in
    * failed). */
  void finishBatchResult (std::size_t i, const Eigen::Isometry3d& T_target_input, double build_ms,
                          CollisionResult& result, std::size_t& failed) const;

  PointCloudConstPtr target_;
  pcl::IndicesConstPtr target_indices_;
  CovarianceCloudConstPtr input_covariances_;
  CovarianceCloudConstPtr target_covariances_;
  CloudModelParams input_params_;
  CloudModelParams target_params_;
  CollisionRequest request_;
  double probability_threshold_ = 0.5;

  CloudModel::ConstPtr input_model_, target_model_;
  bool input_dirty_ = true, target_dirty_ = true;
  bool input_prebuilt_ = false, target_prebuilt_ = false;
  RobustClassifier classifier_;
  /** \brief Whether the last applyFilter() failed: filter() sets it before, applyFilter() clears
    * it at its end. */
  bool filter_failed_ = false;
};
} // namespace pcl_probcollision

#ifdef PCL_NO_PRECOMPILE
#include <pcl_probcollision/impl/probabilistic_collision.hpp>
#endif
