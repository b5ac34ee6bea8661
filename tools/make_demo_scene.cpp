// SPDX-License-Identifier: BSD-3-Clause
// Writes the bundled demo data of pcd_collision (data/README.md) deterministically:
//   table_mug.pcd    a noisy table top with a mug, binary PCD, metres, VIEWPOINT looking down
//   gripper.obj      a parallel-jaw gripper mesh (palm box + two finger boxes)
//   demo_poses.txt   three poses of the gripper in the table frame: clear, touching, penetrating
//
// Usage: make_demo_scene OUTPUT_DIR
//
// Only std::mt19937_64's raw bits are used (no std::*_distribution, which are
// implementation-defined), so the output depends on nothing but the C library's log/cos/sin.

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kSeed = 20111;  // fixed: the committed files are reproducible

// Scene (metres, table frame: z up, table top at z = 0).
constexpr double kTableX = 0.60, kTableY = 0.40, kTableStep = 0.005;
constexpr double kNoiseSigma = 0.0015;
constexpr double kMugX = 0.10, kMugY = 0.0, kMugRadius = 0.04, kMugHeight = 0.10;
constexpr double kMugFloor = 0.006, kMugWall = 0.004;
constexpr double kSensorHeight = 1.0;

// Gripper (gripper frame: origin at the midpoint of the two fingertips' bottom faces, fingers
// pointing down -z, jaw opening along x).
constexpr double kFingerHalfGap = 0.05, kFingerThick = 0.01, kFingerHalfDepth = 0.01, kFingerLength = 0.06;
constexpr double kPalmHalfWidth = 0.06, kPalmHalfDepth = 0.015, kPalmHeight = 0.02;

class Rng
{
public:
  explicit Rng (std::uint64_t seed) : engine_ (seed) {}
  double uniform () { return static_cast<double> (engine_ () >> 11) * (1.0 / 9007199254740992.0); }
  /** \brief Box-Muller. */
  double gaussian ()
  {
    const double u1 = 1.0 - uniform ();  // (0, 1]
    const double u2 = uniform ();
    return std::sqrt (-2.0 * std::log (u1)) * std::cos (2.0 * kPi * u2);
  }

private:
  std::mt19937_64 engine_;
};

void
addNoisy (pcl::PointCloud<pcl::PointXYZ>& cloud, Rng& rng, double x, double y, double z)
{
  const double nx = kNoiseSigma * rng.gaussian ();
  const double ny = kNoiseSigma * rng.gaussian ();
  const double nz = kNoiseSigma * rng.gaussian ();
  cloud.push_back (pcl::PointXYZ (static_cast<float> (x + nx), static_cast<float> (y + ny), static_cast<float> (z + nz)));
}

pcl::PointCloud<pcl::PointXYZ>
makeScene ()
{
  Rng rng (kSeed);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  // Table top on a 5 mm grid; the part under the mug is hidden from the sensor above.
  const int nx = static_cast<int> (std::lround (kTableX / kTableStep)) + 1;
  const int ny = static_cast<int> (std::lround (kTableY / kTableStep)) + 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
    {
      const double x = -0.5 * kTableX + i * kTableStep;
      const double y = -0.5 * kTableY + j * kTableStep;
      if (std::hypot (x - kMugX, y - kMugY) < kMugRadius)
        continue;
      addNoisy (cloud, rng, x, y, 0.0);
    }
  // Mug: outer wall at ~5 mm spacing, top rim, and the inside floor seen through the opening.
  const int around = static_cast<int> (std::lround (2.0 * kPi * kMugRadius / 0.005));
  const int rows = static_cast<int> (std::lround (kMugHeight / 0.005));
  for (int r = 0; r <= rows; ++r)
    for (int a = 0; a < around; ++a)
    {
      const double t = 2.0 * kPi * a / around;
      addNoisy (cloud, rng, kMugX + kMugRadius * std::cos (t), kMugY + kMugRadius * std::sin (t), r * kMugHeight / rows);
    }
  const double inner = kMugRadius - kMugWall;
  const int around_in = static_cast<int> (std::lround (2.0 * kPi * inner / 0.005));
  for (int a = 0; a < around_in; ++a)
  {
    const double t = 2.0 * kPi * a / around_in;
    addNoisy (cloud, rng, kMugX + inner * std::cos (t), kMugY + inner * std::sin (t), kMugHeight);
  }
  for (double y = -inner + 0.0025; y < inner; y += 0.005)
    for (double x = -inner + 0.0025; x < inner; x += 0.005)
      if (std::hypot (x, y) < inner - 0.002)
        addNoisy (cloud, rng, kMugX + x, kMugY + y, kMugFloor);

  cloud.width = static_cast<std::uint32_t> (cloud.size ());
  cloud.height = 1;
  cloud.is_dense = true;
  // Sensor 1 m above the table centre looking straight down: optical axis (0, 0, 1) rotated by
  // 180 degrees about x.
  cloud.sensor_origin_ = Eigen::Vector4f (0.f, 0.f, static_cast<float> (kSensorHeight), 0.f);
  cloud.sensor_orientation_ = Eigen::Quaternionf (0.f, 1.f, 0.f, 0.f);
  return cloud;
}

