// SPDX-License-Identifier: BSD-3-Clause
// pcd_collision through the built binary: the contract of docs/CLI.md and every bad input.

#include "test_files.h"
#include "mini_json.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/pcl_config.h>

#include <Eigen/Core>

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <pty.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using mini_json::Value;

namespace
{
const std::string kExe = PCD_COLLISION_EXE;
const std::string kGenerator = MAKE_DEMO_SCENE_EXE;
const fs::path kData = PROJECT_DATA_DIR;
const fs::path kGripper = kData / "gripper.obj";
const fs::path kScene = kData / "table_mug.pcd";
const fs::path kPoses = kData / "demo_poses.txt";
constexpr std::size_t kScenePoints = 10848;

std::string
quote (const std::string& s)
{
  std::string q = "'";
  for (const char c : s)
    q += (c == '\'') ? std::string ("'\\''") : std::string (1, c);
  return q + "'";
}

using test_files::lines;
using test_files::readFile;
using test_files::writeFile;

std::string
lowercase (std::string s)
{
  std::transform (s.begin (), s.end (), s.begin (), [] (unsigned char c) { return static_cast<char> (std::tolower (c)); });
  return s;
}

/** \brief Bytes and modification time of a file, to prove it was not touched. */
struct Snapshot
{
  std::string bytes;
  long long mtime_ns = 0;
  static Snapshot of (const fs::path& p)
  {
    Snapshot s;
    s.bytes = readFile (p);
    struct stat st;
    if (::stat (p.c_str (), &st) == 0)
      s.mtime_ns = static_cast<long long> (st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
    return s;
  }
  bool operator== (const Snapshot& o) const { return bytes == o.bytes && mtime_ns == o.mtime_ns; }
};

struct ToolRun
{
  int status = -1;  ///< exit status (a signal shows as 128 + n through the shell)
  std::string out, err;
};

class PcdCollisionTool : public ::testing::Test
{
protected:
  void SetUp () override
  {
    const auto* info = ::testing::UnitTest::GetInstance ()->current_test_info ();
    dir_ = fs::path (TEST_WORK_DIR) / info->name ();
    io_ = fs::path (TEST_WORK_DIR) / (std::string (info->name ()) + "_io");
    fs::remove_all (dir_);
    fs::remove_all (io_);
    fs::create_directories (dir_);
    fs::create_directories (io_);
  }

  /** \brief Runs the tool with args, its stdin /dev/null, or piped from `piped_stdin` (through
    * `cat`, so that it is a pipe, not a file). */
  ToolRun run (const std::vector<std::string>& args, const fs::path& piped_stdin = {}) const
  {
    std::string cmd = quote (kExe);
    for (const auto& a : args)
      cmd += " " + quote (a);
    cmd += " > " + quote ((io_ / "stdout").string ()) + " 2> " + quote ((io_ / "stderr").string ());
    cmd = piped_stdin.empty () ? cmd + " < /dev/null" : "cat " + quote (piped_stdin.string ()) + " | " + cmd;
    const int w = std::system (cmd.c_str ());
    ToolRun r;
    r.status = WIFEXITED (w) ? WEXITSTATUS (w) : 1000;
    r.out = readFile (io_ / "stdout");
    r.err = readFile (io_ / "stderr");
    return r;
  }

  /** \brief A -json query that must succeed with one line: its answer, and the stage line
    * `Orienting <input> [...]` it printed for `input` ("" if none). */
  std::pair<Value, std::string>
  answerAndOrienting (const std::vector<std::string>& args, const std::string& input) const
  {
    const ToolRun r = run (args);
    EXPECT_EQ (r.status, 0) << r.err;
    const auto out = lines (r.out);
    EXPECT_EQ (out.size (), 1u) << r.out;
    std::string stage;
    for (const auto& l : lines (r.err))
      if (l.rfind ("Orienting " + input + " [", 0) == 0)
        stage = l;
    return std::make_pair (out.empty () ? Value () : mini_json::parse (out[0]), stage);
  }

  /** \brief Runs a query that must fail: exit status, one error line naming `mention`, nothing
    * on stdout, no other error/warning text, and the listed files byte- and mtime-identical. */
  void expectFailure (const std::vector<std::string>& args, int status, const std::string& mention,
                      std::vector<fs::path> untouched = {}) const
  {
    untouched.push_back (kGripper);
    untouched.push_back (kScene);
    untouched.push_back (kPoses);
    std::vector<Snapshot> before;
    for (const auto& p : untouched)
      before.push_back (Snapshot::of (p));
    const ToolRun r = run (args);
    EXPECT_EQ (r.status, status) << r.err;
    EXPECT_TRUE (r.out.empty ()) << r.out;
    std::size_t error_lines = 0;
    for (const auto& l : lines (r.err))
    {
      if (l.rfind ("pcd_collision: error: ", 0) == 0)
      {
        ++error_lines;
        EXPECT_NE (l.find (mention), std::string::npos) << "error line does not name '" << mention << "': " << l;
      }
      else
      {
        EXPECT_EQ (lowercase (l).find ("error"), std::string::npos) << "stray message: " << l;
        EXPECT_EQ (lowercase (l).find ("warn"), std::string::npos) << "stray message: " << l;
      }
    }
    EXPECT_EQ (error_lines, 1u) << r.err;
    for (std::size_t i = 0; i < untouched.size (); ++i)
      EXPECT_TRUE (Snapshot::of (untouched[i]) == before[i]) << untouched[i] << " changed";
  }

  /** \brief The JSON lines of a successful -json run. */
  std::vector<Value> runJson (std::vector<std::string> args) const
  {
    args.push_back ("-json");
    const ToolRun r = run (args);
    EXPECT_EQ (r.status, 0) << r.err;
    std::vector<Value> values;
    for (const auto& l : lines (r.out))
    {
      try
      {
        values.push_back (mini_json::parse (l));
      }
      catch (const std::exception& e)
      {
        ADD_FAILURE () << e.what () << " in: " << l;
      }
    }
    return values;
  }

