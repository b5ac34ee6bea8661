// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/point_types.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/robust_classifier.h>
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/filters/filter_indices.h>
#include <pcl/point_cloud.h>

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

namespace pcl_probcollision
{
/** \brief Probability that the object sampled by the input cloud (A) collides with the object
  * sampled by the target cloud (B), after Pan, Chitta and Manocha (ISRR 2011); see METHOD.md.
  *
  * Each point is a Gaussian: given covariances, or estimated with CovarianceEstimation
  * (k = 10) plus the cloud's SensorNoiseModel (none by default: set one for sensor data).
  * Each cloud gets a ProbabilisticBVH, built once and reused for every pose until a cloud,
  * its indices, covariances, noise model, k or the hierarchy parameters change.
  *
  * As a filter (pcl::FilterIndices), it keeps the points of A whose collision probability
  * reaches setProbabilityThreshold() (default 0.5); setNegative() keeps the others and
  * setKeepOrganized() keeps an organized layout, as in pcl::CropBox. Filtering runs an
  * exhaustive query so that every point near B is evaluated; points the traversal never came
  * near count as probability 0.
  *
  * \note Non-finite points are skipped (and counted in the result). The two clouds must be in
  * the same units: covariances, thresholds of the hierarchy and noise sigmas are in those units.
  * \note Not thread-safe (a PCL filter object). computeBatch() spreads many poses over
  * threads; for concurrent queries from the caller's own threads build the hierarchies once
  * and call collide() from each thread.
  */
template <typename PointT>
class ProbabilisticCollision : public pcl::FilterIndices<PointT>
{
public:
  using Ptr = pcl::shared_ptr<ProbabilisticCollision<PointT>>;
  using ConstPtr = pcl::shared_ptr<const ProbabilisticCollision<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using CovarianceCloudConstPtr = pcl::PointCloud<Covariance>::ConstPtr;

  ProbabilisticCollision ();

  /** \brief Object B. */
  void setTargetCloud (const PointCloudConstPtr& target) { target_ = target; }
  PointCloudConstPtr getTargetCloud () const { return target_; }
  /** \brief Restricts B to these indices (all points by default). */
  void setTargetIndices (const pcl::IndicesConstPtr& indices) { target_indices_ = indices; }
  pcl::IndicesConstPtr getTargetIndices () const { return target_indices_; }

  /** \brief Covariances of A, index-aligned with the whole input cloud (not its indices);
    * unset means estimated. A non-finite covariance drops its point. */
  void setInputCovariances (const CovarianceCloudConstPtr& covariances) { input_covariances_ = covariances; }
  /** \brief Covariances of B, index-aligned with the whole target cloud; unset means estimated. */
  void setTargetCovariances (const CovarianceCloudConstPtr& covariances) { target_covariances_ = covariances; }

  /** \brief Sensor noise added to A's estimated covariances (default none). The depth models
    * read the input cloud's sensor_origin_ / sensor_orientation_. */
  void setInputNoise (const SensorNoiseModel& noise) { input_noise_ = noise; input_dirty_ = true; }
  const SensorNoiseModel& getInputNoise () const { return input_noise_; }
  /** \brief Sensor noise added to B's estimated covariances (default none). */
  void setTargetNoise (const SensorNoiseModel& noise) { target_noise_ = noise; target_dirty_ = true; }
  const SensorNoiseModel& getTargetNoise () const { return target_noise_; }

  /** \brief k of the covariance estimation, >= 1 (default 10); throws otherwise. */
  void setKSearch (int k);
  int getKSearch () const { return k_; }
  /** \brief Locally denoised point positions for estimated covariances (see
    * CovarianceEstimation::setSurfaceProjection; default on, chosen by the evaluation in
    * docs/RESULTS.md). Off gives the paper's model: every point at its measured position with
    * its full noise and discretisation spread, whose maximum over many points near contact
    * drifts toward 1. Has no effect on a cloud without a sensor noise model or with
    * covariances given by the caller. */
  void setSurfaceProjection (bool project) { project_ = project; input_dirty_ = target_dirty_ = true; }
  bool getSurfaceProjection () const { return project_; }

  /** \brief Every query parameter at once; validated (throws pcl::BadArgumentException). */
  void setRequest (const CollisionRequest& request);
  const CollisionRequest& getRequest () const { return request_; }
  /** \brief Verdict thresholds on P: Free below free_below, InCollision above collision_above. */
  void setThresholds (double free_below, double collision_above);
  /** \brief Seed of the stochastic traversal (and of nothing else). */
  void setSeed (std::uint64_t seed) { request_.seed = seed; }
  /** \brief Hierarchy parameters, used for both clouds; validated. */
  void setHierarchyParams (const BVHParams& params);

  /** \brief Minimum P_i kept by filter(), in [0, 1] (default 0.5); throws otherwise. */
  void setProbabilityThreshold (double p);
  double getProbabilityThreshold () const { return probability_threshold_; }

