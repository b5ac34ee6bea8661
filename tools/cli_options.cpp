// SPDX-License-Identifier: BSD-3-Clause
#include "cli_options.h"

#include <pcl_probcollision/detail/input_checks.h>
#include <pcl_probcollision/detail/parallel.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

namespace pcd_collision
{
namespace
{
std::string
lower (std::string s)
{
  std::transform (s.begin (), s.end (), s.begin (),
                  [] (unsigned char c) { return static_cast<char> (std::tolower (c)); });
  return s;
}

bool
endsWith (const std::string& s, const std::string& suffix)
{
  return s.size () >= suffix.size () && s.compare (s.size () - suffix.size (), suffix.size (), suffix) == 0;
}

std::string
fmt (double v)
{
  std::ostringstream os;
  os << v;
  return os.str ();
}

// Flags that take one value, and flags that take none.
const std::set<std::string> kValueFlags = {
  "-pose", "-poses", "-sigma", "-sigma_a", "-sigma_b", "-sensor", "-sensor_a", "-sensor_b", "-k", "-thresholds", "-seed",
  "-nmax", "-sigma_max", "-epsilon", "-split", "-mesh_density", "-o", "-threads", "-noise_resolution",
  "-noise_resolution_gate", "-noise_stop", "-max_leaf_fits", "-max_surface_pairs", "-orientation", "-orientation_a", "-orientation_b"};
const std::set<std::string> kSwitchFlags = {"-deterministic", "-stochastic", "-exhaustive", "-defer_kernel_fits", "-json",
                                            "-measured", "-surface", "-surface_pooled", "-surface_ladder", "-surface_calibrated", "-distance", "-ignore_normals",
                                            "-closed", "-closed_a", "-closed_b", "-v"};

ParseResult
usage (const std::string& message)
{
  ParseResult r;
  r.kind = ParseResult::Kind::Error;
  r.error = message;
  return r;
}
} // namespace

bool
parseDouble (const std::string& text, double& value)
{
  if (text.empty () || std::isspace (static_cast<unsigned char> (text[0])))
    return false;
  // Decimal numbers only, as the Dask command line reads them: strtod would also take hex
  // floats (0x1p3); "inf" and "nan" are refused below anyway.
  if (text.find_first_not_of ("0123456789+-.eE") != std::string::npos)
    return false;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod (text.c_str (), &end);
  if (end != text.c_str () + text.size ())
    return false;
  if (!std::isfinite (v))
    return false;
  value = v;
  return true;
}

bool
parseInt (const std::string& text, int& value)
{
  if (text.empty () || std::isspace (static_cast<unsigned char> (text[0])))
    return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll (text.c_str (), &end, 10);
  if (end != text.c_str () + text.size () || errno == ERANGE)
    return false;
  if (v < std::numeric_limits<int>::min () || v > std::numeric_limits<int>::max ())
    return false;
  value = static_cast<int> (v);
  return true;
}

bool
parseUint64 (const std::string& text, std::uint64_t& value)
{
  if (text.empty () || !std::isdigit (static_cast<unsigned char> (text[0])))
    return false;  // also rejects "-1", which strtoull would wrap around
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull (text.c_str (), &end, 10);
  if (end != text.c_str () + text.size () || errno == ERANGE)
    return false;
  value = static_cast<std::uint64_t> (v);
  return true;
}

std::vector<std::string>
splitCommas (const std::string& text)
{
  std::vector<std::string> items (1);
  for (const char c : text)
    if (c == ',')
      items.emplace_back ();
    else
      items.back ().push_back (c);
  return items;
}

bool
parseDoubleList (const std::string& text, std::size_t count, std::vector<double>& values)
{
  values.clear ();
  for (const std::string& item : splitCommas (text))
  {
    double v = 0.0;
    if (!parseDouble (item, v))
      return false;
    values.push_back (v);
  }
  return values.size () == count;
}

InputKind
inputKindOf (const std::string& path)
{
  const std::string l = lower (path);
  if (endsWith (l, ".pcd"))
    return InputKind::Cloud;
  for (const char* ext : {".ply", ".obj", ".stl", ".vtk"})
    if (endsWith (l, ext))
      return InputKind::Mesh;
  return InputKind::Unsupported;
}

namespace
{
/** \brief A word for a number that is not finite (nan, inf, infinity, any case, signed or not) or
  * a decimal beyond a double's range (1e999): "not a finite number" rather than "not a number". */
bool
nonFiniteNumber (const std::string& text)
{
  const std::string word = lower (text.empty () || (text[0] != '+' && text[0] != '-') ? text : text.substr (1));
  if (word == "nan" || word == "inf" || word == "infinity")
    return true;
  if (text.empty () || text.find_first_not_of ("0123456789+-.eE") != std::string::npos)
    return false;
  char* end = nullptr;
  const double v = std::strtod (text.c_str (), &end);
  return end == text.c_str () + text.size () && !std::isfinite (v);
}

/** \brief "is not an integer", or "is out of range" for a whole number beyond int's
  * (99999999999999999999 is an integer). */
std::string
notAnInt (const std::string& text)
{
  const std::size_t first = !text.empty () && (text[0] == '+' || text[0] == '-') ? 1 : 0;
  const bool whole = text.size () > first && text.find_first_not_of ("0123456789", first) == std::string::npos;
  return whole ? "is out of range (at most " + std::to_string (std::numeric_limits<int>::max ()) + ")"
               : "is not an integer";
}

/** \brief "is not a number", or "is not a finite number" for a non-finite one. */
std::string
notANumber (const std::string& text)
{
  return nonFiniteNumber (text) ? "is not a finite number" : "is not a number";
}

} // namespace

std::string
poseValueError (const Pose& pose)
{
  static const char* const kNames[6] = {"tx", "ty", "tz", "roll", "pitch", "yaw"};
  for (std::size_t i = 0; i < 6; ++i)
    if (!std::isfinite (pose[i]))
      return std::string (kNames[i]) + " is not a finite number";
  // The bound collide() enforces, refused where the pose is read. Finite angles always give a
  // rotation.
  for (std::size_t i = 0; i < 3; ++i)
    if (!(std::abs (pose[i]) <= pcl_probcollision::detail::kMaxCoordinate))
      return "translation beyond the supported range of +-1e15";
  return std::string ();
}

Eigen::Isometry3d
poseTransform (const Pose& p)
{
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.linear () = (Eigen::AngleAxisd (p[5], Eigen::Vector3d::UnitZ ()) * Eigen::AngleAxisd (p[4], Eigen::Vector3d::UnitY ()) *
                 Eigen::AngleAxisd (p[3], Eigen::Vector3d::UnitX ()))
                    .toRotationMatrix ();
  T.translation () = Eigen::Vector3d (p[0], p[1], p[2]);
  return T;
}

int
parsePoseLine (const std::string& line, Pose& pose, std::string& error)
{
  const std::string body = line.substr (0, line.find ('#'));
  // Tokens are separated by blanks and/or one comma; an empty field (two commas in a row, a
  // leading or a trailing comma) is an error, not a silently skipped number.
  std::vector<std::string> tokens;
  std::string current;
  int commas = 0;  // commas since the last token
  for (const char c : body)
  {
    if (c == ',' || std::isspace (static_cast<unsigned char> (c)))
    {
      if (!current.empty ())
      {
        tokens.push_back (current);
        current.clear ();
        commas = 0;
      }
      if (c == ',' && (++commas > 1 || tokens.empty ()))
      {
        error = "empty field between commas";
        return -1;
      }
    }
    else
      current.push_back (c);
  }
  if (!current.empty ())
    tokens.push_back (current);
  else if (commas > 0)
  {
    error = "trailing comma";
    return -1;
  }
  if (tokens.empty ())
    return 0;
  if (tokens.size () != 6)
  {
    error = "expected 6 numbers (tx ty tz roll pitch yaw), got " + std::to_string (tokens.size ());
    return -1;
  }
  for (std::size_t i = 0; i < 6; ++i)
  {
    if (!parseDouble (tokens[i], pose[i]))
    {
      error = "'" + tokens[i] + "' " + notANumber (tokens[i]);
      return -1;
    }
  }
  error = poseValueError (pose);
  return error.empty () ? 1 : -1;
}

bool
parsePoses (std::istream& in, const std::string& name, std::vector<Pose>& poses, std::string& error)
{
  poses.clear ();
  std::string line;
  std::size_t number = 0;
  while (std::getline (in, line))
  {
    ++number;
    // A UTF-8 byte-order mark, as some editors write at a file's start: not a value, and
    // invisible in a message ("'0' is not a number" with the mark in front).
    if (number == 1 && line.compare (0, 3, "\xEF\xBB\xBF") == 0)
      line.erase (0, 3);
    Pose pose{};
    std::string why;
    const int r = parsePoseLine (line, pose, why);
    if (r < 0)
    {
      error = name + ":" + std::to_string (number) + ": " + why;
      return false;
    }
    if (r > 0)
      poses.push_back (pose);
  }
  if (in.bad ())
  {
    error = name + ": read error";
    return false;
  }
  if (poses.empty ())
  {
    error = name + ": no pose in the file";
    return false;
  }
  return true;
}

pcl_probcollision::CollisionRequest
requestFor (const Options& o)
{
  pcl_probcollision::CollisionRequest r;
  r.free_below = o.free_below;
  r.collision_above = o.collision_above;
  r.exhaustive = o.exhaustive || o.output.has_value ();
  r.max_leaf_fits = o.max_leaf_fits;
  r.max_surface_pairs = o.max_surface_pairs;
  r.defer_kernel_fits = o.defer_kernel_fits;
  r.surface = o.surface;
  r.surface_pooled = o.surface_pooled;
  r.surface_ladder = o.surface_ladder;
  r.surface_calibrated = o.surface_calibrated;
  r.distance = o.distance;
  r.per_point = o.output.has_value ();
  r.enable_timings = true;
  r.traversal = o.stochastic ? pcl_probcollision::TraversalMode::Stochastic
                             : pcl_probcollision::TraversalMode::ExpectedWeight;
  r.seed = o.seed;
  return r;
}

pcl_probcollision::CloudModelParams
modelParamsFor (const Options& o, bool input)
{
  pcl_probcollision::CloudModelParams m;
  m.closed_objects = input ? o.closed_a : o.closed_b;
  m.orientation = input ? o.orientation_a : o.orientation_b;
  m.k = o.k;
  m.noise_resolution = o.noise_resolution;
  m.noise_resolution_gate = o.noise_resolution_gate;
  m.surface_projection = !o.measured;
  m.surface = o.surface;
  m.hierarchy.split_style = o.split == "octree" ? pcl_probcollision::BVHParams::SplitStyle::Octree
                                                : pcl_probcollision::BVHParams::SplitStyle::Pca;
  m.hierarchy.n_max = o.n_max;
  m.hierarchy.noise_stop = o.noise_stop;
  m.hierarchy.n_min = pcl_probcollision::BVHParams::nMinFor (o.n_max);  // the library's rule
  m.hierarchy.sigma_max = o.sigma_max;
  m.hierarchy.epsilon = o.epsilon;
  m.threads = o.threads;
  return m;
}

ParseResult
parseCommandLine (int argc, const char* const* argv)
{
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i)
    args.emplace_back (argv[i] ? argv[i] : "");
  return parseCommandLine (args);
}

