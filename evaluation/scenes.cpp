// SPDX-License-Identifier: BSD-3-Clause
// W3 of the evaluation: the segmented real scans of ../shared/data/scenes, queried as SCENES.md
// lists them, each camera with its own sensor model. The check, never the training set.
#include "workloads.h"

#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/io/pcd_io.h>

#include <chrono>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pcl_probcollision_eval
{
using namespace pcl_probcollision;

void
evaluateScenes (const std::string& data_dir, const std::vector<double>& cloud_merge, std::vector<QueryRow>& rows,
                int& right, int& total)
{
  const std::string dir = data_dir + "/scenes/";
  std::ifstream csv (dir + "queries.csv");
  if (!csv)
    throw std::runtime_error ("cannot read " + dir + "queries.csv");
  std::string line;
  std::getline (csv, line);  // header
  right = total = 0;
  while (std::getline (csv, line))
  {
    std::stringstream ss (line);
    std::vector<std::string> f;
    for (std::string field; std::getline (ss, field, ',');)
      f.push_back (field);
    if (f.size () < 9)
      throw std::runtime_error ("queries.csv: short line: " + line);
    CloudXYZ::Ptr a (new CloudXYZ), b (new CloudXYZ);
    if (pcl::io::loadPCDFile (dir + f[2], *a) != 0 || pcl::io::loadPCDFile (dir + f[3], *b) != 0)
      throw std::runtime_error ("cannot read " + dir + f[2] + " or " + f[3]);
    const SensorNoiseModel noise = f[1] == "stereo_mug" ? SensorNoiseModel::stereo () : SensorNoiseModel::kinect ();
    const Eigen::Isometry3d pose (Eigen::Translation3d (std::stod (f[4]), std::stod (f[5]), std::stod (f[6])));
    for (const OursSetting& s : oursSettings (false, {}, {}, {}, {}, cloud_merge))
    {
      ProbabilisticCollision<pcl::PointXYZ> pc;
      CloudModelParams params = s.model;
      params.noise = noise;
      pc.setInputCloud (a);
      pc.setTargetCloud (b);
      pc.setInputModelParams (params);
      pc.setTargetModelParams (params);
      pc.setRequest (s.request);
      CollisionResult r;
      pc.setInputModel (buildCloudModel (*a, params, nullptr, nullptr, f[2]));
      pc.setTargetModel (buildCloudModel (*b, params, nullptr, nullptr, f[3]));
      const auto start = std::chrono::steady_clock::now ();
      if (!pc.compute (pose, r))
        throw std::runtime_error (f[0] + ": " + r.message);
      QueryRow row;
      row.workload = "W3";
      row.sigma_eff = std::numeric_limits<double>::quiet_NaN ();  // per-point models: no single scale
      row.query = f[0];
      // SCENES.md: signed distance to the table plane (empty for object-object queries).
      row.exact_distance = f.size () > 9 && !f[9].empty () ? std::stod (f[9]) : std::stod (f[8]);
      row.exact_collision = f[7] != "free";
      row.near_contact = f[7] == "in-contact";
      row.method = "ours";
      row.setting = s.name;
      row.score = r.probability;
      row.verdict = verdictName (r.verdict);
      row.signed_distance = r.signed_distance;
      row.signed_distance_std = r.signed_distance_std;
      row.answered_by = answeredByName (r.answered_by);
      row.query_us = std::chrono::duration<double, std::micro> (std::chrono::steady_clock::now () - start).count ();
      rows.push_back (row);
      // Resting objects may read contact or collision, never free; lifted ones must read free.
      if (s.name == "default")
      {
        ++total;
        right += (f[7] == "free") == (r.verdict == Verdict::Free) ? 1 : 0;
      }
    }
  }
}
} // namespace pcl_probcollision_eval