struct Box
{
  std::array<double, 3> lo, hi;
};

std::string
makeGripperObj ()
{
  const std::vector<Box> boxes = {
    {{-kPalmHalfWidth, -kPalmHalfDepth, kFingerLength}, {kPalmHalfWidth, kPalmHalfDepth, kFingerLength + kPalmHeight}},
    {{-kFingerHalfGap - kFingerThick, -kFingerHalfDepth, 0.0}, {-kFingerHalfGap, kFingerHalfDepth, kFingerLength}},
    {{kFingerHalfGap, -kFingerHalfDepth, 0.0}, {kFingerHalfGap + kFingerThick, kFingerHalfDepth, kFingerLength}},
  };
  // Corner c has bits (x, y, z): bit set = hi. Faces as quads with outward normals.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::string obj = "# Parallel-jaw gripper for pcd_collision's demo (tools/make_demo_scene.cpp), metres.\n"
                    "# Frame: origin at the midpoint of the fingertips' bottom faces, fingers along -z,\n"
                    "# jaw opening along x (10 cm between the fingers). Boxes: palm, left finger, right finger.\n";
  char line[128];
  for (const Box& b : boxes)
    for (int c = 0; c < 8; ++c)
    {
      std::snprintf (line, sizeof (line), "v %.4f %.4f %.4f\n", (c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1],
                     (c & 4) ? b.hi[2] : b.lo[2]);
      obj += line;
    }
  for (std::size_t k = 0; k < boxes.size (); ++k)
  {
    const int base = static_cast<int> (8 * k) + 1;  // OBJ indices are 1-based
    for (const auto& q : quads)
    {
      std::snprintf (line, sizeof (line), "f %d %d %d\nf %d %d %d\n", base + q[0], base + q[1], base + q[2], base + q[0],
                     base + q[2], base + q[3]);
      obj += line;
    }
  }
  return obj;
}

std::string
makePoses ()
{
  char buf[1024];
  std::snprintf (
      buf, sizeof (buf),
      "# Poses of data/gripper.obj (the first input, <a>) in the frame of data/table_mug.pcd (<b>):\n"
      "# tx ty tz roll pitch yaw (metres, radians). Table top at z = 0; the mug (radius %.2f m,\n"
      "# height %.2f m) stands at (%.2f, %.2f). The gripper's origin is its fingertips' bottom.\n"
      "# clear: above the mug, fingertips %.2f m over its rim\n"
      "%.3f %.3f %.3f 0 0 0\n"
      "# touching: fingertips on the table surface (0 gap), away from the mug\n"
      "-0.150 0.050 0.000 0 0 0\n"
      "# penetrating: the same, fingers 2 cm into the table\n"
      "-0.150 0.050 -0.020 0 0 0\n",
      kMugRadius, kMugHeight, kMugX, kMugY, 0.15, kMugX, kMugY, kMugHeight + 0.15);
  return buf;
}

bool
writeText (const std::filesystem::path& path, const std::string& text)
{
  const std::filesystem::path tmp = path.string () + ".tmp";
  {
    std::ofstream f (tmp, std::ios::binary);
    f << text;
    if (!f.flush ())
      return false;
  }
  std::error_code ec;
  std::filesystem::rename (tmp, path, ec);
  return !ec;
}
} // namespace

int
main (int argc, char** argv)
{
  if (argc != 2 || std::string (argv[1]) == "-h" || std::string (argv[1]) == "--help")
  {
    std::fprintf (argc == 2 ? stdout : stderr, "Usage: %s OUTPUT_DIR\n"
                  "Writes table_mug.pcd, gripper.obj and demo_poses.txt (deterministic).\n", argv[0]);
    return argc == 2 ? 0 : 2;
  }
  const std::filesystem::path dir (argv[1]);
  if (!std::filesystem::is_directory (dir))
  {
    std::fprintf (stderr, "make_demo_scene: error: '%s' is not a directory\n", argv[1]);
    return 1;
  }
  const pcl::PointCloud<pcl::PointXYZ> scene = makeScene ();
  const std::filesystem::path pcd = dir / "table_mug.pcd";
  const std::string tmp = pcd.string () + ".tmp";
  pcl::PCDWriter writer;
  if (writer.writeBinary (tmp, scene) != 0)
  {
    std::remove (tmp.c_str ());
    std::fprintf (stderr, "make_demo_scene: error: cannot write '%s'\n", pcd.c_str ());
    return 1;
  }
  std::error_code ec;
  std::filesystem::rename (tmp, pcd, ec);
  if (ec || !writeText (dir / "gripper.obj", makeGripperObj ()) || !writeText (dir / "demo_poses.txt", makePoses ()))
  {
    std::fprintf (stderr, "make_demo_scene: error: cannot write into '%s'\n", argv[1]);
    return 1;
  }
  std::printf ("Wrote %s (%zu points), gripper.obj, demo_poses.txt\n", pcd.c_str (), scene.size ());
  return 0;
}
