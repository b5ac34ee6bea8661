// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Command line of pcd_collision: a pure function from argv to Options or a usage error, and
// the parser of -poses files. No PCL and no file-system access here, so it can be unit-tested
// and fuzzed on its own; the library's defaults come from its plain-data headers (Eigen only).

#include <pcl_probcollision/cloud_model_params.h>
#include <pcl_probcollision/collision_request.h>

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <vector>

namespace pcd_collision
{
/** \brief tx, ty, tz, roll, pitch, yaw (data units, radians):
  * p' = Rz(yaw) Ry(pitch) Rx(roll) p + t. */
using Pose = std::array<double, 6>;

/** \brief The rigid transform of a pose, p' = Rz(yaw) Ry(pitch) Rx(roll) p + t: pcd_collision's
  * -pose and -poses, and Python's poses_from_xyzrpy. */
Eigen::Isometry3d poseTransform (const Pose& pose);

/** \brief Why six numbers are no pose the tool takes: a value that is not finite, or a
  * translation beyond the library's range (detail::kMaxCoordinate); empty if none. The rule of
  * -pose, -poses and Python's poses_from_xyzrpy. */
std::string poseValueError (const Pose& pose);

/** \brief The defaults of the options, shown by helpText(). The library's settings are read
  * from the structs that own them (CloudModelParams, BVHParams, CollisionRequest); only what
  * the tool decides itself is written here. */
struct Defaults
{
  /** \brief The tool's own choice, not the library's (none): its inputs are files of unknown
    * origin, mostly scans, where assuming no noise would make near-contact answers
    * overconfident (README, "Which noise model"). */
  static constexpr const char* sensor = "isotropic";
  static constexpr double sigma = pcl_probcollision::SensorNoiseModel::kDefaultIsotropicSigma;
  /** \brief The library's defaults. */
  static inline const pcl_probcollision::CloudModelParams model {};
  static inline const pcl_probcollision::CollisionRequest request {};
  static inline const int k = model.k;
  static inline const double free_below = request.free_below;
  static inline const double collision_above = request.collision_above;
  static inline const std::uint64_t seed = request.seed;
  static inline const bool stochastic = request.traversal == pcl_probcollision::TraversalMode::Stochastic;
  static inline const bool exhaustive = request.exhaustive;
  static inline const bool defer_kernel_fits = request.defer_kernel_fits;
  static inline const std::size_t max_leaf_fits = request.max_leaf_fits;
  static inline const std::size_t max_surface_pairs = request.max_surface_pairs;
  static inline const std::optional<double> noise_resolution = model.noise_resolution;
  static inline const pcl_probcollision::CloudModelParams::ResolutionGate noise_resolution_gate = model.noise_resolution_gate;
  static inline const double noise_stop = model.hierarchy.noise_stop;
  static inline const int n_noise_max = model.hierarchy.n_noise_max;
  static inline const bool surface = request.surface;
  static inline const bool surface_pooled = request.surface_pooled;
  static inline const bool surface_ladder = request.surface_ladder;
  static inline const bool surface_calibrated = request.surface_calibrated;
  static inline const bool distance = request.distance;
  static inline const bool measured = !model.surface_projection;
  static inline const int n_max = model.hierarchy.n_max;
  static inline const int n_min = model.hierarchy.n_min;
  static inline const double sigma_max = model.hierarchy.sigma_max;
  static inline const double epsilon = model.hierarchy.epsilon;
  static inline const char* const split =
      model.hierarchy.split_style == pcl_probcollision::BVHParams::SplitStyle::Octree ? "octree" : "pca";
  /** \brief -threads: one worker per hardware thread (CloudModelParams's and collideBatch's 0). */
  static inline const int threads = model.threads;
  /** \brief Seed of the mesh surface sampling (fixed; -seed does not change it). */
  static constexpr std::uint64_t mesh_sampling_seed = 20111;
};

struct Options
{
  std::string input_a;
  std::string input_b;

  /** \brief -pose (single query); identity when absent. */
  std::optional<Pose> pose;
  /** \brief -poses FILE (batch mode); kStandardInput reads the poses from stdin. */
  std::optional<std::string> poses_file;
  /** \brief -threads N: threads of the build (covariances, hierarchies) and of the poses, >= 0,
    * 0 = one per hardware thread. The output is the same whatever N (timings aside). */
  int threads = Defaults::threads;

