// SPDX-License-Identifier: BSD-3-Clause
// Speed of RobustClassifier::classify (METHOD.md 5.3, 5.5). Each benchmark prints its workload
// in its name and counters; nothing here asserts speed.
//
//   BM_LinearPatches/<n>      Linear rung, Robust training, 2 x n points: two noisy 1 x 1 patches
//                             2 cm apart, sigma = 5 mm, positions jittered by sigma (near contact)
//   BM_RffBowl/<n>            RFF rung alone (D = 256), Robust training: a ball of radius 0.3
//                             (n points) inside a hemispherical bowl of radius 0.4 (n points),
//                             sigma = 1 cm
//   BM_LadderPatches/<n>      default Ladder on the planar patches: the plane is enough
//   BM_LadderBowl/<n>         default Ladder on the bowl: Linear, then RFF D = 256
#include <pcl_probcollision/robust_classifier.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace
{
using pcl_probcollision::ClassifierParams;
using pcl_probcollision::ClassifierResult;
using pcl_probcollision::KernelMode;
using pcl_probcollision::PointSetView;
using pcl_probcollision::RobustClassifier;

struct Cloud
{
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> covariances;
  PointSetView view () const { return PointSetView (means, covariances); }
};

/** \brief n points on a jittered grid over [0,1]^2 at height z, sigma^2 I each. */
Cloud
noisyPatch (int n, double z, double sigma, std::uint64_t seed)
{
  Cloud c;
  std::mt19937_64 rng (seed);
  std::normal_distribution<double> noise (0.0, sigma);
  const int side = static_cast<int> (std::ceil (std::sqrt (static_cast<double> (n))));
  for (int k = 0; k < n; ++k)
  {
    const double x = (k % side + 0.5) / side, y = (k / side + 0.5) / side;
    c.means.emplace_back (x + noise (rng), y + noise (rng), z + noise (rng));
    c.covariances.push_back (sigma * sigma * Eigen::Matrix3d::Identity ());
  }
  return c;
}

/** \brief Fibonacci points on the unit sphere. */
std::vector<Eigen::Vector3d>
fibonacci (int n)
{
  std::vector<Eigen::Vector3d> p;
  const double golden = M_PI * (3.0 - std::sqrt (5.0));
  for (int k = 0; k < n; ++k)
  {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt (1.0 - z * z), phi = k * golden;
    p.emplace_back (r * std::cos (phi), r * std::sin (phi), z);
  }
  return p;
}

/** \brief A ball of radius 0.3 (n points) and the lower half of a sphere of radius 0.4 around
  * it (n points), sigma = 0.01. */
void
bowl (int n, Cloud& ball, Cloud& cup)
{
  const double sigma = 0.01;
  for (const Eigen::Vector3d& u : fibonacci (n))
  {
    ball.means.push_back (0.3 * u);
    ball.covariances.push_back (sigma * sigma * Eigen::Matrix3d::Identity ());
  }
  for (const Eigen::Vector3d& u : fibonacci (2 * n))
    if (u.z () < 0.0)
    {
      cup.means.push_back (0.4 * u);
      cup.covariances.push_back (sigma * sigma * Eigen::Matrix3d::Identity ());
    }
}

void
run (benchmark::State& state, const ClassifierParams& params, const Cloud& a, const Cloud& b)
{
  const RobustClassifier classifier (params);
  ClassifierResult result;
  for (auto _ : state)
  {
    classifier.classify (a.view (), b.view (), result);
    benchmark::DoNotOptimize (&result);
  }
  state.counters["points"] = static_cast<double> (a.means.size () + b.means.size ());
  state.counters["iterations"] = result.iterations;
  state.counters["rung"] = static_cast<double> (result.rung);
  state.counters["P"] = result.probability;
  state.counters["points_per_s"] = benchmark::Counter (
      static_cast<double> (a.means.size () + b.means.size ()), benchmark::Counter::kIsIterationInvariantRate);
}

void
BM_LinearPatches (benchmark::State& state)
{
  const int n = static_cast<int> (state.range (0));
  const Cloud a = noisyPatch (n, 0.0, 0.005, 1), b = noisyPatch (n, 0.02, 0.005, 2);
  ClassifierParams params;
  params.kernel = KernelMode::Linear;
  run (state, params, a, b);
}

void
BM_RffBowl (benchmark::State& state)
{
  Cloud a, b;
  bowl (static_cast<int> (state.range (0)), a, b);
  ClassifierParams params;
  params.kernel = KernelMode::RFF;
  state.counters["D"] = params.rff_features;
  run (state, params, a, b);
}

void
BM_RffBowlStandard (benchmark::State& state)
{
  Cloud a, b;
  bowl (static_cast<int> (state.range (0)), a, b);
  ClassifierParams params;
  params.kernel = KernelMode::RFF;
  params.training = pcl_probcollision::TrainingMode::Standard;
  state.counters["D"] = params.rff_features;
  run (state, params, a, b);
}

void
BM_LadderPatches (benchmark::State& state)
{
  const int n = static_cast<int> (state.range (0));
  const Cloud a = noisyPatch (n, 0.0, 0.005, 1), b = noisyPatch (n, 0.02, 0.005, 2);
  run (state, ClassifierParams (), a, b);
}

void
BM_LadderBowl (benchmark::State& state)
{
  Cloud a, b;
  bowl (static_cast<int> (state.range (0)), a, b);
  run (state, ClassifierParams (), a, b);
}
} // namespace

BENCHMARK (BM_LinearPatches)->Arg (100)->Arg (1000)->Arg (10000)->Unit (benchmark::kMicrosecond);
BENCHMARK (BM_RffBowl)->Arg (100)->Arg (400)->Arg (1000)->Unit (benchmark::kMicrosecond);
BENCHMARK (BM_RffBowlStandard)->Arg (100)->Arg (400)->Arg (1000)->Unit (benchmark::kMicrosecond);
BENCHMARK (BM_LadderPatches)->Arg (100)->Arg (1000)->Unit (benchmark::kMicrosecond);
BENCHMARK (BM_LadderBowl)->Arg (100)->Unit (benchmark::kMicrosecond);

BENCHMARK_MAIN ();
