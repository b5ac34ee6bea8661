// SPDX-License-Identifier: BSD-3-Clause
#include "workloads.h"
#include "mesh_sampling.h"

#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

namespace pcl_probcollision_eval
{
using namespace pcl_probcollision;

std::vector<OursSetting>
oursSettings (bool full)
{
  std::vector<OursSetting> s;
  const CollisionRequest defaults;
  // "default" is exactly what a user gets; "max" the paper's model (measured positions).
  const bool projection = ProbabilisticCollision<pcl::PointXYZ> ().getSurfaceProjection ();
  s.push_back ({"default", defaults, projection});
  s.push_back ({projection ? "max" : "projected", defaults, !projection});
  if (!full)
    return s;
  auto add = [&] (const std::string& name, auto change) {
    OursSetting o {name, defaults, true};
    change (o);
    s.push_back (o);
  };
  add ("k20", [] (OursSetting& o) { o.k = 20; });
  add ("C10", [] (OursSetting& o) { o.request.classifier.C = 10.0; });
  add ("C100", [] (OursSetting& o) { o.request.classifier.C = 100.0; });
  add ("nmax10", [] (OursSetting& o) { o.request.hierarchy.n_max = 10; o.request.hierarchy.n_min = 5; });
  add ("nmax40", [] (OursSetting& o) { o.request.hierarchy.n_max = 40; });
  add ("sigmamax0.02", [] (OursSetting& o) { o.request.hierarchy.sigma_max = 0.02; });
  add ("eps0", [] (OursSetting& o) { o.request.hierarchy.epsilon = 0.0; });
  add ("octree", [] (OursSetting& o) { o.request.hierarchy.split_style = BVHParams::SplitStyle::Octree; });
  add ("linear", [] (OursSetting& o) { o.request.classifier.kernel = KernelMode::Linear; });
  add ("rff", [] (OursSetting& o) { o.request.classifier.kernel = KernelMode::RFF; });
  add ("stochastic", [] (OursSetting& o) { o.request.traversal = TraversalMode::Stochastic; });
  add ("expandedbv", [] (OursSetting& o) { o.request.traversal = TraversalMode::ExpandedBV; });
  add ("deferkernel", [] (OursSetting& o) { o.request.defer_kernel_fits = true; });
  add ("rff256", [] (OursSetting& o) { o.request.classifier.rff_features_large = o.request.classifier.rff_features; });
  return s;
}

PoseQuery
buildOurs (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma, const OursSetting& setting,
           BuildRow& build, std::function<void (std::size_t, std::size_t, double)> on_query)
{
  auto pc = std::make_shared<ProbabilisticCollision<pcl::PointXYZ>> ();
  pc->setInputCloud (robot);
  pc->setTargetCloud (env);
  pc->setInputNoise (SensorNoiseModel::isotropic (sigma));
  pc->setTargetNoise (SensorNoiseModel::isotropic (sigma));
  pc->setSurfaceProjection (setting.projection);
  pc->setKSearch (setting.k);
  CollisionRequest request = setting.request;
  request.enable_timings = true;
  pc->setRequest (request);
  // The first query builds both hierarchies: a pose far away costs no leaf pair.
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity ();
  far.translation () = Eigen::Vector3d::Constant (1e9);
  CollisionResult r;
  if (!pc->compute (far, r))
    throw std::runtime_error ("our method failed to build: " + r.message);
  build.build_ms = r.build_ms;
  const auto a = pc->getInputHierarchy ();
  const auto b = pc->getTargetHierarchy ();
  build.memory_bytes = static_cast<double> (a->bytes () + b->bytes ());
  build.nodes = static_cast<double> (a->nodes ().size () + b->nodes ().size ());
  const int features = setting.request.classifier.rff_features;
  return [pc, on_query, features] (const Eigen::Isometry3d& T) {
    CollisionResult result;
    Answer answer;
    if (!pc->compute (T, result))
      throw std::runtime_error ("our query failed: " + result.message);
    answer.score = result.probability;
    answer.verdict = verdictName (result.verdict);
    if (on_query)
    {
      const double linear = static_cast<double> (result.leaf_pairs_tested - result.kernel_leaf_pairs);
      const double total = static_cast<double> (result.leaf_pairs_tested);
      on_query (result.leaf_pairs_tested, result.kernel_leaf_pairs,
                total > 0 ? (3.0 * linear + features * static_cast<double> (result.kernel_leaf_pairs)) / total : 0.0);
    }
    return answer;
  };
}

CloudXYZ::Ptr
sampleCount (const TriangleMesh& mesh, std::size_t target, std::uint64_t seed)
{
  // sampleMesh keeps every vertex: aim the area samples at what the vertices leave.
  const double area_points = std::max (0.5 * target, static_cast<double> (target) - mesh.vertices.size ());
  const double spacing = std::sqrt (pcd_collision::meshArea (mesh) / area_points);
  return CloudXYZ::Ptr (new CloudXYZ (pcd_collision::sampleMesh (mesh, spacing, seed)));
}

CloudXYZ::Ptr
addNoise (const CloudXYZ& clean, double sigma, std::uint64_t seed)
{
  CloudXYZ::Ptr noisy (new CloudXYZ (clean));
  std::mt19937_64 rng (seed);
  for (auto& p : noisy->points)
  {
    p.x += static_cast<float> (sigma * standardNormal (rng));
    p.y += static_cast<float> (sigma * standardNormal (rng));
    p.z += static_cast<float> (sigma * standardNormal (rng));
  }
  return noisy;
}
} // namespace pcl_probcollision_eval