  fs::path dir_, io_;
};

/** \brief Every object key in v, nested ones as "parent.key" (array elements add nothing). */
void
collectKeys (const Value& v, const std::string& prefix, std::set<std::string>& keys)
{
  for (const auto& [k, child] : v.object)
  {
    keys.insert (prefix + k);
    collectKeys (child, prefix + k + ".", keys);
  }
  for (const auto& child : v.array)
    collectKeys (child, prefix, keys);
}

/** \brief Every leaf value in v by its path ("parent.key", array elements "[i]"), as its text:
  * a number's literal, a string quoted, true, false or null. */
void
collectValues (const Value& v, const std::string& path, std::map<std::string, std::string>& values)
{
  switch (v.type)
  {
    case Value::Type::Object:
      for (const auto& [k, child] : v.object)
        collectValues (child, path.empty () ? k : path + "." + k, values);
      break;
    case Value::Type::Array:
      for (std::size_t i = 0; i < v.array.size (); ++i)
        collectValues (v.array[i], path + "[" + std::to_string (i) + "]", values);
      break;
    case Value::Type::Null: values[path] = "null"; break;
    case Value::Type::Bool: values[path] = v.boolean ? "true" : "false"; break;
    case Value::Type::String: values[path] = "\"" + v.text + "\""; break;
    case Value::Type::Number: values[path] = v.text; break;
  }
}

std::string
poseArg (const Value& pose)
{
  std::string s;
  for (std::size_t i = 0; i < 6; ++i)
    s += (i ? "," : "") + pose[i].text;
  return s;
}

// -------------------------------------------------------------------------------------------
TEST_F (PcdCollisionTool, HelpGoesToStdoutAndExitsZero)
{
  for (const char* flag : {"-h", "--help"})
  {
    const ToolRun r = run ({flag});
    EXPECT_EQ (r.status, 0);
    EXPECT_TRUE (r.err.empty ()) << r.err;
    EXPECT_NE (r.out.find ("Syntax: pcd_collision <a> <b> [options]"), std::string::npos);
    // Every default is on the syntax lines.
    for (const char* d : {"-pose tx,ty,tz,roll,pitch,yaw   = 0,0,0,0,0,0", "= isotropic", "-sigma S        = 0.005",
                          "-k K            = 10", "-thresholds LOW,HIGH   = 0.1,0.9", "-seed N         = 1",
                          "-nmax N         = 20", "-sigma_max S    = 0.05", "-epsilon E      = 0.02", "= pca",
                          "-mesh_density S = median nearest-neighbour spacing"})
      EXPECT_NE (r.out.find (d), std::string::npos) << d;
  }
  // -h wins over anything else on the line, even malformed options.
  EXPECT_EQ (run ({"-sigma", "1O", "-h"}).status, 0);
}

TEST_F (PcdCollisionTool, VersionNamesTheToolsTheLibrarysAndPcls)
{
  for (const char* flag : {"-version", "--version"})
  {
    const ToolRun r = run ({"-sigma", "1O", flag});
    EXPECT_EQ (r.status, 0) << r.err;
    EXPECT_EQ (r.err, "");
    // project(VERSION) of CMakeLists.txt, the one owner of the version.
    EXPECT_EQ (r.out, std::string ("pcd_collision ") + PROJECT_VERSION_STRING + " (library " + PROJECT_VERSION_STRING +
                          ", PCL " + PCL_VERSION_PRETTY + ")\n");
  }
}

TEST_F (PcdCollisionTool, HumanSummaryOnStdoutDiagnosticsOnStderr)
{
  const ToolRun r = run ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0"});
  ASSERT_EQ (r.status, 0) << r.err;
  const auto out = lines (r.out);
  ASSERT_GE (out.size (), 1u);
  EXPECT_EQ (out[0].rfind ("free ", 0), 0u) << out[0];
  EXPECT_NE (out[0].find ("P = 0.000000"), std::string::npos) << out[0];
  EXPECT_NE (out[0].find ("b 10848"), std::string::npos) << out[0];
  EXPECT_NE (r.err.find ("Loading " + kScene.string () + " [done"), std::string::npos) << r.err;
  EXPECT_EQ (r.out.find ("Loading"), std::string::npos);
}

TEST_F (PcdCollisionTool, JsonFieldsAndTypes)
{
  const ToolRun r = run ({kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.02,0,0,0", "-json"});
  ASSERT_EQ (r.status, 0) << r.err;
  const auto out = lines (r.out);
  ASSERT_EQ (out.size (), 1u) << r.out;
  EXPECT_FALSE (r.err.empty ());  // the human text went to stderr
  const Value j = mini_json::parse (out[0]);
  using T = Value::Type;
  ASSERT_EQ (j.type, T::Object);
  EXPECT_EQ (j["probability"].type, T::Number);
  EXPECT_GE (j["probability"].number, 0.0);
  EXPECT_LE (j["probability"].number, 1.0);
  const std::set<std::string> verdicts = {"free", "contact", "collision"};
  EXPECT_EQ (j["verdict"].type, T::String);
  EXPECT_TRUE (verdicts.count (j["verdict"].text)) << j["verdict"].text;
  for (const char* k : {"points_a", "points_b", "points_skipped_nonfinite", "leaf_pairs"})
  {
    EXPECT_TRUE (j[k].isInteger ()) << k;
    EXPECT_GE (j[k].number, 0.0) << k;
  }
  EXPECT_EQ (j["points_b"].number, static_cast<double> (kScenePoints));
  EXPECT_GT (j["points_a"].number, 24.0);  // the 24 vertices plus area samples
  EXPECT_EQ (j["points_skipped_nonfinite"].number, 0.0);
  EXPECT_GT (j["leaf_pairs"].number, 0.0);
  for (const char* k : {"build_ms", "query_ms"})
  {
    EXPECT_EQ (j[k].type, T::Number) << k;
    EXPECT_GE (j[k].number, 0.0) << k;
  }
  EXPECT_EQ (j["lower_bound"].type, T::Bool);
  EXPECT_FALSE (j.has ("pose_index"));  // single query
  const Value& w = j["witness"];
  ASSERT_EQ (w.type, T::Object);
  ASSERT_EQ (w["point"].array.size (), 3u);
  for (const auto& c : w["point"].array)
    EXPECT_EQ (c.type, T::Number);
  ASSERT_EQ (w["normal"].array.size (), 3u);
  for (const auto& c : w["normal"].array)
    EXPECT_TRUE (c.type == T::Number || c.type == T::Null);
  EXPECT_TRUE (w["side"].text == "a" || w["side"].text == "b") << w["side"].text;
  EXPECT_TRUE (w["index"].isInteger ());
  EXPECT_GE (w["index"].number, 0.0);
  EXPECT_LT (w["index"].number, w["side"].text == "a" ? j["points_a"].number : j["points_b"].number);
  EXPECT_EQ (j["inputs"]["a"]["kind"].text, "mesh");
  EXPECT_EQ (j["inputs"]["b"]["kind"].text, "cloud");
  EXPECT_EQ (j["parameters"]["thresholds"][0].number, 0.1);
  EXPECT_EQ (j["parameters"]["sigma_b"].number, 0.005);
  EXPECT_EQ (j["parameters"]["sigma_a"].type, T::Null);  // a mesh gets no noise
}

// The surface layer on two coincident clouds of two points (no point has a normal): it read
// `free P = 0` with `witness: none (no leaf pair tested)` where the separators read contact (a
// probe, 2026-12-04; coincident clouds of 1-100 identical points did the same). The separators
// answer it now, and -distance gives the coincident nearest samples' 0 with both clouds' spread
// (it read `d = +0.0000 +- 0.0000`).
TEST_F (PcdCollisionTool, CloudsWithoutASurfaceAreAnsweredByTheSeparators)
{
  const std::string two = (dir_ / "two.pcd").string ();
  writeFile (two, "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
                  "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 0\n0.01 0 0\n");
  const auto separators = runJson ({two, two, "-sigma", "0.001"});
  const auto v = runJson ({two, two, "-sigma", "0.001", "-surface", "-distance"});
  ASSERT_EQ (v.size (), 1u);
  ASSERT_EQ (separators.size (), 1u);
  EXPECT_EQ (v[0]["answered_by"].text, "separators");
  EXPECT_EQ (v[0]["verdict"].text, "contact");
  EXPECT_EQ (v[0]["probability"].number, separators[0]["probability"].number);
  EXPECT_FALSE (v[0]["no_leaf_tested"].boolean);
  EXPECT_EQ (v[0]["leaf_pairs"].number, separators[0]["leaf_pairs"].number);
  EXPECT_EQ (v[0]["signed_distance"].number, 0.0);
  // At least both sensors' spread (each sample's covariance adds its neighbour's spacing).
  EXPECT_GE (v[0]["signed_distance_std"].number, 0.99 * std::sqrt (2.0) * 0.001);
  EXPECT_TRUE (std::isfinite (v[0]["signed_distance_std"].number));
}

// One object wholly inside the other (a 4 cm cube in the middle of a closed 40 cm box, both
// meshes): out of every leaf's reach, the winding number finds it (-surface, and the ladder's
// containment rung). Its witness normal was [null, null, null] (a probe, 2026-12-03); it is now
// the way out, as at contact: the containing surface's outward normal at its sample nearest the
// witness, turned toward a's side (out of the box for a point of the cube as <a>, into it for a
// point of the cube as <b>).
TEST_F (PcdCollisionTool, AContainmentAnswersWitnessNormalIsTheWayOut)
{
  const auto box = [] (double h) {
    std::ostringstream obj;
    for (const int x : {-1, 1})
      for (const int y : {-1, 1})
        for (const int z : {-1, 1})
          obj << "v " << x * h << " " << y * h << " " << z * h << "\n";
    // Outward winding: the x = -h face is (1 2 4) (1 4 3), its normal -x.
    obj << "f 1 2 4\nf 1 4 3\nf 5 7 8\nf 5 8 6\nf 1 5 6\nf 1 6 2\nf 3 4 8\nf 3 8 7\nf 1 3 7\nf 1 7 5\n"
           "f 2 6 8\nf 2 8 4\n";
    return obj.str ();
  };
  const std::string cube = (dir_ / "cube.obj").string (), room = (dir_ / "room.obj").string ();
  writeFile (cube, box (0.02));
  writeFile (room, box (0.2));
  for (const char* mode : {"-surface", "-surface_ladder"})
    for (const bool cube_is_a : {true, false})
    {
      SCOPED_TRACE (std::string (mode) + (cube_is_a ? ", the cube as <a>" : ", the cube as <b>"));
      const auto v = runJson ({cube_is_a ? cube : room, cube_is_a ? room : cube, mode, "-mesh_density", "0.01"});
      ASSERT_EQ (v.size (), 1u);
      EXPECT_EQ (v[0]["verdict"].text, "collision");
      EXPECT_NEAR (v[0]["signed_distance"].number, -0.18, 0.01);  // the cube's point to the room's nearest sample
      const Value& w = v[0]["witness"];
      ASSERT_EQ (w.type, Value::Type::Object);
      EXPECT_EQ (w["side"].text, cube_is_a ? "a" : "b");
      ASSERT_EQ (w["normal"].array.size (), 3u);
      Eigen::Vector3d n, p;
      for (int i = 0; i < 3; ++i)
      {
        ASSERT_EQ (w["normal"][i].type, Value::Type::Number) << "normal " << i;
        n[i] = w["normal"][i].number;
        p[i] = w["point"][i].number;
      }
      EXPECT_NEAR (n.norm (), 1.0, 1e-6);
      // A face's normal: one axis, the room's wall nearest the cube's point, whose coordinate
      // along that axis is its largest (the cube is centred).
      Eigen::Index k = 0;
      EXPECT_GT (n.cwiseAbs ().maxCoeff (&k), 0.999) << n.transpose ();
      EXPECT_NEAR (std::abs (p[k]), p.cwiseAbs ().maxCoeff (), 1e-6) << p.transpose ();
      EXPECT_GT ((cube_is_a ? 1.0 : -1.0) * n[k] * p[k], 0.0) << "normal " << n.transpose () << " at " << p.transpose ();
    }
}

// docs/CLI.md documents every key -json writes: each one appears in the key table of the
// -json section, as `key` or "key", and the example line there has the keys of a real run.
TEST_F (PcdCollisionTool, JsonKeysAreDocumented)
{
  const std::string doc = readFile (CLI_DOC);
  const std::size_t begin = doc.find ("**`-json`**"), end = doc.find ("**`-o FILE.pcd`**");
  ASSERT_NE (begin, std::string::npos);
  ASSERT_NE (end, std::string::npos);
  std::string table, example;
  for (const auto& l : lines (doc.substr (begin, end - begin)))
  {
    if (l.rfind ("|", 0) == 0)
      table += l + "\n";
    else if (l.rfind ("{\"pose\"", 0) == 0)
      example = l;
  }

  // Every branch: batch (pose_index), -o (output, write), a mesh and a cloud, a witness, the
  // surfaces' orientation (-surface).
  writeFile (dir_ / "poses.txt", "-0.15,0.05,-0.02,0,0,0\n");
  const auto batch = runJson ({kGripper.string (), kScene.string (), "-poses", (dir_ / "poses.txt").string ()});
  const auto written = runJson ({kScene.string (), kGripper.string (), "-pose", "0.15,-0.05,0.02,0,0,0", "-o",
                                 (dir_ / "out.pcd").string ()});
  const auto surface = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-surface"});
  ASSERT_EQ (batch.size (), 1u);
  ASSERT_EQ (written.size (), 1u);
  ASSERT_EQ (surface.size (), 1u);
  ASSERT_EQ (batch[0]["witness"].type, Value::Type::Object);
  ASSERT_EQ (surface[0]["inputs"]["b"]["surface"].type, Value::Type::Object);
  std::set<std::string> keys;
  collectKeys (batch[0], "", keys);
  collectKeys (written[0], "", keys);
  collectKeys (surface[0], "", keys);
  for (const std::string& path : keys)
  {
    const std::string key = path.substr (path.rfind ('.') + 1);
    EXPECT_TRUE (table.find ("`" + key + "`") != std::string::npos || table.find ("\"" + key + "\"") != std::string::npos)
        << "-json writes '" << path << "' but docs/CLI.md does not document it";
  }

  // The documented example, run again, has exactly the documented keys.
  ASSERT_FALSE (example.empty ());
  std::set<std::string> documented, actual;
  collectKeys (mini_json::parse (example), "", documented);
  const auto now = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0"});
  ASSERT_EQ (now.size (), 1u);
  collectKeys (now[0], "", actual);
  EXPECT_EQ (documented, actual);
  // And the same values, but the timings and the inputs' paths (the example's are relative): a
  // changed default showed a stale value there (noise_resolution 0, a probe of the docs, 2026-12-06).
  std::map<std::string, std::string> documented_values, actual_values;
  collectValues (mini_json::parse (example), "", documented_values);
  collectValues (now[0], "", actual_values);
  for (auto* values : {&documented_values, &actual_values})
    for (auto it = values->begin (); it != values->end ();)
    {
      const std::string& k = it->first;
      const bool varies = k == "build_ms" || k == "query_ms" || k.rfind ("timings_ms.", 0) == 0 ||
                          (k.rfind ("inputs.", 0) == 0 && (k.find (".path") != std::string::npos || k.find (".spacing_source") != std::string::npos));
      it = varies ? values->erase (it) : std::next (it);
    }
  EXPECT_EQ (documented_values, actual_values);
}

/** \brief s with every run of white space (line breaks included) made one space. */
std::string
oneSpaced (const std::string& s)
{
  std::string out;
  for (const char c : s)
    if (!std::isspace (static_cast<unsigned char> (c)))
      out += c;
    else if (!out.empty () && out.back () != ' ')
      out += ' ';
  return out;
}

/** \brief A human answer line up to its timings ("; build ..."), which vary from run to run. */
std::string
withoutTimings (const std::string& line)
{
  return line.substr (0, line.find ("; build "));
}

// The answers README.md and docs/CLI.md quote are the tool's: the Quick start's three lines
// (each doc's `pose N:` lines, timings aside) and the demo's lines with other flags that the
// prose quotes, each found both in a doc (white space aside: prose wraps its quotes) and in the
// tool's line for that pose. A change of the answers then fails here until the docs follow.
TEST_F (PcdCollisionTool, TheDemoAnswersTheDocsQuote)
{
  const ToolRun demo = run ({kGripper.string (), kScene.string (), "-poses", kPoses.string ()});
  ASSERT_EQ (demo.status, 0) << demo.err;
  const auto printed = lines (demo.out);
  ASSERT_EQ (printed.size (), 3u) << demo.out;
  for (const std::string doc : {README_DOC, CLI_DOC})
  {
    SCOPED_TRACE (doc);
    std::size_t quoted = 0;
    for (const auto& l : lines (readFile (doc)))
    {
      if (l.rfind ("pose ", 0) != 0 || l.find ("[points a ") == std::string::npos)
        continue;
      ASSERT_LT (quoted, printed.size ()) << "more demo lines quoted than the demo prints: " << l;
      EXPECT_EQ (withoutTimings (l), withoutTimings (printed[quoted])) << "the doc quotes a line the demo does not print";
      ++quoted;
    }
    EXPECT_EQ (quoted, printed.size ());
  }

  struct Quote
  {
    std::vector<std::string> flags;
    std::size_t pose;
    std::string text;
    std::vector<std::string> docs;
  };
  const std::vector<Quote> quotes = {
      {{"-surface"}, 2,
       "collision P >= 1.000000 d = -0.0195 +- 0.0008 (first deciding point) (unobserved: across a hole or behind a sheet)",
       {README_DOC, CLI_DOC}},
      {{"-surface", "-exhaustive"}, 2, "d = -0.0197 +- 0.0006", {README_DOC, CLI_DOC}},
      {{"-surface", "-distance"}, 2, "d = -0.0197 +- 0.0006", {README_DOC}},
      {{"-surface_pooled"}, 2, "contact P >= 0.895334", {README_DOC}},
      {{"-distance"}, 0, "free P = 0.000000 d = +0.1482 +- 0.0049 (nearest samples)", {README_DOC, CLI_DOC}},
      {{"-surface_ladder"}, 2, "collision P >= 1.000000", {README_DOC}},
  };
  for (const Quote& q : quotes)
  {
    std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses", kPoses.string ()};
    args.insert (args.end (), q.flags.begin (), q.flags.end ());
    SCOPED_TRACE (q.flags[0] + (q.flags.size () > 1 ? " " + q.flags[1] : std::string ()) + ": " + q.text);
    const ToolRun r = run (args);
    ASSERT_EQ (r.status, 0) << r.err;
    const auto answers = lines (r.out);
    ASSERT_EQ (answers.size (), 3u) << r.out;
    EXPECT_NE (oneSpaced (answers[q.pose]).find (q.text), std::string::npos) << "the tool prints: " << answers[q.pose];
    for (const std::string& doc : q.docs)
      EXPECT_NE (oneSpaced (readFile (doc)).find (q.text), std::string::npos) << doc << " no longer quotes it";
  }
}

// Results that cannot be written (a full disk: /dev/full) fail the run with exit 1 and a message,
// in each output mode, the first failed line ending a batch; the help alike. Until 2026-12-06 the
// tool exited 0 with its answers lost.
TEST_F (PcdCollisionTool, AResultThatCannotBeWrittenFailsTheRun)
{
  ASSERT_TRUE (fs::exists ("/dev/full"));
  const std::vector<std::vector<std::string>> runs = {
      {kGripper.string (), kScene.string (), "-poses", kPoses.string ()},
      {kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-json"},
      {kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0"},
      {"-h"},
  };
  for (const auto& args : runs)
  {
    std::string cmd = quote (kExe);
    for (const auto& arg : args)
      cmd += " " + quote (arg);
    SCOPED_TRACE (cmd);
    const fs::path err = io_ / "stderr";
    const int w = std::system ((cmd + " > /dev/full 2> " + quote (err.string ()) + " < /dev/null").c_str ());
    ASSERT_TRUE (WIFEXITED (w));
    EXPECT_EQ (WEXITSTATUS (w), 1);
    const std::string message = readFile (err);
    EXPECT_NE (message.find ("pcd_collision: error: cannot write the results to standard output: "), std::string::npos)
        << message;
    // One message: a batch stops at its first line lost.
    const std::size_t first = message.find ("cannot write");
    EXPECT_EQ (message.find ("cannot write", first + 1), std::string::npos) << message;
  }
}

TEST_F (PcdCollisionTool, JsonOfAFileNameThatIsNotUtf8IsUtf8)
{
  // The path's byte 0xff was copied into the line, which no JSON parser then read.
  const fs::path odd = dir_ / "scene\xff.pcd";
  fs::copy_file (kScene, odd);
  const ToolRun r = run ({kGripper.string (), odd.string (), "-pose", "0.1,0,0.25,0,0,0", "-json"});
  ASSERT_EQ (r.status, 0) << r.err;
  EXPECT_EQ (r.out.find ('\xff'), std::string::npos) << r.out;
  EXPECT_NE (r.out.find ("scene\\udcff.pcd\""), std::string::npos) << r.out;
  EXPECT_NO_THROW (mini_json::parse (r.out.substr (0, r.out.find ('\n'))));
}

TEST_F (PcdCollisionTool, JsonNeverPrintsNanWhenNothingIsNear)
{
  // Far apart: no leaf pair, no witness; every field must still be valid JSON.
  const auto v = runJson ({kGripper.string (), kScene.string (), "-pose", "0,0,5,0,0,0"});
  ASSERT_EQ (v.size (), 1u);
  EXPECT_EQ (v[0]["verdict"].text, "free");
  EXPECT_EQ (v[0]["probability"].number, 0.0);
  EXPECT_EQ (v[0]["witness"].type, Value::Type::Null);
}

// "unobserved" (CollisionResult::unobserved): always a boolean, right after the signed distance
// (then -distance's sample_distance and nearest_points);
// false without -surface. The human summary carries the marker exactly on the poses whose JSON
// says true. Whether the surface layer sets it here is its own test's business: with -surface
// only the member and the agreement of both outputs are asserted.
TEST_F (PcdCollisionTool, JsonUnobservedIsAlwaysABoolean)
{
  const std::string marker = "  (unobserved: across a hole or behind a sheet)   [points ";
  auto check = [&] (const std::vector<std::string>& extra, bool surface) {
    std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses", kPoses.string ()};
    args.insert (args.end (), extra.begin (), extra.end ());
    const ToolRun text = run (args);
    args.push_back ("-json");
    const ToolRun r = run (args);
    ASSERT_EQ (r.status, 0) << r.err;
    ASSERT_EQ (text.status, 0) << text.err;
    const auto out = lines (r.out);
    ASSERT_EQ (out.size (), 3u) << r.out;
    const auto human = lines (text.out);  // batch: one "pose i:" line per pose, no witness line
    ASSERT_EQ (human.size (), out.size ()) << text.out;
    for (std::size_t i = 0; i < out.size (); ++i)
    {
      SCOPED_TRACE (out[i]);
      const Value j = mini_json::parse (out[i]);
      ASSERT_TRUE (j.has ("unobserved"));
      ASSERT_EQ (j["unobserved"].type, Value::Type::Bool);
      const bool unobserved = j["unobserved"].boolean;
      if (!surface)
      {
        EXPECT_FALSE (unobserved);
        EXPECT_NE (out[i].find ("\"signed_distance_std\":null,\"unobserved\":false,\"sample_distance\":false,"
                                "\"nearest_points\":null,\"lower_bound\":"),
                   std::string::npos);
      }
      // Next to the signed distance, in the documented order.
      const std::size_t std_at = out[i].find ("\"signed_distance_std\":"),
                        at = out[i].find (std::string ("\"unobserved\":") + (unobserved ? "true" : "false")),
                        lower_at = out[i].find ("\"lower_bound\":");
      ASSERT_NE (at, std::string::npos);
      EXPECT_LT (std_at, at);
      EXPECT_LT (at, lower_at);
      EXPECT_EQ (human[i].find (marker) != std::string::npos, unobserved) << human[i];
      if (!unobserved)
      {
        EXPECT_EQ (human[i].find ("unobserved"), std::string::npos) << human[i];
      }
    }
  };
  {
    SCOPED_TRACE ("without -surface");
    check ({}, false);
  }
  {
    SCOPED_TRACE ("-surface");
    check ({"-surface", "-sigma", "0.0015"}, true);
  }
}

TEST_F (PcdCollisionTool, DemoPosesVerdicts)
{
  const auto v = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string ()});
  ASSERT_EQ (v.size (), 3u);
  for (std::size_t i = 0; i < v.size (); ++i)
    EXPECT_EQ (v[i]["pose_index"].number, static_cast<double> (i));
  // clear: well above the mug.
  EXPECT_EQ (v[0]["verdict"].text, "free");
  EXPECT_LT (v[0]["probability"].number, 0.1);
  // touching (0 gap on a table with 1.5 mm noise): contact.
  EXPECT_EQ (v[1]["verdict"].text, "contact");
  EXPECT_GE (v[1]["probability"].number, 0.5);
  // penetrating: fingers 2 cm into the table. Crossing surfaces read at least as contact; with
  // the default 5 mm sigma the method does not reach the 0.9 collision threshold here (the
  // fingers' exact samples stay out of the maximum; docs/CLI.md, METHOD.md 10).
  EXPECT_NE (v[2]["verdict"].text, "free");
  EXPECT_GT (v[2]["probability"].number, 0.5);
  EXPECT_GE (v[2]["probability"].number, v[1]["probability"].number);
}

// With -surface the penetrating demo pose stops at the first point that decides the collision
// (P >=): its distance is that point's, and the human line says so; -exhaustive visits every
// pair and reports the most significant point, here the fingers' full 2 cm (a deeper distance
// than the stopped query's), without the marker; so does -distance.
TEST_F (PcdCollisionTool, AStoppedQueryNamesItsDistanceTheFirstDecidingPoint)
{
  const std::string marker = " (first deciding point)";
  std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface"};
  const auto stopped = runJson (args);
  const ToolRun text = run (args);
  ASSERT_EQ (text.status, 0) << text.err;
  args.push_back ("-exhaustive");
  const auto full = runJson (args);
  const ToolRun full_text = run (args);
  ASSERT_EQ (full_text.status, 0) << full_text.err;
  const auto human = lines (text.out), full_human = lines (full_text.out);
  ASSERT_EQ (stopped.size (), 3u);
  ASSERT_EQ (full.size (), 3u);
  ASSERT_EQ (human.size (), 3u) << text.out;
  ASSERT_EQ (full_human.size (), 3u) << full_text.out;
  for (std::size_t i = 0; i < 3; ++i)
  {
    SCOPED_TRACE ("pose " + std::to_string (i));
    const bool marked = stopped[i]["lower_bound"].boolean && stopped[i]["signed_distance"].type == Value::Type::Number;
    EXPECT_EQ (human[i].find (marker) != std::string::npos, marked) << human[i];
    EXPECT_EQ (full_human[i].find (marker), std::string::npos) << full_human[i];
    EXPECT_FALSE (full[i]["lower_bound"].boolean);
  }
  ASSERT_TRUE (stopped[2]["lower_bound"].boolean);
  ASSERT_EQ (stopped[2]["signed_distance"].type, Value::Type::Number);
  ASSERT_EQ (full[2]["signed_distance"].type, Value::Type::Number);
  EXPECT_LT (full[2]["signed_distance"].number, stopped[2]["signed_distance"].number);
  EXPECT_NEAR (full[2]["signed_distance"].number, -0.02, 3.0 * full[2]["signed_distance_std"].number + 0.002);
  // -distance asks for an estimate: near contact the same answer as -exhaustive, never a bound.
  args.pop_back ();
  args.push_back ("-distance");
  const auto asked = runJson (args);
  ASSERT_EQ (asked.size (), 3u);
  for (std::size_t i = 1; i < 3; ++i)
  {
    SCOPED_TRACE ("pose " + std::to_string (i) + " with -distance");
    EXPECT_FALSE (asked[i]["lower_bound"].boolean);
    EXPECT_EQ (asked[i]["probability"].number, full[i]["probability"].number);
    EXPECT_EQ (asked[i]["signed_distance"].number, full[i]["signed_distance"].number);
  }
}

// -surface_ladder on the README demo: the clear pose is the separators' alone (no leaf pair
// reached, no distance), the touching and the penetrating poses, which the separators leave in
// the contact band, go to the surface layer, and the 2 cm penetration reads collision; the
// parameters say which combination ran.
TEST_F (PcdCollisionTool, SurfaceLadderAnswersTheDemoPenetrationAsCollision)
{
  const auto plain = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string ()});
  const auto ladder = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface_ladder"});
  const auto surface = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface"});
  ASSERT_EQ (plain.size (), 3u);
  ASSERT_EQ (ladder.size (), 3u);
  ASSERT_EQ (surface.size (), 3u);
  for (std::size_t i = 0; i < 3; ++i)
  {
    SCOPED_TRACE ("pose " + std::to_string (i));
    EXPECT_TRUE (ladder[i]["parameters"]["surface"].boolean);
    EXPECT_TRUE (ladder[i]["parameters"]["surface_ladder"].boolean);
    EXPECT_FALSE (ladder[i]["parameters"]["surface_pooled"].boolean);
    EXPECT_FALSE (plain[i]["parameters"]["surface_ladder"].boolean);
  }
  EXPECT_EQ (ladder[0]["verdict"].text, "free");
  EXPECT_EQ (ladder[0]["probability"].number, plain[0]["probability"].number);
  EXPECT_EQ (ladder[0]["signed_distance"].type, Value::Type::Null);
  // The separators leave the penetration in the contact band; the ladder hands it on.
  EXPECT_EQ (plain[2]["verdict"].text, "contact");
  EXPECT_EQ (ladder[2]["verdict"].text, "collision");
  EXPECT_EQ (ladder[2]["probability"].number, surface[2]["probability"].number);
  ASSERT_EQ (ladder[2]["signed_distance"].type, Value::Type::Number);
  EXPECT_LT (ladder[2]["signed_distance"].number, 0.0);
  EXPECT_GE (ladder[2]["leaf_pairs"].number, plain[2]["leaf_pairs"].number);
  // "answered_by" names the rung: the separators' answer stands on pose 0, the surface layer's on
  // pose 2; the other settings name themselves on every pose. The human line says the same, and
  // only with -surface_ladder.
  const ToolRun text = run ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface_ladder"});
  const ToolRun plain_text = run ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface"});
  ASSERT_EQ (text.status, 0) << text.err;
  ASSERT_EQ (plain_text.status, 0) << plain_text.err;
  const auto human = lines (text.out), plain_human = lines (plain_text.out);
  ASSERT_EQ (human.size (), 3u) << text.out;
  ASSERT_EQ (plain_human.size (), 3u) << plain_text.out;
  EXPECT_EQ (ladder[0]["answered_by"].text, "separators");
  EXPECT_EQ (ladder[2]["answered_by"].text, "surface");
  EXPECT_NE (human[0].find ("  (ladder: separators)   [points "), std::string::npos) << human[0];
  EXPECT_NE (human[2].find ("  (ladder: surface layer)   [points "), std::string::npos) << human[2];
  for (std::size_t i = 0; i < 3; ++i)
  {
    SCOPED_TRACE ("pose " + std::to_string (i));
    ASSERT_EQ (plain[i]["answered_by"].type, Value::Type::String);
    EXPECT_EQ (plain[i]["answered_by"].text, "separators");
    EXPECT_EQ (surface[i]["answered_by"].text, "surface");
    EXPECT_EQ (plain_human[i].find ("(ladder:"), std::string::npos) << plain_human[i];
    const std::string rung = ladder[i]["answered_by"].text;
    EXPECT_TRUE (rung == "separators" || rung == "surface" || rung == "pooled") << rung;
  }
}

// Found probing as a new user (2026-12-03): the gripper 3 cm into the table is a sure collision
// of the separators, so P is a lower bound (lower_bound), but with -distance the surface layer
// then visits every pair for the distance, an estimate: the line no longer calls it the first
// deciding point's, as -surface -distance does not either.
TEST_F (PcdCollisionTool, AnAskedDistanceIsNeverLabelledTheFirstDecidingPoint)
{
  for (const char* setting : {"-surface_ladder", "-surface"})
  {
    SCOPED_TRACE (setting);
    const ToolRun r = run ({kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.03,0,0,0", setting, "-distance"});
    ASSERT_EQ (r.status, 0) << r.err;
    EXPECT_NE (r.out.find ("collision"), std::string::npos) << r.out;
    EXPECT_NE (r.out.find ("d = -0.0"), std::string::npos) << r.out;
    EXPECT_EQ (r.out.find ("first deciding point"), std::string::npos) << r.out;
  }
  // Without -distance the ladder's stopped answer keeps the label where it has a distance.
  const ToolRun stopped = run ({kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.03,0,0,0", "-surface"});
  ASSERT_EQ (stopped.status, 0) << stopped.err;
  EXPECT_NE (stopped.out.find ("first deciding point"), std::string::npos) << stopped.out;
}

// -distance: beyond the query's reach, the distance between the two inputs' nearest samples,
// with both points in b's frame (JSON) and the marker "(nearest samples)" (human line); near
// contact nothing changes. Without the flag, sample_distance is false and nearest_points null.
TEST_F (PcdCollisionTool, DistanceGivesTheNearestSamplesBeyondReach)
{
  const std::string marker = " (nearest samples)";
  std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses", kPoses.string ()};
  const auto plain = runJson (args);
  args.push_back ("-distance");
  const auto v = runJson (args);
  const ToolRun text = run (args);
  ASSERT_EQ (text.status, 0) << text.err;
  const auto human = lines (text.out);
  ASSERT_EQ (plain.size (), 3u);
  ASSERT_EQ (v.size (), 3u);
  ASSERT_EQ (human.size (), 3u) << text.out;
  for (std::size_t i = 0; i < 3; ++i)
  {
    SCOPED_TRACE ("pose " + std::to_string (i));
    ASSERT_EQ (plain[i]["sample_distance"].type, Value::Type::Bool);
    EXPECT_FALSE (plain[i]["sample_distance"].boolean);
    EXPECT_EQ (plain[i]["nearest_points"].type, Value::Type::Null);
    EXPECT_EQ (v[i]["parameters"]["distance"].type, Value::Type::Bool);
    EXPECT_TRUE (v[i]["parameters"]["distance"].boolean);
    EXPECT_EQ (v[i]["verdict"].text, plain[i]["verdict"].text);
    EXPECT_EQ (v[i]["probability"].number, plain[i]["probability"].number);
    EXPECT_EQ (human[i].find (marker) != std::string::npos, v[i]["sample_distance"].boolean) << human[i];
  }
  // The clear pose: fingertips 15 cm over the mug's rim, no leaf pair reached.
  ASSERT_TRUE (v[0]["sample_distance"].boolean);
  EXPECT_TRUE (v[0]["no_leaf_tested"].boolean);
  EXPECT_EQ (plain[0]["signed_distance"].type, Value::Type::Null);
  const double d = v[0]["signed_distance"].number;
  EXPECT_GT (d, 0.14);
  EXPECT_LT (d, 0.15);
  EXPECT_GT (v[0]["signed_distance_std"].number, 0.0);
  const Value& points = v[0]["nearest_points"];
  ASSERT_EQ (points.array.size (), 2u);
  ASSERT_EQ (points.array[0].array.size (), 3u);
  ASSERT_EQ (points.array[1].array.size (), 3u);
  double squared = 0.0;
  for (std::size_t k = 0; k < 3; ++k)
    squared += std::pow (points.array[0].array[k].number - points.array[1].array[k].number, 2);
  EXPECT_NEAR (std::sqrt (squared), d, 1e-8);
  // b's sample is the mug's rim or above it (b's frame: the mug stands at (0.10, 0) up to 0.10).
  EXPECT_GT (points.array[1].array[2].number, 0.09);
  // Touching and penetrating: within reach, so no sample distance (the separators give none).
  for (std::size_t i = 1; i < 3; ++i)
  {
    EXPECT_FALSE (v[i]["sample_distance"].boolean);
    EXPECT_EQ (v[i]["signed_distance"].type, Value::Type::Null);
  }
}

// -max_leaf_fits N caps the fits of a query (budget_exhausted, P a lower bound: P >= in the human
// line with its marker); -noise_resolution C merges samples (fewer model points); -noise_stop C
// keeps nodes within C noise sigmas whole (fewer, larger leaves: fewer box tests). All are in the
// JSON parameters.
TEST_F (PcdCollisionTool, LeafFitCapAndNoiseResolution)
{
  const auto plain = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string ()});
  const auto capped = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-max_leaf_fits", "1"});
  ASSERT_EQ (plain.size (), 3u);
  ASSERT_EQ (capped.size (), 3u);
  std::size_t exhausted = 0;
  for (std::size_t i = 0; i < capped.size (); ++i)
  {
    EXPECT_FALSE (plain[i]["budget_exhausted"].boolean) << i;
    EXPECT_EQ (plain[i]["parameters"]["max_leaf_fits"].number, 0.0);
    EXPECT_EQ (capped[i]["parameters"]["max_leaf_fits"].number, 1.0);
    EXPECT_LE (capped[i]["leaf_pairs"].number, 1.0) << i;
    EXPECT_LE (capped[i]["probability"].number, plain[i]["probability"].number) << i;
    if (capped[i]["budget_exhausted"].boolean)
    {
      ++exhausted;
      EXPECT_TRUE (capped[i]["lower_bound"].boolean) << i;
      EXPECT_GT (plain[i]["leaf_pairs"].number, 1.0) << i;
    }
  }
  EXPECT_GT (exhausted, 0u) << "no demo pose needed a second fit: the test would prove nothing";
  const ToolRun human = run ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-max_leaf_fits", "1"});
  ASSERT_EQ (human.status, 0) << human.err;
  std::size_t marked = 0;
  for (const auto& l : lines (human.out))
    marked += l.find ("budget exhausted") != std::string::npos && l.find ("P >=") != std::string::npos;
  EXPECT_EQ (marked, exhausted);

  // -max_surface_pairs caps the ladder's surface rung: where it runs out, the separators' contact
  // stands, flagged; uncapped, no answer is flagged.
  const auto ladder = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface_ladder"});
  const auto ladder_capped = runJson (
      {kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-surface_ladder", "-max_surface_pairs", "1"});
  ASSERT_EQ (ladder.size (), 3u);
  ASSERT_EQ (ladder_capped.size (), 3u);
  std::size_t surface_exhausted = 0;
  for (std::size_t i = 0; i < ladder_capped.size (); ++i)
  {
    EXPECT_FALSE (ladder[i]["budget_exhausted"].boolean) << i;
    EXPECT_EQ (ladder[i]["parameters"]["max_surface_pairs"].number, 0.0);
    EXPECT_EQ (ladder_capped[i]["parameters"]["max_surface_pairs"].number, 1.0);
    if (!ladder_capped[i]["budget_exhausted"].boolean)
      continue;
    ++surface_exhausted;
    EXPECT_EQ (ladder_capped[i]["answered_by"].text, "separators") << i;
    EXPECT_EQ (ladder_capped[i]["probability"].number, plain[i]["probability"].number) << i;
    EXPECT_EQ (ladder_capped[i]["verdict"].text, "contact") << i;
    EXPECT_NE (ladder[i]["answered_by"].text, "separators") << i;
  }
  EXPECT_GT (surface_exhausted, 0u) << "no demo pose climbed past one leaf pair: the test would prove nothing";
  // A collision the capped rung found stands: -exhaustive goes on past the first one, and the
  // penetrating pose's is found within 512 pairs (found in review: the separators' contact
  // replaced it).
  const auto found = runJson ({kGripper.string (), kScene.string (), "-pose=-0.15,0.05,-0.02,0,0,0", "-surface_ladder",
                               "-exhaustive", "-max_surface_pairs", "512"});
  ASSERT_EQ (found.size (), 1u);
  EXPECT_TRUE (found[0]["budget_exhausted"].boolean);
  EXPECT_EQ (found[0]["verdict"].text, "collision");
  EXPECT_EQ (found[0]["answered_by"].text, "surface");
  // A capped query did not look everywhere, so it never reads free (a probe, 2026-12-06): the
  // surface layer alone, capped at one pair, read the penetrating pose "free P >= 0" and its
  // leaves' distance +0.0166 as the first deciding point's.
  const std::vector<std::string> alone_capped = {kGripper.string (), kScene.string (), "-pose=-0.15,0.05,-0.02,0,0,0",
                                                 "-surface", "-max_surface_pairs", "1"};
  const auto bound = runJson (alone_capped);
  ASSERT_EQ (bound.size (), 1u);
  EXPECT_TRUE (bound[0]["budget_exhausted"].boolean);
  EXPECT_LT (bound[0]["probability"].number, 0.1) << "the bound this case is for: under free's threshold";
  EXPECT_EQ (bound[0]["verdict"].text, "contact");
  const ToolRun bound_line = run (alone_capped);
  ASSERT_EQ (bound_line.status, 0) << bound_line.err;
  EXPECT_EQ (bound_line.out.rfind ("contact   P >= ", 0), 0u) << bound_line.out;
  EXPECT_NE (bound_line.out.find ("(leaves tested before the cap)"), std::string::npos) << bound_line.out;
  EXPECT_EQ (bound_line.out.find ("first deciding point"), std::string::npos) << bound_line.out;

  const auto merged = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-noise_resolution", "3",
                                "-noise_resolution_gate", "everywhere"});
  ASSERT_EQ (merged.size (), 1u);
  EXPECT_EQ (merged[0]["parameters"]["noise_resolution"].number, 3.0);
  EXPECT_LT (merged[0]["points_b"].number, static_cast<double> (kScenePoints));
  EXPECT_GT (merged[0]["points_b"].number, 0.0);
  EXPECT_EQ (merged[0]["parameters"]["noise_resolution_gate"].text, "everywhere");
  // The whole-cloud gate, the default gate: the table's area-weighted spacing is 5.3 mm, so at
  // its declared 5 mm noise it keeps every point, and declared at 8 mm it merges as the ungated
  // rule does.
  const auto kept = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-noise_resolution", "2"});
  ASSERT_EQ (kept.size (), 1u);
  EXPECT_EQ (kept[0]["parameters"]["noise_resolution_gate"].text, "cloud");
  EXPECT_EQ (kept[0]["parameters"]["noise_resolution"].number, 2.0);
  EXPECT_EQ (kept[0]["points_b"].number, static_cast<double> (kScenePoints));
  EXPECT_EQ (kept[0]["inputs"]["b"]["merged_samples"].number, 0.0);
  const auto noisy = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008",
                               "-noise_resolution", "3", "-noise_resolution_gate", "cloud"});
  const auto noisy_all = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008",
                                   "-noise_resolution", "3", "-noise_resolution_gate", "everywhere"});
  ASSERT_EQ (noisy.size (), 1u);
  ASSERT_EQ (noisy_all.size (), 1u);
  EXPECT_LT (noisy[0]["points_b"].number, static_cast<double> (kScenePoints) / 2.0);
  EXPECT_EQ (noisy[0]["points_b"].number, noisy_all[0]["points_b"].number);
  // The merge is reported: in the JSON (the model's points plus the merged samples are the finite
  // ones) and on the stage line.
  EXPECT_EQ (noisy[0]["inputs"]["b"]["merged_samples"].number + noisy[0]["points_b"].number,
             noisy[0]["inputs"]["b"]["finite"].number);
  EXPECT_EQ (noisy[0]["inputs"]["a"]["merged_samples"].number, 0.0);  // the gripper mesh: exact samples
  const ToolRun told =
      run ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008", "-noise_resolution", "2"});
  ASSERT_EQ (told.status, 0) << told.err;
  EXPECT_NE (told.err.find ("(from " + std::to_string (kScenePoints) + " samples merged within 2 noise sigmas)"),
             std::string::npos)
      << told.err;
  EXPECT_EQ (told.err.find ("samples merged"), told.err.rfind ("samples merged")) << "only the table merges: " << told.err;
  // Without -noise_resolution the default radius applies: 2 sigmas (the table merged at 8 mm as
  // above, the same points), none with -surface; the JSON gives the radius applied.
  const auto by_default = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008"});
  const auto told_json = runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008",
                                   "-noise_resolution", "2"});
  ASSERT_EQ (by_default.size (), 1u);
  ASSERT_EQ (told_json.size (), 1u);
  EXPECT_EQ (by_default[0]["parameters"]["noise_resolution"].number, 2.0);
  EXPECT_EQ (by_default[0]["points_b"].number, told_json[0]["points_b"].number);
  EXPECT_LT (by_default[0]["points_b"].number, static_cast<double> (kScenePoints) / 2.0);
  EXPECT_EQ (by_default[0]["probability"].number, told_json[0]["probability"].number);
  const auto surface_default =
      runJson ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-sigma", "0.008", "-surface"});
  ASSERT_EQ (surface_default.size (), 1u);
  EXPECT_EQ (surface_default[0]["parameters"]["noise_resolution"].number, 0.0);
  EXPECT_EQ (surface_default[0]["points_b"].number, static_cast<double> (kScenePoints));
  EXPECT_EQ (surface_default[0]["inputs"]["b"]["merged_samples"].number, 0.0);

  // The demo's table is 5 mm noise on 3-4 mm spacing: at C = 20 most of it stays in whole nodes.
  const auto stopped = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-noise_stop", "20"});
  ASSERT_EQ (stopped.size (), plain.size ());
  std::size_t fewer = 0;
  for (std::size_t i = 0; i < stopped.size (); ++i)
  {
    EXPECT_EQ (plain[i]["parameters"]["noise_stop"].number, 0.0);
    EXPECT_EQ (stopped[i]["parameters"]["noise_stop"].number, 20.0);
    EXPECT_LE (stopped[i]["bv_tests"].number, plain[i]["bv_tests"].number) << i;
    fewer += stopped[i]["bv_tests"].number < plain[i]["bv_tests"].number;
  }
  EXPECT_GT (fewer, 0u) << "-noise_stop 20 changed no hierarchy the demo's poses reach";

  // -defer_kernel_fits: the same verdicts, and the same P where the query did not stop early.
  const auto deferred = runJson ({kGripper.string (), kScene.string (), "-poses", kPoses.string (), "-defer_kernel_fits"});
  ASSERT_EQ (deferred.size (), plain.size ());
  double kernel_pairs = 0.0;
  for (std::size_t i = 0; i < deferred.size (); ++i)
  {
    EXPECT_FALSE (plain[i]["parameters"]["defer_kernel_fits"].boolean);
    EXPECT_TRUE (deferred[i]["parameters"]["defer_kernel_fits"].boolean);
    EXPECT_EQ (deferred[i]["verdict"].text, plain[i]["verdict"].text) << i;
    if (!plain[i]["lower_bound"].boolean && !deferred[i]["lower_bound"].boolean)
    {
      EXPECT_EQ (deferred[i]["probability"].number, plain[i]["probability"].number) << i;
    }
    kernel_pairs += deferred[i]["kernel_leaf_pairs"].number;
  }
  EXPECT_GT (kernel_pairs, 0.0) << "no demo pose needed a kernel rung: nothing was deferred";
}

