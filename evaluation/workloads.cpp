// SPDX-License-Identifier: BSD-3-Clause
#include "workloads.h"
#include "mesh_sampling.h"

#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/covariance_estimation.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>

namespace pcl_probcollision_eval
{
using namespace pcl_probcollision;

void
calibratedSurface (std::vector<OursSetting>& settings)
{
  for (OursSetting& s : settings)
    s.request.surface_calibrated = s.request.surface;  // the maps are the surface layer's
}

std::vector<OursSetting>
oursSettings (bool full, const std::vector<double>& merge, const std::vector<double>& gate,
              const std::vector<double>& stop, const std::vector<double>& cap, const std::vector<double>& cloud_merge)
{
  std::vector<OursSetting> s;
  // "default" is exactly what a user gets; "max" the paper's model (measured positions).
  const OursSetting defaults;
  const bool projection = defaults.model.surface_projection;
  // The separators alone and the surface layer on, whichever the library's default is: the
  // names stay when the default changes (one of the two then answers as "default" does).
  OursSetting classifier = defaults;
  classifier.name = "classifier";
  classifier.request.surface = false;
  classifier.model.surface = false;
  OursSetting surface = defaults;
  surface.name = "surface";
  surface.request.surface = true;
  surface.model.surface = true;
  // The surface layer pooled with the separators (the mean of the two P).
  OursSetting pooled = surface;
  pooled.name = "pooled";
  pooled.request.surface_pooled = true;
  // The ladder: the separators first, the surface layer where they leave the answer open.
  OursSetting ladder = surface;
  ladder.name = "ladder";
  ladder.request.surface_ladder = true;
  // The ladder with a distance asked for (CollisionRequest::distance): every near-contact answer
  // carries the surface layer's distance, including the separators' sure collisions; the
  // surface layer then visits every pair within reach, as exhaustive does.
  OursSetting ladder_distance = ladder;
  ladder_distance.name = "ladder-distance";
  ladder_distance.request.distance = true;
  // The surface layer on models of 20 neighbours instead of 10 (covariances, projected
  // positions and normals): surer near contact in the dense room, not in the sparse one; on the
  // chart, not the default (docs/SURFACE.md, "Twenty neighbours").
  OursSetting surface_k20 = surface;
  surface_k20.name = "surface-k20";
  surface_k20.model.k = 20;
  // The paper's model: also unmerged, whatever the default resolution.
  OursSetting other = classifier;
  other.name = projection ? "max" : "projected";
  other.model.surface_projection = !projection;
  other.model.noise_resolution = 0.0;
  s.push_back (defaults);
  s.push_back (classifier);
  s.push_back (surface);
  s.push_back (pooled);
  s.push_back (ladder);
  s.push_back (ladder_distance);
  s.push_back (surface_k20);
  s.push_back (other);
  // Issue #17 item 1: samples closer than c noise sigmas merged ("merge<c>"), or only where the
  // noise is at least the local sample spacing ("gate<c>"), or the whole cloud where it is
  // sampled finer than its noise ("cloudmerge<c>"), or the hierarchy not split within
  // c point sigmas ("stop<c>"); separators and surface layer each.
  auto addVariant = [&] (const std::string& prefix, double c, const std::function<void (CloudModelParams&)>& change) {
    std::ostringstream name;
    name << c;
    for (const OursSetting* base : {&classifier, &surface})
    {
      OursSetting variant = *base;
      variant.name = (base == &surface ? "surface-" : "") + prefix + name.str ();
      change (variant.model);
      s.push_back (variant);
    }
  };
  auto merged = [] (double c, CloudModelParams::ResolutionGate where) {
    return [c, where] (CloudModelParams& m) {
      m.noise_resolution = c;
      m.noise_resolution_gate = where;
    };
  };
  for (const double c : merge)
    addVariant ("merge", c, merged (c, CloudModelParams::ResolutionGate::Everywhere));
  for (const double c : gate)
    addVariant ("gate", c, merged (c, CloudModelParams::ResolutionGate::WhereNoiseExceedsSpacing));
  for (const double c : cloud_merge)
    addVariant ("cloudmerge", c, merged (c, CloudModelParams::ResolutionGate::WholeCloud));
  for (const double c : stop)
    addVariant ("stop", c, [c] (CloudModelParams& m) { m.hierarchy.noise_stop = c; });
  // Issue #17 item 2: the separators' work capped at n leaf-pair fits a query.
  for (const double n : cap)
  {
    OursSetting capped = classifier;
    capped.request.max_leaf_fits = static_cast<std::size_t> (n);
    capped.name = "cap" + std::to_string (capped.request.max_leaf_fits);
    s.push_back (capped);
    // The ladder with its surface rung capped at about n leaf pairs (max_surface_pairs).
    OursSetting ladder_capped = ladder;
    ladder_capped.request.max_surface_pairs = static_cast<std::size_t> (n);
    ladder_capped.name = "ladder-cap" + std::to_string (ladder_capped.request.max_surface_pairs);
    s.push_back (ladder_capped);
  }
  if (!full)
    return s;
  auto add = [&] (const std::string& name, auto change) {
    OursSetting o = defaults;
    o.name = name;
    o.model.surface_projection = true;
    change (o);
    s.push_back (o);
  };
  add ("k20", [] (OursSetting& o) { o.model.k = 20; });
  add ("C10", [] (OursSetting& o) { o.request.classifier.C = 10.0; });
  add ("C100", [] (OursSetting& o) { o.request.classifier.C = 100.0; });
  add ("nmax10", [] (OursSetting& o) { o.model.hierarchy.n_max = 10; o.model.hierarchy.n_min = 5; });
  add ("nmax40", [] (OursSetting& o) { o.model.hierarchy.n_max = 40; });
  add ("sigmamax0.02", [] (OursSetting& o) { o.model.hierarchy.sigma_max = 0.02; });
  add ("eps0", [] (OursSetting& o) { o.model.hierarchy.epsilon = 0.0; });
  add ("octree", [] (OursSetting& o) { o.model.hierarchy.split_style = BVHParams::SplitStyle::Octree; });
  add ("linear", [] (OursSetting& o) { o.request.classifier.kernel = KernelMode::Linear; });
  add ("rff", [] (OursSetting& o) { o.request.classifier.kernel = KernelMode::RFF; });
  add ("stochastic", [] (OursSetting& o) { o.request.traversal = TraversalMode::Stochastic; });
  add ("expandedbv", [] (OursSetting& o) { o.request.traversal = TraversalMode::ExpandedBV; });
  add ("deferkernel", [] (OursSetting& o) { o.request.defer_kernel_fits = true; });
  add ("rff256", [] (OursSetting& o) { o.request.classifier.rff_features_large = o.request.classifier.rff_features; });
  return s;
}

pcl::PointCloud<pcl::PointNormal>::Ptr
orientedScan (const CloudXYZ& noisy, const Outward& outward, int k)
{
  if (outward.size () != noisy.size ())
    throw std::logic_error ("orientedScan: " + std::to_string (outward.size ()) + " sides for " +
                            std::to_string (noisy.size ()) + " points");
  CovarianceEstimation<pcl::PointXYZ> estimation;
  estimation.setInputCloud (noisy.makeShared ());
  estimation.setKSearch (k);
  estimation.setComputeSurface (true);
  pcl::PointCloud<Covariance> unused;
  estimation.compute (unused);
  const std::vector<Eigen::Vector3f>& normals = estimation.getNormals ();
  pcl::PointCloud<pcl::PointNormal>::Ptr out (new pcl::PointCloud<pcl::PointNormal>);
  out->resize (noisy.size ());
  for (std::size_t i = 0; i < noisy.size (); ++i)
  {
    pcl::PointNormal& p = (*out)[i];
    p.getVector3fMap () = noisy[i].getVector3fMap ();
    Eigen::Vector3f n = i < normals.size () ? normals[i] : Eigen::Vector3f::Zero ();
    if (n.dot (outward[i]) < 0.0f)
      n = -n;
    // No plane (too few distinct neighbours): no normal, the model orients it by propagation.
    if (n.isZero ())
      n.setConstant (std::numeric_limits<float>::quiet_NaN ());
    p.getNormalVector3fMap () = n;
  }
  return out;
}

OursModels
buildOursModels (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma,
                 const CloudModelParams& model, BuildRow& build, const ScanSides& sides, const Solids& solids)
{
  CloudModelParams params = model;
  params.noise = SensorNoiseModel::isotropic (sigma);
  CloudModelParams robot_params = params, env_params = params;
  robot_params.closed_objects = model.closed_objects && solids.robot;
  env_params.closed_objects = model.closed_objects && solids.env;
  const bool scans = sides.robot && sides.env && model.surface;
  pcl::PointCloud<pcl::PointNormal>::Ptr robot_scan, env_scan;
  if (scans)
  {
    robot_scan = orientedScan (*robot, *sides.robot, model.k);
    env_scan = orientedScan (*env, *sides.env, model.k);
  }
  const auto start = std::chrono::steady_clock::now ();
  OursModels m;
  m.robot = scans ? buildCloudModel (*robot_scan, robot_params, nullptr, nullptr, "robot")
                  : buildCloudModel (*robot, robot_params, nullptr, nullptr, "robot");
  m.env = scans ? buildCloudModel (*env_scan, env_params, nullptr, nullptr, "environment")
                : buildCloudModel (*env, env_params, nullptr, nullptr, "environment");
  build.build_ms = std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - start).count ();
  build.memory_bytes = static_cast<double> (m.robot->bytes () + m.env->bytes ());
  build.nodes = static_cast<double> (m.robot->hierarchy ().nodes ().size () + m.env->hierarchy ().nodes ().size ());
  build.points = static_cast<double> (m.robot->size () + m.env->size ());
  return m;
}

