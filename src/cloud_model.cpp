// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/impl/cloud_model.hpp>
#include <pcl_probcollision/detail/huge_pages.h>

#include <pcl/exceptions.h>
#include <pcl/point_types.h>
#include <pcl/impl/instantiate.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <limits>
#include <sstream>

namespace pcl_probcollision
{
void
CloudModelParams::validate () const
{
  if (k < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CloudModelParams::validate] k = " << k << " must be >= 1");
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CloudModelParams::validate] threads = "
                             << threads << " must be >= 0 (0: one per hardware thread)");
  if (noise_resolution && !(*noise_resolution >= 0.0 && std::isfinite (*noise_resolution)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::CloudModelParams::validate] noise_resolution = "
                                                         << *noise_resolution << " must be finite and >= 0");
  hierarchy.validate ();
}

CloudModel::CloudModel (UncertainCloud points, const BVHParams& hierarchy, std::size_t source_size)
{
  if (points.empty ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::CloudModel] no point given");
  // Per-point results are scattered by these indices into arrays of source_size: one outside
  // would write past them (found in review: a negative index crashed a per_point query).
  for (std::size_t j = 0; j < points.source_indices.size (); ++j)
  {
    const int i = points.source_indices[j];
    if (i < 0 || (source_size > 0 && static_cast<std::size_t> (i) >= source_size))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::CloudModel] source index " << i << " of point " << j
                               << (i < 0 ? std::string (" is negative")
                                         : " is outside the source cloud's " + std::to_string (source_size) + " points (source_size)"));
  }
  // Covariances by buildCloudModel's rule (detail::covarianceError); a non-finite one is refused
  // by the hierarchy's build, which names it.
  for (std::size_t j = 0; j < points.covariances.size (); ++j)
  {
    if (!points.covariances[j].allFinite ())
      continue;
    const std::string why = detail::covarianceError (points.covariances[j]);
    if (!why.empty ())
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::CloudModel] covariance of point "
                               << j << (j < points.source_indices.size () ? " (source index " + std::to_string (points.source_indices[j]) + ")" : std::string ())
                               << " " << why);
  }
  const auto start = std::chrono::steady_clock::now ();
  params_.hierarchy = hierarchy;
  buildLocal (std::move (points), {}, hierarchy, source_size);
  if (params_.surface)
    buildSurfaceFromPoints (params_.orientation, params_.k);
  build_ms_ = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
}

void
CloudModel::buildSurfaceFromPoints (NormalOrientation orientation, int k)
{
  // The local means as a float cloud (centred, so float loses nothing that matters here).
  const auto& means = bvh_.means ();
  const auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>> ();
  cloud->resize (means.size ());
  for (std::size_t i = 0; i < means.size (); ++i)
    (*cloud)[i].getVector3fMap () = means[i].cast<float> ();
  CovarianceEstimation<pcl::PointXYZ> estimation;
  estimation.setInputCloud (cloud);
  estimation.setKSearch (k);
  estimation.setSurfaceProjection (false);
  estimation.setComputeSurface (true);
  pcl::PointCloud<Covariance> unused;
  estimation.compute (unused);
  SurfaceModel::Inputs in;
  in.k = k;
  in.normals = estimation.getNormals ();
  in.radii = estimation.getNeighbourRadii ();
  in.neighbours = estimation.getNeighbours ();
  in.closed_objects = params_.closed_objects;
  surface_.build (bvh_, std::move (in), orientation);
}

