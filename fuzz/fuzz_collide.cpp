// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer: arbitrary bytes -> two small clouds (with NaN / Inf / huge coordinates allowed),
// optional covariances (PSD by construction, or arbitrary), a pose and request parameters, then
// the full query through ProbabilisticCollision<PointXYZ> (covariance estimation, hierarchies,
// collide()). Any crash, sanitizer report or broken result contract aborts.
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/console/print.h>
#include <pcl/exceptions.h>

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>

using namespace pcl_probcollision;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace
{
#define FUZZ_REQUIRE(cond)                                                        \
  do                                                                              \
  {                                                                               \
    if (!(cond))                                                                  \
    {                                                                             \
      std::fprintf (stderr, "fuzz_collide: contract broken: %s (line %d)\n", #cond, __LINE__); \
      std::abort ();                                                              \
    }                                                                             \
  } while (0)

float
coordinate (FuzzedDataProvider& in, float scale)
{
  switch (in.ConsumeIntegralInRange<int> (0, 15))
  {
    case 0: return std::numeric_limits<float>::quiet_NaN ();
    case 1: return std::numeric_limits<float>::infinity ();
    case 2: return in.ConsumeFloatingPoint<float> ();  // anything, including 1e38 and denormals
    case 3: return 1e5f + in.ConsumeFloatingPointInRange<float> (-1.f, 1.f);
    default: return scale * in.ConsumeFloatingPointInRange<float> (-1.f, 1.f);
  }
}

Cloud::Ptr
cloud (FuzzedDataProvider& in)
{
  const int n = in.ConsumeIntegralInRange<int> (0, 48);
  const float scale = in.ConsumeBool () ? 0.1f : in.ConsumeFloatingPointInRange<float> (1e-6f, 1e3f);
  Cloud::Ptr c (new Cloud);
  for (int i = 0; i < n; ++i)
  {
    pcl::PointXYZ p;
    p.x = coordinate (in, scale);
    p.y = coordinate (in, scale);
    p.z = coordinate (in, scale);
    c->push_back (p);
  }
  c->is_dense = in.ConsumeBool ();  // may lie
  return c;
}

pcl::PointCloud<Covariance>::Ptr
covariances (FuzzedDataProvider& in, std::size_t n)
{
  if (!in.ConsumeBool ())
    return nullptr;  // estimated
  pcl::PointCloud<Covariance>::Ptr c (new pcl::PointCloud<Covariance>);
  const bool arbitrary = in.ConsumeIntegralInRange<int> (0, 7) == 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    Eigen::Matrix3d m;
    if (arbitrary)
    {
      for (int k = 0; k < 9; ++k)
        m.data ()[k] = in.ConsumeFloatingPoint<double> ();
    }
    else
    {
      Eigen::Matrix3d l = Eigen::Matrix3d::Zero ();
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k <= r; ++k)
          l (r, k) = in.ConsumeFloatingPointInRange<double> (-0.05, 0.05);
      m = l * l.transpose ();
    }
    c->push_back (Covariance (m));
  }
  return c;
}
} // namespace

extern "C" int
LLVMFuzzerInitialize (int*, char***)
{
  pcl::console::setVerbosityLevel (pcl::console::L_ALWAYS);
  return 0;
}

