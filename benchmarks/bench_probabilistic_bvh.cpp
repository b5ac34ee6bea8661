// SPDX-License-Identifier: BSD-3-Clause
// Build and traversal cost of the epsilon-overlap hierarchy (METHOD.md 8). Workloads are in
// the benchmark names and counters; nothing here asserts speed.
//
// Cloud: n points on a sphere of radius 0.5 m with 1 mm radial noise; each point carries a
// surface-like covariance (tangential std = half the sample spacing, normal std 2 mm) and a
// unit area weight. Traversal: two 10,000-point spheres, 1,000 seeded poses with a random
// rotation and the centres 1 m +/- 2 cm apart (gap in [-2, 2] cm: near contact).
#include <pcl_probcollision/detail/bvh_traversal.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include "../test/seeded_draws.h"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using pcl_probcollision_test::draw3;  // one draw a statement: the same workload with every compiler

namespace
{
UncertainCloud
sphereCloud (std::size_t n, std::uint64_t seed)
{
  std::mt19937_64 rng (seed);
  std::normal_distribution<double> g (0.0, 1.0);
  const double radius = 0.5;
  const double spacing = std::sqrt (4.0 * M_PI * radius * radius / static_cast<double> (n));
  const double tangential = 0.5 * spacing, normal = 0.002;
  UncertainCloud c;
  c.means.reserve (n);
  c.covariances.reserve (n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector3d d = draw3 (g, rng).normalized ();
    c.means.push_back ((radius + 0.001 * g (rng)) * d);
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity () - d * d.transpose ();
    c.covariances.push_back (tangential * tangential * P + normal * normal * d * d.transpose ());
    c.area_weights.push_back (1.0);
    c.source_indices.push_back (static_cast<int> (i));
  }
  return c;
}

void
BM_Build (benchmark::State& state)
{
  const std::size_t n = static_cast<std::size_t> (state.range (0));
  BVHParams params;
  params.split_style = state.range (1) == 0 ? BVHParams::SplitStyle::Pca : BVHParams::SplitStyle::Octree;
  const UncertainCloud cloud = sphereCloud (n, 1);
  ProbabilisticBVH bvh;
  for (auto _ : state)
  {
    bvh.build (cloud, params);
    benchmark::DoNotOptimize (bvh.nodes ().data ());
  }
  state.counters["points"] = static_cast<double> (n);
  state.counters["nodes"] = static_cast<double> (bvh.nodes ().size ());
  state.counters["leaves"] = static_cast<double> (bvh.leafCount ());
  state.counters["depth"] = bvh.depth ();
  state.counters["stored_per_point"] = static_cast<double> (bvh.storedPoints ()) / n;
  state.counters["bytes_per_point"] = static_cast<double> (bvh.bytes ()) / n;
  state.counters["points_per_s"] =
      benchmark::Counter (static_cast<double> (n), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel (params.split_style == BVHParams::SplitStyle::Pca ? "sphere+noise, Pca" : "sphere+noise, Octree");
}
BENCHMARK (BM_Build)
    ->ArgNames ({"points", "octree"})
    ->Args ({10000, 0})
    ->Args ({10000, 1})
    ->Args ({100000, 0})
    ->Args ({100000, 1})
    ->Unit (benchmark::kMillisecond);

struct TraversalFixture
{
  ProbabilisticBVH a, b;
  std::vector<Eigen::Isometry3d> poses;
  TraversalFixture () : a (sphereCloud (10000, 2)), b (sphereCloud (10000, 3))
  {
    std::mt19937_64 rng (4);
    std::normal_distribution<double> g (0.0, 1.0);
    std::uniform_real_distribution<double> gap (-0.02, 0.02);
    for (int i = 0; i < 1000; ++i)
    {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
      const double qw = g (rng);
      const Eigen::Vector3d qv = draw3 (g, rng);
      T.linear () = Eigen::Quaterniond (qw, qv.x (), qv.y (), qv.z ()).normalized ().toRotationMatrix ();
      const Eigen::Vector3d dir = draw3 (g, rng).normalized ();
      T.translation () = (1.0 + gap (rng)) * dir;
      poses.push_back (T);
    }
  }
};

const TraversalFixture&
fixture ()
{
  static const TraversalFixture f;
  return f;
}

// range(0): mode (0 ExpectedWeight, 1 Stochastic, 2 ExpandedBV); range(1): 1 = the leaf test
// gathers both leaves (B transformed) before returning 0, 0 = it returns 0 at once.
void
BM_TraversalNearContact (benchmark::State& state)
{
  const TraversalFixture& f = fixture ();
  detail::TraversalParams params;
  params.mode = static_cast<TraversalMode> (
      state.range (0) == 0 ? int (TraversalMode::ExpectedWeight)
                           : state.range (0) == 1 ? int (TraversalMode::Stochastic)
                                                  : int (TraversalMode::ExpandedBV));
  const bool gather = state.range (1) != 0;
  std::vector<double> times_us;
  double node_pairs = 0.0, leaf_pairs = 0.0, disjoint = 0.0;
  std::vector<Eigen::Vector3d> ma, mb;
  std::vector<Eigen::Matrix3d> ca, cb;
  for (auto _ : state)
  {
    times_us.clear ();
    node_pairs = leaf_pairs = disjoint = 0.0;
    for (const auto& T : f.poses)
    {
      auto leaf = [&] (const ProbabilisticBVH::Node& la, const ProbabilisticBVH::Node& lb, double) {
        if (gather)
        {
          f.a.gatherPoints (la, ma, ca);
          f.b.gatherPoints (lb, T, mb, cb);
        }
        return 0.0;
      };
      const auto t0 = std::chrono::steady_clock::now ();
      const detail::TraversalResult r = detail::traverseHierarchies (f.a, f.b, T, params, leaf);
      const auto t1 = std::chrono::steady_clock::now ();
      benchmark::DoNotOptimize (r.probability);
      times_us.push_back (std::chrono::duration<double, std::micro> (t1 - t0).count ());
      node_pairs += static_cast<double> (r.node_pairs_tested);
      leaf_pairs += static_cast<double> (r.leaf_pairs_tested);
      disjoint += static_cast<double> (r.disjoint_pairs);
    }
  }
  std::sort (times_us.begin (), times_us.end ());
  const double np = static_cast<double> (f.poses.size ());
  state.counters["poses"] = np;
  state.counters["median_us"] = times_us[times_us.size () / 2];
  state.counters["p90_us"] = times_us[times_us.size () * 9 / 10];
  state.counters["max_us"] = times_us.back ();
  state.counters["node_pairs"] = node_pairs / np;
  state.counters["disjoint_pairs"] = disjoint / np;
  state.counters["leaf_pairs"] = leaf_pairs / np;
  state.SetLabel ("2 x 10k sphere points, 1000 poses near contact, leaf test returns 0");
}
BENCHMARK (BM_TraversalNearContact)
    ->ArgNames ({"mode", "gather"})
    ->Args ({0, 0})
    ->Args ({0, 1})
    ->Args ({1, 0})
    ->Args ({2, 0})
    ->Unit (benchmark::kMillisecond);
} // namespace

BENCHMARK_MAIN ();