  /** \brief Sensor noise model of each input: none, isotropic, kinect, stereo, lidar; -sensor
    * sets both, -sensor_a / -sensor_b one each. Not used for a mesh (exact). */
  std::string sensor_a = Defaults::sensor;
  std::string sensor_b = Defaults::sensor;
  /** \brief Isotropic sigma of each input (data units); -sigma sets both, -sigma_a / -sigma_b
    * one each. Only meaningful when that input's sensor is "isotropic". */
  double sigma_a = Defaults::sigma;
  double sigma_b = Defaults::sigma;
  /** \brief The option that set one input's noise alone ("-sigma_a" or "-sensor_a", likewise for
    * b), empty when none did: refused for a mesh once the kinds are known (inputKindsUsageError). */
  std::string noise_option_a, noise_option_b;
  int k = Defaults::k;

  double free_below = Defaults::free_below;
  double collision_above = Defaults::collision_above;
  std::uint64_t seed = Defaults::seed;
  int n_max = Defaults::n_max;
  double sigma_max = Defaults::sigma_max;
  double epsilon = Defaults::epsilon;
  std::string split = Defaults::split;
  bool stochastic = Defaults::stochastic;
  /** \brief -measured: surface projection off (CloudModelParams::surface_projection). */
  bool measured = Defaults::measured;
  bool exhaustive = Defaults::exhaustive;
  /** \brief -defer_kernel_fits: CollisionRequest::defer_kernel_fits. */
  bool defer_kernel_fits = Defaults::defer_kernel_fits;
  /** \brief -max_leaf_fits N: CollisionRequest::max_leaf_fits (0 = no cap). */
  std::size_t max_leaf_fits = Defaults::max_leaf_fits;
  /** \brief -max_surface_pairs N: CollisionRequest::max_surface_pairs (0 = no cap). */
  std::size_t max_surface_pairs = Defaults::max_surface_pairs;
  /** \brief -noise_resolution C: CloudModelParams::noise_resolution (0 = no merging; unset: its
    * default, CloudModelParams::noiseResolution()). */
  std::optional<double> noise_resolution = Defaults::noise_resolution;
  /** \brief -noise_resolution_gate everywhere|spacing|cloud: CloudModelParams::noise_resolution_gate. */
  pcl_probcollision::CloudModelParams::ResolutionGate noise_resolution_gate = Defaults::noise_resolution_gate;
  /** \brief -noise_stop C: BVHParams::noise_stop (0 = off). */
  double noise_stop = Defaults::noise_stop;
  bool surface = Defaults::surface;
  /** \brief -surface_pooled: the surface layer pooled with the separators (implies -surface). */
  bool surface_pooled = Defaults::surface_pooled;
  /** \brief -surface_ladder: CollisionRequest::surface_ladder (implies -surface). */
  bool surface_ladder = Defaults::surface_ladder;
  /** \brief -surface_calibrated: CollisionRequest::surface_calibrated. */
  bool surface_calibrated = Defaults::surface_calibrated;
  /** \brief -distance: CollisionRequest::distance (the nearest samples' distance beyond reach). */
  bool distance = Defaults::distance;
  /** \brief -ignore_normals: with -surface, a cloud file's normal_x normal_y normal_z are not
    * read (the cloud is oriented by its viewpoint or by propagation, as one without normals). */
  bool ignore_normals = false;
  /** \brief -closed (both), -closed_a, -closed_b: with -surface, the input samples closed solids
    * (CloudModelParams::closed_objects). */
  bool closed_a = false;
  bool closed_b = false;
  /** \brief -orientation M (both), -orientation_a M, -orientation_b M: with -surface, how the
    * input's surface is oriented (CloudModelParams::orientation; default Auto). */
  pcl_probcollision::NormalOrientation orientation_a = pcl_probcollision::NormalOrientation::Auto;
  pcl_probcollision::NormalOrientation orientation_b = pcl_probcollision::NormalOrientation::Auto;

