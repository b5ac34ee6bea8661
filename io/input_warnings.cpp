// SPDX-License-Identifier: BSD-3-Clause
#include "input_warnings.h"

#include <pcl_probcollision/cloud_model.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

namespace pcl_probcollision
{
namespace io
{
namespace
{
std::string
formatted (const char* format, ...) __attribute__ ((format (printf, 1, 2)));

std::string
formatted (const char* format, ...)
{
  va_list args;
  va_start (args, format);
  va_list again;
  va_copy (again, args);
  const int n = std::vsnprintf (nullptr, 0, format, args);
  va_end (args);
  std::string text (n > 0 ? static_cast<std::size_t> (n) : 0, '\0');
  if (n > 0)
    std::vsnprintf (text.data (), text.size () + 1, format, again);
  va_end (again);
  return text;
}
} // namespace

template <typename PointT>
std::size_t
finiteCount (const pcl::PointCloud<PointT>& cloud)
{
  std::size_t n = 0;
  for (const auto& p : cloud.points)
    n += std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z);
  return n;
}

template <typename PointT>
double
finiteDiagonal (const pcl::PointCloud<PointT>& cloud)
{
  Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : cloud.points)
    if (std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z))
    {
      const Eigen::Vector3d q = p.getVector3fMap ().template cast<double> ();
      lo = lo.cwiseMin (q);
      hi = hi.cwiseMax (q);
    }
  return (hi.array () >= lo.array ()).all () ? (hi - lo).norm () : 0.0;
}

template <typename PointT>
InputFacts
cloudFacts (const std::string& path, const pcl::PointCloud<PointT>& cloud, const XyzRounding& rounding,
            const SensorNoiseModel& noise)
{
  InputFacts facts;
  facts.path = path;
  facts.finite = finiteCount (cloud);
  facts.diagonal = finiteDiagonal (cloud);
  facts.rounding = rounding;
  facts.sensor = noise.name ();
  if (noise.type () == SensorNoiseModel::Type::Isotropic)
  {
    double axial = 0.0, lateral = 0.0;
    noise.sigmas (Eigen::Vector3d::Zero (), Eigen::Vector3d::Zero (), SensorPose (), axial, lateral);
    facts.sigma = axial;
  }
  return facts;
}

#define PCL_PROBCOLLISION_INPUT_FACTS(PointT)                                                                          \
  template std::size_t finiteCount (const pcl::PointCloud<PointT>&);                                                 \
  template double finiteDiagonal (const pcl::PointCloud<PointT>&);                                                   \
  template InputFacts cloudFacts (const std::string&, const pcl::PointCloud<PointT>&, const XyzRounding&,           \
                                  const SensorNoiseModel&);
PCL_PROBCOLLISION_INPUT_FACTS (pcl::PointXYZ)
PCL_PROBCOLLISION_INPUT_FACTS (pcl::PointNormal)
#undef PCL_PROBCOLLISION_INPUT_FACTS

std::string
scaleWarning (const InputFacts& a, const InputFacts& b)
{
  for (const InputFacts* in : {&a, &b})
    if (in->cloud && in->finite < kScaleWarningMinPoints)
      return {};
  const double da = a.diagonal, db = b.diagonal;
  if (!(da > 0.0 && db > 0.0 && std::isfinite (da) && std::isfinite (db)))
    return {};
  const double ratio = std::max (da, db) / std::min (da, db);
  if (!(ratio > kScaleWarningRatio))
    return {};
  return formatted ("the inputs' sizes differ by %.0fx (bounding-box diagonal %.6g in '%s', %.6g in '%s'); both must "
                    "be in the same units (e.g. metres), so convert one of them if they are not",
                    ratio, da, a.path.c_str (), db, b.path.c_str ());
}

std::string
noiseWarning (const InputFacts& in)
{
  if (!in.cloud || in.sensor != "isotropic" || in.finite < kScaleWarningMinPoints)
    return {};
  const double sigma = in.sigma, diagonal = in.diagonal;
  if (!(sigma > 0.0 && diagonal > 0.0 && std::isfinite (diagonal)))
    return {};
  if (sigma > kLargeNoiseWarningRatio * diagonal)
    return formatted ("the noise sigma %.6g of '%s' is %.2g times its size (bounding-box diagonal %.6g), so every "
                      "point's spread covers the whole cloud; sigma is in the data's units, so give -sigma in the "
                      "cloud's units (e.g. -sigma 0.005 for 5 mm in metres)",
                      sigma, in.path.c_str (), sigma / diagonal, diagonal);
  if (!(sigma < kNoiseWarningRatio * diagonal))
    return {};
  return formatted ("the noise sigma %.6g of '%s' is %.2g of its size (bounding-box diagonal %.6g); sigma is in the "
                    "data's units (the default 0.005 is 5 mm in metres), so give -sigma in the cloud's units (e.g. "
                    "-sigma 5 for millimetres)",
                    sigma, in.path.c_str (), sigma / diagonal, diagonal);
}

