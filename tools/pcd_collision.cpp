// SPDX-License-Identifier: BSD-3-Clause
// pcd_collision: probability that two point clouds (or meshes) collide, in PCL's tool style.
// The contract is in docs/CLI.md and `pcd_collision -h`.

#include "cli_options.h"
#include "cloud_input.h"
#include "input_warnings.h"
#include "mesh_input.h"
#include "mesh_sampling.h"
#include "pcd_files.h"
#include "result_json.h"

#include <pcl_probcollision/error_message.h>
#include <pcl_probcollision/probabilistic_collision.h>
#include <pcl_probcollision/version.h>

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/pcl_config.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace pcd_collision
{
namespace
{
namespace fs = std::filesystem;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
// The file formats around the library (io/).
using pcl_probcollision::io::loadCloud;
using pcl_probcollision::io::loadCloudWithNormals;
using pcl_probcollision::io::loadTriangleMesh;
using pcl_probcollision::io::meshDiagonal;
using pcl_probcollision::io::meshPairSpacing;
using pcl_probcollision::io::medianSpacing;
using pcl_probcollision::io::sampleMesh;
using pcl_probcollision::io::sampleMeshWithNormals;
using pcl_probcollision::io::setVtkMessages;
using pcl_probcollision::io::TriangleMesh;

/** \brief A failure with its exit status; main prints "pcd_collision: error: <what>". */
struct Failure
{
  int status;
  std::string message;
};

constexpr int kRuntimeFailure = 1;
constexpr int kUsageError = 2;
/** \brief Poses answered by one computeBatch: their transforms and results (about 0.9 KB a pose)
  * are held for a chunk only, so that a run of millions of poses holds its parsed poses (48 bytes
  * each) and no more (a probe: 250,000 poses held 270 MB, a million 986 MB, before any answer).
  * Each chunk waits for its slowest pose, a few ms against the seconds a chunk takes. */
constexpr std::size_t kPosesPerBatch = 16384;

/** \brief Flushes the results' stream (stdout) and fails where they could not be written (a
  * full disk, a quota): an answer lost must not exit 0. A closed pipe ends the tool by SIGPIPE
  * before this is reached, as for any Unix filter. */
void
flushResults ()
{
  if (std::fflush (stdout) != 0 || std::ferror (stdout))
    throw Failure{kRuntimeFailure, std::string ("cannot write the results to standard output: ") + std::strerror (errno)};
}

double
msSince (std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
}

// ---------------------------------------------------------------------------------------------

struct Input
{
  std::string path;
  InputKind kind = InputKind::Unsupported;
  Cloud::Ptr cloud = pcl::make_shared<Cloud> ();  ///< loaded, or sampled from the mesh
  TriangleMesh mesh;
  /** \brief The surface model's orientation: a mesh's samples with its faces' outward normals, or
    * (with -surface) a cloud with the normals its file stores; null for other clouds. */
  pcl::PointCloud<pcl::PointNormal>::Ptr oriented;
  std::size_t finite = 0;
  /** \brief What holding a cloud file's x y z in float points cost (loadCloud). */
  pcl_probcollision::io::XyzRounding rounding;
  /** \brief What the input warnings judge of it (io/input_warnings.h), set once it is loaded. */
  pcl_probcollision::io::InputFacts facts;
  double spacing = std::numeric_limits<double>::quiet_NaN ();  ///< mesh sample spacing
  std::string spacing_source;
  double load_ms = 0.0;
  double sample_ms = 0.0;
};

void
requireReadable (const std::string& path)
{
  if (std::string why = pcl_probcollision::io::unreadableFile (path); !why.empty ())
    throw Failure{kRuntimeFailure, why};
}

/** \brief Loads an input of in.kind (a face-less .ply already a Cloud); with_normals (-surface without -ignore_normals): a cloud file's
  * normal_x normal_y normal_z too, kept in in.oriented when the file has them. */
void
loadInput (Input& in, bool with_normals, FILE* log)
{
  requireReadable (in.path);
  const auto start = std::chrono::steady_clock::now ();
  std::string error;
  if (in.kind == InputKind::Cloud)
  {
    if (with_normals)
    {
      auto oriented = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>> ();
      bool has_normals = false;
      if (!loadCloudWithNormals (in.path, *oriented, has_normals, error, &in.rounding))
        throw Failure{kRuntimeFailure, error};
      pcl::copyPointCloud (*oriented, *in.cloud);
      if (has_normals)
        in.oriented = oriented;
    }
    else if (!loadCloud (in.path, *in.cloud, error, &in.rounding))
      throw Failure{kRuntimeFailure, error};
    in.finite = pcl_probcollision::io::finiteCount (*in.cloud);
    if (in.finite == 0)
      throw Failure{kRuntimeFailure, "'" + in.path + "' has no finite point (" + std::to_string (in.cloud->size ()) +
                                         " points, all NaN or Inf)"};
    in.load_ms = msSince (start);
    std::fprintf (log, "Loading %s [done, %.1f ms : %zu points, %u x %u, %zu finite]\n", in.path.c_str (), in.load_ms,
                  in.cloud->size (), in.cloud->width, in.cloud->height, in.finite);
  }
  else
  {
    if (!loadTriangleMesh (in.path, in.mesh, error))
      throw Failure{kRuntimeFailure, error};
    in.load_ms = msSince (start);
    std::fprintf (log, "Loading %s [done, %.1f ms : mesh, %zu vertices, %zu triangles]\n", in.path.c_str (), in.load_ms,
                  in.mesh.vertices.size (), in.mesh.triangles.size ());
  }
}

/** \brief A cloud's median nearest-neighbour spacing (io::medianSpacing's number), read from its
  * model's neighbour search where the build measured it, a merged model's from its full-resolution
  * rung (the same cloud, searched whole); else (no model, or none that searched the whole cloud)
  * measured here with a k-d tree of its own, 0.8 s at 5,000,000 points. */
double
cloudSpacing (const pcl_probcollision::CloudModel* model, const Cloud& cloud)
{
  double spacing = model ? model->medianNeighbourSpacing () : std::numeric_limits<double>::quiet_NaN ();
  if (std::isnan (spacing) && model && model->fullResolution ())
    spacing = model->fullResolution ()->medianNeighbourSpacing ();
  return std::isnan (spacing) ? medianSpacing (cloud) : spacing;
}

void
sampleInput (Input& in, double spacing, const std::string& source, FILE* log)
{
  const auto start = std::chrono::steady_clock::now ();
  if (!(spacing > 0.0) || !std::isfinite (spacing))
    throw Failure{kRuntimeFailure, "cannot choose a sample spacing for mesh '" + in.path + "' (" + source +
                                       " is 0); give -mesh_density"};
  try
  {
    in.oriented = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>> (
        sampleMeshWithNormals (in.mesh, spacing, Defaults::mesh_sampling_seed));
    in.cloud->resize (in.oriented->size ());
    for (std::size_t i = 0; i < in.oriented->size (); ++i)
      (*in.cloud)[i].getVector3fMap () = (*in.oriented)[i].getVector3fMap ();
  }
  catch (const std::runtime_error& e)
  {
    throw Failure{kRuntimeFailure, "mesh '" + in.path + "': " + pcl_probcollision::errorMessage (e)};
  }
  in.finite = in.cloud->size ();
  in.spacing = spacing;
  in.spacing_source = source;
  in.sample_ms = msSince (start);
  std::fprintf (log, "Sampling %s [done, %.1f ms : %zu points at spacing %g, %s]\n", in.path.c_str (), in.sample_ms,
                in.cloud->size (), spacing, source.c_str ());
}

/** \brief Refuses an -o that is one of the inputs (same file, through any link), and an -o in a
  * directory that does not exist. */
void
checkOutput (const Options& o)
{
  if (!o.output)
    return;
  const fs::path out (*o.output);
  std::vector<std::string> inputs = {o.input_a, o.input_b};
  if (o.poses_file && *o.poses_file != kStandardInput)
    inputs.push_back (*o.poses_file);
  std::error_code ec;
  for (const std::string& in : inputs)
  {
    bool same = fs::exists (out, ec) && fs::exists (in, ec) && fs::equivalent (out, in, ec);
    if (!same)
    {
      const fs::path a = fs::weakly_canonical (out, ec);
      const fs::path b = fs::weakly_canonical (in, ec);
      same = !ec && a == b;
    }
    if (same)
      throw Failure{kUsageError, "-o '" + *o.output + "' is the input '" + in + "'; refusing to overwrite an input"};
  }
  const fs::path dir = out.has_parent_path () ? out.parent_path () : fs::path (".");
  if (!fs::is_directory (dir, ec))
    throw Failure{kRuntimeFailure, "cannot write '" + *o.output + "': directory '" + dir.string () + "' does not exist"};
  if (fs::is_directory (out, ec))
    throw Failure{kRuntimeFailure, "cannot write '" + *o.output + "': is a directory"};
}

/** \brief What the JSON line says of an input (result_json.h). */
InputSummary
summaryOf (const Input& in, const pcl_probcollision::CloudModel* model)
{
  InputSummary s;
  s.path = in.path;
  s.mesh = in.kind != InputKind::Cloud;
  s.points = in.cloud->size ();
  s.finite = in.finite;
  s.width = in.cloud->width;
  s.height = in.cloud->height;
  s.vertices = in.mesh.vertices.size ();
  s.triangles = in.mesh.triangles.size ();
  s.spacing = in.spacing;
  s.spacing_source = in.spacing_source;
  s.load_ms = in.load_ms;
  s.sample_ms = in.sample_ms;
  summarizeModel (model, s);
  return s;
}

std::string
humanLine (const pcl_probcollision::CollisionResult& r, long long pose_index, bool ladder, bool distance_asked)
{
  char buf[512];
  const std::string prefix = pose_index >= 0 ? "pose " + std::to_string (pose_index) + ": " : std::string ();
  // The signed distance, when the surface layer computed one (NaN is never printed).
  // A query that stopped early (lower_bound) reports the first point that decided the collision,
  // not the deepest: say so, as "P >=" says it of P. An asked distance (-distance) is never that
  // bound, even where P is (the ladder's sure collisions: the separators stopped, the surface
  // layer then visited every pair for the distance). A capped one (budget_exhausted) is the
  // leaves' it tested: a gripper 2 cm into a table read d = +0.0166 there.
  char distance[128] = "";
  if (std::isfinite (r.signed_distance))
  {
    // Under the printed precision the sign is noise: "+0.0000", never "-0.0000" (JSON keeps the value).
    const double d = std::abs (r.signed_distance) < 5e-5 ? 0.0 : r.signed_distance;
    std::snprintf (distance, sizeof (distance), "   d = %+.4f +- %.4f%s", d, r.signed_distance_std,
                   r.budget_exhausted ? " (leaves tested before the cap)"
                   : r.lower_bound && !distance_asked ? " (first deciding point)"
                   : r.sample_distance                ? " (nearest samples)"
                                                      : "");
  }
  // The surface layer's answer rests on surface the samples do not show (CollisionResult::unobserved).
  const char* unobserved = r.unobserved ? "  (unobserved: across a hole or behind a sheet)" : "";
  const char* capped = r.budget_exhausted ? "  (budget exhausted: -max_leaf_fits or -max_surface_pairs reached)" : "";
  // A merged cloud's contact that the unmerged models read as collision (CollisionResult::full_resolution).
  const char* full = r.full_resolution ? "  (full resolution)" : "";
  // With -surface_ladder, the rung that answered (CollisionResult::answered_by); the other
  // settings have one answerer, which the command line names.
  const char* rung = !ladder ? ""
                     : r.answered_by == pcl_probcollision::AnsweredBy::Separators   ? "  (ladder: separators)"
                     : r.answered_by == pcl_probcollision::AnsweredBy::SurfaceLayer ? "  (ladder: surface layer)"
                     : r.answered_by == pcl_probcollision::AnsweredBy::Pooled       ? "  (ladder: pooled)"
                                                                                    : "";
  std::snprintf (buf, sizeof (buf),
                 "%s%-9s P %s %.6f%s%s%s%s%s   [points a %zu, b %zu, non-finite skipped %zu; leaf pairs %zu; build %.1f ms, "
                 "query %.1f ms]",
                 prefix.c_str (), pcl_probcollision::verdictName (r.verdict), r.lower_bound ? ">=" : "=",
                 r.probability, distance, unobserved, rung, capped, full, r.points_a, r.points_b, r.points_skipped_nonfinite,
                 r.leaf_pairs_tested,
                 std::isfinite (r.build_ms) ? r.build_ms : 0.0, std::isfinite (r.query_ms) ? r.query_ms : 0.0);
  return buf;
}

std::string
witnessLine (const pcl_probcollision::CollisionResult& r)
{
  if (r.witness_side == 0)
    return "  witness: none (no leaf pair tested)";
  char buf[256];
  std::snprintf (buf, sizeof (buf), "  witness: %s[%d] at (%.4f, %.4f, %.4f), ", r.witness_side > 0 ? "a" : "b",
                 r.witness_index, r.witness_point.x (), r.witness_point.y (), r.witness_point.z ());
  std::string line = buf;
  // The normal is NaN when the separator's gradient collapsed there (coincident points): never
  // print NaN.
  if (r.witness_normal.allFinite ())
  {
    std::snprintf (buf, sizeof (buf), "normal (%.3f, %.3f, %.3f)", r.witness_normal.x (), r.witness_normal.y (),
                   r.witness_normal.z ());
    line += buf;
  }
  else
    line += "normal undefined (no separating direction)";
  return line;
}

/** \brief What the input warnings judge of an input as loaded under the options of its side;
  * its bounding-box diagonal is a cloud's finite points' or a mesh's vertices' (0 for a single
  * point). */
void
setFacts (Input& in, const std::string& sensor, double sigma)
{
  in.facts.path = in.path;
  in.facts.cloud = in.kind == InputKind::Cloud;
  in.facts.finite = in.finite;
  in.facts.diagonal = in.kind == InputKind::Mesh ? meshDiagonal (in.mesh) : pcl_probcollision::io::finiteDiagonal (*in.cloud);
  in.facts.rounding = in.rounding;
  in.facts.sensor = sensor;
  in.facts.sigma = sigma;
}

/** \brief Prints a warning of io/input_warnings.h on stderr, if there is one. */
void
warn (const std::string& warning)
{
  if (!warning.empty ())
    std::fprintf (stderr, "pcd_collision: warning: %s\n", warning.c_str ());
}

/** \brief The stage line of -surface that says where an input's surface normals got their
  * orientation (NormalOrientation, resolved by the model's build). */
void
reportOrientation (const Input& in, const pcl_probcollision::CloudModel& model, FILE* log)
{
  const pcl_probcollision::NormalOrientation orientation = model.surface ().orientation ();
  std::string how;
  switch (orientation)
  {
    case pcl_probcollision::NormalOrientation::PointNormals:
      how = in.kind == InputKind::Mesh ? "its faces' outward normals"
                                       : "the file's normal_x normal_y normal_z, taken as outward";
      break;
    case pcl_probcollision::NormalOrientation::Viewpoint:
    {
      // Named, because a cloud moved into another frame keeps the VIEWPOINT it was saved with
      // (PCL's default 0 0 0; pcl::transformPointCloud leaves sensor_origin_): a table in a
      // robot's base frame, oriented toward the base under it, reads everything above it as
      // behind the table. Propagating instead loses what lies behind a scan (a part deep in a
      // box seen from one side reads free): the VIEWPOINT should move with the points.
      // The model's own (an organized cloud's rows and columns may have put it elsewhere than
      // the file's VIEWPOINT: CloudModel::kStaleViewpointShare), else the file's.
      const Eigen::Vector3d used = model.surface ().viewpoint () + model.origin ();
      const Eigen::Vector3d o = used.allFinite () ? used : in.cloud->sensor_origin_.head<3> ().cast<double> ();
      char text[240];
      std::snprintf (text, sizeof text,
                     "toward the sensor origin, VIEWPOINT %.6g %.6g %.6g (a cloud moved after it was scanned must "
                     "bring its VIEWPOINT along; -orientation propagate leaves it out)",
                     o.x (), o.y (), o.z ());
      how = text;
      break;
    }
    case pcl_probcollision::NormalOrientation::Propagate: how = "propagated over the neighbours"; break;
    case pcl_probcollision::NormalOrientation::Auto: break;
  }
  std::string why;
  auto percent = [] (double share) { return std::to_string (static_cast<int> (std::lround (100.0 * share))); };
  const double hidden = model.surface ().hiddenFromViewpoint ();
  if (model.surface ().normalsOffSurface ())
    why = "; not the file's normals: they lie along its surface, not across it, so they were not moved with its points "
          "(-orientation point_normals to take them)";
  else if (model.surface ().givenNormalsMisoriented () && orientation == pcl_probcollision::NormalOrientation::Viewpoint)
    why = "; the file's normals' directions only: " + percent (model.surface ().givenNormalsAwayShare ()) +
          " % of them face away from its VIEWPOINT, which sees the cloud as one scan, so their sides were not turned "
          "toward the sensor (-orientation point_normals to take them)";
  else if (model.surface ().normalsTurnedToViewpoint ())
    why = "; not the file's normals: they all face its VIEWPOINT, as PCL's normal estimation turns them, and " +
          percent (hidden) + " % of the points lie behind others from there (one scan hides none), so they are not outward "
          "(-orientation point_normals to take them)";
  else if (orientation == pcl_probcollision::NormalOrientation::Propagate && std::isfinite (hidden))
    why = hidden > pcl_probcollision::SurfaceModel::kMaxHiddenShare
              ? "; not toward its VIEWPOINT, from which " + percent (hidden) + " % of the points lie behind others (one scan hides none)"
              : std::string ("; not toward its VIEWPOINT, which sees it edge-on or not as one scan does");
  // -orientation asked for a rule that could not orient this input (SurfaceModel falls back to
  // propagation): say which, and why.
  const pcl_probcollision::NormalOrientation asked = model.params ().orientation;
  if (asked == pcl_probcollision::NormalOrientation::Viewpoint && orientation != asked)
    why = "; -orientation viewpoint refused: its VIEWPOINT sees it edge-on or not as one scan does (or is not finite)";
  else if (asked == pcl_probcollision::NormalOrientation::PointNormals && orientation != asked)
    why = "; -orientation point_normals refused: it has no normals";
  // -closed: whether the winding number confirmed a closed solid, so that the surface has an inside.
  const double closed = model.surface ().closedShare ();
  if (std::isfinite (closed))
    why += std::string (model.surface ().insideKnown () ? "; closed: " : "; not closed, so two-sided: ") + "outside in front of " +
           percent (closed) + " %, inside behind " + percent (model.surface ().solidShare ()) +
           " % of the probed samples (closed needs " + percent (pcl_probcollision::SurfaceModel::kMinClosedShare) + " and " +
           percent (pcl_probcollision::SurfaceModel::kMinSolidShare) + ")";
  else if (orientation == pcl_probcollision::NormalOrientation::Propagate)
    why += "; two-sided (-closed if it samples closed solids)";
  std::fprintf (log, "Orienting %s [%s: %s%s]\n", in.path.c_str (), pcl_probcollision::orientationName (orientation),
                how.c_str (), why.c_str ());
}

/** \brief Terminal progress lines (Progress, BuildTicker) appear only after this long: short runs
  * show nothing. */
constexpr std::chrono::milliseconds kProgressDelay (200);
/** \brief Returns to the start of the line and erases it: a progress line leaves nothing behind. */
constexpr const char* kEraseLine = "\r\033[K";

/** \brief "\r[12/300 poses]" on stderr when it is a terminal, at most every 0.2 s, first after
  * 0.2 s (short runs show nothing); erased at the end and before summary lines that share the
  * terminal. */
class Progress
{
public:
  Progress (std::size_t total, bool enabled)
    : total_ (total), enabled_ (enabled && total > 1), last_ (std::chrono::steady_clock::now ()) {}
  void show (std::size_t done)
  {
    if (!enabled_ || done >= total_)
      return;
    const auto now = std::chrono::steady_clock::now ();
    if (now - last_ < kProgressDelay)
      return;
    last_ = now;
    std::fprintf (stderr, "\r[%zu/%zu poses]", done, total_);
    std::fflush (stderr);
    shown_ = true;
  }
  void clear ()
  {
    if (!shown_)
      return;
    std::fputs (kEraseLine, stderr);
    std::fflush (stderr);
    shown_ = false;
  }

private:
  std::size_t total_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_;
};

/** \brief "\rBuilding floor.pcd ... 12 s" on stderr when it is a terminal, while a model builds
  * (a 5,000,000-point cloud takes 10-20 s, with nothing else to show): drawn on a thread of its
  * own after 0.2 s (as Progress: short builds show nothing) and then every second, erased when
  * the build returns, before its stage line. */
class BuildTicker
{
public:
  explicit BuildTicker (bool enabled) : enabled_ (enabled) {}
  BuildTicker (const BuildTicker&) = delete;
  BuildTicker& operator= (const BuildTicker&) = delete;

  /** \brief Shows `label` with the seconds since this call until the returned guard is gone. */
  auto
  show (const std::string& label)
  {
    struct Guard
    {
      BuildTicker* ticker;
      ~Guard ()
      {
        if (ticker)
          ticker->stop ();
      }
    };
    if (!enabled_)
      return Guard{nullptr};
    stopping_ = false;
    thread_ = std::thread ([this, label, start = std::chrono::steady_clock::now ()] {
      std::unique_lock<std::mutex> lock (mutex_);
      if (wake_.wait_for (lock, kProgressDelay, [this] { return stopping_; }))
        return;
      do
      {
        const double seconds = std::chrono::duration<double> (std::chrono::steady_clock::now () - start).count ();
        std::fprintf (stderr, "\r%s ... %.0f s", label.c_str (), seconds);
        std::fflush (stderr);
      } while (!wake_.wait_for (lock, std::chrono::seconds (1), [this] { return stopping_; }));
      std::fputs (kEraseLine, stderr);
      std::fflush (stderr);
    });
    return Guard{this};
  }

private:
  void
  stop ()
  {
    {
      std::lock_guard<std::mutex> lock (mutex_);
      stopping_ = true;
    }
    wake_.notify_one ();
    thread_.join ();
  }

  bool enabled_;
  bool stopping_ = false;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
};

int
run (int argc, char** argv)
{
  const ParseResult parsed = parseCommandLine (argc, argv);
  if (parsed.kind == ParseResult::Kind::Help)
  {
    std::fputs (helpText ().c_str (), stdout);
    return 0;
  }
  if (parsed.kind == ParseResult::Kind::Version)
  {
    std::printf ("pcd_collision %s (library %s, PCL %s)\n", PCL_PROBCOLLISION_VERSION_STRING,
                 pcl_probcollision::libraryVersion (), PCL_VERSION_PRETTY);
    return 0;
  }
  if (parsed.kind == ParseResult::Kind::Error)
    throw Failure{kUsageError, parsed.error};
  const Options& o = parsed.options;

  // PCL's and VTK's own messages would repeat our one-line errors; -v shows them (the mesh
  // loader keeps VTK silent by default).
  if (o.verbose)
    setVtkMessages (true);
  else
    pcl::console::setVerbosityLevel (pcl::console::L_ALWAYS);
  FILE* const log = stderr;                           // progress and stage lines
  FILE* const human = o.json ? stderr : stdout;       // the summary

  checkOutput (o);

  // Poses first: a malformed file fails before the (slow) loading.
  std::vector<Pose> poses;
  const bool batch = o.poses_file.has_value ();
  if (batch && *o.poses_file == kStandardInput)
  {
    // A pipe from a pose generator: read to its end, so that a malformed line still fails
    // before any query, as in a file.
    std::string error;
    if (!parsePoses (std::cin, "standard input", poses, error))
      throw Failure{kRuntimeFailure, error};
  }
  else if (batch)
  {
    std::string error = pcl_probcollision::io::unreadableFile (*o.poses_file);
    std::ifstream f (*o.poses_file);
    if (!error.empty () || !parsePoses (f, *o.poses_file, poses, error))
      throw Failure{kRuntimeFailure, error};
  }
  else
    poses.push_back (o.pose.value_or (Pose{0, 0, 0, 0, 0, 0}));

  Input a, b;
  a.path = o.input_a;
  a.kind = inputKindOf (a.path);
  b.path = o.input_b;
  b.kind = inputKindOf (b.path);
  // A .ply whose header declares no face is a cloud: the kinds are known before the (slow)
  // loading, and so is an option that needs a mesh among the inputs. A .ply whose header cannot
  // be read has no kind to judge options by: it is reported as its loader would (exit 1), not
  // called a mesh by its name.
  for (Input* in : {&a, &b})
    if (in->kind == InputKind::Mesh)
    {
      bool faceless = false;
      std::string error;
      if (!pcl_probcollision::io::plyKind (in->path, faceless, error))
        throw Failure{kRuntimeFailure, error};
      if (faceless)
        in->kind = InputKind::Cloud;
    }
  if (const std::string why = inputKindsUsageError (o, a.kind == InputKind::Mesh, b.kind == InputKind::Mesh); !why.empty ())
    throw Failure{kUsageError, why};
  const bool with_normals = o.surface && !o.ignore_normals;
  loadInput (a, with_normals, log);
  loadInput (b, with_normals, log);
  // The units and precision warnings (one pass over each input: 5,000,000 points are 60 MB).
  setFacts (a, o.sensor_a, o.sigma_a);
  setFacts (b, o.sensor_b, o.sigma_b);
  warn (pcl_probcollision::io::scaleWarning (a.facts, b.facts));
  for (const Input* in : {&a, &b})
    warn (pcl_probcollision::io::noiseWarning (in->facts));
  for (const Input* in : {&a, &b})
    warn (pcl_probcollision::io::roundingWarning (in->facts));
  // A mesh oriented by its faces (-surface, -orientation auto or point_normals) has an inside.
  for (const auto& [in, orientation, option] :
       {std::tuple<const Input*, pcl_probcollision::NormalOrientation, const char*> {&a, o.orientation_a, "-orientation_a"},
        {&b, o.orientation_b, "-orientation_b"}})
    if (o.surface && in->kind == InputKind::Mesh && orientation != pcl_probcollision::NormalOrientation::Propagate &&
        orientation != pcl_probcollision::NormalOrientation::Viewpoint)
    {
      const pcl_probcollision::io::MeshEdges edges = pcl_probcollision::io::meshEdges (in->mesh);
      warn (pcl_probcollision::io::openMeshWarning (in->path, edges, option));
      warn (pcl_probcollision::io::insideOutMeshWarning (in->path, edges.isClosed (), pcl_probcollision::io::meshSignedVolume (in->mesh),
                                                         option, in == &a ? "-closed_a" : "-closed_b"));
    }

  // A cloud's model does not depend on the other input. When the other is a mesh, whose
  // sampling first measures this cloud's spacing with a k-d tree of its own (serial: 0.8 s at
  // 5,000,000 points), the model is built meanwhile on the other threads; with -threads 1
  // everything stays on one. The model is the one compute() would build (same parameters and
  // name); if its build fails, compute() builds it again and reports the failure as before.
  const unsigned workers = o.threads > 0 ? static_cast<unsigned> (o.threads) : std::max (1u, std::thread::hardware_concurrency ());
  using pcl_probcollision::SensorNoiseModel;
  // A cloud's model as compute() builds it: the tool's parameters with that input's noise, and
  // the name compute() gives it.
  auto buildCloud = [&o] (const Input& in, const std::string& sensor, double sigma, bool input) {
    pcl_probcollision::CloudModelParams params = modelParamsFor (o, input);
    params.noise = SensorNoiseModel::fromName (sensor, sigma);
    return pcl_probcollision::buildCloudModel (*in.cloud, params, nullptr, nullptr, input ? "input" : "target");
  };
  // A cloud against a mesh sampled at its spacing is built first (on its own thread beside the
  // rest of the setup, or when the sampling asks for it with one thread): the build's neighbour
  // search measures the spacing (CloudModel::medianNeighbourSpacing), so the sampling needs no
  // k-d tree of its own over the cloud (0.85 s for 5,000,000 points).
  auto earlyBuild = [&] (const Input& cloud, const Input& other, const std::string& sensor, double sigma, bool input) {
    std::shared_future<pcl_probcollision::CloudModel::ConstPtr> model;
    if (cloud.kind == InputKind::Cloud && !cloud.oriented && other.kind == InputKind::Mesh && !o.mesh_spacing)
      model = std::async (workers > 1 ? std::launch::async : std::launch::deferred, buildCloud, std::cref (cloud),
                          sensor, sigma, input)
                  .share ();
    return model;
  };
  BuildTicker ticker (::isatty (STDERR_FILENO));
  auto early_a = earlyBuild (a, b, o.sensor_a, o.sigma_a, true);
  auto early_b = earlyBuild (b, a, o.sensor_b, o.sigma_b, false);

  // MeshSampled mode: spacing from -mesh_density, the other cloud, or the meshes' size.
  for (Input* m : {&a, &b})
  {
    if (m->kind != InputKind::Mesh)
      continue;
    const Input& other = (m == &a) ? b : a;
    if (o.mesh_spacing)
      sampleInput (*m, *o.mesh_spacing, "-mesh_density", log);
    else if (other.kind == InputKind::Cloud)
    {
      // The other cloud's early build measured it; a build that failed is left to compute(),
      // which reports its error, and the spacing is then measured here.
      pcl_probcollision::CloudModel::ConstPtr built;
      const auto& early = (m == &a) ? early_b : early_a;
      if (early.valid ())
      {
        try
        {
          const auto shown = ticker.show ("Building " + other.path);
          built = early.get ();
        }
        catch (const pcl::PCLException&)
        {
        }
      }
      const double spacing = cloudSpacing (built.get (), *other.cloud);
      sampleInput (*m, spacing, "median nearest-neighbour spacing of '" + other.path + "'", log);
    }
    else
      sampleInput (*m, meshPairSpacing (a.mesh, b.mesh),
                   "both inputs are meshes: 1/100 of the smaller bounding-box diagonal, or wider for 500000 samples", log);
  }

  pcl_probcollision::ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (a.cloud);
  pc.setTargetCloud (b.cloud);
  pc.setInputModelParams (modelParamsFor (o, true));
  pc.setTargetModelParams (modelParamsFor (o, false));
  // A mesh is exact (zero covariance) and oriented by its faces: its model is built here from
  // the samples with their normals. A cloud whose file has normals (with -surface) is built here
  // too, as compute() would build it (its noise, the same name), from the points with their
  // normals, which the surface model takes as outward.
  auto orientedModel = [&] (const Input& in, const SensorNoiseModel& noise, bool input) {
    const auto shown = ticker.show ("Building " + in.path);
    if (in.kind == InputKind::Mesh)
    {
      const pcl::PointCloud<pcl_probcollision::Covariance> exact (in.oriented->width, in.oriented->height);
      return pcl_probcollision::buildCloudModel (*in.oriented, modelParamsFor (o, input), nullptr, &exact, in.path);
    }
    pcl_probcollision::CloudModelParams params = modelParamsFor (o, input);
    params.noise = noise;
    return pcl_probcollision::buildCloudModel (*in.oriented, params, nullptr, nullptr, input ? "input" : "target");
  };
  if (a.oriented)
    pc.setInputModel (orientedModel (a, SensorNoiseModel::fromName (o.sensor_a, o.sigma_a), true));
  else
    pc.setInputNoise (SensorNoiseModel::fromName (o.sensor_a, o.sigma_a));
  if (b.oriented)
    pc.setTargetModel (orientedModel (b, SensorNoiseModel::fromName (o.sensor_b, o.sigma_b), false));
  else
    pc.setTargetNoise (SensorNoiseModel::fromName (o.sensor_b, o.sigma_b));
  // The build time of the models built here (compute() reuses them, so it counts none).
  double models_build_ms = 0.0;
  // The other clouds' models are built here too (or taken from their early build), so that every
  // model gets its stage line (a 5,000,000-point cloud takes seconds); a build that fails is
  // reported with the file's name.
  auto cloudModel = [&] (const Input& in, const std::shared_future<pcl_probcollision::CloudModel::ConstPtr>& early,
                         const std::string& sensor, double sigma, bool input) {
    if (in.oriented)
      return;
    try
    {
      const auto shown = ticker.show ("Building " + in.path);
      const auto built = early.valid () ? early.get () : buildCloud (in, sensor, sigma, input);
      input ? pc.setInputModel (built) : pc.setTargetModel (built);
      models_build_ms += built->buildMilliseconds ();
    }
    catch (const pcl::PCLException& e)
    {
      // The library names the cloud by its role ("target point 0 at ..."); the user knows files.
      throw Failure{kRuntimeFailure, "'" + in.path + "' (" + (input ? "<a>" : "<b>") + "): " + pcl_probcollision::errorMessage (e)};
    }
  };
  cloudModel (a, early_a, o.sensor_a, o.sigma_a, true);
  cloudModel (b, early_b, o.sensor_b, o.sigma_b, false);
  // Models built from oriented points (a mesh's samples, a cloud with normals) count too: the
  // answer's build time is every model's, whoever built it.
  if (a.oriented)
    models_build_ms += pc.getInputModel ()->buildMilliseconds ();
  if (b.oriented)
    models_build_ms += pc.getTargetModel ()->buildMilliseconds ();
  for (const auto& [in, model] : {std::pair (&a, pc.getInputModel ()), std::pair (&b, pc.getTargetModel ())})
    if (model)
      // The model's memory (CloudModel::bytes), for whoever sizes a large map.
    {
      // A cloud modelled by its merged samples (-noise_resolution) says how many there were.
      char merged[96] = "";
      if (model->mergedSamples () > 0)
        std::snprintf (merged, sizeof merged, " (from %zu samples merged within %g noise sigmas)",
                       model->size () + model->mergedSamples (), model->params ().noiseResolution ());
      std::fprintf (log, "Building %s [done, %.1f ms : %zu points%s, %zu hierarchy nodes%s, %.2f MB]\n", in->path.c_str (),
                    model->buildMilliseconds (), model->size (), merged, model->hierarchy ().nodes ().size (),
                    model->params ().surface ? ", surface model" : "", static_cast<double> (model->bytes ()) / 1e6);
      // The model's own precision warning (float points whose spacing is coarse against their
      // spread: a float32 file far from its origin), unless the file's rounding was warned of.
      warn (pcl_probcollision::io::modelWarning (in->facts, model->warning ()));
    }
  pc.setRequest (requestFor (o));

  Progress progress (poses.size (), batch && ::isatty (STDERR_FILENO));
  // Summary lines on a terminal that also shows the progress: erase the progress first.
  const bool shares_terminal = !o.json && ::isatty (STDOUT_FILENO);
  // Two meshes are sampled exactly (zero covariance), so nothing models the surface between
  // their samples: a thin part through a thin wall can pass between the samples of both and read
  // free (FCL's piano legs, 40 mm across, through its 9 mm floor at a 90 mm spacing).
  // A free answer whose samples came within reach of each other (leaf pairs were fitted) says
  // so, once a run.
  const bool both_meshes = a.kind == InputKind::Mesh && b.kind == InputKind::Mesh;
  bool warned_between_samples = false;
  // -json: both inputs' summaries and the members every line repeats, made at the first answer
  // (the models are built then and stay): formatted for each line, they were most of its cost.
  std::optional<InputSummary> summary_a, summary_b;
  std::string run_members;
  // Prints pose i and its answer (the answer of pose `local` of its chunk's computeBatch); throws
  // Failure for a failed query.
  auto emit = [&] (std::size_t i, std::size_t local, const Eigen::Isometry3d& T, pcl_probcollision::CollisionResult& result) {
    if (!result.ok () || shares_terminal)
      progress.clear ();
    if (!result.ok ())
    {
      // computeBatch names the pose by its place in the chunk: the failure line names it once,
      // by its place in the run, after "pose i: ".
      const std::string prefix = "pose " + std::to_string (local) + ": ";
      std::string message = result.message.rfind (prefix, 0) == 0 ? result.message.substr (prefix.size ()) : result.message;
      throw Failure{kRuntimeFailure, (batch ? "pose " + std::to_string (i) + ": " : std::string ()) + "query failed: " +
                                         (message.empty () ? std::string ("the query failed") : message)};
    }
    // The models are built once, before the first pose, and every answer carries that time: it
    // belongs to the first pose, as a serial loop of compute() would report it.
    if (i > 0 && std::isfinite (result.build_ms))
      result.build_ms = 0.0;
    if (i == 0)
      result.build_ms += models_build_ms;
    // With -surface, how each surface was oriented, once both models exist.
    if (i == 0 && o.surface)
    {
      reportOrientation (a, *pc.getInputModel (), log);
      reportOrientation (b, *pc.getTargetModel (), log);
    }

    std::optional<double> write_ms;
    std::size_t written = 0;
    if (o.output)
    {
      const auto start = std::chrono::steady_clock::now ();
      Cloud moved (*a.cloud);
      for (auto& p : moved.points)
        p.getVector3fMap () = (T.cast<float> () * p.getVector3fMap ());
      std::vector<LabelledCloud> sides (2);
      sides[0].cloud = &moved;
      sides[0].probabilities = &result.probabilities_a;
      sides[0].label = 0;
      sides[1].cloud = b.cloud.get ();
      sides[1].probabilities = &result.probabilities_b;
      sides[1].label = 1;
      const Eigen::Vector4f origin = b.kind == InputKind::Cloud ? b.cloud->sensor_origin_ : Eigen::Vector4f::Zero ();
      const Eigen::Quaternionf orientation =
          b.kind == InputKind::Cloud ? b.cloud->sensor_orientation_ : Eigen::Quaternionf::Identity ();
      std::string error;
      if (!writeResultCloud (*o.output, sides, requestFor (o), origin, orientation, written, error))
        throw Failure{kRuntimeFailure, error};
      write_ms = msSince (start);
    }

    if (!warned_between_samples)
    {
      const bool free = result.verdict == pcl_probcollision::Verdict::Free;
      const std::string where = batch ? "pose " + std::to_string (i) : "the pose";
      std::string warning = pcl_probcollision::io::betweenSamplesWarning (both_meshes, free, result.leaf_pairs_tested, where,
                                                                          std::max (a.spacing, b.spacing));
      // One mesh sampled at the user's -mesh_density, coarser than the cloud it meets.
      if (warning.empty () && !both_meshes && o.mesh_spacing && (a.kind == InputKind::Mesh || b.kind == InputKind::Mesh))
      {
        const Input& mesh = a.kind == InputKind::Mesh ? a : b;
        const Input& cloud = a.kind == InputKind::Mesh ? b : a;
        const auto cloud_model = a.kind == InputKind::Mesh ? pc.getTargetModel () : pc.getInputModel ();
        if (free && result.leaf_pairs_tested > 0)
        {
          const double spacing = cloudSpacing (cloud_model.get (), *cloud.cloud);
          warning = pcl_probcollision::io::coarseMeshWarning (free, result.leaf_pairs_tested, where, mesh.path, mesh.spacing,
                                                              spacing);
        }
      }
      if (!warning.empty ())
      {
        warned_between_samples = true;
        progress.clear ();
        warn (warning);
      }
    }
    const long long index = batch ? static_cast<long long> (i) : -1;
    if (o.json)
    {
      if (!summary_a)
      {
        summary_a = summaryOf (a, pc.getInputModel ().get ());
        summary_b = summaryOf (b, pc.getTargetModel ().get ());
        run_members = runMembersJson (o, *summary_a, *summary_b);
      }
      std::fprintf (stdout, "%s\n",
                    resultJson (o, *summary_a, *summary_b, result, poses[i], index, write_ms, written, &run_members).c_str ());
      flushResults ();
    }
    else
    {
      std::fprintf (human, "%s\n", humanLine (result, index, o.surface_ladder, o.distance).c_str ());
      if (!batch)
        std::fprintf (human, "%s\n", witnessLine (result).c_str ());
      flushResults ();  // human is stdout here
    }
    if (o.output)
      std::fprintf (log, "Writing %s [done, %.1f ms : %zu points, a then b, fields x y z intensity rgb label]\n",
                    o.output->c_str (), *write_ms, written);
    progress.show (i + 1);
  };
  // The poses are answered on `workers` threads and each answer is printed as soon as it and every
  // pose before it are done (computeBatch's `ready`, one call at a time, on the threads that
  // answer): the lines stream in pose order, and no thread waits for a batch's slowest pose, but
  // at the end of each chunk of kPosesPerBatch. An answer printed is dropped (with -o it holds
  // both clouds' per-point values).
  std::vector<Eigen::Isometry3d> transforms;
  std::vector<pcl_probcollision::CollisionResult> results;
  for (std::size_t first = 0; first < poses.size (); first += kPosesPerBatch)
  {
    const std::size_t count = std::min (kPosesPerBatch, poses.size () - first);
    transforms.clear ();
    for (std::size_t k = 0; k < count; ++k)
      transforms.push_back (poseTransform (poses[first + k]));
    pc.computeBatch (transforms, results, static_cast<int> (workers), [&] (std::size_t k) {
      emit (first + k, k, transforms[k], results[k]);
      results[k] = pcl_probcollision::CollisionResult ();
    });
  }
  progress.clear ();
  return 0;
}
} // namespace
} // namespace pcd_collision

int
main (int argc, char** argv)
{
  pcd_collision::installInterruptCleanup ();
  try
  {
    const int status = pcd_collision::run (argc, argv);
    pcd_collision::flushResults ();  // what else went to stdout (the help)
    return status;
  }
  catch (const pcd_collision::Failure& f)
  {
    std::fprintf (stderr, "pcd_collision: error: %s\n", f.message.c_str ());
    return f.status;
  }
  catch (const std::exception& e)
  {
    std::fprintf (stderr, "pcd_collision: error: %s\n", pcl_probcollision::errorMessage (e).c_str ());
    return 1;
  }
  catch (...)
  {
    std::fprintf (stderr, "pcd_collision: error: unknown exception\n");
    return 1;
  }
}