void
CloudModel::buildLocal (UncertainCloud&& points, std::vector<PackedCovariance>&& packed, const BVHParams& hierarchy,
                        std::size_t source_size, int threads)
{
  if (source_size == 0)
  {
    source_size = points.size ();
    for (const int i : points.source_indices)
      source_size = std::max (source_size, static_cast<std::size_t> (std::max (i, 0)) + 1);
  }
  // The centroid is the local origin; means are validated by the hierarchy's build, so a
  // non-finite one is reported there (the centroid is then unused).
  Eigen::Vector3d sum = Eigen::Vector3d::Zero ();
  for (const Eigen::Vector3d& m : points.means)
    sum += m;
  const Eigen::Vector3d centroid = sum / static_cast<double> (points.size ());
  if (centroid.allFinite ())
  {
    Eigen::AlignedBox3d box;
    for (Eigen::Vector3d& m : points.means)
    {
      m -= centroid;
      box.extend (m);
    }
    origin_ = centroid;
    diagonal_ = box.isEmpty () ? 0.0 : box.diagonal ().norm ();
  }
  if (packed.empty ())
    bvh_.build (std::move (points), hierarchy, threads);
  else
    bvh_.build (std::move (points), std::move (packed), hierarchy, threads);
  source_size_ = source_size;
}

std::vector<int>
CloudModel::pointOfHierarchySource (std::size_t sources) const
{
  std::vector<int> point_of (sources, -1);
  for (std::size_t j = 0; j < bvh_.size (); ++j)
    point_of[static_cast<std::size_t> (bvh_.sourceIndex (static_cast<int> (j)))] = static_cast<int> (j);
  return point_of;
}

void
CloudModel::adoptMerge (const CloudModelParams& params, std::size_t source_size, std::size_t candidates,
                        const std::vector<int>& cluster_of, std::vector<int>&& seeds, const std::string& name)
{
  // The hierarchy's source indices are merged points (the merged cloud's indices).
  const std::vector<int> point_of_merged = pointOfHierarchySource (seeds.size ());
  detail::assignHugePages (point_of_source_, source_size, -1);
  std::size_t mapped = 0;
  for (std::size_t i = 0; i < cluster_of.size () && i < source_size; ++i)
    if (cluster_of[i] >= 0 && point_of_merged[static_cast<std::size_t> (cluster_of[i])] >= 0)
    {
      point_of_source_[i] = point_of_merged[static_cast<std::size_t> (cluster_of[i])];
      ++mapped;
    }
  representatives_ = std::move (seeds);
  merged_samples_ = mapped - bvh_.size ();
  skipped_ = candidates - mapped;
  source_size_ = source_size;
  params_ = params;
  if (merged_samples_ > 0 && bvh_.size () <= static_cast<std::size_t> (std::max (params.k, 1)))
  {
    std::ostringstream out;
    out << name << ": noise_resolution " << params.noiseResolution () << " merged its " << mapped << " samples into "
        << bvh_.size () << " point" << (bvh_.size () == 1 ? "" : "s") << ", no more than the covariance estimation's k = "
        << params.k << ": the model no longer resolves the object's shape (lower noise_resolution; 2 is the evaluated choice)";
    addWarning (out.str ());
    PCL_WARN ("[pcl_probcollision::buildCloudModel] %s\n", out.str ().c_str ());
  }
}

void
CloudModel::adoptCoincident (std::size_t source_size, std::size_t candidates, const std::vector<int>& distinct_of,
                             const std::vector<int>& seeds, double spacing)
{
  if (full_resolution_)
    const_cast<CloudModel&> (*full_resolution_).adoptCoincident (source_size, candidates, distinct_of, seeds, spacing);
  // A merged model's stays NaN (measured on no cloud of the caller's).
  if (!std::isnan (neighbour_spacing_))
    neighbour_spacing_ = spacing;
  // The model point of each distinct sample: through a merge's map where its samples merged.
  const std::vector<int> point_of_distinct =
      point_of_source_.empty () ? pointOfHierarchySource (seeds.size ()) : std::move (point_of_source_);
  // Hierarchy source indices name distinct samples, or a merge's seeds among them.
  if (representatives_.empty ())
    representatives_ = seeds;
  else
    for (int& r : representatives_)
      r = seeds[static_cast<std::size_t> (r)];
  detail::assignHugePages (point_of_source_, source_size, -1);
  std::size_t samples = 0, mapped = 0;
  for (std::size_t i = 0; i < distinct_of.size () && i < source_size; ++i)
  {
    const int c = distinct_of[i];
    if (c < 0)
      continue;
    ++samples;
    if (point_of_distinct[static_cast<std::size_t> (c)] >= 0)
    {
      point_of_source_[i] = point_of_distinct[static_cast<std::size_t> (c)];
      ++mapped;
    }
  }
  coincident_samples_ = samples - seeds.size ();
  skipped_ = candidates - mapped;
  source_size_ = source_size;
}