PoseQuery
oursQuery (const OursModels& models, const CollisionRequest& request,
           std::function<void (std::size_t, std::size_t, double)> on_query)
{
  auto classifier = std::make_shared<const RobustClassifier> (request.classifier);
  const int features = request.classifier.rff_features;
  const CloudModel::ConstPtr a = models.robot, b = models.env;
  return [a, b, classifier, request, on_query, features] (const Eigen::Isometry3d& T) {
    CollisionResult result;
    Answer answer;
    // T places the robot (A) in the environment's (B's) frame; collide() maps B into A's.
    if (!collide (*a, *b, T.inverse (), request, result, classifier.get ()))
      throw std::runtime_error ("our query failed: " + result.message);
    answer.score = result.probability;
    answer.verdict = verdictName (result.verdict);
    answer.signed_distance = result.signed_distance;
    answer.signed_distance_std = result.signed_distance_std;
    answer.surface = request.surface;
    answer.answered_by = answeredByName (result.answered_by);
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

PoseQuery
buildOurs (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma, const OursSetting& setting,
           BuildRow& build, std::function<void (std::size_t, std::size_t, double)> on_query, const ScanSides& sides,
           const Solids& solids)
{
  return oursQuery (buildOursModels (robot, env, sigma, setting.model, build, sides, solids), setting.request,
                    std::move (on_query));
}

CloudXYZ::Ptr
sampleCount (const TriangleMesh& mesh, std::size_t target, std::uint64_t seed, Outward* outward, bool vertices)
{
  // sampleMesh keeps every vertex: aim the area samples at what the vertices leave (without
  // them, at the whole target).
  const double area_points =
      vertices ? std::max (0.5 * target, static_cast<double> (target) - mesh.vertices.size ()) : static_cast<double> (target);
  const double spacing = std::sqrt (pcl_probcollision::io::meshArea (mesh) / area_points);
  const pcl::PointCloud<pcl::PointNormal> with =
      pcl_probcollision::io::sampleMeshWithNormals (mesh, spacing, seed, pcl_probcollision::io::kMaxMeshSamples, vertices);
  CloudXYZ::Ptr cloud (new CloudXYZ);
  cloud->resize (with.size ());
  if (outward)
    outward->resize (with.size ());
  for (std::size_t i = 0; i < with.size (); ++i)
  {
    (*cloud)[i].getVector3fMap () = with[i].getVector3fMap ();
    if (outward)
      (*outward)[i] = with[i].getNormalVector3fMap ();
  }
  return cloud;
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