TEST_F (PcdCollisionTool, BatchEqualsSingleRunsPoseByPose)
{
  // Extra poses in the batch: rotated ones and a comma/space mix, to exercise the cache with
  // a new pose each time.
  writeFile (dir_ / "poses.txt", readFile (kPoses) +
                                     "\n# rotated\n-0.15, 0.05, -0.01, 0.3, -0.2, 1.0\n0.1,0,0.12,0,0,3.14159\n");
  const auto batch = runJson ({kGripper.string (), kScene.string (), "-poses", (dir_ / "poses.txt").string ()});
  ASSERT_EQ (batch.size (), 5u);
  EXPECT_EQ (batch[0]["pose"][2].number, 0.25);
  for (std::size_t i = 0; i < batch.size (); ++i)
  {
    const auto single = runJson ({kGripper.string (), kScene.string (), "-pose", poseArg (batch[i]["pose"])});
    ASSERT_EQ (single.size (), 1u);
    const Value& b = batch[i];
    const Value& s = single[0];
    EXPECT_EQ (b["verdict"].text, s["verdict"].text) << i;
    EXPECT_EQ (b["probability"].text, s["probability"].text) << i;
    EXPECT_EQ (b["lower_bound"].boolean, s["lower_bound"].boolean) << i;
    for (const char* k : {"points_a", "points_b", "points_skipped_nonfinite", "leaf_pairs", "bv_tests"})
      EXPECT_EQ (b[k].number, s[k].number) << k << " at pose " << i;
    EXPECT_EQ (b["witness"].type, s["witness"].type) << i;
    if (b["witness"].type == Value::Type::Object)
    {
      EXPECT_EQ (b["witness"]["index"].number, s["witness"]["index"].number) << i;
      EXPECT_EQ (b["witness"]["side"].text, s["witness"]["side"].text) << i;
    }
  }
  // Hierarchies are built once: every pose after the first reuses them.
  for (std::size_t i = 1; i < batch.size (); ++i)
    EXPECT_EQ (batch[i]["build_ms"].number, 0.0) << i;
}

