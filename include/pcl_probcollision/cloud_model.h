// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model_params.h>
#include <pcl_probcollision/point_types.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/surface_model.h>
#include <pcl_probcollision/uncertain_points.h>

#include <pcl/point_cloud.h>
#include <pcl/types.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace pcl_probcollision
{
class CloudModel;

/** \brief Builds the model of the object sampled by a PCL cloud: covariances estimated
  * (CovarianceEstimation with params.k, params.noise and params.surface_projection) unless
  * given, non-finite points skipped, the hierarchy built in the local frame (CloudModel).
  *
  * \param[in] cloud the points (only x, y, z are read, and the viewpoint for the depth noise
  *            models); read during the call only
  * \param[in] params per-cloud settings (validated)
  * \param[in] indices the points to use (all when null)
  * \param[in] covariances covariances index-aligned with the whole cloud (estimated when null);
  *            a non-finite one drops its point. Given, they are the whole spread: params.noise
  *            and the discretisation term are not added
  * \param[in] name what error messages call the cloud ("input", "target", a file name)
  * \return the model
  * \throws pcl::BadArgumentException, its description starting with name (what() puts
  *         "pcl_probcollision::buildCloudModel : " before it; errorMessage() gives the
  *         description alone), for invalid params, covariances of the wrong size or not positive
  *         semi-definite, an index outside the cloud, a coordinate beyond +-1e15, a depth noise
  *         model with a non-finite sensor_origin_ (SensorNoiseModel::sensorPoseError), or no
  *         finite point. A PCL warning (PCL_WARN) accompanies warning(). */
template <typename PointT>
std::shared_ptr<const CloudModel>
buildCloudModel (const pcl::PointCloud<PointT>& cloud, const CloudModelParams& params = CloudModelParams (),
                 const pcl::Indices* indices = nullptr, const pcl::PointCloud<Covariance>* covariances = nullptr,
                 const std::string& name = "cloud");

/** \brief A 64-bit hash of the x, y, z of every point of the cloud (their bits, non-finite points
  * included, in order) and of the indices, when given (the points a model is built from): what
  * CloudModel::sourceFingerprint() holds, so that a cloud and indices can be checked against the
  * model built from them (ProbabilisticCollision::filter() does). It detects changes, it is no
  * cryptographic hash. About 2 ns a point (8 ms for 5,000,000 points). */
template <typename PointT>
std::uint64_t
cloudFingerprint (const pcl::PointCloud<PointT>& cloud, const pcl::Indices* indices = nullptr)
{
  // FNV-1a over 32-bit words, one lane per coordinate (three independent multiply chains run 4
  // times as fast as one: 1.6 against 7.3 ns a point). Each step is invertible, so a change of
  // any one coordinate or index always changes the hash.
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  const auto bits = [] (float v) {
    std::uint32_t b;
    std::memcpy (&b, &v, sizeof b);
    return b;
  };
  std::uint64_t hx = 0xcbf29ce484222325ULL, hy = hx, hz = hx, hi = hx;
  for (const PointT& p : cloud)
  {
    hx = (hx ^ bits (p.x)) * kPrime;
    hy = (hy ^ bits (p.y)) * kPrime;
    hz = (hz ^ bits (p.z)) * kPrime;
  }
  // No indices (every point) and an empty list differ: the count of indices + 1 goes in.
  if (indices)
  {
    for (const int i : *indices)
      hi = (hi ^ static_cast<std::uint32_t> (i)) * kPrime;
    hi = (hi ^ static_cast<std::uint64_t> (indices->size () + 1)) * kPrime;
  }
  return (((((hx * kPrime) ^ hy) * kPrime ^ hz) * kPrime ^ hi) * kPrime) ^ static_cast<std::uint64_t> (cloud.size ());
}

/** \brief The model of one object known from a point cloud: its uncertain points (one
  * Gaussian each) and their epsilon-overlap hierarchy, built once and then immutable.
  *
  * Build it with buildCloudModel() from a PCL cloud, or from points with covariances you
  * already have. Query two models with collide (a, b, T_a_b, request, result). A model can be
  * shared by any number of queries and threads (share it as ConstPtr).
  *
  * Local frame: the points are stored and the hierarchy is built about the points' centroid,
  * kept in double as origin(). Single-precision coordinates far from the origin (a map frame,
  * UTM) then lose nothing in the arithmetic of the query: the query composes the pose with the
  * two origins in double (collide()). Everything the model reports to a caller (witness
  * points, origin()) is in the cloud's own frame; hierarchy() and its boxes are in the local
  * frame, cloud frame = local frame + origin().
  *
  * A model never sees the cloud again after its build: a cloud changed afterwards (e.g. by
  * pcl::transformPointCloud in place) needs a new model.
  */
class CloudModel
{
public:
  /** \brief Shared pointer to a model. */
  using Ptr = std::shared_ptr<CloudModel>;
  /** \brief Shared pointer to a const model (what queries share). */
  using ConstPtr = std::shared_ptr<const CloudModel>;

  /** \brief Builds the model from points with covariances, in the cloud's frame.
    * \param[in] points means, covariances, optional area weights and source indices; taken over
    * \param[in] hierarchy hierarchy parameters (validated)
    * \param[in] source_size size of the caller's cloud the source indices refer to (per-point
    *            results are index-aligned with it); 0 means points.size() (or one past the
    *            largest source index, when there are any)
    * \throws pcl::BadArgumentException for invalid parameters, sizes that disagree or
    *         non-finite values (ProbabilisticBVH::build), a source index below 0 or at least
    *         source_size (when given), or no point at all. The model carries no surface
    *         (CollisionRequest::surface is then answered by the separators); buildCloudModel()
    *         builds one. */
  explicit CloudModel (UncertainCloud points, const BVHParams& hierarchy = BVHParams (), std::size_t source_size = 0);

  /** \brief The hierarchy, in the local frame (cloud frame = local + origin()). */
  const ProbabilisticBVH& hierarchy () const { return bvh_; }
  /** \brief The local frame's origin in the cloud's frame: the centroid of the points. */
  const Eigen::Vector3d& origin () const { return origin_; }
  /** \brief Number of points in the model (finite points of the cloud, within its indices). */
  std::size_t size () const { return bvh_.size (); }
  /** \brief Size of the caller's cloud: per-point results are index-aligned with it. */
  std::size_t sourceSize () const { return source_size_; }
  /** \brief cloudFingerprint() of the cloud and indices buildCloudModel() built the model from
    * (all the cloud's points, and the indices where given); 0 for a model built from points
    * directly. */
  std::uint64_t sourceFingerprint () const { return source_fingerprint_; }
  /** \brief Points of the cloud (within its indices) left out as non-finite. */
  std::size_t skippedPoints () const { return skipped_; }
  /** \brief The settings the model was built with (defaults but for the hierarchy when built
    * from points directly). */
  const CloudModelParams& params () const { return params_; }
  /** \brief Wall time of the build in milliseconds: covariance estimation and hierarchy. */
  double buildMilliseconds () const { return build_ms_; }
  /** \brief The cloud's median nearest-neighbour spacing, as io::medianSpacing() measures it
    * (detail::medianNearestSpacing), read from the covariance estimation's own neighbour search:
    * what pcd_collision samples a mesh at, without a second k-d tree over a large cloud. NaN
    * when the build did not search the whole cloud's neighbours (covariances given without the
    * surface model, indices given, samples merged: fullResolution(), where kept, has the
    * cloud's) or cannot tell (a sampled point with more than k coincident neighbours); the caller
    * then measures it itself. */
  double medianNeighbourSpacing () const { return neighbour_spacing_; }
  /** \brief Bounding-box diagonal of the model's points (their means, merged ones where samples
    * were merged), in data units; 0 for a single point. What Python's collide() judges units by
    * (io::scaleWarning): a millimetre model against a metre one differs by about 1000x. */
  double diagonal () const { return diagonal_; }
  /** \brief The oriented surface (METHOD.md 10a), in the local frame; empty() when built
    * with CloudModelParams::surface off. */
  const SurfaceModel& surface () const { return surface_; }
  /** \brief Memory held in bytes (the hierarchy, its points, the surface model and the map of
    * merged samples). */
  std::size_t bytes () const
  {
    return bvh_.bytes () + surface_.bytes () + (point_of_source_.capacity () + representatives_.capacity ()) * sizeof (int) +
           (full_resolution_ ? full_resolution_->bytes () : 0);
  }
  /** \brief Where samples were merged and CloudModelParams::keep_full_resolution kept it: the
    * model of the same cloud unmerged, which collide() asks when the merged answer is contact
    * leaning to collision. Null otherwise. */
  const CloudModel* fullResolution () const { return full_resolution_.get (); }
  /** \brief Samples merged into another (CloudModelParams::noise_resolution): the finite
    * samples in the model minus size(); 0 when none merged. */
  std::size_t mergedSamples () const { return merged_samples_; }
  /** \brief Samples exactly coincident with an earlier one of the cloud (x y z equal, and the
    * normal for point types with one), modelled once with it: every point of a scan duplicated
    * collapsed its neighbourhoods and moved near-contact verdicts toward free. 0 when none. */
  std::size_t coincidentSamples () const { return coincident_samples_; }
  /** \brief CovarianceEstimation::getNeighbourScatterRatio() of the build: about 0.6 on a
    * surface scan, near 0 where the samples lie along lines (0.03 on a LiDAR's rings); NaN when
    * the build estimated no covariance (given without the surface model). */
  double neighbourScatterRatio () const { return neighbour_scatter_ratio_; }
  /** \brief Below this neighbourScatterRatio(), with the cloud spread over an area, the samples
    * are scan lines: the model measures their spacing along the lines, and a part lying between
    * two lines 0.6-0.9 m apart read free (docs/RELIABILITY.md), so warning() says so. Three times
    * a LiDAR's 0.03, a sixth of a surface scan's 0.59-0.69. */
  static constexpr double kScanLineRatio = 0.1;
  /** \brief The points' middle standard deviation (about their principal axes) at least this
    * share of their largest: a cloud spread over an area. A rod's, a cable's or a row's samples
    * lie along one line, rightly. */
  static constexpr double kScanLineExtentRatio = 0.1;
  /** \brief When samples were merged or coincided: per index of the caller's cloud, the model
    * point (index into hierarchy().means()) that stands for it, -1 when none does (non-finite,
    * outside the indices). Empty when none merged nor coincided: point j then stands for
    * hierarchy().sourceIndex(j) alone. */
  const std::vector<int>& pointOfSource () const { return point_of_source_; }
  /** \brief The caller's index of the sample a model point's hierarchy source index names:
    * hierarchy().sourceIndex(j) itself when none merged nor coincided, else the index of the
    * sample its merge was seeded from (the first of coincident ones). */
  int sourceIndex (int hierarchy_source) const
  {
    return representatives_.empty () || hierarchy_source < 0 ? hierarchy_source
                                                             : representatives_[static_cast<std::size_t> (hierarchy_source)];
  }
  /** \brief A warning about the input, empty when there is none: coordinates so far from the
    * origin that their float spacing exceeds a tenth of the points' typical standard deviation
    * (the input itself has then lost precision; the model cannot restore it), or a
    * CloudModelParams::noise_resolution that merged the cloud into no more points than the
    * covariance estimation's k (each neighbourhood then spans the whole object, and the model
    * no longer resolves its shape: the stereo mug of ../shared/data merged within 30 noise
    * deviations into one point read free 5 cm into its table); given normals off their points'
    * planes, closed_objects asked of a surface that does not check closed, or samples along lines
    * over an area (assessScanLines: a LiDAR's rings), each appended after "; ". collide() passes
    * it on in CollisionResult::message. */
  const std::string& warning () const { return warning_; }

  /** \brief Float spacing (one ulp) at the largest coordinate magnitude of the cloud divided by
    * the points' typical standard deviation (median over points of sqrt(trace / 3)); warning()
    * is set above kPrecisionWarningRatio. */
  double precisionRatio () const { return precision_ratio_; }
  /** \brief The ratio above which warning() is set: the input's float spacing above a tenth of
    * the points' standard deviation. */
  static constexpr double kPrecisionWarningRatio = 0.1;
  /** \brief An organized cloud's VIEWPOINT farther than this share of the points' mean distance
    * from where its rows and columns say its sensor was (organizedSensorPose), or (for a noise
    * model that reads the sensor's pose) its optical axis off by more than 2 degrees (the cosine
    * below), was left behind when the cloud moved: the model takes the sensor's pose, and
    * warning() says so. The estimate is exact to float rounding on a pinhole image (within 0.2 and 5
    * micrometres on the real Kinect and stereo scans of ../shared/data). */
  static constexpr double kStaleViewpointShare = 0.01;
  static constexpr double kStaleAxisCosine = 0.99939;  ///< cos 2 degrees
  /** \brief With noise_resolution unset, a merge whose points' bounding-box diagonal is under
    * this share of the samples' is not taken (the cloud stays unmerged): the object is only a
    * few noise deviations across, and the merge averages its shape away (a 2 cm cube sampled
    * every 4 mm with 1 mm of scatter, declared at 5 mm: 60 % of its diagonal lost; it read free
    * 2-8 mm over a table). CloudModelParams::noise_resolution's other such rule: a merge into no
    * more than k points. */
  static constexpr double kMinMergedDiagonal = 0.75;

private:
  friend void offsetModel (CloudModel& model, const Eigen::Vector3d& offset);
  CloudModel () = default;
  /** \brief Centres the points on their centroid (origin()) and builds the hierarchy there, on
    * the covariances `packed` holds, or where it is empty on points.covariances. */
  void buildLocal (UncertainCloud&& points, std::vector<PackedCovariance>&& packed, const BVHParams& hierarchy,
                   std::size_t source_size, int threads = 1);

  /** \brief buildCloudModel() but for sourceFingerprint(), which buildCloudModel() sets on what
    * this returns (one place for its several returns, merged or not). */
  template <typename PointT>
  static std::shared_ptr<const CloudModel>
  buildFromCloud (const pcl::PointCloud<PointT>& cloud, const CloudModelParams& params, const pcl::Indices* indices,
                  const pcl::PointCloud<Covariance>* covariances, const std::string& name);
  template <typename PointT>
  friend std::shared_ptr<const CloudModel>
  buildCloudModel (const pcl::PointCloud<PointT>& cloud, const CloudModelParams& params,
                   const pcl::Indices* indices, const pcl::PointCloud<Covariance>* covariances,
                   const std::string& name);
  /** \brief Takes a model built from a merged cloud (impl/resolution.hpp) back to the caller's
    * cloud: cluster_of maps its indices to merged points, seeds the merged points to its indices.
    * Sets warning() where the merge left no more points than the covariance estimation's k. */
  void adoptMerge (const CloudModelParams& params, std::size_t source_size, std::size_t candidates,
                   const std::vector<int>& cluster_of, std::vector<int>&& seeds, const std::string& name);
  /** \brief Per hierarchy source index below sources, the model point that holds it (-1 for none). */
  std::vector<int> pointOfHierarchySource (std::size_t sources) const;
  /** \brief Takes a model built from a cloud's distinct samples (detail::mergeCoincident:
    * distinct_of per index of the caller's cloud, seeds per distinct sample) back to the caller's
    * cloud, as adoptMerge does, and its full-resolution model with it; a model that measured
    * its spacing takes spacing, the caller's cloud's. */
  void adoptCoincident (std::size_t source_size, std::size_t candidates, const std::vector<int>& distinct_of,
                        const std::vector<int>& seeds, double spacing);
  /** \brief Adds to warning() where the samples lie along lines spread over an area, as a
    * LiDAR's rings do (neighbourScatterRatio() under kScanLineRatio, the points spread at least
    * kScanLineExtentRatio as wide as long). */
  void assessScanLines (const std::string& name);
  /** \brief Appends text to warning(), after "; " where it says something already. */
  void addWarning (const std::string& text);
  /** \brief Sets precisionRatio() and warning() from the largest input coordinate magnitude. */
  void assessPrecision (double max_abs_coordinate, const std::string& name);
  /** \brief Adds to warning() where the given normals lie off their points' planes
    * (SurfaceModel::givenNormalSpreadRatio above kMaxNormalSpreadRatio). */
  void assessNormals (const std::string& name);
  /** \brief Adds to warning() where closed_objects was asked for and the propagated orientation
    * did not check closed (SurfaceModel::insideKnown() false): its inside is then not used. */
  void assessClosed (const std::string& name);

  /** \brief Builds the surface model from the local points alone (the constructor from an
    * UncertainCloud): normals and neighbours estimated here; there is no viewpoint and
    * there are no given normals, so Auto means Propagate. */
  void buildSurfaceFromPoints (NormalOrientation orientation, int k);
  ProbabilisticBVH bvh_;
  SurfaceModel surface_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero ();
  std::size_t source_size_ = 0;
  std::uint64_t source_fingerprint_ = 0;
  std::size_t skipped_ = 0;
  std::size_t merged_samples_ = 0;
  std::size_t coincident_samples_ = 0;
  double neighbour_scatter_ratio_ = std::numeric_limits<double>::quiet_NaN ();
  std::vector<int> point_of_source_;
  std::vector<int> representatives_;
  std::shared_ptr<const CloudModel> full_resolution_;
  CloudModelParams params_;
  double build_ms_ = 0.0;
  double neighbour_spacing_ = std::numeric_limits<double>::quiet_NaN ();
  double diagonal_ = 0.0;
  double precision_ratio_ = 0.0;
  std::string warning_;
};

/** \brief Declares the cloud a model was built from to be given about offset: its point p stands
  * for offset + p, in double. Moves origin() (and fullResolution()'s) by offset; nothing else
  * changes. For coordinates a float cannot hold (a map frame far from the origin, in double):
  * subtract a point near the cloud in double, build from the differences (and a viewpoint moved
  * alike), then offset the model; Python's build_model does so for float64 points far from the
  * origin. Call it on a model nothing else uses yet. */
void offsetModel (CloudModel& model, const Eigen::Vector3d& offset);
} // namespace pcl_probcollision

#ifdef PCL_NO_PRECOMPILE
#include <pcl_probcollision/impl/cloud_model.hpp>
#endif
