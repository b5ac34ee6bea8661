// SPDX-License-Identifier: BSD-3-Clause
// A PCL pipeline with ProbabilisticCollision as one more filter:
//
//   load scan -> PassThrough (z) -> VoxelGrid (5 mm) -> StatisticalOutlierRemoval
//     -> SACSegmentation (table plane) -> gripper posed on the table
//     -> ProbabilisticCollision::filter: the scene points the gripper would touch -> save
//
// Usage: gripper_filter [SCAN.pcd] [OUTPUT.pcd] [DEPTH]
//   SCAN    default ../shared/data/scans/table_scene_mug_stereo_textured.pcd
//   OUTPUT  default gripper_contacts.pcd (written atomically: a new temporary file beside it, then
//           a rename)
//   DEPTH   how far the fingertips go below the table surface, metres (default 0.01)
//
// The gripper is the one of data/gripper.obj (palm 12 x 3 x 2 cm, two 1 x 2 x 6 cm fingers 10 cm
// apart), generated here as a box-surface cloud so that the example needs nothing but PCL.

#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/common/transforms.h>
#include <pcl/filters/passthrough.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

using PointT = pcl::PointXYZRGB;
using Cloud = pcl::PointCloud<PointT>;

namespace
{
/** \brief Surface samples of an axis-aligned box at about `step` spacing. */
void
addBox (Cloud& cloud, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float step)
{
  const Eigen::Vector3f size = hi - lo;
  int n[3];
  for (int a = 0; a < 3; ++a)
    n[a] = std::max (1, static_cast<int> (std::ceil (size[a] / step)));
  PointT p;
  p.r = 40;
  p.g = 120;
  p.b = 255;
  for (int i = 0; i <= n[0]; ++i)
    for (int j = 0; j <= n[1]; ++j)
      for (int k = 0; k <= n[2]; ++k)
      {
        const bool on_surface = i == 0 || i == n[0] || j == 0 || j == n[1] || k == 0 || k == n[2];
        if (!on_surface)
          continue;
        p.getVector3fMap () = lo + Eigen::Vector3f (size[0] * i / n[0], size[1] * j / n[1], size[2] * k / n[2]);
        cloud.push_back (p);
      }
}

/** \brief The gripper in its own frame: origin at the fingertips' bottom, fingers along -z. */
Cloud::Ptr
makeGripper (float step)
{
  auto g = pcl::make_shared<Cloud> ();
  addBox (*g, {-0.06f, -0.015f, 0.06f}, {0.06f, 0.015f, 0.08f}, step);  // palm
  addBox (*g, {-0.06f, -0.01f, 0.0f}, {-0.05f, 0.01f, 0.06f}, step);   // left finger
  addBox (*g, {0.05f, -0.01f, 0.0f}, {0.06f, 0.01f, 0.06f}, step);     // right finger
  return g;
}

/** \brief The depth argument as a finite number, read whole ("0.01x" is refused, not read as 0.01). */
bool
parseDepth (const char* text, double& depth)
{
  char* end = nullptr;
  depth = std::strtod (text, &end);
  return *text != '\0' && *end == '\0' && std::isfinite (depth);
}

/** \brief Why `out` cannot be written without harm, or "": it is the scan (the same file through any
  * link), a directory, or in a directory that does not exist. */
std::string
outputProblem (const std::string& out, const std::string& scan)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  bool same = fs::exists (out, ec) && fs::exists (scan, ec) && fs::equivalent (out, scan, ec);
  if (!same)
  {
    const fs::path a = fs::weakly_canonical (out, ec);
    const fs::path b = fs::weakly_canonical (scan, ec);
    same = !ec && a == b;
  }
  if (same)
    return "is the input scan; refusing to overwrite it";
  if (fs::is_directory (out, ec))
    return "is a directory";
  const fs::path dir = fs::path (out).has_parent_path () ? fs::path (out).parent_path () : fs::path (".");
  if (!fs::is_directory (dir, ec))
    return "cannot be written: directory '" + dir.string () + "' does not exist";
  return "";
}