ParseResult
parseCommandLine (const std::vector<std::string>& args)
{
  for (const std::string& a : args)
  {
    if (a == "--")
      break;
    const bool help = a == "-h" || a == "--help" || a == "-help";
    if (help || a == "-version" || a == "--version")
    {
      ParseResult r;
      r.kind = help ? ParseResult::Kind::Help : ParseResult::Kind::Version;
      return r;
    }
  }

  Options o;
  std::vector<std::string> positional;
  std::set<std::string> seen;
  std::optional<double> sigma, sigma_a, sigma_b;
  std::optional<std::string> sensor, sensor_a, sensor_b;
  std::optional<pcl_probcollision::NormalOrientation> orientation, orientation_a, orientation_b;
  bool deterministic = false;
  bool only_positional = false;

  for (std::size_t i = 0; i < args.size (); ++i)
  {
    const std::string& arg = args[i];
    if (only_positional || arg.empty () || arg[0] != '-' || arg == "-")
    {
      positional.push_back (arg);
      continue;
    }
    if (arg == "--")
    {
      only_positional = true;
      continue;
    }
    // -name=value is -name value (split at the first '=', so a value may hold more).
    const std::size_t eq = arg.find ('=');
    const std::string a = arg.substr (0, eq);
    const bool inline_value = eq != std::string::npos;
    const bool takes_value = kValueFlags.count (a) > 0;
    if (!takes_value && kSwitchFlags.count (a) == 0)
      return usage ("unknown option '" + a + "' (see -h)");
    if (!seen.insert (a).second)
      return usage ("option " + a + " given more than once");
    if (!takes_value && inline_value)
      return usage ("option " + a + " takes no value");
    if (!takes_value)
    {
      if (a == "-deterministic")
        deterministic = true;
      else if (a == "-stochastic")
        o.stochastic = true;
      else if (a == "-measured")
        o.measured = true;
      else if (a == "-exhaustive")
        o.exhaustive = true;
      else if (a == "-defer_kernel_fits")
        o.defer_kernel_fits = true;
      else if (a == "-surface")
        o.surface = true;
      else if (a == "-surface_pooled")
        o.surface = o.surface_pooled = true;
      else if (a == "-surface_ladder")
        o.surface = o.surface_ladder = true;
      else if (a == "-surface_calibrated")
        o.surface_calibrated = true;
      else if (a == "-distance")
        o.distance = true;
      else if (a == "-ignore_normals")
        o.ignore_normals = true;
      else if (a == "-closed")
        o.closed_a = o.closed_b = true;
      else if (a == "-closed_a")
        o.closed_a = true;
      else if (a == "-closed_b")
        o.closed_b = true;
      else if (a == "-json")
        o.json = true;
      else if (a == "-v")
        o.verbose = true;
      continue;
    }
    if (!inline_value && i + 1 >= args.size ())
      return usage ("option " + a + " needs a value (see -h)");
    const std::string v = inline_value ? arg.substr (eq + 1) : args[++i];
    const std::string bad = "option " + a + ": '" + v + "' ";

    // A noise deviation: >= 0 and within the coordinate range (SensorNoiseModel::isotropic's rule).
    auto nonNegative = [&] (std::optional<double>& out) -> std::optional<ParseResult> {
      double d = 0.0;
      if (!parseDouble (v, d))
        return usage (bad + notANumber (v));
      if (d < 0.0)
        return usage (bad + "must be >= 0");
      if (!(d <= pcl_probcollision::detail::kMaxCoordinate))
        return usage (bad + "must be at most 1e15, the supported coordinate range");
      out = d;
      return std::nullopt;
    };

    if (a == "-pose")
    {
      std::vector<double> vals;
      if (!parseDoubleList (v, 6, vals))
      {
        // Six values, one of them no number: name it (-pose 0,0,0,0,0,nan has six numbers' shape).
        const std::vector<std::string> items = splitCommas (v);
        double unused = 0.0;
        for (std::size_t i = 0; items.size () == 6 && i < 6; ++i)
          if (!parseDouble (items[i], unused))
            return usage (bad + "value " + std::to_string (i + 1) + " '" + items[i] + "' " + notANumber (items[i]) +
                          " (tx,ty,tz,roll,pitch,yaw)");
        return usage (bad + "must be six comma-separated numbers tx,ty,tz,roll,pitch,yaw");
      }
      Pose p{};
      std::copy (vals.begin (), vals.end (), p.begin ());
      if (const std::string why = poseValueError (p); !why.empty ())  // finite: parseDoubleList
        return usage (bad + "has a " + why);
      o.pose = p;
    }
    else if (a == "-poses")
    {
      if (v.empty ())
        return usage ("option -poses needs a file name");
      o.poses_file = v;
    }
    else if (a == "-threads")
    {
      if (!parseInt (v, o.threads))
        return usage (bad + notAnInt (v));
      if (const std::string why = pcl_probcollision::detail::threadsRangeError (o.threads); !why.empty ())
        return usage (bad + why);
    }
    else if (a == "-sigma")
    {
      if (auto e = nonNegative (sigma))
        return *e;
    }
    else if (a == "-sigma_a")
    {
      if (auto e = nonNegative (sigma_a))
        return *e;
    }
    else if (a == "-sigma_b")
    {
      if (auto e = nonNegative (sigma_b))
        return *e;
    }
    else if (a == "-sensor" || a == "-sensor_a" || a == "-sensor_b")
    {
      if (v != "none" && v != "isotropic" && v != "kinect" && v != "stereo" && v != "lidar")
        return usage (bad + "must be one of isotropic, kinect, stereo, lidar, none");
      (a == "-sensor" ? sensor : a == "-sensor_a" ? sensor_a : sensor_b) = v;
    }
    else if (a == "-k")
    {
      if (!parseInt (v, o.k))
        return usage (bad + notAnInt (v));
      if (o.k < 1)
        return usage (bad + "must be >= 1");
    }
    else if (a == "-thresholds")
    {
      std::vector<double> vals;
      if (!parseDoubleList (v, 2, vals))
        return usage (bad + "must be two comma-separated numbers LOW,HIGH");
      // The library's rule and words (CollisionRequest::thresholdsError).
      pcl_probcollision::CollisionRequest thresholds;
      thresholds.free_below = vals[0];
      thresholds.collision_above = vals[1];
      if (const std::string why = thresholds.thresholdsError (); !why.empty ())
        return usage (bad + "(LOW,HIGH: free_below,collision_above) " + why);
      o.free_below = vals[0];
      o.collision_above = vals[1];
    }
    else if (a == "-seed")
    {
      if (!parseUint64 (v, o.seed))
        return usage (bad + "is not a non-negative 64-bit integer");
    }
    else if (a == "-nmax")
    {
      if (!parseInt (v, o.n_max))
        return usage (bad + notAnInt (v));
      if (o.n_max < 1)
        return usage (bad + "must be >= 1");
    }
    else if (a == "-sigma_max")
    {
      if (!parseDouble (v, o.sigma_max))
        return usage (bad + notANumber (v));
      if (o.sigma_max < 0.0)
        return usage (bad + "must be >= 0");
    }
    else if (a == "-epsilon")
    {
      if (!parseDouble (v, o.epsilon))
        return usage (bad + notANumber (v));
      if (!(o.epsilon >= 0.0 && o.epsilon < 0.5))
        return usage (bad + "must be in [0, 0.5)");
    }
    else if (a == "-noise_resolution")
    {
      // "auto", the default the help names: the library's choice (unset: 2 without -surface, 0 with it).
      double radius = 0.0;
      if (lower (v) == "auto")
        o.noise_resolution.reset ();
      else if (!parseDouble (v, radius))
        return usage (bad + notANumber (v) + " (or auto)");
      else if (!(radius >= 0.0) || !std::isfinite (radius))
        return usage (bad + "must be a finite number >= 0 (noise standard deviations; 0: no merging) or auto");
      else
        o.noise_resolution = radius;
    }
    else if (a == "-noise_resolution_gate")
    {
      if (!pcl_probcollision::CloudModelParams::resolutionGateFromName (v, o.noise_resolution_gate))
        return usage (bad + "must be everywhere, spacing or cloud");
    }
    else if (a == "-noise_stop")
    {
      if (!parseDouble (v, o.noise_stop))
        return usage (bad + notANumber (v));
      if (!(o.noise_stop >= 0.0) || !std::isfinite (o.noise_stop))
        return usage (bad + "must be a finite number >= 0 (noise standard deviations; 0: off)");
    }
    else if (a == "-max_leaf_fits" || a == "-max_surface_pairs")
    {
      std::uint64_t n = 0;
      if (!parseUint64 (v, n))
        return usage (bad + "is not a non-negative integer (0: no cap)");
      (a == "-max_leaf_fits" ? o.max_leaf_fits : o.max_surface_pairs) = static_cast<std::size_t> (n);
    }
    else if (a == "-orientation" || a == "-orientation_a" || a == "-orientation_b")
    {
      auto& slot = a == "-orientation" ? orientation : a == "-orientation_a" ? orientation_a : orientation_b;
      std::string names;
      for (const auto mode : pcl_probcollision::kNormalOrientations)
      {
        if (v == pcl_probcollision::orientationName (mode))
          slot = mode;
        names += (names.empty () ? "" : ", ") + std::string (pcl_probcollision::orientationName (mode));
      }
      if (!slot)
        return usage (bad + "must be one of " + names);
    }
    else if (a == "-split")
    {
      if (v != "pca" && v != "octree")
        return usage (bad + "must be pca or octree");
      o.split = v;
    }
    else if (a == "-mesh_density")
    {
      double d = 0.0;
      if (!parseDouble (v, d))
        return usage (bad + notANumber (v));
      if (!(d > 0.0))
        return usage (bad + "must be > 0 (a sample spacing in data units)");
      o.mesh_spacing = d;
    }
    else if (a == "-o")
    {
      if (lower (v).size () <= 4 || !endsWith (lower (v), ".pcd"))
        return usage (bad + "must name a .pcd file");
      o.output = v;
    }
  }

  if (positional.size () != 2)
    return usage ("expected two input files <a> <b>, got " + std::to_string (positional.size ()) +
                  " (see -h)");
  for (const std::string& p : positional)
    if (inputKindOf (p) == InputKind::Unsupported)
      return usage ("input '" + p + "': unsupported file type (expected .pcd, .ply, .obj, .stl or .vtk)");
  o.input_a = positional[0];
  o.input_b = positional[1];

  if (o.pose && o.poses_file)
    return usage ("options -pose and -poses cannot be combined");
  if (o.output && o.poses_file)
    return usage ("option -o writes one query's result and cannot be combined with -poses");
  if (deterministic && o.stochastic)
    return usage ("options -deterministic and -stochastic cannot be combined");
  if (o.surface_pooled && o.surface_ladder)
    return usage ("options -surface_pooled and -surface_ladder cannot be combined");
  if ((o.closed_a || o.closed_b) && !o.surface)
    return usage ("options -closed, -closed_a and -closed_b need -surface (or -surface_pooled, -surface_ladder): they "
                  "say where the surface layer's inside is");
  if (o.max_surface_pairs > 0 && !o.surface)
    return usage ("option -max_surface_pairs needs -surface (or -surface_pooled, -surface_ladder): it caps the "
                  "surface layer's work (-max_leaf_fits caps the separators')");
  if (o.ignore_normals && !o.surface)
    return usage ("option -ignore_normals needs -surface (or -surface_pooled, -surface_ladder): the normals a file "
                  "stores orient the surface layer's surfaces only");
  if (o.surface_calibrated && !o.surface)
    return usage ("option -surface_calibrated needs -surface (or -surface_pooled, -surface_ladder): it maps the "
                  "surface layer's probability");
  // Without merging the gate has nothing to let through: accepted, it changed nothing (found by
  // a probe); -noise_resolution 0 is "never merge" too.
  if (seen.count ("-noise_resolution_gate") && !(modelParamsFor (o, true).noiseResolution () > 0.0))
    return usage ("option -noise_resolution_gate needs -noise_resolution C > 0: it says where merging applies, and "
                  "without it nothing is merged (with 0) or only a depth scan's dense samples (by default with -surface)");
  if ((orientation || orientation_a || orientation_b) && !o.surface)
    return usage ("options -orientation, -orientation_a and -orientation_b need -surface (or -surface_pooled, "
                  "-surface_ladder): they orient the surface layer's surfaces");
  // -orientation sets both inputs, -orientation_a / -orientation_b one each whatever the order.
  o.orientation_a = orientation_a.value_or (orientation.value_or (o.orientation_a));
  o.orientation_b = orientation_b.value_or (orientation.value_or (o.orientation_b));
  // -sensor sets both inputs, -sensor_a / -sensor_b one each whatever the order; likewise the
  // sigmas, which only an isotropic input uses.
  o.sensor_a = sensor_a.value_or (sensor.value_or (Defaults::sensor));
  o.sensor_b = sensor_b.value_or (sensor.value_or (Defaults::sensor));
  // Whether an input is a mesh is known only from its contents (a .ply without faces is a cloud):
  // inputKindsUsageError judges these.
  o.noise_option_a = sigma_a ? "-sigma_a" : sensor_a ? "-sensor_a" : "";
  o.noise_option_b = sigma_b ? "-sigma_b" : sensor_b ? "-sensor_b" : "";
  const std::string iso = "isotropic";
  if (sigma && (o.sensor_a != iso || o.sensor_b != iso))
    return usage ("option -sigma needs the isotropic model for both inputs (got " + o.sensor_a + " for <a>, " +
                  o.sensor_b + " for <b>); use -sigma_a or -sigma_b for one input");
  if (sigma_a && o.sensor_a != iso)
    return usage ("option -sigma_a needs the isotropic model for <a> (got " + o.sensor_a + ")");
  if (sigma_b && o.sensor_b != iso)
    return usage ("option -sigma_b needs the isotropic model for <b> (got " + o.sensor_b + ")");
  if (sigma)
    o.sigma_a = o.sigma_b = *sigma;
  if (sigma_a)
    o.sigma_a = *sigma_a;
  if (sigma_b)
    o.sigma_b = *sigma_b;

  ParseResult r;
  r.kind = ParseResult::Kind::Run;
  r.options = o;
  return r;
}

