// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer: arbitrary bytes -> pcd_collision's argument parser (split into argv on NUL bytes)
// and its -poses file parser (the same bytes as a file). Any crash or sanitizer report aborts, and
// so does an accepted value outside its documented range.
#include "cli_options.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#define FUZZ_REQUIRE(cond)                                                              \
  do                                                                                    \
  {                                                                                     \
    if (!(cond))                                                                        \
    {                                                                                   \
      std::fprintf (stderr, "fuzz_cli_options: contract broken: %s (line %d)\n", #cond, __LINE__); \
      std::abort ();                                                                    \
    }                                                                                   \
  } while (0)

using namespace pcd_collision;

extern "C" int
LLVMFuzzerTestOneInput (const std::uint8_t* data, std::size_t size)
{
  const std::string bytes (reinterpret_cast<const char*> (data), size);

  // Command line: NUL-separated arguments.
  std::vector<std::string> args;
  std::string::size_type start = 0;
  while (start <= bytes.size () && args.size () < 64)
  {
    const auto end = bytes.find ('\0', start);
    args.push_back (bytes.substr (start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  const ParseResult parsed = parseCommandLine (args);
  if (parsed.kind == ParseResult::Kind::Error)
    FUZZ_REQUIRE (!parsed.error.empty ());
  if (parsed.kind == ParseResult::Kind::Run)
  {
    const Options& o = parsed.options;
    FUZZ_REQUIRE (!o.input_a.empty () && !o.input_b.empty ());
    FUZZ_REQUIRE (std::isfinite (o.sigma_a) && o.sigma_a >= 0.0);  // 0: no sensor noise
    FUZZ_REQUIRE (std::isfinite (o.sigma_b) && o.sigma_b >= 0.0);
    FUZZ_REQUIRE (o.k >= 1);
    FUZZ_REQUIRE (o.free_below > 0.0 && o.free_below <= 0.5);
    FUZZ_REQUIRE (o.collision_above >= 0.5 && o.collision_above < 1.0);
    FUZZ_REQUIRE (o.n_max >= 1);
    FUZZ_REQUIRE (std::isfinite (o.sigma_max) && o.sigma_max >= 0.0);
    FUZZ_REQUIRE (o.epsilon >= 0.0 && o.epsilon < 0.5);
    FUZZ_REQUIRE (!(o.pose && o.poses_file));
    if (o.pose)
      for (const double v : *o.pose)
        FUZZ_REQUIRE (std::isfinite (v));
    if (o.mesh_spacing)
      FUZZ_REQUIRE (std::isfinite (*o.mesh_spacing) && *o.mesh_spacing > 0.0);
  }

  // The same bytes as a -poses file.
  std::istringstream file (bytes);
  std::vector<Pose> poses;
  std::string error;
  if (parsePoses (file, "fuzz.txt", poses, error))
  {
    FUZZ_REQUIRE (!poses.empty ());
    for (const Pose& p : poses)
      for (const double v : p)
        FUZZ_REQUIRE (std::isfinite (v));
  }
  else
    FUZZ_REQUIRE (error.rfind ("fuzz.txt:", 0) == 0 || error.find ("fuzz.txt") != std::string::npos);

  // Single numbers, as the flags parse them.
  double d = 0.0;
  if (parseDouble (bytes, d))
    FUZZ_REQUIRE (std::isfinite (d));
  return 0;
}