void
CloudModel::assessScanLines (const std::string& name)
{
  const std::vector<Eigen::Vector3d>& means = bvh_.means ();
  if (!(neighbour_scatter_ratio_ < kScanLineRatio) || means.size () < 3)
    return;
  // The points' own spread (the hierarchy's boxes are grown by the noise), from up to ~10,000.
  const std::size_t stride = std::max<std::size_t> (1, means.size () / 10000);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero ();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero ();
  double count = 0.0;
  for (std::size_t i = 0; i < means.size (); i += stride)
  {
    sum += means[i];
    second.noalias () += means[i] * means[i].transpose ();
    count += 1.0;
  }
  const Eigen::Vector3d mean = sum / count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  const Eigen::Vector3d l = solver.computeDirect (second / count - mean * mean.transpose (), Eigen::EigenvaluesOnly).eigenvalues ();
  if (!(l[1] > 0.0 && std::sqrt (l[1] / l[2]) >= kScanLineExtentRatio))
    return;
  std::ostringstream out;
  out.precision (2);
  out << name << ": its samples lie along lines, as a LiDAR's rings do (each point's nearest neighbours spread "
      << neighbour_scatter_ratio_ << " as wide as long, a surface scan's about 0.6): the model measures their spacing "
      << "along the lines, and a part lying between two lines can read free (docs/RELIABILITY.md)";
  addWarning (out.str ());  // buildCloudModel prints warning() once
}

void
CloudModel::addWarning (const std::string& text)
{
  warning_ = warning_.empty () ? text : warning_ + "; " + text;
}

void
CloudModel::assessPrecision (double max_abs_coordinate, const std::string& name)
{
  // The points' typical standard deviation: median of sqrt(trace / 3) over up to ~1000 points.
  const std::vector<PackedCovariance>& covs = bvh_.covariances ();
  const std::size_t stride = std::max<std::size_t> (1, covs.size () / 1000);
  std::vector<double> sigmas;
  for (std::size_t i = 0; i < covs.size (); i += stride)
    sigmas.push_back (std::sqrt (std::max (0.0, (double (covs[i].xx) + covs[i].yy + covs[i].zz) / 3.0)));
  std::nth_element (sigmas.begin (), sigmas.begin () + sigmas.size () / 2, sigmas.end ());
  const double sigma = sigmas.empty () ? 0.0 : sigmas[sigmas.size () / 2];
  const float top = static_cast<float> (max_abs_coordinate);
  const double spacing = static_cast<double> (std::nextafter (top, std::numeric_limits<float>::infinity ()) - top);
  // Exact points (no spread at all) have no noise to compare the spacing with.
  precision_ratio_ = sigma > 0.0 ? spacing / sigma : 0.0;
  warning_.clear ();
  if (precision_ratio_ > kPrecisionWarningRatio)
  {
    std::ostringstream out;
    out.precision (3);
    out << name << ": coordinates up to " << max_abs_coordinate << " have a float spacing of " << spacing
        << ", more than a tenth of the points' typical standard deviation " << sigma
        << ": the input lost precision before the library saw it (store the cloud about a local origin)";
    warning_ = out.str ();
  }
}