/** \brief Writes the cloud to a temporary file beside `path`, then renames it over `path`. The
  * temporary file gets a fresh name (mkstemp: `.NAME.tmp-XXXXXX`), never an existing file's: a
  * fixed `path + ".tmp"` overwrote, and then renamed away, a scan called OUTPUT.tmp. */
bool
saveAtomically (const std::string& path, const Cloud& cloud)
{
  namespace fs = std::filesystem;
  const fs::path target (path);
  const fs::path dir = target.has_parent_path () ? target.parent_path () : fs::path (".");
  const std::string pattern = (dir / ("." + target.filename ().string () + ".tmp-XXXXXX")).string ();
  std::vector<char> name (pattern.begin (), pattern.end ());
  name.push_back ('\0');
  const int fd = ::mkstemp (name.data ());
  if (fd < 0)
    return false;
  // mkstemp creates the file 0600; the output gets the usual 0666 & ~umask.
  const mode_t mask = ::umask (0);
  ::umask (mask);
  ::fchmod (fd, 0666 & ~mask);
  ::close (fd);
  const std::string tmp (name.data ());
  if (pcl::io::savePCDFileBinary (tmp, cloud) != 0 || std::rename (tmp.c_str (), path.c_str ()) != 0)
  {
    std::remove (tmp.c_str ());
    return false;
  }
  return true;
}
} // namespace

