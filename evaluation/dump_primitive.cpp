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
#include "eval_options.h"
#include "primitives.h"

#include <pcl/io/pcd_io.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace
{
const char* const kUsage = "usage: dump_primitive --out DIR [--seed N] [--scale S] [--quick] PREFIX";

int
usage (const std::string& message)
{
  std::fprintf (stderr, "dump_primitive: %s\n%s\n", message.c_str (), kUsage);
  return 2;
}
} // namespace

int
main (int argc, char** argv)
{
  namespace opt = pcl_probcollision_eval::options;
  std::string out, prefix;
  unsigned long long seed = 1;
  double scale = 1.0;
  bool quick = false;
  // The values are read by the evaluation's option readers (eval_options.h), as evaluate_collision
  // reads its own; a refusal exits 2 naming the option and the value, --help prints the usage
  // and exits 0 (it was "unknown or incomplete argument '--help'", exit 2, before 2026-12-04).
  try
  {
    for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      const std::string name = "option " + a;
      auto value = [&] () -> std::string {
        if (i + 1 >= argc)
          throw std::invalid_argument (name + " needs a value");
        return argv[++i];
      };
      if (a == "--help" || a == "-h")
      {
        std::printf ("%s\n", kUsage);
        return 0;
      }
      if (a == "--out")
        out = value ();
      else if (a == "--seed")
        seed = opt::wholeNumber (name, value ());
      else if (a == "--scale")
        scale = opt::number (name, value (), 0.0, true);
      else if (a == "--quick")
        quick = true;
      else if (!a.empty () && a[0] != '-' && prefix.empty ())
        prefix = a;
      else
        throw std::invalid_argument ("unknown argument '" + a + "'");
    }
  }
  catch (const std::invalid_argument& e)
  {
    return usage (e.what ());
  }
  if (out.empty () || prefix.empty ())
    return usage ("--out and PREFIX are required");
  try
  {
    int written = 0;
    for (const auto& q : pcl_probcollision_eval::makePrimitiveQueries (scale, seed, quick))
    {
      if (q.name.compare (0, prefix.size (), prefix) != 0)
        continue;
      std::string base = q.name;
      for (char& c : base)
        c = c == '/' ? '_' : c;
      if (written == 0)
        std::filesystem::create_directories (out);  // only once a query matches
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
