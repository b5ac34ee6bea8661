// SPDX-License-Identifier: BSD-3-Clause
// The whole query on FCL's piano-in-a-room models (../shared/data/meshes, millimetres): both
// meshes sampled to about 10,000 points, Gaussian noise of 0.5% of the piano's bounding-box
// diagonal added to every sample and declared as isotropic sensor noise, default parameters.
// Prints the build time (covariance estimation + hierarchy, both clouds) and the query time
// over random piano poses inside the room (median, p90, max).
#include "mesh_input.h"
#include "mesh_sampling.h"

#include <pcl_probcollision/probabilistic_collision.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

using namespace pcl_probcollision;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace
{
struct Workload
{
  Cloud::Ptr piano, room;
  double sigma = 0.0;
  Eigen::Vector3d room_lo, room_hi;
  std::vector<Eigen::Isometry3d> poses;
};

Cloud::Ptr
noisySamples (const std::string& file, std::size_t target_points, double sigma, std::uint64_t seed,
              Eigen::Vector3d* lo = nullptr, Eigen::Vector3d* hi = nullptr)
{
  pcl_probcollision::io::TriangleMesh mesh;
  std::string error;
  if (!pcl_probcollision::io::loadTriangleMesh (file, mesh, error))
    throw std::runtime_error (error);
  // Every vertex is kept too: aim the area samples at what the vertices leave.
  const double area_points = std::max (0.5 * target_points, static_cast<double> (target_points) - mesh.vertices.size ());
  const double spacing = std::sqrt (pcl_probcollision::io::meshArea (mesh) / area_points);
  Cloud::Ptr cloud (new Cloud (pcl_probcollision::io::sampleMesh (mesh, spacing, seed)));
  std::mt19937_64 rng (seed + 1);
  std::normal_distribution<double> noise (0.0, sigma);
  Eigen::Vector3d l = Eigen::Vector3d::Constant (1e300), h = -l;
  for (auto& p : cloud->points)
  {
    p.x += static_cast<float> (noise (rng));
    p.y += static_cast<float> (noise (rng));
    p.z += static_cast<float> (noise (rng));
    l = l.cwiseMin (p.getVector3fMap ().cast<double> ());
    h = h.cwiseMax (p.getVector3fMap ().cast<double> ());
  }
  if (lo)
    *lo = l;
  if (hi)
    *hi = h;
  return cloud;
}

const Workload&
workload ()
{
  static const Workload w = [] {
    Workload w;
    const std::string dir = std::string (PCL_PROBCOLLISION_SHARED_DATA) + "/meshes/";
    pcl_probcollision::io::TriangleMesh rob;
    std::string error;
    if (!pcl_probcollision::io::loadTriangleMesh (dir + "piano_room_rob.obj", rob, error))
      throw std::runtime_error (error);
    w.sigma = 0.005 * pcl_probcollision::io::meshDiagonal (rob);
    w.piano = noisySamples (dir + "piano_room_rob.obj", 10000, w.sigma, 1);
    w.room = noisySamples (dir + "piano_room_env.obj", 10000, w.sigma, 2, &w.room_lo, &w.room_hi);
    std::mt19937_64 rng (3);
    std::uniform_real_distribution<double> u (0.0, 1.0);
    for (int i = 0; i < 500; ++i)
    {
      // One draw a statement: the order of a call's arguments is unspecified (g++ and clang
      // differ), and with it the workload.
      const double x = u (rng);
      const double y = u (rng);
      const double z = u (rng);
      const Eigen::Vector3d t = w.room_lo + (w.room_hi - w.room_lo).cwiseProduct (Eigen::Vector3d (x, y, z));
      const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom ();
      w.poses.push_back (Eigen::Translation3d (t) * q);
    }
    return w;
  }();
  return w;
}

/** \brief Both clouds' settings: isotropic noise of the workload. */
CloudModelParams
modelParams (const Workload& w)
{
  CloudModelParams params;
  params.noise = SensorNoiseModel::isotropic (w.sigma);
  return params;
}

void
BM_BuildBothClouds (benchmark::State& state)
{
  const Workload& w = workload ();
  for (auto _ : state)
  {
    const CloudModel::ConstPtr piano = buildCloudModel (*w.piano, modelParams (w));
    const CloudModel::ConstPtr room = buildCloudModel (*w.room, modelParams (w));
    benchmark::DoNotOptimize (piano->size () + room->size ());
    state.counters["build_ms_per_cloud"] = (piano->buildMilliseconds () + room->buildMilliseconds ()) / 2.0;
  }
  state.counters["points_piano"] = static_cast<double> (w.piano->size ());
  state.counters["points_room"] = static_cast<double> (w.room->size ());
  state.counters["sigma_mm"] = w.sigma;
}
BENCHMARK (BM_BuildBothClouds)->Unit (benchmark::kMillisecond)->Iterations (3);

void
BM_QueryRandomPoses (benchmark::State& state)
{
  const Workload& w = workload ();
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputModel (buildCloudModel (*w.piano, modelParams (w)));  // built once, as a planner would
  pc.setTargetModel (buildCloudModel (*w.room, modelParams (w)));
  CollisionResult r;
  std::vector<double> ms;
  std::size_t verdicts[4] = {0, 0, 0, 0};
  for (auto _ : state)
  {
    ms.clear ();
    for (const Eigen::Isometry3d& pose : w.poses)
    {
      const auto t0 = std::chrono::steady_clock::now ();
      pc.compute (pose, r);
      ms.push_back (std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - t0).count ());
      ++verdicts[static_cast<int> (r.verdict)];
    }
  }
  std::sort (ms.begin (), ms.end ());
  state.counters["poses"] = static_cast<double> (ms.size ());
  state.counters["median_ms"] = ms[ms.size () / 2];
  state.counters["p90_ms"] = ms[ms.size () * 9 / 10];
  state.counters["max_ms"] = ms.back ();
  const double runs = static_cast<double> (state.iterations ());
  state.counters["free"] = verdicts[1] / runs;
  state.counters["contact"] = verdicts[2] / runs;
  state.counters["collision"] = verdicts[3] / runs;
}
BENCHMARK (BM_QueryRandomPoses)->Unit (benchmark::kMillisecond)->Iterations (1);
} // namespace

BENCHMARK_MAIN ();