int
main (int argc, char** argv)
{
  const std::string scan_path = argc > 1 ? argv[1] : "../shared/data/scans/table_scene_mug_stereo_textured.pcd";
  const std::string out_path = argc > 2 ? argv[2] : "gripper_contacts.pcd";
  if (argc > 4 || (argc > 1 && (std::string (argv[1]) == "-h" || std::string (argv[1]) == "--help")))
  {
    std::printf ("Usage: %s [SCAN.pcd] [OUTPUT.pcd] [DEPTH]\n", argv[0]);
    return argc > 4 ? 2 : 0;
  }
  double depth = 0.01;
  if (argc > 3 && !parseDepth (argv[3], depth))
  {
    std::fprintf (stderr, "gripper_filter: error: DEPTH '%s' is not a finite number (metres below the table)\n", argv[3]);
    return 2;
  }
  // Checked before the work, so that a long run does not end in an error or overwrite the scan.
  const std::string problem = outputProblem (out_path, scan_path);
  if (!problem.empty ())
  {
    std::fprintf (stderr, "gripper_filter: error: OUTPUT '%s' %s\n", out_path.c_str (), problem.c_str ());
    return 2;
  }

  // 1. Load and clean up the scan with stock PCL filters.
  auto scan = pcl::make_shared<Cloud> ();
  if (pcl::io::loadPCDFile (scan_path, *scan) != 0 || scan->empty ())
  {
    std::fprintf (stderr, "gripper_filter: error: cannot read '%s'\n", scan_path.c_str ());
    return 1;
  }
  auto cropped = pcl::make_shared<Cloud> ();
  pcl::PassThrough<PointT> pass;
  pass.setInputCloud (scan);
  pass.setFilterFieldName ("z");
  pass.setFilterLimits (0.0f, 1.5f);
  pass.filter (*cropped);

  auto voxels = pcl::make_shared<Cloud> ();
  pcl::VoxelGrid<PointT> grid;
  grid.setInputCloud (cropped);
  grid.setLeafSize (0.005f, 0.005f, 0.005f);
  grid.filter (*voxels);

  auto scene = pcl::make_shared<Cloud> ();
  pcl::StatisticalOutlierRemoval<PointT> sor;
  sor.setInputCloud (voxels);
  sor.setMeanK (50);
  sor.setStddevMulThresh (1.0);
  sor.filter (*scene);
  std::printf ("scan %zu points -> PassThrough %zu -> VoxelGrid %zu -> SOR %zu\n", scan->size (), cropped->size (),
               voxels->size (), scene->size ());

  // 2. The table plane.
  pcl::SACSegmentation<PointT> seg;
  seg.setOptimizeCoefficients (true);
  seg.setModelType (pcl::SACMODEL_PLANE);
  seg.setMethodType (pcl::SAC_RANSAC);
  seg.setDistanceThreshold (0.01);
  seg.setMaxIterations (1000);
  seg.setInputCloud (scene);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients plane;
  seg.segment (inliers, plane);
  if (inliers.indices.size () < 100)
  {
    std::fprintf (stderr, "gripper_filter: error: no table plane found\n");
    return 1;
  }
  // Unit normal towards the sensor (at the origin of the scan frame): d > 0.
  Eigen::Vector3f n (plane.values[0], plane.values[1], plane.values[2]);
  float d = plane.values[3] / n.norm ();
  n.normalize ();
  if (d < 0)
  {
    n = -n;
    d = -d;
  }
  // Where to put the gripper: the table point with the most table points around it (within
  // the gripper's reach), so that the fingers land on seen table, not in an occlusion shadow.
  const std::vector<int>& table = inliers.indices;
  std::size_t best_count = 0;
  Eigen::Vector3f best = (*scene)[table.front ()].getVector3fMap ();
  for (std::size_t a = 0; a < table.size (); a += 10)
  {
    const Eigen::Vector3f c = (*scene)[table[a]].getVector3fMap ();
    std::size_t count = 0;
    for (const int b : table)
      count += ((*scene)[b].getVector3fMap () - c).squaredNorm () < 0.07f * 0.07f;
    if (count > best_count)
    {
      best_count = count;
      best = c;
    }
  }
  const Eigen::Vector3f on_table = best - (n.dot (best) + d) * n;
  std::printf ("table plane: %zu inliers, normal (%.3f, %.3f, %.3f), d %.3f m\n", inliers.indices.size (), n.x (),
               n.y (), n.z (), d);

  // 3. The gripper, fingers pointing into the table, fingertips `depth` below its surface.
  Eigen::Vector3f x_axis = Eigen::Vector3f::UnitX () - n.x () * n;
  x_axis.normalize ();
  Eigen::Affine3f pose = Eigen::Affine3f::Identity ();
  pose.linear ().col (0) = x_axis;
  pose.linear ().col (1) = n.cross (x_axis);
  pose.linear ().col (2) = n;
  pose.translation () = on_table - static_cast<float> (depth) * n;
  auto gripper = pcl::make_shared<Cloud> ();
  pcl::transformPointCloud (*makeGripper (0.0025f), *gripper, pose);
  std::printf ("gripper: %zu points, fingertips at (%.3f, %.3f, %.3f), %.3f m below the table\n", gripper->size (),
               pose.translation ().x (), pose.translation ().y (), pose.translation ().z (), depth);

  // 4. ProbabilisticCollision is a pcl::FilterIndices: same calls as the filters above. The
  //    scene gets the stereo camera's noise model (the VIEWPOINT survives the filters); the
  //    gripper is exact (zero covariance).
  pcl_probcollision::ProbabilisticCollision<PointT> touch;
  touch.setInputCloud (scene);
  touch.setTargetCloud (gripper);
  touch.setTargetCovariances (
      pcl::make_shared<pcl::PointCloud<pcl_probcollision::Covariance>> (gripper->width, gripper->height));
  touch.setInputNoise (pcl_probcollision::SensorNoiseModel::stereo ());
  touch.setProbabilityThreshold (0.5);
  Cloud touched;
  touch.filter (touched);

  pcl_probcollision::CollisionResult result;
  if (!touch.compute (result))
  {
    std::fprintf (stderr, "gripper_filter: error: %s\n", result.message.c_str ());
    return 1;
  }
  std::printf ("pair: %s, P = %.4f; %zu of %zu scene points would be touched (P_i >= 0.5)\n",
               pcl_probcollision::verdictName (result.verdict), result.probability, touched.size (), scene->size ());

  // 5. Save them.
  if (touched.empty ())
  {
    std::printf ("no scene point would be touched; nothing written\n");
    return 0;
  }
  if (!saveAtomically (out_path, touched))
  {
    std::fprintf (stderr, "gripper_filter: error: cannot write '%s'\n", out_path.c_str ());
    return 1;
  }
  std::printf ("wrote %s\n", out_path.c_str ());
  return 0;
}