extern "C" int
LLVMFuzzerTestOneInput (const std::uint8_t* data, std::size_t size)
{
  FuzzedDataProvider in (data, size);
  ProbabilisticCollision<pcl::PointXYZ> pc;
  const auto a = cloud (in);
  const auto b = cloud (in);
  pc.setInputCloud (a);
  pc.setTargetCloud (b);
  pc.setInputCovariances (covariances (in, a->size ()));
  pc.setTargetCovariances (covariances (in, b->size ()));
  try
  {
    pc.setKSearch (in.ConsumeIntegralInRange<int> (-1, 12));
  }
  catch (const pcl::PCLException&)
  {
  }
  const double sigma = in.ConsumeFloatingPointInRange<double> (0.0, 0.05);
  if (sigma > 0.0)
  {
    pc.setInputNoise (SensorNoiseModel::isotropic (sigma));
    pc.setTargetNoise (SensorNoiseModel::isotropic (sigma));
  }
  CollisionRequest rq;
  rq.exhaustive = in.ConsumeBool ();
  rq.per_point = in.ConsumeBool ();
  rq.traversal = static_cast<TraversalMode> (in.ConsumeIntegralInRange<int> (0, 2));
  rq.seed = in.ConsumeIntegral<std::uint64_t> ();
  rq.rho_min = in.ConsumeFloatingPointInRange<double> (0.0, 1.0);
  BVHParams hierarchy;
  hierarchy.n_max = in.ConsumeIntegralInRange<int> (1, 40);
  hierarchy.n_min = in.ConsumeIntegralInRange<int> (1, hierarchy.n_max);
  // Bounded below the valid [0, 0.5): with a larger sibling overlap the hierarchy's size grows
  // exponentially with its depth (48 points, octree, epsilon 0.49: std::bad_alloc; epsilon 0.39:
  // 20 s under ASan, fuzz/regressions/). A known, documented defect (docs/RELIABILITY.md, "Found,
  // not fixed"); up to 0.15 a 48-point build stays below 1000 nodes.
  hierarchy.epsilon = in.ConsumeFloatingPointInRange<double> (0.0, 0.15);
  hierarchy.split_style = in.ConsumeBool () ? BVHParams::SplitStyle::Pca : BVHParams::SplitStyle::Octree;
  try
  {
    pc.setRequest (rq);
    pc.setHierarchyParams (hierarchy);
  }
  catch (const pcl::PCLException&)
  {
    return 0;  // rejected at the setter, as documented
  }
  const CollisionRequest& used = pc.getRequest ();

  double pose[6];
  for (double& v : pose)
    v = in.ConsumeBool () ? in.ConsumeFloatingPointInRange<double> (-0.2, 0.2) : in.ConsumeFloatingPoint<double> ();
  const Eigen::Isometry3d T = Eigen::Translation3d (pose[0], pose[1], pose[2]) *
                              Eigen::AngleAxisd (pose[5], Eigen::Vector3d::UnitZ ()) *
                              Eigen::AngleAxisd (pose[4], Eigen::Vector3d::UnitY ()) *
                              Eigen::AngleAxisd (pose[3], Eigen::Vector3d::UnitX ());
  if (std::getenv ("FUZZ_COLLIDE_VERBOSE"))  // to turn an artifact into a precise report
  {
    std::fprintf (stderr, "a: %zu points, b: %zu points, k %d, sigma %g, exhaustive %d, per_point %d, traversal %d, "
                  "rho_min %g, n_max %d, n_min %d, epsilon %g, split %d, pose %g %g %g %g %g %g\n",
                  a->size (), b->size (), pc.getKSearch (), sigma, used.exhaustive, used.per_point,
                  static_cast<int> (used.traversal), used.rho_min, pc.getHierarchyParams ().n_max, pc.getHierarchyParams ().n_min,
                  pc.getHierarchyParams ().epsilon, static_cast<int> (pc.getHierarchyParams ().split_style), pose[0], pose[1], pose[2],
                  pose[3], pose[4], pose[5]);
    for (const auto* c : {a.get (), b.get ()})
      for (const auto& p : c->points)
        std::fprintf (stderr, "  %.9g %.9g %.9g\n", p.x, p.y, p.z);
  }
  for (int round = 0; round < 2; ++round)  // the second reuses the hierarchies
  {
    CollisionResult r;
    const bool ok = pc.compute (T, r);
    FUZZ_REQUIRE (ok == r.ok ());
    if (!ok)
    {
      FUZZ_REQUIRE (std::isnan (r.probability));
      FUZZ_REQUIRE (r.verdict == Verdict::Unknown);
      FUZZ_REQUIRE (!r.message.empty ());
      continue;
    }
    FUZZ_REQUIRE (std::isfinite (r.probability));
    FUZZ_REQUIRE (r.probability >= 0.0 && r.probability <= 1.0);
    FUZZ_REQUIRE (r.verdict == verdictFor (r.probability, used));
    FUZZ_REQUIRE (r.points_a + r.points_b + r.points_skipped_nonfinite <= a->size () + b->size ());
    if (r.witness_side != 0)
    {
      FUZZ_REQUIRE (r.witness_point.allFinite ());
      FUZZ_REQUIRE (r.witness_index >= 0);
      FUZZ_REQUIRE (static_cast<std::size_t> (r.witness_index) < (r.witness_side > 0 ? a->size () : b->size ()));
    }
    if (used.per_point)
    {
      FUZZ_REQUIRE (r.probabilities_a.size () == a->size ());
      FUZZ_REQUIRE (r.probabilities_b.size () == b->size ());
      for (const auto* v : {&r.probabilities_a, &r.probabilities_b})
        for (const float p : *v)
          FUZZ_REQUIRE (std::isnan (p) || (p >= 0.0f && p <= 1.0f));
    }
  }
  return 0;
}
