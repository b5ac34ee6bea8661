// SPDX-License-Identifier: BSD-3-Clause
// Writes W2 queries (evaluation/primitives.h) as PCD files, so that one of them can be run alone
// through pcd_collision: the clouds the evaluation samples for a seed and noise scale, the placed
// object as the robot (moved by the pose) and the fixed one as the environment, as
// evaluate_collision passes them to our method. W1's cells have their own --dump.
//
//   dump_primitive --out DIR [--seed N] [--scale S] [--quick] PREFIX
//
// Every query whose name ("<scenario>/<gap in sigma>s", e.g. sphere_box_dense/-4s) starts with
// PREFIX is written to DIR/<scenario>_<gap>_robot.pcd and _env.pcd; a line per query gives its
// point counts, exact signed distance and the pcd_collision command that answers it.
#include "primitives.h"

#include <cli_options.h>

#include <pcl/io/pcd_io.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

namespace
{
int
usage (const char* message)
{
  std::fprintf (stderr, "dump_primitive: %s\nusage: dump_primitive --out DIR [--seed N] [--scale S] [--quick] PREFIX\n",
                message);
  return 2;
}
} // namespace

int
main (int argc, char** argv)
{
  std::string out, prefix;
  unsigned long long seed = 1;
  double scale = 1.0;
  bool quick = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--out" && has_value)
      out = argv[++i];
    else if (a == "--seed" && has_value)
    {
      std::uint64_t v = 0;
      if (!pcd_collision::parseUint64 (argv[++i], v))
        return usage (("--seed '" + std::string (argv[i]) + "' is not a whole number").c_str ());
      seed = v;
    }
    else if (a == "--scale" && has_value)
    {
      if (!pcd_collision::parseDouble (argv[++i], scale) || !(scale > 0.0))
        return usage (("--scale '" + std::string (argv[i]) + "' is not a number above 0").c_str ());
    }
    else if (a == "--quick")
      quick = true;
    else if (!a.empty () && a[0] != '-' && prefix.empty ())
      prefix = a;
    else
      return usage (("unknown or incomplete argument '" + a + "'").c_str ());
  }
  if (out.empty () || prefix.empty ())
    return usage ("--out and PREFIX are required");
  try
  {
    std::filesystem::create_directories (out);
    int written = 0;
    for (const auto& q : pcl_probcollision_eval::makePrimitiveQueries (scale, seed, quick))
    {
      if (q.name.compare (0, prefix.size (), prefix) != 0)
        continue;
      std::string base = q.name;
      for (char& c : base)
        c = c == '/' ? '_' : c;
      const std::string robot = out + "/" + base + "_robot.pcd", env = out + "/" + base + "_env.pcd";
      if (pcl::io::savePCDFileBinary (robot, *q.b) != 0 || pcl::io::savePCDFileBinary (env, *q.a) != 0)
      {
        std::fprintf (stderr, "dump_primitive: cannot write '%s' or '%s'\n", robot.c_str (), env.c_str ());
        return 1;
      }
      std::printf ("%s: robot %zu points, env %zu points, exact distance %.9g m; pcd_collision %s %s -sigma %.9g\n",
                   q.name.c_str (), q.b->size (), q.a->size (), q.exact_distance, robot.c_str (), env.c_str (), q.sigma);
      ++written;
    }
    if (written == 0)
    {
      std::fprintf (stderr, "dump_primitive: no W2 query name starts with '%s' (names: <scenario>/<gap>s)\n",
                    prefix.c_str ());
      return 1;
    }
  }
  catch (const std::exception& e)
  {
    std::fprintf (stderr, "dump_primitive: %s\n", e.what ());
    return 1;
  }
  return 0;
}
