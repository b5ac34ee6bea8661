// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/covariance_estimation.h>
#include <pcl_probcollision/detail/huge_pages.h>
#include <pcl_probcollision/detail/input_checks.h>
#include <pcl_probcollision/detail/parallel.h>
#include <pcl_probcollision/detail/sample_spacing.h>
#include <pcl_probcollision/impl/resolution.hpp>
#include <pcl_probcollision/organized_sensor_pose.h>

#include <pcl/common/point_tests.h>
#include <pcl/point_types.h>
#include <pcl/console/print.h>
#include <pcl/exceptions.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
template <typename PointT>
std::shared_ptr<const CloudModel>
buildCloudModel (const pcl::PointCloud<PointT>& cloud, const CloudModelParams& params, const pcl::Indices* indices,
                 const pcl::PointCloud<Covariance>* covariances, const std::string& name)
{
  // The merged model's inner build fingerprints the merged cloud first; this outer call, the
  // caller's cloud, sets it last.
  const auto model = std::const_pointer_cast<CloudModel> (CloudModel::buildFromCloud (cloud, params, indices, covariances, name));
  model->source_fingerprint_ = cloudFingerprint (cloud, indices);
  return model;
}

template <typename PointT>
std::shared_ptr<const CloudModel>
CloudModel::buildFromCloud (const pcl::PointCloud<PointT>& cloud, const CloudModelParams& params,
                            const pcl::Indices* indices, const pcl::PointCloud<Covariance>* covariances,
                            const std::string& name)
{
  const auto start = std::chrono::steady_clock::now ();
  // what()'s function (PCLException's), without the source path PCL_THROW_EXCEPTION would add;
  // the descriptions start with name (errorMessage() keeps them alone).
  static constexpr const char* kFunction = "pcl_probcollision::buildCloudModel";
  params.validate ();
  std::ostringstream err;
  if (covariances && covariances->size () != cloud.size ())
  {
    err << name << " covariances have " << covariances->size () << " entries for " << cloud.size () << " points";
    throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
  }
  if (indices)
    for (const int i : *indices)
      if (i < 0 || static_cast<std::size_t> (i) >= cloud.size ())
      {
        err << name << " index " << i << " outside the cloud of " << cloud.size () << " points";
        throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
      }
  const std::size_t n = indices ? indices->size () : cloud.size ();
  auto at = [&] (std::size_t j) { return indices ? (*indices)[j] : static_cast<int> (j); };
  // A point's own normal, as the surface model takes it: finite and not zero (point types with
  // normals only).
  // Its length in double: in float a normal of length 1e20 (or 1e-20) overflowed (underflowed)
  // on the way to unit length and was set aside.
  const auto usableNormal = [] (const auto& p) {
    const Eigen::Vector3d given = Eigen::Vector3f (p.normal_x, p.normal_y, p.normal_z).template cast<double> ();
    return given.allFinite () && given.squaredNorm () > 0.0;
  };

  // Finite but absurd coordinates overflow the float arithmetic of the k-d tree (FLANN's middle
  // split computes (min + max) / 2 = inf; found by fuzz/fuzz_collide): refuse them by name.
  float max_abs = 0.0f;
  std::size_t finite_points = 0;
  for (std::size_t j = 0; j < n; ++j)
  {
    const PointT& p = cloud[at (j)];
    if (!pcl::isXYZFinite (p))
      continue;
    ++finite_points;
    const float m = std::max ({std::abs (p.x), std::abs (p.y), std::abs (p.z)});
    if (!(m <= static_cast<float> (detail::kMaxCoordinate)))
    {
      err.precision (9);
      err << name << " point " << at (j) << " at (" << p.x << ", " << p.y << ", " << p.z
          << ") is beyond the supported coordinate range of +-1e15";
      throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
    }
    max_abs = std::max (max_abs, m);
    // NaN or zero marks a point without a normal (PCL's convention); an infinite component is a
    // broken normal, which read as "none" would silently drop what the caller gave.
    if constexpr (pcl::traits::has_normal_v<PointT>)
      if (params.surface && (std::isinf (p.normal_x) || std::isinf (p.normal_y) || std::isinf (p.normal_z)))
      {
        err << name << " point " << at (j) << " has a normal with an infinite component (" << p.normal_x << ", "
            << p.normal_y << ", " << p.normal_z << "); give NaN or 0 for none";
        throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
      }
  }
  // Refused here, before the estimation, whose PCL base class would also print "input_ is
  // empty!" on stderr for an empty cloud.
  if (finite_points == 0)
  {
    err << name << " has no finite point (" << n << " given, " << n << " non-finite)";
    throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
  }

  // An organized cloud says where its sensor was (organizedSensorPose). A VIEWPOINT elsewhere was
  // left behind when the cloud moved (pcl::transformPointCloud keeps sensor_origin_ and
  // sensor_orientation_): it would put every depth model's ray and the surface layer's shadows
  // in the wrong place (a stale VIEWPOINT refused left a single view two-sided, and 54 of 77
  // collisions inside it read free). The model is the cloud's with its sensor's pose, and says so.
  if (const std::optional<SensorPose> sensor = organizedSensorPose (cloud))
  {
    const SensorPose given = SensorPose::fromViewpoint (cloud.sensor_origin_, cloud.sensor_orientation_);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero ();
    std::size_t finite = 0;
    for (const PointT& p : cloud)
      if (pcl::isXYZFinite (p))
      {
        centroid += p.getVector3fMap ().template cast<double> () - sensor->origin;
        ++finite;
      }
    const double distance = centroid.norm () / double (std::max<std::size_t> (finite, 1));
    const bool moved = !((given.origin - sensor->origin).norm () <= CloudModel::kStaleViewpointShare * distance);
    const bool turned = params.noise.usesSensorPose () && !(std::abs (given.axis.dot (sensor->axis)) >= CloudModel::kStaleAxisCosine);
    if (moved || turned)
    {
      pcl::PointCloud<PointT> posed = cloud;
      posed.sensor_origin_ = Eigen::Vector4f (float (sensor->origin.x ()), float (sensor->origin.y ()), float (sensor->origin.z ()), 0.0f);
      posed.sensor_orientation_ = Eigen::Quaternionf::FromTwoVectors (Eigen::Vector3f::UnitZ (), sensor->axis.cast<float> ());
      const auto model = std::const_pointer_cast<CloudModel> (buildCloudModel (posed, params, indices, covariances, name));
      std::ostringstream out;
      out.precision (4);
      out << name << ": its sensor was at (" << sensor->origin.x () << ", " << sensor->origin.y () << ", " << sensor->origin.z ()
          << ") looking along (" << sensor->axis.x () << ", " << sensor->axis.y () << ", " << sensor->axis.z ()
          << "), where the planes of its rows and columns of points meet, not at its VIEWPOINT (" << given.origin.x () << ", "
          << given.origin.y () << ", " << given.origin.z () << ") looking along (" << given.axis.x () << ", " << given.axis.y ()
          << ", " << given.axis.z ()
          << "): the cloud was moved without it (pcl::transformPointCloud leaves sensor_origin_ and sensor_orientation_); "
             "the model takes its sensor's pose";
      model->warning_ = model->warning_.empty () ? out.str () : model->warning_ + "; " + out.str ();
      PCL_WARN ("[pcl_probcollision::buildCloudModel] %s\n", out.str ().c_str ());
      return model;
    }
  }

  // A depth noise model needs the sensor's position (it would make every covariance NaN, and the
  // points would be blamed); the merge below reads it too.
  if (!covariances && params.noise.usesSensorPose ())
  {
    const std::string why =
        params.noise.sensorPoseError (SensorPose::fromViewpoint (cloud.sensor_origin_, cloud.sensor_orientation_));
    if (!why.empty ())
    {
      err << name << " " << why << " (the cloud's sensor_origin_, a PCD file's VIEWPOINT)";
      throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
    }
  }

  // Given covariances must be covariances (detail::covarianceError, the constructor's rule too): a
  // NaN one marks a missing value and drops its point; a negative one is an error.
  if (covariances)
    for (std::size_t j = 0; j < n; ++j)
    {
      const Covariance& c = (*covariances)[at (j)];
      if (!c.isFinite ())
        continue;
      const std::string why = detail::covarianceError (c.xx, c.xy, c.xz, c.yy, c.yz, c.zz);
      if (!why.empty ())
      {
        err << name << " covariance of point " << at (j) << " " << why;
        throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
      }
    }

  using Gate = CloudModelParams::ResolutionGate;
  // The merge radius applied. With the surface model and none given, the whole-cloud gate
  // merges the dense samples of a cloud of two densities alone (detail::WholeCloudMerge::
  // DenseSamples, a depth scan's near objects), at the default radius, and never a whole cloud:
  // the surface layer on whole merged clouds lost easy answers in W1's dense room at 2-4 %
  // (docs/PERFORMANCE.md, "The whole-cloud merge as the separators' default").
  const bool dense_only = params.surface && !params.noise_resolution && params.noise_resolution_gate == Gate::WholeCloud;
  const double radius = dense_only ? CloudModelParams::kDefaultNoiseResolution : params.noiseResolution ();

  // Samples closer than their noise, merged (CloudModelParams::noise_resolution): the model of
  // the merged cloud, mapped back to every sample of this one; null when no two samples merge.
  // gate_k as detail::mergeByNoise takes it.
  const auto mergedModel = [&] (int gate_k) -> std::shared_ptr<const CloudModel> {
    pcl::PointCloud<PointT> merged;
    std::vector<int> cluster_of, seeds;
    if (!detail::mergeByNoise (cloud, indices, params.noise, radius, gate_k, params.threads, merged, cluster_of, seeds))
      return nullptr;
    // The default radius leaves an object smaller than its noise unmerged: its merge would keep no
    // more points than k, which no longer resolve its shape (a radius given says so in a warning).
    if (!params.noise_resolution && merged.size () <= static_cast<std::size_t> (std::max (params.k, 1)))
      return nullptr;
    CloudModelParams once = params;
    once.noise_resolution = 0.0;
    const auto model = std::const_pointer_cast<CloudModel> (buildCloudModel (merged, once, nullptr, nullptr, name));
    // Nor one the merge shrinks: merged points lie inside their clusters, and over an object a
    // few noise deviations across their projection takes its shape for noise (a 2 cm cube
    // sampled every 4 mm with 1 mm of scatter, declared at 5 mm, became a 9 mm blob that read
    // free 2-8 mm over a table). Where the merged points' box diagonal is under
    // CloudModel::kMinMergedDiagonal of the samples', the default leaves the cloud unmerged.
    if (!params.noise_resolution)
    {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ()), hi = -lo;
      for (std::size_t j = 0; j < n; ++j)
        if (pcl::isXYZFinite (cloud[at (j)]))
        {
          const Eigen::Vector3d p = cloud[at (j)].getVector3fMap ().template cast<double> ();
          lo = lo.cwiseMin (p);
          hi = hi.cwiseMax (p);
        }
      Eigen::Vector3d mlo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ()), mhi = -mlo;
      for (const Eigen::Vector3d& p : model->bvh_.means ())
      {
        mlo = mlo.cwiseMin (p);
        mhi = mhi.cwiseMax (p);
      }
      if ((mhi - mlo).norm () < CloudModel::kMinMergedDiagonal * (hi - lo).norm ())
        return nullptr;
    }
    CloudModelParams applied = params;  // the radius the merge applied, where the surface model's default set it
    if (dense_only)
      applied.noise_resolution = radius;
    model->adoptMerge (applied, cloud.size (), n, cluster_of, std::move (seeds), name);
    model->neighbour_spacing_ = std::numeric_limits<double>::quiet_NaN ();  // measured on the merged cloud
    model->build_ms_ = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
    return model;
  };
  const bool merging = radius > 0.0 && !covariances;
  // The whole-cloud gate reads the covariance estimation's neighbour radii (below) and decides
  // there; the other gates merge first.
  // The merged model, when samples merge; with keep_full_resolution the unmerged one is built
  // on below and kept in it (CloudModel::fullResolution()).
  std::shared_ptr<const CloudModel> merged_model;
  std::future<std::shared_ptr<const CloudModel>> merged_aside;  // the whole-cloud gate's, being built
  if (merging && params.noise_resolution_gate != Gate::WholeCloud)
  {
    merged_model = mergedModel (params.noise_resolution_gate == Gate::WhereNoiseExceedsSpacing ? params.k : 0);
    if (merged_model && !params.keep_full_resolution)
      return merged_model;
  }

  // Estimate what the caller did not give: covariances, neighbour radii (area weights) and the
  // surface displacements. The estimation reads the cloud through a non-owning pointer: it is
  // used only during this call.
  pcl::PointCloud<Covariance> estimated;
  std::vector<float> radii;
  std::vector<Eigen::Vector3d> displacements;
  std::vector<Eigen::Vector3f> normals;
  std::vector<int> neighbours;
  double neighbour_spacing = std::numeric_limits<double>::quiet_NaN ();
  double scatter_ratio = std::numeric_limits<double>::quiet_NaN ();
  if (!covariances || params.surface)
  {
    // With covariances given, the estimation runs for the surface model alone (its normals,
    // radii and neighbours), without noise or projection.
    const typename pcl::PointCloud<PointT>::ConstPtr view (&cloud, [] (const pcl::PointCloud<PointT>*) {});
    CovarianceEstimation<PointT> estimation;
    estimation.setInputCloud (view);
    if (indices)
      estimation.setIndices (pcl::IndicesConstPtr (indices, [] (const pcl::Indices*) {}));
    estimation.setKSearch (params.k);
    estimation.setNumberOfThreads (params.threads);
    if (!covariances)
    {
      estimation.setSensorNoise (params.noise);
      estimation.setSurfaceProjection (params.surface_projection);
    }
    else
      estimation.setSurfaceProjection (false);
    estimation.setComputeSurface (params.surface);
    // A cloud with a usable normal at every finite point takes its own (below): no normal fits.
    if constexpr (pcl::traits::has_normal_v<PointT>)
    {
      bool all_given = params.surface;
      for (std::size_t j = 0; j < n && all_given; ++j)
        all_given = !pcl::isXYZFinite (cloud[at (j)]) || usableNormal (cloud[at (j)]);
      estimation.setComputeNormals (!all_given);
    }
    detail::reserveHugePages (estimated.points, n);  // compute() resizes it to n
    estimation.compute (estimated);
    scatter_ratio = estimation.getNeighbourScatterRatio ();
    const auto copyOf = [] (const auto& from, auto& to) {  // on memory offered to huge pages
      detail::reserveHugePages (to, from.size ());
      to.assign (from.begin (), from.end ());
    };
    // medianNeighbourSpacing(): io::medianSpacing's rule on the estimation's own search, whose
    // k-d tree holds the cloud's finite points in cloud order as medianSpacing's does, so that
    // the squared distances, and the number, are the same.
    const std::vector<float>& nearest_sqr = estimation.getNearestSquaredDistances ();
    if (!indices && nearest_sqr.size () == n)
    {
      std::size_t finite = 0;
      for (std::size_t j = 0; j < n; ++j)
        finite += pcl::isXYZFinite (cloud[j]) ? 1 : 0;
      std::size_t ordinal = 0, j = 0;  // the ordinal-th finite point is cloud[j]; asked in increasing order
      neighbour_spacing = detail::medianNearestSpacing (finite, detail::kSpacingQueries, [&] (std::size_t i) {
        for (; j < n; ++j)
          if (pcl::isXYZFinite (cloud[j]) && ordinal++ == i)
            break;
        const float v = nearest_sqr[j++];
        return std::isnan (v) ? std::numeric_limits<double>::quiet_NaN () : std::sqrt (static_cast<double> (v));
      });
    }
    // Exactly coincident samples (a cloud concatenated with itself): the model of each position
    // once (detail::mergeCoincident), mapped back to every sample, with the spacing measured
    // above (io::medianSpacing's, which skips coincident neighbours). Found by the neighbour
    // search itself, so a cloud without any pays nothing; one with them is estimated again.
    if (!covariances && estimation.hasCoincidentPoints ())
    {
      pcl::PointCloud<PointT> distinct;
      std::vector<int> distinct_of, seeds;
      if (detail::mergeCoincident (cloud, indices, distinct, distinct_of, seeds))
      {
        const auto model = std::const_pointer_cast<CloudModel> (buildCloudModel (distinct, params, nullptr, nullptr, name));
        model->adoptCoincident (cloud.size (), n, distinct_of, seeds, neighbour_spacing);
        model->build_ms_ = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
        return model;
      }
    }
    copyOf (estimation.getNeighbourRadii (), radii);
    // Sampled finer than its noise (ResolutionGate::WholeCloud, detail::wholeCloudMerge): the
    // merged cloud's model instead, the estimation above spent once; where most samples are twice
    // as dense as their noise but most of the area is not, the samples within it merge. A cloud
    // sampled coarser goes on, modelled as unmerged.
    if (merging && params.noise_resolution_gate == Gate::WholeCloud)
    {
      const detail::SmallestDeviation smallestDeviation (
          params.noise, SensorPose::fromViewpoint (cloud.sensor_origin_, cloud.sensor_orientation_));
      const auto deviation = [&] (std::size_t j) {
        const PointT& p = cloud[at (j)];
        if (!pcl::isXYZFinite (p))
          return std::numeric_limits<double>::quiet_NaN ();
        return smallestDeviation (p.getVector3fMap ().template cast<double> ());
      };
      detail::WholeCloudMerge decision =
          merged_model ? detail::WholeCloudMerge::None : detail::wholeCloudMerge (radii, params.k, deviation);
      if (dense_only && decision == detail::WholeCloudMerge::Everything)
        decision = detail::WholeCloudMerge::None;
      if (decision != detail::WholeCloudMerge::None)
      {
        // mergedModel's gate_k: 0 merges every sample, k only those spaced within their noise.
        const int gate_k = decision == detail::WholeCloudMerge::DenseSamples ? params.k : 0;
        if (!params.keep_full_resolution)
        {
          merged_model = mergedModel (gate_k);
          if (merged_model)
            return merged_model;
        }
        else
        {
          // The merged model reads nothing of the unmerged one: it is built beside it, on a
          // thread of its own where the build has more than one (its clustering is serial,
          // 0.4 s of 5,000,000 points, and so are parts of the hierarchy's build); after it
          // where no thread can be started (as detail::parallelFor does).
          const bool aside = detail::threadCount (params.threads) > 1;
          try
          {
            merged_aside = std::async (aside ? std::launch::async : std::launch::deferred, mergedModel, gate_k);
          }
          catch (const std::system_error&)
          {
            merged_aside = std::async (std::launch::deferred, mergedModel, gate_k);
          }
        }
      }
    }
    copyOf (estimation.getSurfaceDisplacements (), displacements);
    copyOf (estimation.getNormals (), normals);
    copyOf (estimation.getNeighbours (), neighbours);
  }

  // The model's points: the finite ones with a finite covariance, in cloud order. Chunks count
  // theirs, then fill their own slots on the build's threads (5,000,000 points: 0.4 s serial).
  // The slots do not depend on the ranges.
  const auto covarianceOf = [&] (std::size_t j) -> const Covariance& {
    static const Covariance kNaN = Covariance::nan ();
    return covariances ? (*covariances)[at (j)] : (estimated.size () == n ? estimated[j] : kNaN);
  };
  const auto kept = [&] (std::size_t j) { return pcl::isXYZFinite (cloud[at (j)]) && covarianceOf (j).isFinite (); };
  const std::size_t workers = detail::threadCount (params.threads);
  const std::size_t chunk = detail::cheapChunk (n, workers);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  std::vector<std::size_t> first (chunks + 1, 0);  // model slot of each chunk's first kept point
  detail::parallelChunks (n, chunk, workers, [&] (std::size_t c, std::size_t begin, std::size_t end) {
    std::size_t count = 0;
    for (std::size_t j = begin; j < end; ++j)
      count += kept (j) ? 1 : 0;
    first[c + 1] = count;
  });
  for (std::size_t c = 0; c < chunks; ++c)
    first[c + 1] += first[c];
  const std::size_t model_points = first[chunks];
  const std::size_t skipped = n - model_points;
  // The covariances go to the hierarchy packed, as it keeps them: no 72-byte-a-point double copy
  // (360 MB written and read once at 5,000,000 points). The values are the same: a Covariance is
  // float, and its matrix symmetric.
  UncertainCloud points;
  std::vector<PackedCovariance> packed;
  detail::resizeHugePages (points.means, model_points);
  detail::resizeHugePages (packed, model_points);
  detail::resizeHugePages (points.source_indices, model_points);
  const bool weights = !radii.empty () && !covariances;
  if (weights)
    detail::resizeHugePages (points.area_weights, model_points);
  std::vector<std::size_t> kept_slots (params.surface ? model_points : 0);  // estimation slot of each model point (surface model)
  detail::parallelChunks (n, chunk, workers, [&] (std::size_t c, std::size_t begin, std::size_t end) {
    std::size_t slot = first[c];
    for (std::size_t j = begin; j < end; ++j)
    {
      if (!kept (j))
        continue;
      const int i = at (j);
      points.means[slot] = cloud[i].getVector3fMap ().template cast<double> ();
      if (!displacements.empty ())
        points.means[slot] += displacements[j];
      packed[slot] = PackedCovariance (covarianceOf (j).matrix ());
      points.source_indices[slot] = i;
      if (weights)
        points.area_weights[slot] = static_cast<double> (radii[j]) * radii[j];
      if (params.surface)
        kept_slots[slot] = j;
      ++slot;
    }
  });
  if (points.empty ())
  {
    // Every finite point was dropped for its covariance (given NaN, a missing value): say so,
    // rather than blame the positions.
    err << name << " has no finite point with a finite covariance (" << n << " given, " << n - finite_points
        << " non-finite, " << skipped - (n - finite_points) << " with a non-finite covariance)";
    throw pcl::BadArgumentException (err.str (), nullptr, kFunction);
  }
  // What the points took over is freed before the hierarchy's build, which is the peak of memory
  // (5,000,000 points: 52 bytes a point less).
  pcl::PointCloud<Covariance> ().swap (estimated);
  std::vector<Eigen::Vector3d> ().swap (displacements);
  if (!params.surface)
    std::vector<float> ().swap (radii);

  std::shared_ptr<CloudModel> model (new CloudModel);
  model->buildLocal (std::move (points), std::move (packed), params.hierarchy, cloud.size (), params.threads);
  if (params.surface)
  {
    // The surface model's inputs, re-indexed from estimation slots / cloud indices to model
    // points.
    SurfaceModel::Inputs in;
    const std::size_t m = kept_slots.size ();
    const std::size_t k = static_cast<std::size_t> (params.k);
    std::vector<int> model_of (cloud.size (), -1);
    for (std::size_t p = 0; p < m; ++p)
      model_of[static_cast<std::size_t> (at (kept_slots[p]))] = static_cast<int> (p);
    in.k = params.k;
    in.threads = params.threads;
    in.normals.resize (m);
    in.radii.resize (m);
    in.neighbours.assign (m * k, -1);
    for (std::size_t p = 0; p < m; ++p)
    {
      const std::size_t j = kept_slots[p];
      in.normals[p] = normals.empty () ? Eigen::Vector3f::Zero () : normals[j];
      in.radii[p] = radii[j];
      for (std::size_t q = 0; q < k; ++q)
      {
        const int c = neighbours[j * k + q];
        in.neighbours[p * k + q] = c >= 0 ? model_of[static_cast<std::size_t> (c)] : -1;
      }
    }
    if constexpr (pcl::traits::has_normal_v<PointT>)
    {
      in.given.assign (m, 0);
      for (std::size_t p = 0; p < m; ++p)
      {
        const PointT& pt = cloud[at (kept_slots[p])];
        if (usableNormal (pt))
        {
          // As given (its bits: the surface model normalises it); rescaled in double only where
          // its float length overflows or leaves float's normal range.
          const Eigen::Vector3f given (pt.normal_x, pt.normal_y, pt.normal_z);
          const float length2 = given.squaredNorm ();
          in.normals[p] = std::isfinite (length2) && length2 >= std::numeric_limits<float>::min ()
                              ? given
                              : Eigen::Vector3f (given.cast<double> ().normalized ().cast<float> ());
          in.given[p] = 1;
        }
      }
    }
    const Eigen::Vector3d view = cloud.sensor_origin_.template head<3> ().template cast<double> ();
    if (view.allFinite ())
      in.viewpoint = view - model->origin_;
    in.closed_objects = params.closed_objects;
    model->surface_.build (model->bvh_, std::move (in), params.orientation);
  }
  model->params_ = params;
  model->skipped_ = skipped;
  model->neighbour_spacing_ = neighbour_spacing;
  model->assessPrecision (max_abs, name);
  model->assessNormals (name);
  model->assessClosed (name);
  model->neighbour_scatter_ratio_ = scatter_ratio;
  model->assessScanLines (name);
  model->build_ms_ = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
  if (!model->warning_.empty ())
    PCL_WARN ("[pcl_probcollision::buildCloudModel] %s\n", model->warning_.c_str ());
  if (merged_aside.valid ())
    merged_model = merged_aside.get ();
  if (merged_model)
  {
    // The unmerged model above is the merged one's full-resolution rung; the build time counts
    // both.
    CloudModelParams unmerged = params;
    unmerged.noise_resolution = 0.0;
    model->params_ = unmerged;
    const auto coarse = std::const_pointer_cast<CloudModel> (merged_model);
    coarse->full_resolution_ = std::move (model);
    coarse->build_ms_ = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
    return coarse;
  }
  return model;
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_buildCloudModel(T)                                                                   \
  template PCL_EXPORTS std::shared_ptr<const pcl_probcollision::CloudModel> pcl_probcollision::buildCloudModel<T> ( \
      const pcl::PointCloud<T>&, const pcl_probcollision::CloudModelParams&, const pcl::Indices*,                 \
      const pcl::PointCloud<pcl_probcollision::Covariance>*, const std::string&);
