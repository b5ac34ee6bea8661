// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// The command lines' warnings about their inputs (units, noise, precision, meshes sampled too
// coarsely): one owner of their rules and words for pcd_collision and the Dask command line
// (python -m pcl_probcollision.dask), which print them with their own prefix. Warnings, not
// errors: each names a likely mistake the answer would silently carry.

#include "cloud_input.h"
#include "mesh_sampling.h"

#include <pcl_probcollision/sensor_noise.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <string>

namespace pcl_probcollision
{
namespace io
{
/** \brief Sizes (bounding-box diagonals) differing by more than this get a units warning. */
constexpr double kScaleWarningRatio = 100.0;
/** \brief Fewest finite points of a cloud whose extent the units warnings judge. A handful of
  * points (a probe, two points 1 mm apart) has no telling size; a scan has thousands. */
constexpr std::size_t kScaleWarningMinPoints = 50;
/** \brief An isotropic sigma below this fraction of its cloud's bounding-box diagonal gets a
  * units warning. No sensor is that precise on what it scans (10 um on a 1 m part is 1e-5);
  * the default sigma, 5 mm in metres, given to a millimetre scan of a metre-sized object is
  * 5 um there, 2.8e-6 of a piano's diagonal. A cloud's rounding to float is judged against it
  * too under a depth sensor's model. */
constexpr double kNoiseWarningRatio = 1e-5;
/** \brief An isotropic sigma above this multiple of its cloud's bounding-box diagonal gets a
  * units warning too. A cloud drawn with a noise sigma spreads over several sigmas, so a sigma
  * beyond its whole extent was not its noise: most likely millimetres given to a cloud in metres
  * (-sigma 5 on a 1 m scan). */
constexpr double kLargeNoiseWarningRatio = 1.0;

/** \brief What the warnings judge of one input, as the command line read it. */
struct InputFacts
{
  std::string path;           ///< as given (the warnings name it)
  bool cloud = true;          ///< a point cloud; false for a mesh
  std::size_t finite = 0;     ///< finite points of a cloud
  double diagonal = 0.0;      ///< bounding-box diagonal (a cloud's finite points, a mesh's vertices)
  XyzRounding rounding;       ///< what holding a cloud file's x y z in float cost (loadCloud)
  std::string sensor;         ///< its noise model's name (SensorNoiseModel::name: "isotropic", "kinect", ...)
  double sigma = 0.0;         ///< the isotropic sigma (data units)
};

/** \brief Number of a cloud's points with finite x y z (NaN points of organized clouds are skipped). */
template <typename PointT>
std::size_t finiteCount (const pcl::PointCloud<PointT>& cloud);

/** \brief Bounding-box diagonal of a cloud's finite points (0 for none or one point). */
template <typename PointT>
double finiteDiagonal (const pcl::PointCloud<PointT>& cloud);

/** \brief The facts of a cloud read from path (loadCloud or loadCloudWithNormals gave rounding)
  * under noise: its finite points and their extent, the noise model's name and, for an isotropic
  * model, its sigma. PointT: pcl::PointXYZ or pcl::PointNormal. */
template <typename PointT>
InputFacts cloudFacts (const std::string& path, const pcl::PointCloud<PointT>& cloud, const XyzRounding& rounding,
                       const SensorNoiseModel& noise);

/** \brief Both inputs must be in the same units: a millimetre scan against a metre mesh makes
  * their sizes differ by 1000x. The warning when they differ by more than kScaleWarningRatio
  * (clouds under kScaleWarningMinPoints are not judged; a mesh always is), else empty. A
  * screw against a room is legitimate, hence a warning. */
std::string scaleWarning (const InputFacts& a, const InputFacts& b);

/** \brief The warning when a cloud's isotropic sigma is below kNoiseWarningRatio of its size
  * (most likely the default, 0.005 in metres, given to a cloud in millimetres: the answer is
  * then for a near noise-free cloud) or above kLargeNoiseWarningRatio of it (a sigma in
  * millimetres given to a cloud in metres: every point's spread then covers the whole object),
  * else empty. */
std::string noiseWarning (const InputFacts& in);

/** \brief The warning when holding a cloud file's x y z in PCL's float points (24 bits: about
  * 0.5 mm at 10 km) moved a coordinate by more than CloudModel::kPrecisionWarningRatio (a tenth)
  * of its isotropic sigma, or, under a depth sensor's model, by more than kNoiseWarningRatio of
  * its size; else empty. The answer is then for the rounded cloud. */
std::string roundingWarning (const InputFacts& in);

/** \brief The built model's own precision warning (CloudModel::warning: float points whose
  * spacing is coarse against their spread), naming the file; empty when the model has none or
  * when roundingWarning (in) already said it of the file. */
std::string modelWarning (const InputFacts& in, const std::string& model_warning);

/** \brief The warning for a mesh whose faces the surface layer takes as enclosing an inside
  * (-surface, oriented by its faces) although the mesh is not closed (isClosedMesh false): inside
  * an open container the space its walls half-enclose reads inside (a box resting in an open bin
  * read collision, 0.45 m deep). orientation_option names the option that makes its surface
  * two-sided instead (-orientation_a or -orientation_b). A mesh closed but for faces wound
  * against their neighbours (MeshEdges::flipped, no open edge) is named as such: behind a flipped
  * face inside reads outside. Empty for a closed mesh. */
std::string openMeshWarning (const std::string& path, const MeshEdges& edges, const std::string& orientation_option);

/** \brief The warning for a closed mesh whose faces wind inward (meshSignedVolume < 0), oriented
  * by its faces (-surface): the surface layer takes the space around it as its inside, so a part
  * within it reads free (right for a cavity, a closed room; wrong for a solid exported inside
  * out). orientation_option and closed_option name the options that orient it outward instead.
  * Empty for a mesh that is not closed (openMeshWarning's case) or whose volume is positive. */
std::string insideOutMeshWarning (const std::string& path, bool closed, double signed_volume,
                                  const std::string& orientation_option, const std::string& closed_option);

/** \brief The warning for a "free" answer (where: "pose 3", "the pose") when both inputs are
  * meshes sampled spacing apart and their samples came within reach (leaf pairs were tested): a
  * part thinner than the spacing crossing a thin wall passes between samples. Empty otherwise.
  * The command lines say it once a run, of the first such answer. */
std::string betweenSamplesWarning (bool both_meshes, bool free, std::size_t leaf_pairs_tested, const std::string& where,
                                   double spacing);

/** \brief How much coarser than the other cloud's median spacing a mesh's samples may be (a
  * -mesh_density of the user's) before a free answer within reach is warned of. */
constexpr double kCoarseMeshRatio = 2.0;

/** \brief The warning for a "free" answer (where: "pose 3", "the pose") between a mesh sampled
  * mesh_spacing apart and a cloud of median spacing cloud_spacing, more than kCoarseMeshRatio
  * times finer, where their samples came within reach (leaf pairs were tested): a part of the
  * cloud thinner than the mesh's spacing passes between its samples (a 5 cm cube 2 cm into a
  * ground mesh sampled 0.3 m apart read free). Empty otherwise; said once a run. */
std::string coarseMeshWarning (bool free, std::size_t leaf_pairs_tested, const std::string& where,
                               const std::string& mesh_path, double mesh_spacing, double cloud_spacing);
} // namespace io
} // namespace pcl_probcollision