// -poses -: a pose generator's pipe is read as the file would be.
TEST_F (PcdCollisionTool, PosesFromStandardInputAreAnsweredAsFromAFile)
{
  const std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses"};
  std::vector<std::string> from_file = args, from_stdin = args;
  from_file.push_back (kPoses.string ());
  from_stdin.push_back ("-");
  const ToolRun f = run (from_file), p = run (from_stdin, kPoses);
  ASSERT_EQ (f.status, 0) << f.err;
  ASSERT_EQ (p.status, 0) << p.err;
  std::vector<std::string> expected, got;
  for (const auto& l : lines (f.out))
    expected.push_back (withoutTimings (l));
  for (const auto& l : lines (p.out))
    got.push_back (withoutTimings (l));
  ASSERT_EQ (expected.size (), 3u);
  EXPECT_EQ (got, expected);

  writeFile (dir_ / "bad.txt", "0 0 0 0 0 0\n0 0 0 0 0\n");
  const ToolRun bad = run (from_stdin, dir_ / "bad.txt");
  EXPECT_EQ (bad.status, 1);
  EXPECT_EQ (bad.out, "");
  EXPECT_NE (bad.err.find ("standard input:2: expected 6 numbers"), std::string::npos) << bad.err;
}

// A run longer than one batch of poses (kPosesPerBatch, 16,384: each batch's transforms and
// results are held only while it runs) answers every pose in order, each as alone: the demo's
// penetrating pose, 16,388th of 16,390 (the others clear), reads as in a file of its own.
TEST_F (PcdCollisionTool, ARunLongerThanOneBatchAnswersEachPoseInOrder)
{
  const std::size_t count = 16390, deep = 16388;
  std::ostringstream poses;
  for (std::size_t i = 0; i < count; ++i)
    poses << (i == deep ? "-0.15 0.05 -0.02 0 0 0\n" : "0.1 0 0.25 0 0 0\n");
  writeFile (dir_ / "many.txt", poses.str ());
  writeFile (dir_ / "one.txt", "-0.15 0.05 -0.02 0 0 0\n");
  const ToolRun many = run ({kGripper.string (), kScene.string (), "-poses", (dir_ / "many.txt").string (), "-threads", "2"});
  const ToolRun one = run ({kGripper.string (), kScene.string (), "-poses", (dir_ / "one.txt").string ()});
  ASSERT_EQ (many.status, 0) << many.err;
  ASSERT_EQ (one.status, 0) << one.err;
  const auto got = lines (many.out);
  ASSERT_EQ (got.size (), count);
  for (std::size_t i = 0; i < count; ++i)
    ASSERT_EQ (got[i].rfind ("pose " + std::to_string (i) + ": " + (i == deep ? "" : "free"), 0), 0u) << got[i];
  const std::string alone = withoutTimings (lines (one.out).at (0));
  EXPECT_EQ (withoutTimings (got[deep]), "pose " + std::to_string (deep) + alone.substr (std::string ("pose 0").size ()));
}

// -threads: every line the same as one thread's, in pose order, timings aside (300 poses, 1 to 3
// threads, streamed as the batch answers them).
TEST_F (PcdCollisionTool, ThreadsGiveOneThreadsOutputInPoseOrder)
{
  std::ostringstream poses;
  for (int i = 0; i < 300; ++i)
    poses << -0.15 + 0.01 * (i % 7) << " 0.05 " << 0.25 - 0.006 * i << " " << 0.02 * (i % 5) << " 0 " << 0.1 * i << "\n";
  writeFile (dir_ / "poses.txt", poses.str ());
  // The timing members and the human line's timings are the only parts allowed to differ.
  const std::regex timings ("\"(build_ms|query_ms)\":[^,]*,|,\"timings_ms\":\\{[^}]*\\}|build [0-9.]+ ms, query [0-9.]+ ms");
  auto answers = [&] (const std::string& threads, bool json) {
    std::vector<std::string> args = {kGripper.string (), kScene.string (), "-poses", (dir_ / "poses.txt").string (),
                                     "-surface_pooled", "-threads", threads};
    if (json)
      args.push_back ("-json");
    const ToolRun r = run (args);
    EXPECT_EQ (r.status, 0) << r.err;
    std::vector<std::string> out;
    for (const auto& l : lines (r.out))
      out.push_back (std::regex_replace (l, timings, ""));
    return out;
  };
  for (const bool json : {true, false})
  {
    const std::vector<std::string> one = answers ("1", json);
    ASSERT_EQ (one.size (), 300u);
    for (const char* threads : {"2", "3", "0"})
      EXPECT_EQ (answers (threads, json), one) << "-threads " << threads << (json ? " -json" : "");
    if (!json)
      continue;
    // In pose order, with the timings really removed (the regex matched).
    for (std::size_t i = 0; i < one.size (); ++i)
    {
      const Value v = mini_json::parse (one[i]);
      EXPECT_EQ (v["pose_index"].number, static_cast<double> (i));
      EXPECT_EQ (v.object.count ("query_ms"), 0u);
      EXPECT_EQ (v.object.count ("timings_ms"), 0u);
    }
  }
}

// A query that fails mid-batch stops the run at its line with any thread count: the lines before
// it printed, none after, exit status 1, the pose named by its index in the file.
// A pose the library would refuse (a translation beyond +-1e15) is refused where the file is read,
// naming its line, before any query: until 2026-11-30 the batch stopped there with "pose 150:
// query failed" (a 0-based index that comment lines shift, and no file; found in review).
TEST_F (PcdCollisionTool, AnOutOfRangePoseIsRefusedWithItsLineBeforeAnyQuery)
{
  std::ostringstream poses;
  poses << "# tx ty tz roll pitch yaw\n";
  for (int i = 0; i < 200; ++i)
    poses << (i == 150 ? "1e300 0 0 0 0 0" : "0.1 0 0.25 0 0 " + std::to_string (0.01 * i)) << "\n";
  writeFile (dir_ / "poses.txt", poses.str ());
  for (const char* threads : {"1", "2"})
  {
    const ToolRun r = run ({kGripper.string (), kScene.string (), "-poses", (dir_ / "poses.txt").string (), "-json",
                            "-threads", threads});
    EXPECT_EQ (r.status, 1) << "-threads " << threads;
    EXPECT_EQ (lines (r.out).size (), 0u) << "-threads " << threads;
    EXPECT_NE (r.err.find ("poses.txt:152: translation beyond the supported range"), std::string::npos) << r.err;
  }
}