  /** \brief -mesh_density S: sample spacing of mesh inputs in data units (> 0). */
  std::optional<double> mesh_spacing;

  /** \brief -o FILE.pcd */
  std::optional<std::string> output;
  bool json = false;
  bool verbose = false;
};

struct ParseResult
{
  enum class Kind
  {
    Run,    ///< options are valid
    Help,     ///< -h / --help: print the help and exit 0
    Version,  ///< -version / --version: print the versions and exit 0
    Error     ///< usage error: print `error` and exit 2
  };
  Kind kind = Kind::Error;
  Options options;
  std::string error;
};

/** \brief Parses argv[1..argc-1]. A flag's value is the next argument or follows '='
  * (-pose 0,0,1,0,0,0 or -pose=0,0,1,0,0,0). Strict: unknown flags, missing or malformed values,
  * values out of range, repeated flags, conflicting flags and a wrong number of positional
  * arguments are usage errors naming the flag or argument. */
ParseResult parseCommandLine (const std::vector<std::string>& args);
ParseResult parseCommandLine (int argc, const char* const* argv);

/** \brief The query the options ask for (-thresholds, -exhaustive, the surface layer's flags,
  * ...; -o adds per-point values and visits every pair): pcd_collision's, and through Python's
  * pcd_collision_params the Dask layer's. */
pcl_probcollision::CollisionRequest requestFor (const Options& o);

/** \brief How an input (<a> when `input`, else <b>) is modelled (-k, the hierarchy's flags, the
  * surface's, -threads, ...); its noise is left to the caller (none for a mesh's exact samples,
  * SensorNoiseModel::fromName for a cloud). Shared as requestFor is. */
pcl_probcollision::CloudModelParams modelParamsFor (const Options& o, bool input);

/** \brief The usage error of options that ask for an input of a kind the inputs turn out not to
  * be, or "" when none: -mesh_density sets a mesh's sample spacing, so with two clouds it would
  * change nothing; -sigma_a, -sensor_a (or _b) set one input's noise, which a mesh, sampled
  * exactly, does not have. Asked once the inputs' kinds are known (a .ply is a mesh, or a cloud when its
  * header declares no face: isFacelessPly), by pcd_collision before it loads them and by the Dask
  * layer (Python's pcd_collision_input_usage_error), so both refuse the same inputs. */
std::string inputKindsUsageError (const Options& o, bool mesh_a, bool mesh_b);

/** \brief The -h text; its syntax lines show every default. */
std::string helpText ();

/** \brief The input kinds the tool reads, by file extension (case-insensitive). */
enum class InputKind
{
  Unsupported,
  Cloud,  ///< .pcd
  Mesh    ///< .ply .obj .stl .vtk; the tool reads a .ply without faces as a cloud (isFacelessPly)
};
InputKind inputKindOf (const std::string& path);

/** \brief Strict number parsing: the whole string must be consumed, finite, no empty string. */
bool parseDouble (const std::string& text, double& value);
bool parseInt (const std::string& text, int& value);
bool parseUint64 (const std::string& text, std::uint64_t& value);
/** \brief The items between commas, empty ones included ("1,,2" has three). */
std::vector<std::string> splitCommas (const std::string& text);
/** \brief Splits on ',' (the CLI forms, e.g. -pose 0,0,0.1,0,0,0) and parses each as a double. */
bool parseDoubleList (const std::string& text, std::size_t count, std::vector<double>& values);

/** \brief One line of a -poses file: six numbers separated by spaces, tabs and/or commas; a
  * '#' starts a comment. Returns 1 with the pose, 0 for a blank or comment-only line, -1 with
  * a reason in error for a malformed line. */
int parsePoseLine (const std::string& line, Pose& pose, std::string& error);

/** \brief The -poses name of standard input, as Unix filters spell it. */
inline constexpr const char* kStandardInput = "-";

/** \brief A whole -poses file; false with "NAME:LINE: reason" in error on the first malformed
  * line, or when it holds no pose at all. Lines end at '\n' alone. The one reader of the
  * format: pcd_collision's and, through Python's read_poses, the Dask command line's. */
bool parsePoses (std::istream& in, const std::string& name, std::vector<Pose>& poses,
                 std::string& error);
} // namespace pcd_collision