void
offsetModel (CloudModel& model, const Eigen::Vector3d& offset)
{
  model.origin_ += offset;
  // The unmerged model a merged one keeps was built from the same cloud in the same build.
  if (model.full_resolution_)
    offsetModel (const_cast<CloudModel&> (*model.full_resolution_), offset);
}

void
CloudModel::assessClosed (const std::string& name)
{
  // Asked closed, checked not closed: the query then treats the surface as open (two-sided), so
  // an object wholly inside reads free; say so, as pcd_collision's Orienting line does (a probe
  // of a C++ pipeline found the refusal silent, 2026-12-06).
  if (!params_.closed_objects || surface_.empty () || surface_.orientation () != NormalOrientation::Propagate ||
      surface_.insideKnown ())
    return;
  std::ostringstream out;
  out.precision (2);
  out << name << ": closed_objects was asked for, but its propagated orientation does not check closed (outside in front "
      << 100.0 * surface_.closedShare () << " %, inside behind " << 100.0 * surface_.solidShare () << " %; "
      << 100.0 * SurfaceModel::kMinClosedShare << " and " << 100.0 * SurfaceModel::kMinSolidShare
      << " % needed): its inside is not used, and an object wholly inside it can read free (give it oriented normals, or "
         "a viewpoint)";
  addWarning (out.str ());
}

void
CloudModel::assessNormals (const std::string& name)
{
  if (surface_.givenNormalsFaceAwayFromViewpoint () && surface_.orientation () == NormalOrientation::PointNormals &&
      !surface_.givenNormalsMisoriented ())
  {
    const std::string away =
        name + ": its normals face away from its viewpoint, which a sensor cannot see (it sees a surface's front): they "
               "look turned the wrong way and are taken as given, so what lies in front of the surface reads inside it "
               "(negate them, or leave them out to orient the surface from the viewpoint)";
    addWarning (away);
  }
  if (surface_.givenNormalsMisoriented ())
  {
    std::ostringstream out;
    out.precision (2);
    out << name << ": " << 100.0 * surface_.givenNormalsAwayShare ()
        << " % of its normals face away from its viewpoint, which sees it as one scan (a sensor sees only fronts): "
           "their sides were not turned toward the sensor (Open3D's estimate_normals leaves them so), and they are "
        << (surface_.orientation () == NormalOrientation::PointNormals
                ? "taken as given, as orientation point_normals asks, so parts of the surface face inward (turn them "
                  "toward the sensor first, or leave orientation auto)"
                : "taken as directions, turned toward the viewpoint");
    addWarning (out.str ());
  }
  const double ratio = surface_.givenNormalSpreadRatio ();
  if (!(ratio > SurfaceModel::kMaxNormalSpreadRatio))
    return;
  std::ostringstream out;
  out.precision (2);
  out << name << ": its normals lie along its surface, not across it (the neighbours spread " << ratio
      << " times as much along a normal as across it, median; about 0 where they belong), so they do not belong to these "
         "points (moved with pcl::transformPointCloud instead of transformPointCloudWithNormals?): "
      << (surface_.normalsOffSurface () ? "set aside, the surface oriented as a cloud's without normals"
                                        : "taken as given, as orientation point_normals asks");
  // The same call leaves sensor_origin_ behind too; where that VIEWPOINT now orients the surface,
  // say so (found by a probe: with both stale, a collision 1.8 cm deep read free).
  if (surface_.normalsOffSurface () && surface_.orientation () == NormalOrientation::Viewpoint)
    out << "; its VIEWPOINT orients the surface instead, and pcl::transformPointCloud leaves that behind as well: if the "
           "sensor did not move with the points, set sensor_origin_ where it was or orient by propagation";
  addWarning (out.str ());
}
} // namespace pcl_probcollision

#ifndef PCL_NO_PRECOMPILE
PCL_INSTANTIATE (buildCloudModel, PCL_PROBCOLLISION_POINT_TYPES)
#endif