TEST_F (PcdCollisionTool, OutputCloudLoadsInPclWithFields)
{
  const fs::path out = dir_ / "result.pcd";
  const auto v = runJson ({kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.02,0,0,0", "-o", out.string ()});
  ASSERT_EQ (v.size (), 1u);
  ASSERT_TRUE (fs::exists (out));
  const std::size_t na = static_cast<std::size_t> (v[0]["inputs"]["a"]["points"].number);
  EXPECT_EQ (v[0]["output"]["points"].number, static_cast<double> (na + kScenePoints));
  EXPECT_FALSE (v[0]["lower_bound"].boolean);  // -o implies an exhaustive query
  EXPECT_TRUE (v[0]["parameters"]["exhaustive"].boolean);

  pcl::PCLPointCloud2 blob;
  ASSERT_EQ (pcl::io::loadPCDFile (out.string (), blob), 0);
  EXPECT_EQ (static_cast<std::size_t> (blob.width) * blob.height, na + kScenePoints);
  const char* names[] = {"x", "y", "z", "intensity", "rgb", "label"};
  for (const char* n : names)
    ASSERT_GE (pcl::getFieldIndex (blob, n), 0) << n;
  EXPECT_EQ (blob.fields[pcl::getFieldIndex (blob, "intensity")].datatype, pcl::PCLPointField::FLOAT32);
  EXPECT_EQ (blob.fields[pcl::getFieldIndex (blob, "label")].datatype, pcl::PCLPointField::UINT32);

  pcl::PointCloud<pcl::PointXYZI> xyzi;
  pcl::PointCloud<pcl::PointXYZRGBL> rgbl;
  pcl::fromPCLPointCloud2 (blob, xyzi);
  pcl::fromPCLPointCloud2 (blob, rgbl);
  ASSERT_EQ (xyzi.size (), na + kScenePoints);
  pcl::PointCloud<pcl::PointXYZ> scene;
  ASSERT_EQ (pcl::io::loadPCDFile (kScene.string (), scene), 0);

  std::size_t labels[2] = {0, 0}, evaluated = 0, red = 0;
  float min_a_z = 1e9f;
  for (std::size_t i = 0; i < xyzi.size (); ++i)
  {
    const std::uint32_t label = rgbl[i].label;
    ASSERT_LE (label, 1u);
    ++labels[label];
    EXPECT_EQ (label, i < na ? 0u : 1u) << i;  // a first, then b
    const float p = xyzi[i].intensity;
    const std::uint32_t rgb = rgbl[i].rgba & 0xffffffu;
    if (std::isfinite (p))
    {
      ++evaluated;
      EXPECT_GE (p, 0.f);
      EXPECT_LE (p, 1.f);
      const std::uint32_t expected = p < 0.1f ? 0x00c000u : (p > 0.9f ? 0xff0000u : 0xffff00u);
      EXPECT_EQ (rgb, expected) << "point " << i << " p " << p;
      red += rgb == 0xff0000u;
    }
    else
      EXPECT_EQ (rgb, 0x808080u) << i;
    if (i < na)
      min_a_z = std::min (min_a_z, xyzi[i].z);
    else
    {
      // b is written as is.
      EXPECT_EQ (xyzi[i].x, scene[i - na].x);
      EXPECT_EQ (xyzi[i].z, scene[i - na].z);
    }
  }
  EXPECT_EQ (labels[0], na);
  EXPECT_EQ (labels[1], kScenePoints);
  EXPECT_GT (evaluated, 0u);
  EXPECT_GT (red, 0u);  // a penetrating pose
  EXPECT_NEAR (min_a_z, -0.02f, 1e-4f);  // a was moved by the pose (fingertips at z = -0.02)
}

TEST_F (PcdCollisionTool, AtomicWriteLeavesNoTempFileAndReplacesOldOutput)
{
  const fs::path out = dir_ / "result.pcd";
  writeFile (out, "old contents");
  const ToolRun r = run ({kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-o", out.string ()});
  ASSERT_EQ (r.status, 0) << r.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator (dir_))
    names.push_back (e.path ().filename ().string ());
  EXPECT_EQ (names, std::vector<std::string> ({"result.pcd"}));
  EXPECT_EQ (readFile (out).rfind ("# .PCD", 0), 0u);
  EXPECT_EQ (fs::status (out).permissions () & fs::perms::owner_read, fs::perms::owner_read);
}

TEST_F (PcdCollisionTool, AnOutputThroughASymbolicLinkReplacesTheFileItNames)
{
  // As a shell's `>` does: the link stays and its target gets the result (the atomic rename
  // replaced the link itself before), a dangling link's target is created, a loop is refused.
  writeFile (dir_ / "real.pcd", "old contents");
  fs::create_symlink ("real.pcd", dir_ / "link.pcd");
  fs::create_directories (dir_ / "sub");
  fs::create_symlink (fs::path ("..") / "link.pcd", dir_ / "sub" / "chain.pcd");
  fs::create_symlink ("new.pcd", dir_ / "dangling.pcd");
  const std::vector<std::string> query = {kGripper.string (), kScene.string (), "-pose", "0.1,0,0.25,0,0,0", "-o"};
  for (const fs::path& out : {dir_ / "link.pcd", dir_ / "sub" / "chain.pcd", dir_ / "dangling.pcd"})
  {
    std::vector<std::string> args = query;
    args.push_back (out.string ());
    const ToolRun r = run (args);
    ASSERT_EQ (r.status, 0) << out << ": " << r.err;
    EXPECT_TRUE (fs::is_symlink (out)) << out;
  }
  EXPECT_FALSE (fs::is_symlink (dir_ / "real.pcd"));
  EXPECT_EQ (readFile (dir_ / "real.pcd").rfind ("# .PCD", 0), 0u);
  EXPECT_EQ (readFile (dir_ / "new.pcd").rfind ("# .PCD", 0), 0u);

  fs::create_symlink ("loop_b.pcd", dir_ / "loop_a.pcd");
  fs::create_symlink ("loop_a.pcd", dir_ / "loop_b.pcd");
  std::vector<std::string> args = query;
  args.push_back ((dir_ / "loop_a.pcd").string ());
  const ToolRun r = run (args);
  EXPECT_EQ (r.status, 1);
  EXPECT_NE (r.err.find ("loop_a.pcd"), std::string::npos) << r.err;
  EXPECT_NE (lowercase (r.err).find ("symbolic links"), std::string::npos) << r.err;
  EXPECT_TRUE (fs::is_symlink (dir_ / "loop_a.pcd"));
}

TEST_F (PcdCollisionTool, OutputNeverOverwritesAnInput)
{
  fs::copy_file (kScene, dir_ / "scene.pcd");
  fs::copy_file (kGripper, dir_ / "gripper.obj");
  fs::create_symlink (dir_ / "scene.pcd", dir_ / "link.pcd");
  const std::string a = (dir_ / "gripper.obj").string (), b = (dir_ / "scene.pcd").string ();
  const std::vector<fs::path> inputs = {dir_ / "scene.pcd", dir_ / "gripper.obj"};
  expectFailure ({a, b, "-o", b}, 2, "-o", inputs);
  expectFailure ({a, b, "-o", (dir_ / "." / "scene.pcd").string ()}, 2, "refusing to overwrite an input", inputs);
  expectFailure ({a, b, "-o", (dir_ / "link.pcd").string ()}, 2, "-o", inputs);
  expectFailure ({a, (dir_ / "link.pcd").string (), "-o", b}, 2, "-o", inputs);
  EXPECT_TRUE (fs::is_symlink (dir_ / "link.pcd"));
}

// ------------------------------------------------------------------------------- bad inputs
TEST_F (PcdCollisionTool, MissingFile)
{
  const std::string missing = (dir_ / "nope.pcd").string ();
  expectFailure ({kGripper.string (), missing}, 1, missing);
  expectFailure ({missing, kScene.string (), "-json"}, 1, missing);
}

TEST_F (PcdCollisionTool, FileThatIsNotAPcdOrMesh)
{
  writeFile (dir_ / "junk.pcd", "this is not a point cloud\n");
  writeFile (dir_ / "junk.obj", "neither is this a mesh\n");
  writeFile (dir_ / "notes.txt", "0 0 0\n");
  expectFailure ({kGripper.string (), (dir_ / "junk.pcd").string ()}, 1, "junk.pcd", {dir_ / "junk.pcd"});
  expectFailure ({(dir_ / "junk.obj").string (), kScene.string ()}, 1, "junk.obj", {dir_ / "junk.obj"});
  // An extension the tool does not read is a usage error.
  expectFailure ({(dir_ / "notes.txt").string (), kScene.string ()}, 2, "notes.txt", {dir_ / "notes.txt"});
}

TEST_F (PcdCollisionTool, TruncatedPcd)
{
  const std::string full = readFile (kScene);
  const std::size_t data = full.find ("DATA binary\n") + 12;
  writeFile (dir_ / "truncated.pcd", full.substr (0, data + 1000));
  expectFailure ({kGripper.string (), (dir_ / "truncated.pcd").string ()}, 1, "truncated.pcd", {dir_ / "truncated.pcd"});
  // Cut inside the header.
  writeFile (dir_ / "header_only.pcd", full.substr (0, 60));
  expectFailure ({(dir_ / "header_only.pcd").string (), kScene.string ()}, 1, "header_only.pcd");
}

TEST_F (PcdCollisionTool, PcdWithoutXyz)
{
  writeFile (dir_ / "noxyz.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS intensity\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 3\nHEIGHT 1\n"
                                 "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n1\n2\n3\n");
  expectFailure ({kGripper.string (), (dir_ / "noxyz.pcd").string ()}, 1, "noxyz.pcd", {dir_ / "noxyz.pcd"});
}

// PCL's reader takes "abc" for 0, "1.5x" for 1.5 and a missing value for 0 in an ASCII PCD; the
// tool names the value or the line.
TEST_F (PcdCollisionTool, AsciiPcdValueThatIsNotANumber)
{
  const std::string header = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\n"
                             "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";
  writeFile (dir_ / "word.pcd", header + "0 0 0\n1 abc 1\n2 2 2\n");
  expectFailure ({kGripper.string (), (dir_ / "word.pcd").string ()}, 1, "word.pcd' line 13, value 2: 'abc' is not a number",
                 {dir_ / "word.pcd"});
  writeFile (dir_ / "tail.pcd", header + "0 0 0\n\n1 1 1.5x\n2 2 2\n");
  expectFailure ({(dir_ / "tail.pcd").string (), kScene.string ()}, 1, "tail.pcd' line 14, value 3: '1.5x' is not a number",
                 {dir_ / "tail.pcd"});
  // A line short of a value (PCL read it as 0: a point at the origin, said nothing) or with one
  // too many (PCL dropped it) is refused, naming the line; so is a line of a wider point type.
  writeFile (dir_ / "short.pcd", header + "0 0 0\n1 1\n2 2 2\n");
  expectFailure ({kGripper.string (), (dir_ / "short.pcd").string ()}, 1,
                 "short.pcd' line 13: 2 values, expected 3 (its header's FIELDS and COUNT)", {dir_ / "short.pcd"});
  writeFile (dir_ / "long.pcd", header + "0 0 0\n1 1 1\n2 2 2 2\n");
  expectFailure ({kGripper.string (), (dir_ / "long.pcd").string ()}, 1, "long.pcd' line 14: 4 values, expected 3",
                 {dir_ / "long.pcd"});
  const std::string rgb = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\n"
                          "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n";
  writeFile (dir_ / "rgb_short.pcd", rgb + "0 0 0 4278190080\n1 1 1\n");
  expectFailure ({kGripper.string (), (dir_ / "rgb_short.pcd").string ()}, 1, "rgb_short.pcd' line 13: 3 values, expected 4",
                 {dir_ / "rgb_short.pcd"});
  writeFile (dir_ / "rgb.pcd", rgb + "0 0 0 4278190080\n1 1 1 4278190080\n");
  // A padding field ("_"): PCL's writer leaves its values out of an ascii file; with them or
  // without, the lines are read, and a line short of a real value is refused.
  const std::string padded = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 4\nWIDTH 2\n"
                             "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n";
  writeFile (dir_ / "padded.pcd", padded + "0 0 0\n1 1 1 0 0 0 0\n");
  const ToolRun pad = run ({kGripper.string (), (dir_ / "padded.pcd").string (), "-pose", "0,0,10,0,0,0", "-mesh_density", "0.01"});
  EXPECT_EQ (pad.status, 0) << pad.err;
  writeFile (dir_ / "padded_short.pcd", padded + "0 0 0\n1 1\n");
  expectFailure ({kGripper.string (), (dir_ / "padded_short.pcd").string ()}, 1,
                 "padded_short.pcd' line 13: 2 values, expected 3 (or 7 with its padding)", {dir_ / "padded_short.pcd"});
  const ToolRun colour = run ({kGripper.string (), (dir_ / "rgb.pcd").string (), "-pose", "0,0,10,0,0,0", "-mesh_density", "0.01"});
  EXPECT_EQ (colour.status, 0) << colour.err;
  // nan, inf and exponents are numbers (a NaN point is skipped, as PCL does).
  writeFile (dir_ / "fine.pcd", header + "nan nan nan\n1e-1 -2.5E+0 1\n0.25 inf 3\n");
  const ToolRun r = run ({kGripper.string (), (dir_ / "fine.pcd").string (), "-pose", "0,0,10,0,0,0", "-mesh_density", "0.01"});
  EXPECT_EQ (r.status, 0) << r.err;
  EXPECT_NE (r.out.find ("free"), std::string::npos) << r.out;
}

// A PCD header PCL reads into a wrong cloud without a word (found by the probe of 2026-12-03):
// a coordinate with COUNT 3 (PCL matched it to no field and left y = 0 in every point: the mug
// over its table read free instead of contact), a field named twice (the first one read), a
// VIEWPOINT value PCL cannot read (origin 0 0 0, the quaternion left uninitialised).
TEST_F (PcdCollisionTool, PcdHeaderThatPclMisreadsIsRefused)
{
  auto pcd = [] (const std::string& fields, const std::string& size, const std::string& type, const std::string& count,
                 const std::string& viewpoint, const std::string& data) {
    return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT " + count +
           "\nWIDTH 2\nHEIGHT 1\nVIEWPOINT " + viewpoint + "\nPOINTS 2\nDATA ascii\n" + data;
  };
  writeFile (dir_ / "count.pcd", pcd ("x y z", "4 4 4", "F F F", "1 3 1", "0 0 0 1 0 0 0", "0 1 1 1 0\n1 2 2 2 1\n"));
  expectFailure ({kGripper.string (), (dir_ / "count.pcd").string ()}, 1,
                 "count.pcd': field 'y' has COUNT 3 (a coordinate or normal component needs COUNT 1)", {dir_ / "count.pcd"});
  writeFile (dir_ / "twice.pcd", pcd ("x y z x", "4 4 4 4", "F F F F", "1 1 1 1", "0 0 0 1 0 0 0", "0 0 0 5\n1 1 1 6\n"));
  expectFailure ({kGripper.string (), (dir_ / "twice.pcd").string ()}, 1, "twice.pcd': field 'x' appears 2 times in its FIELDS",
                 {dir_ / "twice.pcd"});
  writeFile (dir_ / "nan_view.pcd", pcd ("x y z", "4 4 4", "F F F", "1 1 1", "nan 0 -5 1 0 0 0", "0 0 0\n1 1 1\n"));
  expectFailure ({kGripper.string (), (dir_ / "nan_view.pcd").string ()}, 1,
                 "nan_view.pcd' line 9: VIEWPOINT value 1 'nan' is not a finite number (VIEWPOINT tx ty tz qw qx qy qz)",
                 {dir_ / "nan_view.pcd"});
  writeFile (dir_ / "long_view.pcd", pcd ("x y z", "4 4 4", "F F F", "1 1 1", "0 0 -5 1 0 0 0 9", "0 0 0\n1 1 1\n"));
  expectFailure ({kGripper.string (), (dir_ / "long_view.pcd").string ()}, 1,
                 "long_view.pcd' line 9: VIEWPOINT has 8 values, expected 7", {dir_ / "long_view.pcd"});
  // A wider field of another name is fine, as is a finite VIEWPOINT.
  writeFile (dir_ / "wide.pcd", pcd ("x y z v", "4 4 4 4", "F F F F", "1 1 1 3", "0 0 -5 1 0 0 0", "0 0 0 1 2 3\n1 1 1 4 5 6\n"));
  const ToolRun wide = run ({kGripper.string (), (dir_ / "wide.pcd").string (), "-pose", "0,0,10,0,0,0", "-mesh_density", "0.01"});
  EXPECT_EQ (wide.status, 0) << wide.err;
  EXPECT_NE (wide.out.find ("free"), std::string::npos) << wide.out;
}

// An ascii PLY value that is not a number: PCL's reader takes it for NaN (and an integer
// property's for 0), so a point with `abc` was skipped and counted as non-finite, said nowhere
// else (a probe, 2026-12-03). Refused now as in an ascii PCD, naming the file, the line and the
// value; so is a line short of a value or with one too many, which PCL's reader refused as
// "corrupt" without its line, and a mesh's face index that is not one. Binary PLY is unchanged.
TEST_F (PcdCollisionTool, AsciiPlyValueThatIsNotANumber)
{
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "end_header\n";
  const auto refused = [&] (const std::string& name, const std::string& text, const std::string& mention) {
    writeFile (dir_ / name, text);
    expectFailure ({kGripper.string (), (dir_ / name).string ()}, 1, name + "' " + mention, {dir_ / name});
  };
  refused ("word.ply", header + "0 0 0\n1 abc 1\n2 2 2\n", "line 9, value 2: 'abc' is not a number");
  refused ("tail.ply", header + "0 0 0\n1 1 1.5x\n2 2 2\n", "line 9, value 3: '1.5x' is not a number");
  refused ("hex.ply", header + "0 0 0\n0x1p3 1 1\n2 2 2\n", "line 9, value 1: '0x1p3' is not a number");
  refused ("short.ply", header + "0 0 0\n1 1\n2 2 2\n", "line 9: 2 values, expected 3 (its header's properties of element 'vertex')");
  refused ("long.ply", header + "0 0 0\n1 1 1\n2 2 2 2\n", "line 10: 4 values, expected 3");
  refused ("blank.ply", header + "0 0 0\n\n1 1 1\n", "line 9: 0 values, expected 3");
  refused ("cut.ply", header + "0 0 0\n1 1 1\n", "is truncated: it ends at line 9, within the 3 entries of element 'vertex' its header declares");
  // An integer property: PCL read "1.5" and "abc" as 0, and 300 as a uchar as 44.
  const std::string ints = "ply\nformat ascii 1.0\nelement vertex 2\nproperty int x\nproperty int y\nproperty int z\n"
                           "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  refused ("int.ply", ints + "0 0 0 1 2 3\n1 1.5 1 1 2 3\n", "line 12, value 2: '1.5' is not an integer within the range of int (property 'y')");
  refused ("colour.ply", ints + "0 0 0 1 2 3\n1 1 1 1 300 3\n", "line 12, value 5: '300' is not an integer within the range of uchar");
  // A mesh's face index that is not a number (PCL's reader made it vertex 0).
  writeFile (dir_ / "face.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 x 2\n");
  expectFailure ({(dir_ / "face.ply").string (), kScene.string ()}, 1, "face.ply' line 13, value 3: 'x' is not an integer",
                 {dir_ / "face.ply"});
  writeFile (dir_ / "face_short.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
  expectFailure ({(dir_ / "face_short.ply").string (), kScene.string ()}, 1, "face_short.ply' line 13: 3 values, too few",
                 {dir_ / "face_short.ply"});
  // A face list whose indices PCL's reader does not take (uchar, ushort, short, char): it read "no
  // triangles" (a probe, 2026-12-03); now the header line and the type are named. int and uint read.
  for (const char* type : {"uchar", "ushort", "short", "char", "int8", "uint16"})
  {
    const std::string name = std::string ("face_") + type + ".ply";
    writeFile (dir_ / name, "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "element face 1\nproperty list uchar " +
                                type + " vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expectFailure ({(dir_ / name).string (), kScene.string ()}, 1,
                   name + "' is not a readable PLY file (header line 8: the face list 'vertex_indices' has " + type +
                     " indices; PCL's PLY reader reads int or uint indices only)",
                   {dir_ / name});
  }
  for (const char* type : {"int", "uint"})
  {
    const std::string name = std::string ("face_") + type + ".ply";
    writeFile (dir_ / name, "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "element face 1\nproperty list uchar " +
                                type + " vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    const auto v = runJson ({(dir_ / name).string (), kScene.string (), "-pose", "0,0,10,0,0,0"});
    ASSERT_EQ (v.size (), 1u) << name;
    EXPECT_EQ (v[0]["verdict"].text, "free") << name;
  }
  // nan, inf, exponents, signs, CR line ends and colours are read; a NaN point is skipped and counted as
  // before, in ascii and in binary (whose values are not text: unchanged).
  writeFile (dir_ / "fine.ply", "ply\nformat ascii 1.0\nelement vertex 4\n" + xyz +
                                    "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
                                    "nan nan nan 0 0 0\r\n1e-1 -2.5E+0 1 255 0 0\r\n0.25 inf 3 0 255 0\r\n+1 2. .5 0 0 255\r\n");
  std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n" + xyz + "end_header\n";
  for (const float v : {std::nanf (""), 0.0f, 0.0f, 1.0f, 2.0f, 3.0f})
    binary.append (reinterpret_cast<const char*> (&v), sizeof v);
  writeFile (dir_ / "binary.ply", binary);
  for (const auto& [name, skipped] : {std::pair<std::string, double> ("fine.ply", 2), std::pair<std::string, double> ("binary.ply", 1)})
  {
    const auto v = runJson ({kGripper.string (), (dir_ / name).string (), "-pose", "0,0,10,0,0,0", "-mesh_density", "0.01"});
    ASSERT_EQ (v.size (), 1u) << name;
    EXPECT_EQ (v[0]["verdict"].text, "free") << name;
    EXPECT_EQ (v[0]["points_skipped_nonfinite"].number, skipped) << name;
  }
}

// A PLY face list of types PCL's reader does not take, in ascii and binary: indices other than int
// and uint left every face out ("no triangles"), and so did ushort counts, while char and short
// counts read "malformed or truncated" (a probe, 2026-12-04: the index check of 2026-12-03 left
// the count out). Refused now naming the header line and the type; the types it takes give every
// face (a triangle and a quad: 3 triangles).
TEST_F (PcdCollisionTool, PlyFaceListTypesPclDoesNotReadAreRefusedInAsciiAndBinary)
{
  const auto sizeOf = [] (const std::string& type) -> std::size_t {
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32")
      return 4;
    return type == "short" || type == "ushort" || type == "int16" || type == "uint16" ? 2 : 1;
  };
  // 5 vertices (x y z float), a triangle and a quad; format "ascii", "binary_little_endian" or
  // "binary_big_endian".
  const auto mesh = [&] (const std::string& format, const std::string& count, const std::string& index) {
    std::string text = "ply\nformat " + format + " 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 2\nproperty list " + count + " " + index +
                       " vertex_indices\nend_header\n";
    const std::vector<std::vector<int>> faces = {{0, 1, 2}, {1, 3, 2, 4}};
    const float vertices[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0};
    if (format == "ascii")
    {
      text += "0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 0 0\n3 0 1 2\n4 1 3 2 4\n";
      return text;
    }
    const bool big = format == "binary_big_endian";
    const auto put = [&] (std::uint32_t bits, std::size_t size) {
      for (std::size_t k = 0; k < size; ++k)
        text.push_back (static_cast<char> ((bits >> (8 * (big ? size - 1 - k : k))) & 0xffu));
    };
    for (const float v : vertices)
    {
      std::uint32_t bits = 0;
      std::memcpy (&bits, &v, 4);
      put (bits, 4);
    }
    for (const auto& face : faces)
    {
      put (static_cast<std::uint32_t> (face.size ()), sizeOf (count));
      for (const int i : face)
        put (static_cast<std::uint32_t> (i), sizeOf (index));
    }
    return text;
  };
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"})
  {
    const std::string tag = format.substr (0, 10);
    for (const std::string index : {"uchar", "ushort", "short", "char"})
    {
      const std::string name = "index_" + index + "_" + tag + ".ply";
      writeFile (dir_ / name, mesh (format, "uchar", index));
      expectFailure ({(dir_ / name).string (), kScene.string ()}, 1,
                     name + "' is not a readable PLY file (header line 8: the face list 'vertex_indices' has " + index +
                       " indices; PCL's PLY reader reads int or uint indices only)",
                     {dir_ / name});
    }
    for (const std::string count : {"ushort", "short", "char", "uint16"})
    {
      const std::string name = "count_" + count + "_" + tag + ".ply";
      writeFile (dir_ / name, mesh (format, count, "int"));
      expectFailure ({(dir_ / name).string (), kScene.string ()}, 1,
                     name + "' is not a readable PLY file (header line 8: the face list 'vertex_indices' has " + count +
                       " counts; PCL's PLY reader reads uchar, int or uint counts only)",
                     {dir_ / name});
    }
    for (const std::string count : {"uchar", "int", "uint"})
      for (const std::string index : {"int", "uint"})
      {
        const std::string name = "read_" + count + "_" + index + "_" + tag + ".ply";
        writeFile (dir_ / name, mesh (format, count, index));
        const auto v = runJson ({(dir_ / name).string (), kScene.string (), "-pose", "0,0,10,0,0,0"});
        ASSERT_EQ (v.size (), 1u) << name;
        EXPECT_EQ (v[0]["inputs"]["a"]["triangles"].number, 3.0) << name;
        EXPECT_EQ (v[0]["inputs"]["a"]["vertices"].number, 5.0) << name;
      }
  }
}

// A PLY whose header lines end in CRLF (a probe of 2026-12-03 reported it refused as "truncated or
// corrupt"; not reproduced): PCL's reader and the header and value checks take it, ascii and
// binary, cloud and mesh, and the answer is the one of the same file with LF line ends.
TEST_F (PcdCollisionTool, PlyWithCrlfHeaderLinesReadsAsWithLf)
{
  const auto ply = [] (const std::string& format, bool mesh, const std::string& eol) {
    std::vector<std::string> header = {"ply", "format " + format + " 1.0", "comment exported", "element vertex 100",
                                       "property float x", "property float y", "property float z"};
    if (mesh)
      header.insert (header.end (), {"element face 2", "property list uchar int vertex_indices"});
    header.push_back ("end_header");
    std::string text;
    for (const std::string& line : header)
      text += line + eol;
    std::ostringstream ascii;
    for (int i = 0; i < 100; ++i)
    {
      const float p[3] = {-0.05f + 0.01f * static_cast<float> (i % 10), -0.05f + 0.01f * static_cast<float> (i / 10), 0.004f};
      if (format == "ascii")
        ascii << p[0] << ' ' << p[1] << ' ' << p[2] << eol;
      else
        text.append (reinterpret_cast<const char*> (p), sizeof p);
    }
    if (mesh && format == "ascii")
      ascii << "3 0 9 90" << eol << "4 9 99 90 0" << eol;
    text += ascii.str ();
    if (mesh && format != "ascii")
      for (const std::vector<int>& face : {std::vector<int>{0, 9, 90}, std::vector<int>{9, 99, 90, 0}})
      {
        text.push_back (static_cast<char> (face.size ()));
        for (const int i : face)
          text.append (reinterpret_cast<const char*> (&i), sizeof i);
      }
    return text;
  };
  for (const std::string format : {"ascii", "binary_little_endian"})
    for (const bool mesh : {false, true})
    {
      std::vector<Value> answers;
      for (const std::string eol : {"\n", "\r\n"})
      {
        const std::string name = std::string (mesh ? "mesh_" : "cloud_") + format + (eol == "\n" ? "_lf" : "_crlf") + ".ply";
        writeFile (dir_ / name, ply (format, mesh, eol));
        const auto v = runJson ({(dir_ / name).string (), kScene.string (), "-pose", "0,0,0,0,0,0"});
        ASSERT_EQ (v.size (), 1u) << name;
        EXPECT_EQ (v[0]["inputs"]["a"]["kind"].text, mesh ? "mesh" : "cloud") << name;
        if (mesh)
          EXPECT_EQ (v[0]["inputs"]["a"]["triangles"].number, 3.0) << name;
        else
          EXPECT_EQ (v[0]["inputs"]["a"]["finite"].number, 100.0) << name;
        answers.push_back (v[0]);
      }
      const std::string what = std::string (mesh ? "mesh, " : "cloud, ") + format;
      EXPECT_EQ (answers[0]["verdict"].text, answers[1]["verdict"].text) << what;
      EXPECT_EQ (answers[0]["probability"].number, answers[1]["probability"].number) << what;
      EXPECT_EQ (answers[0]["points_a"].number, answers[1]["points_a"].number) << what;
      EXPECT_EQ (answers[0]["leaf_pairs"].number, answers[1]["leaf_pairs"].number) << what;
      EXPECT_GT (answers[0]["leaf_pairs"].number, 0.0) << what << ": the answer should rest on a fit";
    }
}

// Options that changed nothing were accepted (a probe, 2026-12-03): -mesh_density with two clouds
// (it sets a mesh's sample spacing) and -noise_resolution_gate without -noise_resolution. Both are
// usage errors now, naming the option and why, found before any input is loaded; a .ply without
// faces is a cloud (its header says so), a mesh among the inputs takes -mesh_density.
TEST_F (PcdCollisionTool, OptionsThatWouldChangeNothingAreUsageErrors)
{
  const std::string sheet = (dir_ / "sheet.ply").string ();
  writeFile (sheet, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "end_header\n0 0 0\n0.01 0 0\n0 0.01 0\n");
  const std::string why = "option -mesh_density: neither input is a mesh (both are point clouds; a .ply without faces is "
                          "one), and it sets a mesh's sample spacing only: it would change nothing";
  expectFailure ({kScene.string (), kScene.string (), "-mesh_density", "0.01"}, 2, why);
  expectFailure ({sheet, kScene.string (), "-mesh_density", "0.01", "-json"}, 2, why, {sheet});
  const ToolRun refused = run ({sheet, kScene.string (), "-mesh_density", "0.01"});
  EXPECT_EQ (refused.err.find ("Loading"), std::string::npos) << refused.err;
  for (const std::string& cloud : {sheet, kScene.string ()})
  {
    const ToolRun r = run ({kGripper.string (), cloud, "-mesh_density", "0.01", "-pose", "0,0,1,0,0,0"});
    EXPECT_EQ (r.status, 0) << r.err;
    EXPECT_NE (r.err.find ("at spacing 0.01, -mesh_density"), std::string::npos) << r.err;
  }
  expectFailure ({kGripper.string (), kScene.string (), "-surface", "-noise_resolution_gate", "everywhere"}, 2,
                 "option -noise_resolution_gate needs -noise_resolution C > 0");
  expectFailure ({kGripper.string (), kScene.string (), "-noise_resolution", "0", "-noise_resolution_gate", "everywhere"},
                 2, "option -noise_resolution_gate needs -noise_resolution C > 0");
  const ToolRun gated = run ({kGripper.string (), kScene.string (), "-noise_resolution", "2", "-noise_resolution_gate",
                              "everywhere", "-pose", "0,0,1,0,0,0"});
  EXPECT_EQ (gated.status, 0) << gated.err;
  // -sigma_a / -sensor_a go by the input's contents too: a .ply without faces is a cloud and takes
  // them (it was refused as "is a mesh" by its extension, a probe of 2026-12-03); a mesh does not.
  const ToolRun sheet_sigma = run ({sheet, kScene.string (), "-sigma_a", "0.002", "-pose", "0,0,1,0,0,0", "-json"});
  EXPECT_EQ (sheet_sigma.status, 0) << sheet_sigma.err;
  EXPECT_NE (sheet_sigma.out.find ("\"sigma_a\":0.002"), std::string::npos) << sheet_sigma.out;
  expectFailure ({kGripper.string (), kScene.string (), "-sensor_a", "kinect"}, 2,
                 "option -sensor_a: <a> '" + kGripper.string () + "' is a mesh, sampled exactly with no sensor noise");
  // A .ply whose header cannot be read has no kind: it is reported as the loader reports it (exit
  // 1), not called "a mesh" by its extension (a probe, 2026-12-04: a missing sheet.ply with
  // -sigma_a read "option -sigma_a: <a> 'missing.ply' is a mesh").
  const std::string missing = (dir_ / "missing.ply").string ();
  expectFailure ({missing, kScene.string (), "-sigma_a", "0.002"}, 1, "cannot read '" + missing + "': No such file or directory");
  expectFailure ({kScene.string (), missing, "-sensor_b", "kinect"}, 1, "cannot read '" + missing + "': No such file or directory");
  const std::string malformed = (dir_ / "malformed.ply").string ();
  writeFile (malformed, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "bogus line\nend_header\n0 0 0\n0.01 0 0\n0 0.01 0\n");
  expectFailure ({malformed, kScene.string (), "-sigma_a", "0.002"}, 1,
                 "'" + malformed + "' is not a readable PLY file (header line 7: unknown keyword 'bogus')", {malformed});
}

// A depth camera's whole scan under the default 5 mm noise: its near objects' samples lie 1-3 mm
// apart, its far wall's few samples hold half the area, so the whole cloud is not sampled finer
// than its noise by area; its dense samples merge (ResolutionGate::WholeCloud). Unmerged, the
// gripper 10 mm deep in the scanned objects read contact (P 0.71-0.80) at these poses, in 0.2-0.3
// s each (docs/PERFORMANCE.md, "A depth scan's dense samples merged").
TEST_F (PcdCollisionTool, ADepthScansDenseSamplesMergeByDefault)
{
  const std::string scan = std::string (PCL_PROBCOLLISION_SHARED_DATA) + "/scans/milk_cartoon_all_small_clorox.pcd";
  writeFile (dir_ / "poses.txt", "# 10 mm deep in the scan's objects\n"
                                 "-0.083765 0.230389 0.509920 -2.285140 -2.430389 3.013395\n"
                                 "-0.134738 0.102478 0.681527 -0.568911 0.604779 -2.569657\n"
                                 "0.191663 0.187210 0.523223 -0.439843 0.122615 2.833328\n"
                                 "# 32 and 19 mm clear of every point\n"
                                 "0.306044 -0.106362 0.976387 1.617668 -1.942521 -1.468775\n"
                                 "0.211362 0.202001 0.517560 -2.892743 -0.296443 0.823555\n");
  const ToolRun r = run ({kGripper.string (), scan, "-poses", (dir_ / "poses.txt").string ()});
  ASSERT_EQ (r.status, 0) << r.err;
  EXPECT_NE (r.err.find ("points (from 241407 samples merged within 2 noise sigmas)"), std::string::npos) << r.err;
  for (const char* line : {"pose 0: collision", "pose 1: collision", "pose 2: collision", "pose 3: free", "pose 4: free"})
    EXPECT_NE (r.out.find (line), std::string::npos) << line << "\n" << r.out;
}

// Two meshes are sampled exactly: a part narrower than the spacing through a thin wall can pass
// between the samples. FCL's piano (legs 40 mm across, through the 9 mm floor at the identity)
// reads free at 90 mm (1/100 of the room's diagonal, the default before), and the tool says why
// it may be wrong; at the default, 1/100 of the piano's diagonal widened to 20.4 mm for 500,000
// samples, it reads collision.
TEST_F (PcdCollisionTool, TwoMeshesWarnWhereAFreeAnswerCameWithinReach)
{
  const std::string shared = PCL_PROBCOLLISION_SHARED_DATA;
  const std::string piano = shared + "/meshes/piano_room_rob.obj", room = shared + "/meshes/piano_room_env.obj";
  const ToolRun through = run ({piano, room, "-mesh_density", "90"});
  ASSERT_EQ (through.status, 0) << through.err;
  EXPECT_NE (through.out.find ("free"), std::string::npos) << through.out;  // the miss this warns of
  EXPECT_NE (through.err.find ("pcd_collision: warning: the pose reads free, but both inputs are meshes sampled 90 apart"),
             std::string::npos) << through.err;
  EXPECT_NE (through.err.find ("-mesh_density"), std::string::npos) << through.err;
  // At the default spacing the legs cross the floor's samples: collision, nothing to warn of.
  const ToolRun fine = run ({piano, room});
  ASSERT_EQ (fine.status, 0) << fine.err;
  EXPECT_NE (fine.out.find ("collision"), std::string::npos) << fine.out;
  EXPECT_NE (fine.err.find ("at spacing 20.36"), std::string::npos) << fine.err;
  EXPECT_EQ (fine.err.find ("warning"), std::string::npos) << fine.err;
  // Far apart: free without a leaf pair, no warning.
  const ToolRun far = run ({piano, room, "-pose", "0,0,30000,0,0,0", "-mesh_density", "90"});
  ASSERT_EQ (far.status, 0) << far.err;
  EXPECT_NE (far.out.find ("free"), std::string::npos) << far.out;
  EXPECT_EQ (far.err.find ("warning"), std::string::npos) << far.err;
}

// A cloud against a mesh sampled at the user's -mesh_density, 150 times coarser than the cloud: a
// 5 cm cube 2 cm into a ground box sampled 0.3 m apart read free with no warning (a probe,
// 2026-12-04); the two-mesh warning above did not apply. It is warned of now, once; far above
// the ground, free without a leaf pair, it is not.
TEST_F (PcdCollisionTool, ACoarseMeshWarnsWhereAFreeAnswerCameWithinReach)
{
  std::ostringstream obj;
  for (const int z : {-1, 0})
    for (const int y : {-5, 5})
      for (const int x : {-5, 5})
        obj << "v " << x << " " << y << " " << z << "\n";
  obj << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 2 4 8 6\nf 4 3 7 8\nf 3 1 5 7\n";
  writeFile (dir_ / "ground.obj", obj.str ());
  std::ostringstream points;
  int n = 0;
  for (int i = 0; i <= 25; ++i)
    for (int j = 0; j <= 25; ++j)
      for (int k = 0; k <= 25; ++k)
        if (i % 25 == 0 || j % 25 == 0 || k % 25 == 0)
        {
          points << 0.002 * i << " " << 0.002 * j << " " << 0.002 * k - 0.02 << "\n";  // 2 cm under z = 0
          ++n;
        }
  writeFile (dir_ / "cube.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string (n) +
                                    "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string (n) + "\nDATA ascii\n" +
                                    points.str ());
  const std::string cube = (dir_ / "cube.pcd").string (), ground = (dir_ / "ground.obj").string ();
  const ToolRun into = run ({cube, ground, "-mesh_density", "0.3", "-sigma", "0.001", "-pose", "0.1,-2.5,0,0,0,0"});
  ASSERT_EQ (into.status, 0) << into.err;
  EXPECT_NE (into.out.find ("free"), std::string::npos) << into.out;  // the miss this warns of
  EXPECT_NE (into.err.find ("pcd_collision: warning: the pose reads free, but mesh '" + ground + "' is sampled 0.3 apart, 150 "
                            "times the other input's median spacing"),
             std::string::npos) << into.err;
  const ToolRun above = run ({cube, ground, "-mesh_density", "0.3", "-sigma", "0.001", "-pose", "0.1,-2.5,100,0,0,0"});
  ASSERT_EQ (above.status, 0) << above.err;
  EXPECT_NE (above.out.find ("free"), std::string::npos) << above.out;
  EXPECT_EQ (above.err.find ("reads free, but"), std::string::npos) << above.err;
}

TEST_F (PcdCollisionTool, EmptyCloud)
{
  writeFile (dir_ / "empty.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 0\n"
                                 "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA ascii\n");
  expectFailure ({(dir_ / "empty.pcd").string (), kScene.string ()}, 1, "empty.pcd", {dir_ / "empty.pcd"});
}

TEST_F (PcdCollisionTool, AllNanCloud)
{
  writeFile (dir_ / "nan.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                               "HEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\nnan nan nan\nnan nan nan\n"
                               "nan nan nan\nnan nan nan\n");
  expectFailure ({kGripper.string (), (dir_ / "nan.pcd").string ()}, 1, "nan.pcd", {dir_ / "nan.pcd"});
}

TEST_F (PcdCollisionTool, MeshWithoutTriangles)
{
  writeFile (dir_ / "points.obj", "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\n");
  expectFailure ({(dir_ / "points.obj").string (), kScene.string ()}, 1, "points.obj", {dir_ / "points.obj"});
}

TEST_F (PcdCollisionTool, PoseLineWithFiveNumbers)
{
  writeFile (dir_ / "poses.txt", "# good first line\n0 0 0.3 0 0 0\n\n0,0,0.2,0,0\n");
  const std::string p = (dir_ / "poses.txt").string ();
  expectFailure ({kGripper.string (), kScene.string (), "-poses", p}, 1, p + ":4:", {dir_ / "poses.txt"});
  // The same mistake on the command line is a usage error.
  expectFailure ({kGripper.string (), kScene.string (), "-pose", "0,0,0.2,0,0"}, 2, "-pose");
}

TEST_F (PcdCollisionTool, MalformedAndOutOfRangeNumbers)
{
  const std::string a = kGripper.string (), b = kScene.string ();
  expectFailure ({a, b, "-sigma", "-1"}, 2, "-sigma");
  expectFailure ({a, b, "-sigma", "1O"}, 2, "-sigma");
  expectFailure ({a, b, "-k", "1O"}, 2, "-k");
  expectFailure ({a, b, "-sigma", "0.01x"}, 2, "-sigma");
  expectFailure ({a, b, "-thresholds", "0.6,0.9"}, 2, "-thresholds");
  expectFailure ({a, b, "-sigma"}, 2, "-sigma");
}

TEST_F (PcdCollisionTool, UnknownFlagAndWrongCounts)
{
  const std::string a = kGripper.string (), b = kScene.string ();
  expectFailure ({a, b, "-sigm", "0.01"}, 2, "-sigm");
  expectFailure ({a}, 2, "two input files");
  expectFailure ({a, b, b}, 2, "two input files");
  expectFailure ({}, 2, "two input files");
}

// Errors name the user's file or flag, never our sources: PCL_THROW_EXCEPTION puts the source
// file into what(), and the tool prints pcl_probcollision::errorMessage instead.
TEST_F (PcdCollisionTool, ErrorMessagesCarryNoSourcePaths)
{
  writeFile (dir_ / "far.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                               "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1e16 0 0\n0 0 0\n");
  const std::string a = kGripper.string (), b = kScene.string ();
  const std::vector<std::vector<std::string>> runs = {
    {b, b, "-sigma", "1e200"},                   // rejected by the library (non-finite covariance)
    {(dir_ / "far.pcd").string (), b},           // rejected by the library (coordinate range)
    {a, b, "-mesh_density", "1e-9"},             // rejected by the mesh sampler
    {a, b, "-sigma", "-1"}, {a, b, "-k", "0"}, {a, b, "-epsilon", "0.5"}};  // rejected by the parser
  for (const auto& args : runs)
  {
    const ToolRun r = run (args);
    EXPECT_NE (r.status, 0) << args.back ();
    const std::string err = r.err.substr (std::min (r.err.find ("pcd_collision: error: "), r.err.size ()));
    ASSERT_FALSE (err.empty ()) << r.err;
    for (const char* leak : {".cpp", ".hpp", ".h ", ".h:", " @ ", "/src/", "/include/", "/impl/"})
      EXPECT_EQ (err.find (leak), std::string::npos) << leak << " in: " << err;
  }
  // The sampler's refusal gives the spacing as asked, not rounded to 0.000000 by a fixed format.
  const ToolRun fine = run ({a, b, "-mesh_density", "1e-9"});
  EXPECT_NE (fine.err.find ("sampling the mesh at spacing 1e-09 would give about 2.12e+16 points (limit "), std::string::npos)
      << fine.err;
}

TEST_F (PcdCollisionTool, OutputIntoMissingDirectory)
{
  const std::string out = (dir_ / "no_such_dir" / "out.pcd").string ();
  expectFailure ({kGripper.string (), kScene.string (), "-o", out}, 1, out);
  EXPECT_FALSE (fs::exists (dir_ / "no_such_dir"));
}

// ------------------------------------------------------------------------------ other inputs
TEST_F (PcdCollisionTool, OrganizedCloudWithNansAndDoubleFields)
{
  // 2 x 2 organized, one NaN, x y z stored as doubles with an extra field: any point type.
  writeFile (dir_ / "org.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS rgb x y z\nSIZE 4 8 8 8\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                               "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n"
                               "0 0 0 0.5\n0 0.01 0 0.5\n0 nan nan nan\n0 0.01 0.01 0.5\n");
  const auto v = runJson ({(dir_ / "org.pcd").string (), kScene.string (), "-sigma", "0.002"});
  ASSERT_EQ (v.size (), 1u);
  EXPECT_EQ (v[0]["inputs"]["a"]["width"].number, 2.0);
  EXPECT_EQ (v[0]["inputs"]["a"]["height"].number, 2.0);
  EXPECT_EQ (v[0]["inputs"]["a"]["finite"].number, 3.0);
  EXPECT_EQ (v[0]["points_a"].number, 3.0);
  EXPECT_EQ (v[0]["points_skipped_nonfinite"].number, 1.0);
  EXPECT_EQ (v[0]["verdict"].text, "free");  // 0.5 m above the table
}

// A PLY without faces is a point cloud (noise, covariances, "kind":"cloud"); with faces, a mesh.
TEST_F (PcdCollisionTool, PlyWithoutFacesIsACloud)
{
  // A 10 x 10 grid at 1/64 m, 0.5 m above the table, exact in float and in six decimals: ascii
  // (doubles), ascii with "element face 0", and binary (floats) hold the same points.
  std::string ascii, binary;
  for (int i = 0; i < 100; ++i)
  {
    const float p[3] = {static_cast<float> (i % 10) / 64, static_cast<float> (i / 10) / 64, 0.5f};
    ascii += std::to_string (p[0]) + " " + std::to_string (p[1]) + " " + std::to_string (p[2]) + "\n";
    binary.append (reinterpret_cast<const char*> (p), sizeof (p));  // x86-64: little-endian
  }
  const std::string vertex = "element vertex 100\n";
  writeFile (dir_ / "grid.ply", "ply\nformat ascii 1.0\ncomment a scan\n" + vertex +
                                    "property double x\nproperty double y\nproperty double z\nend_header\n" + ascii);
  writeFile (dir_ / "grid_face0.PLY", "ply\nformat ascii 1.0\n" + vertex + "property float x\nproperty float y\n"
                                          "property float z\nelement face 0\nproperty list uchar int vertex_indices\n"
                                          "end_header\n" + ascii);
  writeFile (dir_ / "grid_binary.ply", "ply\nformat binary_little_endian 1.0\n" + vertex +
                                           "property float x\nproperty float y\nproperty float z\nend_header\n" + binary);
  std::string probability;
  for (const char* name : {"grid.ply", "grid_face0.PLY", "grid_binary.ply"})
  {
    SCOPED_TRACE (name);
    const auto v = runJson ({(dir_ / name).string (), kScene.string (), "-pose", "0,0,-0.49,0,0,0"});
    ASSERT_EQ (v.size (), 1u);
    const Value& a = v[0]["inputs"]["a"];
    EXPECT_EQ (a["kind"].text, "cloud");
    EXPECT_EQ (a["points"].number, 100.0);
    EXPECT_EQ (a["finite"].number, 100.0);
    EXPECT_EQ (a["width"].number, 100.0);
    EXPECT_EQ (a["height"].number, 1.0);
    EXPECT_EQ (v[0]["parameters"]["sigma_a"].number, 0.005);  // a cloud gets the sensor noise
    if (probability.empty ())
      probability = v[0]["probability"].text;
    EXPECT_EQ (v[0]["probability"].text, probability);
  }
  // The grid as the other cloud: a mesh's spacing follows it.
  writeFile (dir_ / "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n4 0 1 2 3\n");
  const auto mesh = runJson ({(dir_ / "quad.ply").string (), (dir_ / "grid.ply").string ()});
  ASSERT_EQ (mesh.size (), 1u);
  EXPECT_EQ (mesh[0]["inputs"]["a"]["kind"].text, "mesh");
  EXPECT_EQ (mesh[0]["inputs"]["b"]["kind"].text, "cloud");
  EXPECT_EQ (mesh[0]["inputs"]["a"]["spacing"].number, 1.0 / 64);
  // Cut short, or without x y z: one error naming the file.
  writeFile (dir_ / "short.ply", "ply\nformat binary_little_endian 1.0\n" + vertex +
                                     "property float x\nproperty float y\nproperty float z\nend_header\n" + binary.substr (0, 500));
  expectFailure ({(dir_ / "short.ply").string (), kScene.string ()}, 1, "short.ply", {dir_ / "short.ply"});
  writeFile (dir_ / "noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float intensity\nend_header\n1\n2\n");
  expectFailure ({(dir_ / "noxyz.ply").string (), kScene.string ()}, 1, "noxyz.ply", {dir_ / "noxyz.ply"});
}

TEST_F (PcdCollisionTool, MeshFormatsAndDensity)
{
  writeFile (dir_ / "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n4 0 1 2 3\n");
  writeFile (dir_ / "quad.stl", "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\n"
                                "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0.1 0 0\nvertex 0.1 0.1 0\n"
                                "vertex 0 0.1 0\nendloop\nendfacet\nendsolid q\n");
  writeFile (dir_ / "quad.vtk", "# vtk DataFile Version 3.0\nquad\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
                                "0 0 0 0.1 0 0 0.1 0.1 0 0 0.1 0\nPOLYGONS 1 5\n4 0 1 2 3\n");
  for (const char* name : {"quad.ply", "quad.stl", "quad.vtk"})
  {
    const auto v = runJson ({(dir_ / name).string (), kScene.string (), "-mesh_density", "0.01", "-pose", "0,0,0.3,0,0,0"});
    ASSERT_EQ (v.size (), 1u) << name;
    EXPECT_EQ (v[0]["inputs"]["a"]["kind"].text, "mesh") << name;
    EXPECT_EQ (v[0]["inputs"]["a"]["triangles"].number, 2.0) << name;
    EXPECT_EQ (v[0]["inputs"]["a"]["spacing"].number, 0.01) << name;
    // 0.01 m^2 at 1 cm spacing: about 100 samples plus the 4 vertices.
    EXPECT_GT (v[0]["points_a"].number, 70.0) << name;
    EXPECT_LT (v[0]["points_a"].number, 140.0) << name;
    EXPECT_EQ (v[0]["verdict"].text, "free") << name;
  }
  // Deterministic sampling; the default spacing follows the other cloud.
  const auto d1 = runJson ({kGripper.string (), kScene.string ()});
  const auto d2 = runJson ({kGripper.string (), kScene.string ()});
  ASSERT_EQ (d1.size (), 1u);
  ASSERT_EQ (d2.size (), 1u);
  EXPECT_EQ (d1[0]["points_a"].number, d2[0]["points_a"].number);
  EXPECT_GT (d1[0]["inputs"]["a"]["spacing"].number, 0.002);
  EXPECT_LT (d1[0]["inputs"]["a"]["spacing"].number, 0.006);
  // On one thread the cloud is built before the sampling too (its neighbour search measures the
  // spacing): the same spacing, samples and answer.
  const auto d3 = runJson ({kGripper.string (), kScene.string (), "-threads", "1"});
  ASSERT_EQ (d3.size (), 1u);
  EXPECT_EQ (d3[0]["inputs"]["a"]["spacing"].number, d1[0]["inputs"]["a"]["spacing"].number);
  EXPECT_EQ (d3[0]["points_a"].number, d1[0]["points_a"].number);
  EXPECT_EQ (d3[0]["probability"].text, d1[0]["probability"].text);
  // Two meshes: 1/100 of the smaller bounding-box diagonal (the quad's, 0.141 against the
  // gripper's 0.147), both together far under 500,000 expected samples.
  const auto mm = runJson ({kGripper.string (), (dir_ / "quad.ply").string (), "-pose", "0,0,0.5,0,0,0"});
  ASSERT_EQ (mm.size (), 1u);
  EXPECT_NEAR (mm[0]["inputs"]["a"]["spacing"].number, 0.01 * std::sqrt (0.1 * 0.1 + 0.1 * 0.1), 1e-6);
  EXPECT_EQ (mm[0]["inputs"]["b"]["spacing"].number, mm[0]["inputs"]["a"]["spacing"].number);
  // Both models are built by the tool from the samples: their build counts (it read 0 before).
  EXPECT_GT (mm[0]["build_ms"].number, 0.0);
}

// A normal run prints its stage lines on stderr and nothing else: no VTK or PCL warning.
TEST_F (PcdCollisionTool, NormalRunsPrintOnlyStageLinesOnStderr)
{
  writeFile (dir_ / "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n4 0 1 2 3\n");
  writeFile (dir_ / "quad.vtk", "# vtk DataFile Version 3.0\nquad\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
                                "0 0 0 0.1 0 0 0.1 0.1 0 0 0.1 0\nPOLYGONS 1 5\n4 0 1 2 3\n");
  for (const fs::path& a : {kGripper, dir_ / "quad.ply", dir_ / "quad.vtk"})
  {
    SCOPED_TRACE (a.string ());
    const ToolRun r = run ({a.string (), kScene.string (), "-pose", "0,0,0.3,0,0,0"});
    ASSERT_EQ (r.status, 0) << r.err;
    // One line per model built, in the order a, b.
    const std::size_t built_a = r.err.find ("Building " + a.string () + " [done, ");
    const std::size_t built_b = r.err.find ("Building " + kScene.string () + " [done, ");
    EXPECT_NE (built_a, std::string::npos) << r.err;
    EXPECT_NE (built_b, std::string::npos) << r.err;
    EXPECT_LT (built_a, built_b) << r.err;
    // The scene's model memory ends its line: 10,848 points at 40-400 bytes a point.
    if (built_b != std::string::npos)
    {
      const std::size_t end = r.err.find (" MB]", built_b), start = r.err.rfind (", ", end);
      ASSERT_NE (end, std::string::npos) << r.err;
      ASSERT_NE (start, std::string::npos) << r.err;
      const double bytes = std::stod (r.err.substr (start + 2, end - start - 2)) * 1e6;
      EXPECT_GT (bytes, 40.0 * 10848) << r.err;
      EXPECT_LT (bytes, 400.0 * 10848) << r.err;
    }
    for (std::string l : lines (r.err))
    {
      EXPECT_TRUE (l.rfind ("Loading ", 0) == 0 || l.rfind ("Sampling ", 0) == 0 || l.rfind ("Building ", 0) == 0) << l;
      for (const std::string& path : {a.string (), kScene.string ()})
        for (std::size_t at = l.find (path); at != std::string::npos; at = l.find (path))
          l.erase (at, path.size ());
      EXPECT_EQ (lowercase (l).find ("vtk"), std::string::npos) << l;
      EXPECT_EQ (lowercase (l).find ("warn"), std::string::npos) << l;
    }
  }
}

// On a terminal a build that takes a while shows "Building <file> ... N s" on stderr, erased
// before the build's stage line; through a pipe nothing but the stage lines (docs/CLI.md).
TEST_F (PcdCollisionTool, OnATerminalALongBuildShowsItsElapsedTime)
{
  // 250,000 points on one thread: a build of one to two seconds (the line appears at 0.2 s).
  const fs::path plane = dir_ / "plane.pcd";
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int i = 0; i < 500; ++i)
    for (int j = 0; j < 500; ++j)
      cloud.push_back (pcl::PointXYZ (0.002f * static_cast<float> (i), 0.002f * static_cast<float> (j),
                                      0.0015f * std::sin (0.7f * static_cast<float> (i)) * std::cos (1.3f * static_cast<float> (j))));
  ASSERT_EQ (pcl::io::savePCDFileBinary (plane.string (), cloud), 0);
  const std::vector<std::string> args = {kGripper.string (), plane.string (), "-pose", "0.5,0.5,0.3,0,0,0", "-threads", "1"};

  int terminal = -1;
  const pid_t pid = ::forkpty (&terminal, nullptr, nullptr, nullptr);
  ASSERT_GE (pid, 0) << std::strerror (errno);
  if (pid == 0)
  {
    std::vector<std::string> words = args;
    words.insert (words.begin (), kExe);
    std::vector<char*> argv;
    for (std::string& w : words)
      argv.push_back (w.data ());
    argv.push_back (nullptr);
    ::execv (kExe.c_str (), argv.data ());
    ::_exit (127);
  }
  std::string shown;
  char buffer[4096];
  for (ssize_t got; (got = ::read (terminal, buffer, sizeof buffer)) > 0;)
    shown.append (buffer, static_cast<std::size_t> (got));
  int w = 0;
  ASSERT_EQ (::waitpid (pid, &w, 0), pid);
  ::close (terminal);
  ASSERT_TRUE (WIFEXITED (w));
  EXPECT_EQ (WEXITSTATUS (w), 0) << shown;
  const std::string line = "\rBuilding " + plane.string () + " ... ";
  const std::size_t at = shown.find (line);
  ASSERT_NE (at, std::string::npos) << shown;
  std::size_t end = at + line.size ();
  while (end < shown.size () && std::isdigit (static_cast<unsigned char> (shown[end])))
    ++end;
  EXPECT_GT (end, at + line.size ()) << shown;  // the seconds
  EXPECT_EQ (shown.compare (end, 2, " s"), 0) << shown;
  const std::size_t erased = shown.find ("\r\033[K", at);
  const std::size_t done = shown.find ("Building " + plane.string () + " [done, ");
  ASSERT_NE (erased, std::string::npos) << shown;
  ASSERT_NE (done, std::string::npos) << shown;
  EXPECT_LT (erased, done) << shown;

  // Through a pipe the same run prints its stage lines alone.
  const ToolRun r = run (args);
  ASSERT_EQ (r.status, 0) << r.err;
  EXPECT_EQ (r.err.find ('\r'), std::string::npos) << r.err;
  EXPECT_NE (r.err.find ("Building " + plane.string () + " [done, "), std::string::npos) << r.err;
}

// -sensor_a / -sensor_b give each cloud its own noise model; -sensor sets both.
TEST_F (PcdCollisionTool, SensorPerInput)
{
  auto query = [&] (std::vector<std::string> sensors) {
    std::vector<std::string> args = {kScene.string (), kScene.string (), "-pose", "0,0,0.01,0,0,0"};
    args.insert (args.end (), sensors.begin (), sensors.end ());
    const auto v = runJson (args);
    EXPECT_EQ (v.size (), 1u);
    return v.empty () ? Value () : v[0];
  };
  const Value none = query ({"-sensor", "none"}), none_each = query ({"-sensor_a", "none", "-sensor_b", "none"});
  EXPECT_EQ (none["probability"].text, none_each["probability"].text);
  EXPECT_EQ (none_each["parameters"]["sensor"].text, "none");

  const Value b_only = query ({"-sensor_b", "kinect"}), overridden = query ({"-sensor", "kinect", "-sensor_a", "isotropic"});
  EXPECT_EQ (b_only["probability"].text, overridden["probability"].text);
  const Value& p = b_only["parameters"];
  EXPECT_EQ (p["sensor"].type, Value::Type::Null);  // the inputs differ
  EXPECT_EQ (p["sensor_a"].text, "isotropic");
  EXPECT_EQ (p["sensor_b"].text, "kinect");
  EXPECT_EQ (p["sigma_a"].number, 0.005);
  EXPECT_EQ (p["sigma_b"].type, Value::Type::Null);  // no sigma in the kinect model

  // Each input gets its own model: the mixed pair answers unlike either model on both.
  const Value mixed = query ({"-sensor_a", "stereo", "-sensor_b", "kinect"});
  EXPECT_NE (mixed["probability"].text, query ({"-sensor", "stereo"})["probability"].text);
  EXPECT_NE (mixed["probability"].text, query ({"-sensor", "kinect"})["probability"].text);
  EXPECT_NE (mixed["probability"].text, query ({"-sensor_a", "kinect", "-sensor_b", "stereo"})["probability"].text);

  // A mesh gets no noise: its sensor is null.
  const auto mesh = runJson ({kGripper.string (), kScene.string (), "-sensor_b", "stereo", "-pose", "0,0,0.3,0,0,0"});
  ASSERT_EQ (mesh.size (), 1u);
  EXPECT_EQ (mesh[0]["parameters"]["sensor_a"].type, Value::Type::Null);
  EXPECT_EQ (mesh[0]["parameters"]["sensor_b"].text, "stereo");
}

TEST_F (PcdCollisionTool, StochasticTraversalIsSeeded)
{
  const std::vector<std::string> base = {kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.01,0,0,0",
                                         "-stochastic", "-exhaustive"};
  auto with = [&] (const std::string& seed) {
    auto args = base;
    args.push_back ("-seed");
    args.push_back (seed);
    return runJson (args);
  };
  const auto a = with ("7"), b = with ("7");
  ASSERT_EQ (a.size (), 1u);
  ASSERT_EQ (b.size (), 1u);
  EXPECT_EQ (a[0]["probability"].text, b[0]["probability"].text);
  EXPECT_EQ (a[0]["parameters"]["traversal"].text, "stochastic");
  EXPECT_EQ (a[0]["parameters"]["seed"].number, 7.0);
  EXPECT_EQ (run ({kGripper.string (), kScene.string (), "-stochastic", "-deterministic"}).status, 2);
}

// -measured switches the surface projection off: the touching pose reads a different P, and the
// JSON says which model answered.
TEST_F (PcdCollisionTool, MeasuredPositionsAreAnOption)
{
  const std::vector<std::string> base = {kGripper.string (), kScene.string (), "-pose", "-0.15,0.05,-0.01,0,0,0",
                                         "-exhaustive"};
  auto measured_args = base;
  measured_args.push_back ("-measured");
  const auto projected = runJson (base), measured = runJson (measured_args);
  ASSERT_EQ (projected.size (), 1u);
  ASSERT_EQ (measured.size (), 1u);
  EXPECT_EQ (projected[0]["parameters"]["positions"].text, "projected");
  EXPECT_EQ (measured[0]["parameters"]["positions"].text, "measured");
  EXPECT_NE (projected[0]["probability"].text, measured[0]["probability"].text);
}

// ---------------------------------------------------------------------- clouds with normals
/** \brief n points spread evenly over a sphere of radius r about the origin (a Fibonacci
  * lattice), with their outward unit normals times `sign`, as ascii PCD rows "x y z [nx ny nz]". */
std::string
sphereRows (int n, double r, double sign, bool normals)
{
  std::string rows;
  char buf[160];
  for (int i = 0; i < n; ++i)
  {
    const double polar = std::acos (1.0 - 2.0 * (i + 0.5) / n);
    const double azimuth = M_PI * (1.0 + std::sqrt (5.0)) * (i + 0.5);
    const double d[3] = {std::cos (azimuth) * std::sin (polar), std::sin (azimuth) * std::sin (polar), std::cos (polar)};
    if (normals)
      std::snprintf (buf, sizeof (buf), "%.7f %.7f %.7f %.7f %.7f %.7f\n", r * d[0], r * d[1], r * d[2], sign * d[0],
                     sign * d[1], sign * d[2]);
    else
      std::snprintf (buf, sizeof (buf), "%.7f %.7f %.7f\n", r * d[0], r * d[1], r * d[2]);
    rows += buf;
  }
  return rows;
}

std::string
pcdHeader (const std::string& fields, int n)
{
  const int k = static_cast<int> (std::count (fields.begin (), fields.end (), ' ')) + 1;
  std::string size, type, count;
  for (int i = 0; i < k; ++i)
  {
    size += i ? " 4" : "4";
    type += i ? " F" : "F";
    count += i ? " 1" : "1";
  }
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT " + count + "\nWIDTH " +
         std::to_string (n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string (n) + "\nDATA ascii\n";
}

// With -surface, a cloud whose file stores normals is oriented by them, taken as outward: a probe
// 1.5 cm inside a sphere of radius 10 cm (its points 1 cm to 2 cm deep) collides with the sphere
// whose normals point out and is free of the same sphere with its normals reversed (then the
// probe is outside it). -ignore_normals orients both the same way (by propagation), so both
// answer alike; a propagated orientation is not trusted to say where the inside is, so only a
// probe across the sphere's surface (a crossing) is asserted to collide. Without -surface the
// normals change nothing.
TEST_F (PcdCollisionTool, SurfaceOrientsACloudByItsFilesNormals)
{
  constexpr int kSphere = 2000, kProbe = 60;
  const std::string xyz = "x y z", with_normals = "x y z normal_x normal_y normal_z";
  writeFile (dir_ / "outward.pcd", pcdHeader (with_normals, kSphere) + sphereRows (kSphere, 0.1, +1.0, true));
  writeFile (dir_ / "inward.pcd", pcdHeader (with_normals, kSphere) + sphereRows (kSphere, 0.1, -1.0, true));
  writeFile (dir_ / "plain.pcd", pcdHeader (xyz, kSphere) + sphereRows (kSphere, 0.1, 1.0, false));
  writeFile (dir_ / "outward.ply", "ply\nformat ascii 1.0\nelement vertex " + std::to_string (kSphere) +
                                       "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
                                       "property float ny\nproperty float nz\nend_header\n" +
                                       sphereRows (kSphere, 0.1, +1.0, true));
  writeFile (dir_ / "probe.pcd", pcdHeader (xyz, kProbe) + sphereRows (kProbe, 0.005, 1.0, false));
  const std::string probe = (dir_ / "probe.pcd").string ();
  auto query = [&] (const char* sphere, std::vector<std::string> extra, const char* pose = "0.085,0,0,0,0,0") {
    std::vector<std::string> args = {probe, (dir_ / sphere).string (), "-sigma", "0.001", "-pose", pose, "-json"};
    args.insert (args.end (), extra.begin (), extra.end ());
    const ToolRun r = run (args);
    EXPECT_EQ (r.status, 0) << r.err;
    const auto out = lines (r.out);
    EXPECT_EQ (out.size (), 1u) << r.out;
    return std::make_pair (out.empty () ? Value () : mini_json::parse (out[0]), r.err);
  };
  auto orienting = [&] (const std::string& err, const char* sphere) {
    for (const auto& l : lines (err))
      if (l.rfind ("Orienting " + (dir_ / sphere).string () + " [", 0) == 0)
        return l;
    return std::string ("(no Orienting line)");
  };

  for (const char* sphere : {"outward.pcd", "outward.ply"})
  {
    SCOPED_TRACE (sphere);
    const auto [out, err] = query (sphere, {"-surface"});
    EXPECT_EQ (out["verdict"].text, "collision");
    ASSERT_EQ (out["signed_distance"].type, Value::Type::Number);
    EXPECT_LT (out["signed_distance"].number, -0.005);
    EXPECT_NE (orienting (err, sphere).find ("[point_normals: the file's normal_x normal_y normal_z"), std::string::npos)
        << err;
    EXPECT_NE (orienting (err, "probe.pcd").find ("[propagate:"), std::string::npos) << err;  // no normals in it
  }
  {
    const auto [out, err] = query ("inward.pcd", {"-surface"});
    EXPECT_EQ (out["verdict"].text, "free");
    ASSERT_EQ (out["signed_distance"].type, Value::Type::Number);
    EXPECT_GT (out["signed_distance"].number, 0.005);
    EXPECT_NE (orienting (err, "inward.pcd").find ("[point_normals:"), std::string::npos) << err;
  }
  std::vector<std::string> inside;
  for (const char* sphere : {"inward.pcd", "plain.pcd"})
  {
    SCOPED_TRACE (sphere);
    const auto [out, err] = query (sphere, {"-surface", "-ignore_normals"});
    inside.push_back (out["probability"].text + " " + out["signed_distance"].text);
    EXPECT_NE (orienting (err, sphere).find ("[propagate:"), std::string::npos) << err;
    const auto across = query (sphere, {"-surface", "-ignore_normals"}, "0.1,0,0,0,0,0");
    EXPECT_EQ (across.first["verdict"].text, "collision");
  }
  EXPECT_EQ (inside[0], inside[1]);
  // Without -surface the file's normals are not read: reversed or absent, the same answer, and
  // no Orienting line.
  const auto [plain, plain_err] = query ("plain.pcd", {});
  const auto [inward, inward_err] = query ("inward.pcd", {});
  EXPECT_EQ (plain["probability"].text, inward["probability"].text);
  EXPECT_EQ (plain["verdict"].text, inward["verdict"].text);
  for (const char* key : {"points_b", "leaf_pairs", "bv_tests"})
    EXPECT_EQ (plain[key].text, inward[key].text) << key;
  EXPECT_EQ (plain["signed_distance"].type, Value::Type::Null);
  EXPECT_EQ (inward_err.find ("Orienting"), std::string::npos) << inward_err;
}

// -closed_b: the plain sphere (no normals, PCL's default VIEWPOINT, which sees it as no scan does)
// samples a closed solid, so its propagated orientation, checked by the winding number, says
// where its inside is: the probe 1-2 cm inside it collides, where without the option the
// propagated surface is two-sided and the probe, deeper than its points reach, reads free.
// -closed_a (the probe alone) leaves the sphere two-sided. The stage line says which, and so does
// the JSON (inputs.b.surface).
TEST_F (PcdCollisionTool, ClosedGivesAPropagatedSolidAnInside)
{
  constexpr int kSphere = 2000, kProbe = 60;
  writeFile (dir_ / "plain.pcd", pcdHeader ("x y z", kSphere) + sphereRows (kSphere, 0.1, 1.0, false));
  writeFile (dir_ / "probe.pcd", pcdHeader ("x y z", kProbe) + sphereRows (kProbe, 0.005, 1.0, false));
  const std::string sphere = (dir_ / "plain.pcd").string ();
  auto query = [&] (std::vector<std::string> extra) {
    std::vector<std::string> args = {(dir_ / "probe.pcd").string (), sphere, "-sigma", "0.001", "-pose",
                                     "0.085,0,0,0,0,0", "-json", "-surface"};
    args.insert (args.end (), extra.begin (), extra.end ());
    return answerAndOrienting (args, sphere);
  };
  const auto [closed, closed_stage] = query ({"-closed_b"});
  EXPECT_EQ (closed["verdict"].text, "collision");
  ASSERT_EQ (closed["signed_distance"].type, Value::Type::Number);
  EXPECT_LT (closed["signed_distance"].number, -0.005);
  EXPECT_NE (closed_stage.find ("[propagate: "), std::string::npos) << closed_stage;
  EXPECT_NE (closed_stage.find ("; closed: outside in front of 100 %"), std::string::npos) << closed_stage;
  const Value& solid = closed["inputs"]["b"]["surface"];
  ASSERT_EQ (solid.type, Value::Type::Object);
  EXPECT_EQ (solid["orientation"].text, "propagate");
  EXPECT_TRUE (solid["inside_known"].boolean);
  EXPECT_EQ (solid["closed_share"].number, 1.0);
  EXPECT_GE (solid["solid_share"].number, 0.9);
  for (const std::vector<std::string>& extra : {std::vector<std::string> {}, std::vector<std::string> {"-closed_a"}})
  {
    const auto [open, open_stage] = query (extra);
    EXPECT_EQ (open["verdict"].text, "free") << (extra.empty () ? "" : extra[0]);
    EXPECT_NE (open_stage.find ("two-sided (-closed if it samples closed solids)"), std::string::npos) << open_stage;
    const Value& two_sided = open["inputs"]["b"]["surface"];
    ASSERT_EQ (two_sided.type, Value::Type::Object);
    EXPECT_EQ (two_sided["orientation"].text, "propagate");
    EXPECT_FALSE (two_sided["inside_known"].boolean);
    EXPECT_EQ (two_sided["closed_share"].type, Value::Type::Null);  // not checked
  }
}

// A sphere saved with PCL's normals, turned toward its VIEWPOINT beside it (most of them then
// point in): taken as outward they made the probe inside read free even with -closed, without a
// word. The normals are set aside (the Orienting line says why), so -closed_b checks the
// propagated sphere closed and the probe collides; -orientation_b point_normals takes them anyway.
TEST_F (PcdCollisionTool, NormalsTurnedTowardAViewpointBesideASolidAreSetAside)
{
  constexpr int kSphere = 2000, kProbe = 60;
  std::string rows;
  for (const std::string& row : lines (sphereRows (kSphere, 0.1, 1.0, true)))
  {
    double v[6];
    ASSERT_EQ (std::sscanf (row.c_str (), "%lf %lf %lf %lf %lf %lf", v, v + 1, v + 2, v + 3, v + 4, v + 5), 6);
    // pcl::flipNormalTowardsViewpoint toward (-0.3, 0, 0)
    const double toward = v[3] * (-0.3 - v[0]) - v[4] * v[1] - v[5] * v[2];
    char buf[160];
    const double s = toward < 0.0 ? -1.0 : 1.0;
    std::snprintf (buf, sizeof (buf), "%.7f %.7f %.7f %.7f %.7f %.7f\n", v[0], v[1], v[2], s * v[3], s * v[4], s * v[5]);
    rows += buf;
  }
  std::string header = pcdHeader ("x y z normal_x normal_y normal_z", kSphere);
  const std::string origin = "VIEWPOINT 0 0 0 ";
  header.replace (header.find (origin), origin.size (), "VIEWPOINT -0.3 0 0 ");
  writeFile (dir_ / "turned.pcd", header + rows);
  writeFile (dir_ / "probe.pcd", pcdHeader ("x y z", kProbe) + sphereRows (kProbe, 0.005, 1.0, false));
  const std::string sphere = (dir_ / "turned.pcd").string ();
  auto query = [&] (std::vector<std::string> extra) {
    std::vector<std::string> args = {(dir_ / "probe.pcd").string (), sphere, "-sigma", "0.001", "-json", "-surface"};
    args.insert (args.end (), extra.begin (), extra.end ());
    return answerAndOrienting (args, sphere);
  };
  const auto [closed, closed_stage] = query ({"-closed_b"});
  EXPECT_EQ (closed["verdict"].text, "collision");
  EXPECT_NE (closed_stage.find ("[propagate: propagated over the neighbours; not the file's normals: they all face its "
                                "VIEWPOINT"),
             std::string::npos)
      << closed_stage;
  EXPECT_NE (closed_stage.find ("; closed: "), std::string::npos) << closed_stage;
  EXPECT_EQ (closed["inputs"]["b"]["surface"]["orientation"].text, "propagate");
  EXPECT_GT (closed["inputs"]["b"]["surface"]["hidden_from_viewpoint"].number, 0.1);
  const auto [open, open_stage] = query ({});
  EXPECT_NE (open_stage.find ("two-sided (-closed if it samples closed solids)"), std::string::npos) << open_stage;
  const auto [taken, taken_stage] = query ({"-closed_b", "-orientation_b", "point_normals"});
  EXPECT_NE (taken_stage.find ("[point_normals: the file's normal_x"), std::string::npos) << taken_stage;
  EXPECT_NE (taken["verdict"].text, "collision");
}

// A closed box's samples rotated 90 degrees about x, their face normals not (transformPointCloud
// where transformPointCloudWithNormals was meant): the normals lie along four of the faces. Auto
// sets them aside with a warning naming the file, the Orienting line says why, and a ball at the
// box's centre reads collision with -closed_b; taken by name they read it otherwise.
TEST_F (PcdCollisionTool, NormalsNotMovedWithTheirPointsAreSetAside)
{
  std::string rows;
  int count = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (const double side : {-1.0, 1.0})
      for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j)
        {
          double p[3], n[3] = {0.0, 0.0, 0.0};
          p[axis] = 0.1 * side;
          p[(axis + 1) % 3] = -0.1 + 0.01 * i;
          p[(axis + 2) % 3] = -0.1 + 0.01 * j;
          n[axis] = side;
          char buf[160];
          // (x, y, z) -> (x, -z, y) about the box's centre (0.5, 0, 0.3); the normal as it was.
          std::snprintf (buf, sizeof (buf), "%.6f %.6f %.6f %.0f %.0f %.0f\n", 0.5 + p[0], -p[2], 0.3 + p[1], n[0], n[1], n[2]);
          rows += buf;
          ++count;
        }
  writeFile (dir_ / "stale.pcd", pcdHeader ("x y z normal_x normal_y normal_z", count) + rows);
  writeFile (dir_ / "ball.pcd", pcdHeader ("x y z", 60) + sphereRows (60, 0.03, 1.0, false));
  const std::string box = (dir_ / "stale.pcd").string ();
  const std::vector<std::string> args = {(dir_ / "ball.pcd").string (), box, "-sigma", "0.001", "-json", "-surface", "-closed_b",
                                         "-pose", "0.5,0,0.3,0,0,0"};
  const ToolRun r = run (args);
  ASSERT_EQ (r.status, 0) << r.err;
  EXPECT_NE (r.err.find ("stale.pcd"), std::string::npos) << r.err;
  EXPECT_NE (r.err.find ("its normals lie along its surface, not across it"), std::string::npos) << r.err;
  const auto [answer, stage] = answerAndOrienting (args, box);
  EXPECT_EQ (answer["verdict"].text, "collision");
  EXPECT_NE (stage.find ("not the file's normals: they lie along its surface"), std::string::npos) << stage;
  EXPECT_NE (stage.find ("; closed: "), std::string::npos) << stage;
  std::vector<std::string> taken_args = args;
  taken_args.insert (taken_args.end (), {"-orientation_b", "point_normals"});
  const auto [taken, taken_stage] = answerAndOrienting (taken_args, box);
  EXPECT_NE (taken_stage.find ("[point_normals: the file's normal_x"), std::string::npos) << taken_stage;
  EXPECT_NE (taken["verdict"].text, "collision");
}

// -orientation_b: the table scan, oriented toward its VIEWPOINT by default, is propagated when
// asked (two-sided: its inside no longer known), and when normals are asked of it, which it has
// not; the JSON's parameters and inputs.b.surface and the Orienting line say so, and why. The
// gripper keeps its faces' normals.
TEST_F (PcdCollisionTool, OrientationSetsHowASurfaceIsOriented)
{
  for (const std::string mode : {"auto", "propagate", "point_normals"})
  {
    const ToolRun r = run ({kGripper.string (), kScene.string (), "-surface", "-orientation_b", mode, "-pose",
                            "0.1,0,0.25,0,0,0", "-json"});
    ASSERT_EQ (r.status, 0) << r.err;
    const auto out = lines (r.out);
    ASSERT_EQ (out.size (), 1u) << r.out;
    const Value j = mini_json::parse (out[0]);
    EXPECT_EQ (j["parameters"]["orientation_a"].text, "auto");
    EXPECT_EQ (j["parameters"]["orientation_b"].text, mode);
    EXPECT_EQ (j["inputs"]["a"]["surface"]["orientation"].text, "point_normals");
    const std::string used = mode == "auto" ? "viewpoint" : "propagate";
    EXPECT_EQ (j["inputs"]["b"]["surface"]["orientation"].text, used);
    EXPECT_EQ (j["inputs"]["b"]["surface"]["inside_known"].boolean, mode == "auto");
    EXPECT_NE (r.err.find ("Orienting " + kScene.string () + " [" + used + ": "), std::string::npos) << r.err;
    // The VIEWPOINT used is named (a cloud moved into another frame keeps the one it was saved with).
    EXPECT_EQ (r.err.find ("[viewpoint: toward the sensor origin, VIEWPOINT 0 0 1 (a cloud moved after it was scanned must bring") != std::string::npos,
               mode == "auto")
        << r.err;
    EXPECT_EQ (r.err.find ("-orientation point_normals refused: it has no normals") != std::string::npos,
               mode == "point_normals")
        << r.err;
  }
}

// Only some normal fields: with -surface an error naming the file and the missing field (exit
// 1); without -surface the normals are not read and the file is a plain cloud.
TEST_F (PcdCollisionTool, PartialNormalFieldsFailWithSurface)
{
  writeFile (dir_ / "half.pcd", pcdHeader ("x y z normal_x normal_z", 200) + [] {
    std::string rows;
    for (int i = 0; i < 200; ++i)
      rows += std::to_string ((i % 20) * 0.005) + " " + std::to_string ((i / 20) * 0.005) + " 0.5 0 1\n";
    return rows;
  }());
  const std::string half = (dir_ / "half.pcd").string ();
  expectFailure ({half, kScene.string (), "-surface"}, 1, "'normal_y'", {dir_ / "half.pcd"});
  expectFailure ({half, kScene.string (), "-surface", "-json"}, 1, "half.pcd", {dir_ / "half.pcd"});
  EXPECT_EQ (run ({half, kScene.string ()}).status, 0);
  EXPECT_EQ (run ({half, kScene.string (), "-surface", "-ignore_normals"}).status, 0);
}

TEST_F (PcdCollisionTool, DemoDataIsReproducible)
{
  // The recipe in data/README.md regenerates the committed files byte for byte.
  const std::string cmd = quote (kGenerator) + " " + quote (dir_.string ()) + " > /dev/null";
  ASSERT_EQ (std::system (cmd.c_str ()), 0);
  for (const char* name : {"table_mug.pcd", "gripper.obj", "demo_poses.txt"})
    EXPECT_TRUE (readFile (dir_ / name) == readFile (kData / name)) << name << " differs from data/" << name;
}
} // namespace
