// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// pcd_collision's -json line (docs/CLI.md, "JSON output"): one owner of its members, written by
// pcd_collision and, through the Python module, by the Dask command line
// (pcl_probcollision.pcd_collision_json_line).

#include "cli_options.h"

#include <pcl_probcollision/collision_result.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace pcl_probcollision
{
class CloudModel;
}

namespace pcd_collision
{
/** \brief How a model's surface was oriented: the member "surface" of an input (SurfaceModel). */
struct SurfaceFacts
{
  std::string orientation;  ///< orientationName() of SurfaceModel::orientation()
  bool inside_known = false;
  double hidden_from_viewpoint = std::numeric_limits<double>::quiet_NaN ();  ///< NaN writes null
  double closed_share = std::numeric_limits<double>::quiet_NaN ();
  double solid_share = std::numeric_limits<double>::quiet_NaN ();
};

/** \brief What a JSON line says of one input: the file, what it held, its load and sampling
  * times, and what its model made of it. */
struct InputSummary
{
  std::string path;
  bool mesh = false;
  std::size_t points = 0;  ///< the cloud's points, or the mesh's samples
  std::size_t finite = 0;  ///< clouds
  std::uint64_t width = 0, height = 0;  ///< clouds
  std::size_t vertices = 0, triangles = 0;  ///< meshes
  double spacing = std::numeric_limits<double>::quiet_NaN ();  ///< meshes: the sample spacing
  std::string spacing_source;                                   ///< meshes
  double load_ms = 0.0;
  double sample_ms = 0.0;  ///< meshes
  /** \brief CloudModel::mergedSamples(); unset (null) when the input has no model. */
  std::optional<std::size_t> merged_samples;
  /** \brief Unset (null) without a surface model. */
  std::optional<SurfaceFacts> surface;
};

/** \brief The model's part of an InputSummary (merged_samples, surface); model may be null. */
void summarizeModel (const pcl_probcollision::CloudModel* model, InputSummary& summary);

/** \brief One JSON line of pcd_collision -json for result r of pose (its index in a -poses file,
  * or -1 for -pose), under options o; write_ms and points_written describe -o's file (output
  * member only with -o). The witness and nearest points are written as r holds them (b's
  * frame); r.build_ms is the first pose's only. No trailing newline. run_members, when given,
  * is runMembersJson (o, a, b), formatted once for a run's lines. */
std::string resultJson (const Options& o, const InputSummary& a, const InputSummary& b,
                        const pcl_probcollision::CollisionResult& r, const Pose& pose, long long pose_index,
                        const std::optional<double>& write_ms = std::nullopt, std::size_t points_written = 0,
                        const std::string* run_members = nullptr);

/** \brief The members of resultJson's line that every pose of a run repeats ("inputs" and
  * "parameters"), without the braces (JsonWriter::members). */
std::string runMembersJson (const Options& o, const InputSummary& a, const InputSummary& b);
} // namespace pcd_collision