std::string
roundingWarning (const InputFacts& in)
{
  const double change = in.rounding.largest_change;
  if (!in.cloud || !(change > 0.0))
    return {};
  const bool isotropic = in.sensor == "isotropic";
  const double limit = isotropic ? CloudModel::kPrecisionWarningRatio * in.sigma : kNoiseWarningRatio * in.diagonal;
  if (!(change > limit))
    return {};
  const std::string scale = isotropic ? formatted ("%.2g of its sigma %.6g", change / in.sigma, in.sigma)
                                      : formatted ("%.2g of its size, bounding-box diagonal %.6g",
                                                   change / in.diagonal, in.diagonal);
  return formatted ("'%s' stores x y z in double precision up to %.6g from its origin; PCL's float points keep them "
                    "to within %.3g (%s), and the answer is for the rounded cloud; move the inputs nearer the origin "
                    "to keep it (docs/CLI.md, \"Coordinates far from the origin\")",
                    in.path.c_str (), in.rounding.largest_magnitude, change, scale.c_str ());
}

std::string
modelWarning (const InputFacts& in, const std::string& model_warning)
{
  if (model_warning.empty () || !roundingWarning (in).empty ())
    return {};
  return "'" + in.path + "': " + model_warning;
}

std::string
openMeshWarning (const std::string& path, const MeshEdges& edges, const std::string& orientation_option)
{
  if (edges.isClosed ())
    return {};
  if (edges.open == 0 && edges.fins == 0 && edges.flipped > 0)
    return formatted ("mesh '%s' is not closed: at %zu of its edges both triangles run the same way, so some faces are "
                      "wound against their neighbours (flipped). The surface layer takes each face's winding as "
                      "outward, so behind a flipped face inside reads outside and a part there can read free: fix "
                      "those faces' winding, or give %s propagate, which orients its samples by their neighbours "
                      "(with -closed for a solid)",
                      path.c_str (), edges.flipped, orientation_option.c_str ());
  return formatted ("mesh '%s' is not closed (an edge does not border exactly two triangles wound oppositely): the "
                    "surface layer takes its faces to enclose an inside all the same, so inside an open container (a "
                    "bin, a shelf) the space its walls surround reads inside. For such a container give %s propagate, "
                    "which makes its surface two-sided; a solid whose mesh merely has cracks or T-junctions is "
                    "better left as it is",
                    path.c_str (), orientation_option.c_str ());
}

std::string
insideOutMeshWarning (const std::string& path, bool closed, double signed_volume, const std::string& orientation_option,
                      const std::string& closed_option)
{
  if (!closed || !(signed_volume < 0.0))
    return {};
  return formatted ("mesh '%s' is closed but its faces wind inward (it encloses %g cubic units negatively): the surface "
                    "layer takes the space around it as its inside, so a part within it reads free. Right for a "
                    "cavity (a closed room); for a solid exported inside out, reverse its faces or give %s propagate "
                    "%s, which orient it outward",
                    path.c_str (), -signed_volume, orientation_option.c_str (), closed_option.c_str ());
}

std::string
betweenSamplesWarning (bool both_meshes, bool free, std::size_t leaf_pairs_tested, const std::string& where,
                       double spacing)
{
  if (!both_meshes || !free || leaf_pairs_tested == 0)
    return {};
  return formatted ("%s reads free, but both inputs are meshes sampled %g apart and their samples come within reach "
                    "of each other there: a part thinner than that crossing a thin wall passes between samples and "
                    "reads free. Check it with a smaller -mesh_density (said once a run)",
                    where.c_str (), spacing);
}

std::string
coarseMeshWarning (bool free, std::size_t leaf_pairs_tested, const std::string& where, const std::string& mesh_path,
                   double mesh_spacing, double cloud_spacing)
{
  if (!free || leaf_pairs_tested == 0 || !(mesh_spacing > kCoarseMeshRatio * cloud_spacing))
    return {};
  return formatted ("%s reads free, but mesh '%s' is sampled %g apart, %.0f times the other input's median spacing "
                    "%g, and their samples come within reach there: a part of the other thinner than that passes "
                    "between the mesh's samples and reads free. Check it with a smaller -mesh_density (said once a run)",
                    where.c_str (), mesh_path.c_str (), mesh_spacing, mesh_spacing / cloud_spacing, cloud_spacing);
}
} // namespace io
} // namespace pcl_probcollision