std::string
inputKindsUsageError (const Options& o, bool mesh_a, bool mesh_b)
{
  if (o.mesh_spacing && !mesh_a && !mesh_b)
    return "option -mesh_density: neither input is a mesh (both are point clouds; a .ply without faces is one), and "
           "it sets a mesh's sample spacing only: it would change nothing";
  // A mesh is sampled exactly, with a zero covariance: a noise model or sigma named for it alone
  // would be ignored (-sensor and -sigma, for both inputs, apply to the clouds among them).
  for (const auto& [input, path, option, mesh] : {std::tuple ("a", o.input_a, o.noise_option_a, mesh_a),
                                                  std::tuple ("b", o.input_b, o.noise_option_b, mesh_b)})
    if (mesh && !option.empty ())
      return "option " + option + ": <" + input + "> '" + path +
             "' is a mesh, sampled exactly with no sensor noise; the option applies to a cloud";
  return {};
}

std::string
helpText ()
{
  using D = Defaults;
  std::ostringstream h;
  h << "Probabilistic collision check between two noisy point clouds or meshes (pcl_probcollision).\n"
       "\n"
       "Syntax: pcd_collision <a> <b> [options]\n"
       "\n"
       "  <a>, <b>   a .pcd point cloud with x y z fields (any point type; organized clouds and NaN\n"
       "             points are fine), a .ply without faces (a point cloud too) or a triangle mesh\n"
       "             .ply .obj .stl .vtk. <a> is moved by the pose, <b> stays where it is. Both must\n"
       "             be in the same units.\n"
       "  An option's value is the next argument or follows '=': -k 20 or -k=20.\n"
       "\n"
       "Pose of <a> (p' = Rz(yaw) Ry(pitch) Rx(roll) p + t; data units and radians):\n"
       "  -pose tx,ty,tz,roll,pitch,yaw   = 0,0,0,0,0,0\n"
       "  -poses FILE     batch mode: one pose per line, six numbers separated by spaces or commas,\n"
       "                  '#' comments and blank lines allowed; hierarchies are built once;\n"
       "                  FILE '-' reads the poses from standard input, to its end\n"
       "  -threads N      = "
    << D::threads
    << "       threads building the models and answering -poses (0: one per hardware\n"
       "                  thread); answers stream in pose order and are the same whatever N\n"
       "                  (timings aside)\n"
       "\n"
       "Uncertainty (mesh inputs are exact: zero covariance, no noise):\n"
       "  -sensor isotropic|kinect|stereo|lidar|none   = "
    << D::sensor
    << "\n"
       "                  sensor noise added to both clouds; depth models use each PCD's VIEWPOINT\n"
       "  -sensor_a M     = -sensor   sensor noise model of <a> only (same names)\n"
       "  -sensor_b M     = -sensor   sensor noise model of <b> only\n"
       "  -sigma S        = "
    << fmt (D::sigma)
    << "   isotropic noise sigma of both clouds, data units (isotropic model only)\n"
       "  -sigma_a S      = -sigma   isotropic sigma of <a> only\n"
       "  -sigma_b S      = -sigma   isotropic sigma of <b> only\n"
       "  -k K            = "
    << D::k
    << "      neighbours of the covariance estimation\n"
       "  -noise_resolution C   = auto   merge samples closer than C noise sigmas into one,\n"
       "                  where the gate lets them (0: never; auto: "
    << fmt (pcl_probcollision::CloudModelParams::kDefaultNoiseResolution)
    << " without -surface, 0 with it)\n"
       "  -noise_resolution_gate everywhere|spacing|cloud   = "
    << pcl_probcollision::CloudModelParams::resolutionGateName (D::noise_resolution_gate)
    << "\n                  where -noise_resolution merges: every sample; only samples spaced\n"
       "                  closer than their noise; or a whole cloud sampled finer than its noise\n"
       "                  (its median noise sigma at least its area-weighted spacing), else the\n"
       "                  samples spaced closer than their noise where most are twice as dense\n"
       "                  as it (a depth scan's near objects before a sparse far wall), else none;\n"
       "                  needs a radius C > 0 (with -surface: -noise_resolution C)\n"
       "  -noise_stop C   = "
    << fmt (D::noise_stop)
    << "      do not split a hierarchy node of at most "
    << D::n_noise_max
    << " points whose extent is within\n"
       "                  C noise sigmas (0: off; 2 is the evaluated choice: a little faster at 4 %)\n"
       "\n"
       "Query:\n"
       "  -thresholds LOW,HIGH   = "
    << fmt (D::free_below) << "," << fmt (D::collision_above)
    << "   P < LOW is free, P > HIGH is collision, else contact\n"
       "  -measured       points at their measured positions with their full spread (the\n"
       "                  paper's model); default: projected onto their local surface\n"
       "  -deterministic  (default) expected-weight traversal\n"
       "  -stochastic     stochastic traversal, seeded by -seed\n"
       "  -seed N         = "
    << D::seed
    << "       seed of the stochastic traversal\n"
       "  -exhaustive     visit every reachable leaf pair (no early stop; P is then exact, not a bound)\n"
       "  -defer_kernel_fits  fit every reached leaf pair's plane before any kernel rung: the same\n"
       "                  verdicts, median query 1.3-1.9 times faster; a collision's P (a lower\n"
       "                  bound) may be lower\n"
       "  -max_leaf_fits N   = "
    << D::max_leaf_fits
    << "   at most N leaf pairs tested a query, nearest first (0: no cap); a capped\n"
       "                  query prints P >= and \"budget exhausted\": P is a lower bound\n"
       "  -max_surface_pairs N   = "
    << D::max_surface_pairs
    << "   with -surface: the surface layer tests at most about N leaf pairs a query\n"
       "                  (0: no cap); capped, P is a lower bound (\"budget exhausted\"), and the\n"
       "                  ladder keeps the separators' contact; bounds its worst case\n"
       "  -surface        the surface layer (experimental, issue #16): each cloud's points against the\n"
       "                  other's oriented surface; prints the signed distance d +- std\n"
       "  -surface_pooled -surface, its P pooled with the separators' (their mean; experimental)\n"
       "  -surface_ladder -surface only where the separators leave it open: their answer where they\n"
       "                  reach nothing or read collision, else the surface layer's (pooled with\n"
       "                  theirs where they read free); experimental\n"
       "  -surface_calibrated  with -surface: P in [0.1, 0.9] through the calibration map fitted on\n"
       "                  the evaluation's procedural scenes (rankings and verdicts at 0.1,0.9\n"
       "                  unchanged; off by default: it does not carry over to other scenes)\n"
       "  -distance       a distance at any separation: where the query reaches no leaf pair (the\n"
       "                  objects beyond reach), d +- std is the distance between the two clouds'\n"
       "                  nearest samples, marked (nearest samples); near contact only -surface\n"
       "                  gives a distance\n"
       "  -ignore_normals with -surface: orient clouds as if their files had no normal_x normal_y\n"
       "                  normal_z (by default a cloud's stored normals are its outward ones)\n"
       "  -closed         with -surface: both inputs sample closed solids (not an open sheet, one\n"
       "                  scan's view or a room seen from within): a cloud oriented by propagation\n"
       "                  is checked by the winding number and, where it checks out, has an inside\n"
       "                  (by default such a cloud is two-sided); -closed_a, -closed_b: one input\n"
       "  -orientation auto|point_normals|viewpoint|propagate   = "
    << pcl_probcollision::orientationName (pcl_probcollision::CloudModelParams ().orientation)
    << "\n"
       "                  with -surface: how both surfaces are oriented (auto: a mesh's faces or a\n"
       "                  file's normals, else a VIEWPOINT that sees the cloud as one scan does, else\n"
       "                  propagation); -orientation_a M, -orientation_b M: one input\n"
       "  -nmax N         = "
    << D::n_max
    << "      hierarchy: a node with more points is split (n_min = min(" << D::n_min
    << ", nmax))\n"
       "  -sigma_max S    = "
    << fmt (D::sigma_max)
    << "    hierarchy: a node with more variation is split\n"
       "  -epsilon E      = "
    << fmt (D::epsilon)
    << "    hierarchy: sibling overlap, fraction of the parent's extent, [0, 0.5)\n"
       "  -split pca|octree   = "
    << D::split
    << "\n"
       "  -mesh_density S = median nearest-neighbour spacing of the other cloud\n"
       "                  (both meshes: 1/100 of the smaller bounding-box diagonal, or wider\n"
       "                  for 500000 samples); mesh sample spacing,\n"
       "                  data units: samples uniform by area (fixed seed) plus every vertex;\n"
       "                  needs a mesh among the inputs\n"
       "\n"
       "Output:\n"
       "  -o FILE.pcd     write both clouds after the pose (a then b) with fields intensity (per-point\n"
       "                  collision probability, NaN = not evaluated), rgb (free green, contact yellow,\n"
       "                  collision red, not evaluated grey) and label (0 = a, 1 = b); implies\n"
       "                  -exhaustive; never overwrites an input; not with -poses\n"
       "  -json           one JSON object per query on stdout (one line each); human text to stderr\n"
       "  -v              also show PCL's and VTK's own messages\n"
       "  -h, -help, --help  this help\n"
       "  -version, --version  the tool's, the library's and PCL's versions\n"
       "\n"
       "Exit status: 0 the query ran (whatever the verdict), 1 runtime failure (unreadable or\n"
       "malformed file, including a malformed -poses line; no finite point; write failure; query\n"
       "failed), 2 usage error (unknown option, malformed or out-of-range value, wrong number of\n"
       "inputs, unsupported file type, -o naming an input).\n";
  return h.str ();
}
} // namespace pcd_collision