  /** \brief Query with both clouds in their own frames as given (identity pose). */
  bool compute (CollisionResult& result) { return compute (Eigen::Isometry3d::Identity (), result); }
  /** \brief Query with A moved by a rigid pose: A's point p is tested at T_target_input * p in
    * B's frame. Hierarchies are reused across calls.
    * \return false, with result.status and message set and a PCL_ERROR, when the inputs are
    * unusable (no cloud, no finite point, a non-rigid or non-finite pose). */
  bool compute (const Eigen::Isometry3d& T_target_input, CollisionResult& result);
  /** \brief compute() for many poses, spread over threads (collideBatch()).
    *
    * results[i] is what compute (T_target_input[i], results[i]) gives (timings aside),
    * whatever the thread count, except that a failed pose's message starts with "pose <i>: ".
    * A bad pose fails alone; the others are still answered. Hierarchies are (re)built once, before the threads
    * start; with request.enable_timings every result's build_ms is the time this call spent on
    * them (0 when they were reused), so do not sum it over the results.
    * \param[in] T_target_input rigid poses of A in B's frame, as for compute()
    * \param[out] results resized to T_target_input.size()
    * \param[in] threads worker threads: 0 = std::thread::hardware_concurrency(), never more
    *            than poses; negative throws pcl::BadArgumentException
    * \return true when every pose succeeded (true for no pose); a PCL_ERROR names the first
    *         failure otherwise. */
  bool computeBatch (const std::vector<Eigen::Isometry3d>& T_target_input, std::vector<CollisionResult>& results,
                     int threads = 0);

  /** \brief The hierarchies of the last successful compute (null before). */
  std::shared_ptr<const ProbabilisticBVH> getInputHierarchy () const { return input_bvh_; }
  std::shared_ptr<const ProbabilisticBVH> getTargetHierarchy () const { return target_bvh_; }

  /** \brief Like pcl::Filter::filter, but the output is cleared first, so a failed call never
    * leaves stale points behind. */
  void filter (PointCloud& output) { output.clear (); pcl::FilterIndices<PointT>::filter (output); }
  void filter (pcl::Indices& indices) { indices.clear (); pcl::FilterIndices<PointT>::filter (indices); }

protected:
  void applyFilter (pcl::Indices& indices) override;
  using pcl::FilterIndices<PointT>::applyFilter;

private:
  /** \brief Checks the inputs and (re)builds whatever hierarchy is out of date; false with
    * result's status and message on bad input. */
  bool prepare (CollisionResult& result);
  /** \brief prepare() once the inputs are initialised (initCompute). */
  bool buildHierarchies (CollisionResult& result);
  /** \brief Whether T_target_input is a finite rotation plus translation; result says why not. */
  static bool checkPose (const Eigen::Isometry3d& T_target_input, CollisionResult& result);
  /** \brief Turns collide()'s answer (A's frame, hierarchy order) into compute()'s: the
    * witness in the target's frame, per-point values on the callers' clouds, skipped points
    * and, with timings, build_ms. */
  void finishResult (const Eigen::Isometry3d& T_target_input, double build_ms, CollisionResult& result) const;

  PointCloudConstPtr target_;
  pcl::IndicesConstPtr target_indices_;
  CovarianceCloudConstPtr input_covariances_;
  CovarianceCloudConstPtr target_covariances_;
  SensorNoiseModel input_noise_;
  SensorNoiseModel target_noise_;
  int k_ = 10;
  bool project_ = true;
  CollisionRequest request_;
  double probability_threshold_ = 0.5;

  /** \brief What a hierarchy was built from: rebuilt when any of it changes. */
  struct Source
  {
    const void* cloud = nullptr;
    const void* indices = nullptr;
    const void* covariances = nullptr;
    int k = 0;
    BVHParams params;
    bool operator== (const Source& o) const
    {
      return cloud == o.cloud && indices == o.indices && covariances == o.covariances && k == o.k &&
             params == o.params;
    }
  };
  /** \brief Builds one cloud's uncertain points and hierarchy. */
  bool buildHierarchy (const PointCloudConstPtr& cloud, const pcl::IndicesConstPtr& indices,
                       const CovarianceCloudConstPtr& covariances, const SensorNoiseModel& noise,
                       const char* which, std::shared_ptr<const ProbabilisticBVH>& bvh,
                       std::size_t& skipped, std::string& message) const;

  Source input_source_, target_source_;
  bool input_dirty_ = true, target_dirty_ = true;
  std::shared_ptr<const ProbabilisticBVH> input_bvh_, target_bvh_;
  std::size_t input_skipped_ = 0, target_skipped_ = 0;
  RobustClassifier classifier_;
};
} // namespace pcl_probcollision

#ifdef PCL_NO_PRECOMPILE
#include <pcl_probcollision/impl/probabilistic_collision.hpp>
#endif
