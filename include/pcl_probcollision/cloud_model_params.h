// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/sensor_noise.h>

#include <optional>
#include <string>

namespace pcl_probcollision
{
/** \brief How a CloudModel is built from a point cloud: the per-cloud settings, with their
  * defaults. The query's settings are in CollisionRequest.
  *
  * Which noise model to choose: the library's default is none, so that covariances come from
  * the sampling alone (the k-nearest-neighbour spread) and a cloud whose points are exact
  * (a mesh sample, a CAD model) stays exact. Sensor data needs its sensor's model:
  * SensorNoiseModel::kinect(), stereo() or lidar() when the cloud carries its viewpoint
  * (sensor_origin_), isotropic(sigma) with the sensor's depth noise otherwise. pcd_collision
  * defaults to isotropic 5 mm instead because its inputs are files of unknown origin, mostly
  * scans, where assuming no noise would make near-contact answers overconfident (docs/CLI.md).
  */
/** \brief Where the surface model's normals get their orientation (which side is outside). */
enum class NormalOrientation
{
  /** \brief Default: the point type's normals when it has finite ones (meshes: the faces'),
    * unless they all face the viewpoint while it does not see the cloud as one scan (PCL's normal
    * estimation turned them toward it: SurfaceModel::normalsTurnedToViewpoint) or lie along the
    * surface (not moved with their points: SurfaceModel::normalsOffSurface) or face away from a
    * viewpoint that sees the cloud as one scan with sides that disagree between neighbours (never
    * oriented: SurfaceModel::givenNormalsMisoriented, whose directions are then turned toward
    * it), else the
    * viewpoint when the cloud's sensor_origin_ lies outside its bounding box, more than 10
    * median spacings from its nearest sample (SurfaceModel::kMinViewSpacings), and sees it as
    * one scan does (at most 10 % of the points hidden behind others from there:
    * SurfaceModel::hiddenFromViewpoint), else propagation. */
  Auto,
  /** \brief The normals the points carry (PointNormal and the other *Normal types), taken as
    * outward; points without a finite one are oriented by propagation from their neighbours.
    * With none given at all, the surface is propagated (SurfaceModel::orientation() says
    * Propagate). */
  PointNormals,
  /** \brief Toward the sensor origin (sensor_origin_): a scan sees the outside of what it
    * scans. Trusted only where the surface faces the sensor (|cos| >= 0.2); grazing points take
    * their orientation from their neighbours. A viewpoint that sees the cloud edge-on (under 1 %
    * of the points facing it, or over a tenth of them on the other side from the rest of their
    * part once one orientation is carried over it: a sheet in the sensor's plane, whose noise
    * tilts patches of its normals either way, or a closed object's far side, which faces it from
    * behind) orients nothing, and the surface is propagated instead (SurfaceModel::orientation()
    * says Propagate). */
  Viewpoint,
  /** \brief Propagated over the neighbour graph (Hoppe et al. 1992) from the point farthest
    * from the centroid, pointing away from it; then each connected part is flipped if needed so
    * that its enclosed volume (divergence theorem) is positive: for closed objects. */
  Propagate
};

/** \brief "auto", "point_normals", "viewpoint" or "propagate" (inline: pcd_collision's option
  * parser, which links no library, reads the names from here). */
inline const char*
orientationName (NormalOrientation orientation)
{
  switch (orientation)
  {
    case NormalOrientation::Auto: return "auto";
    case NormalOrientation::PointNormals: return "point_normals";
    case NormalOrientation::Viewpoint: return "viewpoint";
    case NormalOrientation::Propagate: return "propagate";
  }
  return "unknown";
}

/** \brief Every NormalOrientation, in declaration order. */
constexpr NormalOrientation kNormalOrientations[] = {NormalOrientation::Auto, NormalOrientation::PointNormals,
                                                     NormalOrientation::Viewpoint, NormalOrientation::Propagate};

/** \brief How one cloud is modelled: its covariance estimation, sensor noise, hierarchy and
  * (optionally) surface model, with their documented defaults (README, "Choosing a setting").
  * validate() throws pcl::BadArgumentException naming the first member out of range. */
struct CloudModelParams
{
  /** \brief Neighbours of the covariance estimation (Pauly et al.), >= 1. Default 10. */
  int k = 10;
  /** \brief Sensor noise added to the estimated covariances. Default none (see above). */
  SensorNoiseModel noise;
  /** \brief Locally denoised point positions (CovarianceEstimation::setSurfaceProjection).
    * Default on, chosen by the evaluation (docs/RESULTS.md). Off gives the paper's model:
    * every point at its measured position with its full noise and discretisation spread,
    * whose maximum over many points near contact drifts toward 1. No effect without a noise
    * model or with covariances given by the caller. */
  bool surface_projection = true;
  /** \brief Build the surface model (METHOD.md 10a: oriented normals, local spacing, the
    * winding-number dipoles) that CollisionRequest::surface queries. Default off, as the
    * surface layer is (experimental, issue #16); it costs a normal fit and an orientation pass
    * per point at build time. */
  bool surface = false;
  /** \brief How the surface's normals are oriented. Default Auto. */
  NormalOrientation orientation = NormalOrientation::Auto;
  /** \brief The cloud samples closed objects: solids sampled all round (a segmented object from
    * several views, a solid's mesh vertices without faces), not an open sheet, one scan's partial
    * view or an environment seen from within. Where the orientation is propagated (no normals
    * and no usable viewpoint), the build then checks it with the winding number
    * (SurfaceModel::closedShare) and, where it checks out, the surface layer trusts it to say
    * where the inside is (SurfaceModel::insideKnown): a point behind it is inside, and a part
    * deep inside, out of reach of its surface, is found. Default off: a propagated surface is
    * two-sided (a point behind it is as far from it as one in front), since propagation cannot
    * tell a solid from a room seen from within. No effect on given normals or a viewpoint,
    * which are trusted anyway. */
  bool closed_objects = false;
  /** \brief Resolution tied to the noise (issue #17): samples closer than noise_resolution
    * times the sensor noise's smallest standard deviation (at the sample seeding a merge, see
    * detail::noiseClusters) are merged into one sample at their centroid, whose covariance is
    * then estimated at the merged spacing; every merged sample reports its merged point's
    * per-point values. In noise standard deviations, >= 0; 0 merges nothing. Unset (the
    * default): noiseResolution() decides, kDefaultNoiseResolution (2) without the surface model
    * and 0 with it; a cloud the default would merge into no more than k points, or whose merged
    * points' box diagonal would shrink below CloudModel::kMinMergedDiagonal of its own (an object
    * a few noise deviations across), stays unmerged, where a radius given merges it (the first
    * with a warning).
    * With the default noise_resolution_gate only a cloud sampled finer than its noise merges,
    * and keep_full_resolution asks the unmerged models again where a merged answer leans to
    * collision. On the evaluation's reported run (seed 1, 2026-12-05) the separators then answer
    * as unmerged at 0.25-1 % noise and, at 2-4 %, gain 12 easy answers and lose 1, with a lower
    * Brier score in every cell and a worst query up to 11 times shorter. The surface layer on
    * merged models loses easy answers in the dense room at 2-4 % (docs/PERFORMANCE.md, "The
    * whole-cloud merge as the separators' default"), so a model with the surface model merges a
    * whole cloud only when asked; with the default gate it merges the dense samples of a cloud of
    * two densities (a depth camera's scan, ResolutionGate::WholeCloud) at
    * kDefaultNoiseResolution, as a model without it does, and CloudModel::params() of such a
    * model gives that radius. No effect without a noise model (noise None) or with covariances
    * given by the caller. */
  std::optional<double> noise_resolution;
  /** \brief The merge radius of a model without the surface model when noise_resolution is
    * unset, in noise standard deviations: the evaluated choice (docs/PERFORMANCE.md, "The merge
    * radius"). */
  static constexpr double kDefaultNoiseResolution = 2.0;
  /** \brief noise_resolution as the build applies it to a whole cloud: its value when set, else
    * kDefaultNoiseResolution without the surface model and 0 with it (where the default gate
    * still merges a depth scan's dense samples at kDefaultNoiseResolution; see
    * noise_resolution). */
  double
  noiseResolution () const
  {
    return noise_resolution ? *noise_resolution : surface ? 0.0 : kDefaultNoiseResolution;
  }
  /** \brief Where noise_resolution merges (issue #17 item 1). Everywhere: every sample within
    * the radius of a seed. WhereNoiseExceedsSpacing: only samples whose local spacing is at most
    * their noise's smallest standard deviation, the spacing sqrt(pi / k) times the distance to
    * the k-th nearest neighbour (k as above: the square root of the surface area per sample
    * that k neighbours cover); a sample spaced wider than its noise is never merged, so a cloud
    * sampled coarser than its noise is modelled exactly as with noise_resolution = 0.
    * WholeCloud: the whole cloud merges (as Everywhere) when it is sampled finer than its noise,
    * its median noise deviation at least its typical spacing (the area-weighted median of the
    * local spacings); else, where more than half of its samples are at least twice as dense as
    * their noise (detail::kDenseSpacingSquaredPerVariance) though most of its area is not (a
    * depth camera's scan: near objects a millimetre or two apart, a far wall's few samples
    * holding half the area), the samples within their noise merge, as WhereNoiseExceedsSpacing
    * merges them; otherwise nothing merges and the model is exactly the unmerged one
    * (detail::wholeCloudMerge, read from the covariance estimation's own neighbour search).
    * Default WholeCloud: on the evaluation it changes no answer at noise below the clouds'
    * spacing and, above it, cuts the near-contact Brier score by a third and the query time many
    * times, where Everywhere loses easy answers at 0.25-1 % noise (docs/PERFORMANCE.md, issue #17
    * item 1); on a Kinect scan under 5 mm noise its dense samples' merge takes the
    * median query from 19 to 0.5 ms and reads 243 of 247 collisions as collision instead of 57
    * (docs/PERFORMANCE.md, "A depth scan's dense samples merged"). */
  enum class ResolutionGate
  {
    Everywhere,
    WhereNoiseExceedsSpacing,
    WholeCloud
  };
  /** \brief Where noise_resolution merges (see ResolutionGate; default WholeCloud). */
  ResolutionGate noise_resolution_gate = ResolutionGate::WholeCloud;
  /** \brief Where noise_resolution merged samples, also keep the unmerged model
    * (CloudModel::fullResolution()): a query whose merged answer is the separators' contact
    * leaning to collision (P at least 0.5) is asked again at full resolution, with a budget of
    * 256 leaf-pair fits, and its collision stands when it finds one (collide(),
    * CollisionResult::full_resolution; the surface layer's answers are not asked again). The
    * merged point's covariance is broad, so a deep collision can read contact on the merged
    * model alone; this rung gives it back its collision (docs/PERFORMANCE.md, "A
    * full-resolution rung for merged clouds"). Default on; it costs the unmerged hierarchy's
    * build and memory on a cloud that merges, nothing on one that does not. */
  bool keep_full_resolution = true;
  /** \brief "everywhere", "spacing" or "cloud" (pcd_collision's -noise_resolution_gate). */
  static const char*
  resolutionGateName (ResolutionGate gate)
  {
    switch (gate)
    {
      case ResolutionGate::Everywhere: return "everywhere";
      case ResolutionGate::WhereNoiseExceedsSpacing: return "spacing";
      case ResolutionGate::WholeCloud: return "cloud";
    }
    return "unknown";
  }
  /** \brief The gate resolutionGateName() names; false, leaving gate as it was, for any other name. */
  static bool
  resolutionGateFromName (const std::string& name, ResolutionGate& gate)
  {
    for (const ResolutionGate g : {ResolutionGate::Everywhere, ResolutionGate::WhereNoiseExceedsSpacing, ResolutionGate::WholeCloud})
      if (name == resolutionGateName (g))
      {
        gate = g;
        return true;
      }
    return false;
  }
  /** \brief The hierarchy built over the points (BVHParams' defaults). */
  BVHParams hierarchy;
  /** \brief Threads of the build (covariance estimation and hierarchy): 0 = one per hardware
    * thread (default), as for collideBatch(). The model is the same for any count. */
  int threads = 0;

  /** \brief Throws pcl::BadArgumentException naming the first member out of range. */
  void validate () const;
};
} // namespace pcl_probcollision
