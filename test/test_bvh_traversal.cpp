// SPDX-License-Identifier: BSD-3-Clause
// detail/bvh_traversal.h: the simultaneous traversal of two hierarchies (METHOD.md 8.5, 6.3,
// 11.7) in its three modes (expected weight, stochastic, expanded boxes): the crossing that only
// sibling overlap finds, brute force over all point pairs as the oracle, reach weights, early
// stop, counters, threads, and the relative pose. Leaf tests here are simple geometric ones, not
// the robust classifier. ThreadsGiveSerialAnswers runs under ThreadSanitizer in CI
// (scripts/ci-reliability.sh).
#include <pcl_probcollision/detail/bvh_traversal.h>
#include <pcl_probcollision/probabilistic_bvh.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "scenes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

using namespace pcl_probcollision;
using detail::TraversalParams;
using detail::TraversalResult;
using Node = ProbabilisticBVH::Node;
using pcl_probcollision_test::Phi;
using pcl_probcollision_test::randomPose;
using pcl_probcollision_test::Shape;
using pcl_probcollision_test::shapeCloud;
using pcl_probcollision_test::transformCloud;

namespace
{
// Leaf test: P = max over point pairs of Phi((r - d) / sigma), the probability that a pair
// comes within the contact radius r when their distance carries Gaussian error sigma; B's
// points mapped by T_a_b through the gather helper. Rigid-invariant; > 0.5 when d < r.
struct GaussianPairLeafTest
{
  const ProbabilisticBVH& a;
  const ProbabilisticBVH& b;
  Eigen::Isometry3d T_a_b;
  double sigma;
  double r = kContactRadius;
  std::vector<Eigen::Vector3d> ma, mb;
  std::vector<Eigen::Matrix3d> ca, cb;

  static constexpr double kContactRadius = 0.03;

  GaussianPairLeafTest (const ProbabilisticBVH& a_, const ProbabilisticBVH& b_,
                        const Eigen::Isometry3d& T, double s)
    : a (a_), b (b_), T_a_b (T), sigma (s) {}

  double
  operator() (const Node& la, const Node& lb, double /*reach_weight*/)
  {
    const PointSetView va = a.gatherPoints (la, ma, ca);
    const PointSetView vb = b.gatherPoints (lb, T_a_b, mb, cb);
    double d2 = std::numeric_limits<double>::infinity ();
    for (std::size_t i = 0; i < va.size; ++i)
      for (std::size_t j = 0; j < vb.size; ++j)
        d2 = std::min (d2, (va.means[i] - vb.means[j]).squaredNorm ());
    return Phi ((r - std::sqrt (d2)) / sigma);
  }
};

// The same value over all points of both clouds (the hierarchy bypassed).
double
bruteGaussianPair (const ProbabilisticBVH& a, const ProbabilisticBVH& b,
                   const Eigen::Isometry3d& T_a_b, double sigma, double* min_distance = nullptr)
{
  GaussianPairLeafTest t (a, b, T_a_b, sigma);
  // The roots' ranges hold every point (with duplicates), mapped with the same arithmetic.
  const double p = t (a.node (0), b.node (0), 1.0);
  if (min_distance)
  {
    double d2 = std::numeric_limits<double>::infinity ();
    for (const auto& x : t.ma)
      for (const auto& y : t.mb)
        d2 = std::min (d2, (x - y).squaredNorm ());
    *min_distance = std::sqrt (d2);
  }
  return p;
}

TraversalParams
exhaustiveExpectedWeight (double margin)
{
  TraversalParams p;
  p.mode = TraversalMode::ExpectedWeight;
  p.exhaustive = true;
  p.rho_min = 0.0;
  p.box_margin = margin;
  return p;
}
} // namespace

TEST (BVHTraversal, OverlapFindsCrossingThatNoOverlapMisses)
{
  // METHOD.md 8.2 / thesis Fig. 7.3a. A is a strip on z = 0 (40 x 2 grid, spacing h = 0.025,
  // x from 0.0125 to 0.9875); its root splits at x = 0.5, exactly between two columns. B is a
  // strip in the plane x = 0.5 (2 x 11 grid in y, z) crossing A there. Without overlap A's
  // children end at x = 0.4875 and start at 0.5125, so both are disjoint from B's plane and
  // the crossing is lost; with epsilon = 0.02 the band (0.0195 > h / 2) puts the column at
  // 0.5125 into the left child, whose box then straddles x = 0.5. Exact points (zero
  // covariance): coverage 1, so disjoint pairs are pruned (q = 0) and only geometry decides.
  const double h = 0.025;
  UncertainCloud a, b;
  for (int i = 0; i < 40; ++i)
    for (int r = 0; r < 2; ++r)
    {
      a.means.push_back (Eigen::Vector3d ((i + 0.5) * h, r * h, 0.0));
      a.covariances.push_back (Eigen::Matrix3d::Zero ());
    }
  for (int k = 0; k < 11; ++k)
    for (int r = 0; r < 2; ++r)
    {
      b.means.push_back (Eigen::Vector3d (0.5, r * h, -0.045 + 0.01 * k));
      b.covariances.push_back (Eigen::Matrix3d::Zero ());
    }
  const double threshold = 0.02;  // the closest pair is sqrt(0.0125^2 + 0.005^2) = 0.0135 apart

  // Leaf test: 1 when some pair of leaf points is closer than threshold.
  auto run = [&] (double epsilon, TraversalMode mode) {
    BVHParams p;
    p.epsilon = epsilon;
    ProbabilisticBVH ba (a, p), bb (b, p);
    const Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
    std::vector<Eigen::Vector3d> ma, mb;
    std::vector<Eigen::Matrix3d> ca, cb;
    auto leaf = [&] (const Node& la, const Node& lb, double) {
      ba.gatherPoints (la, ma, ca);
      bb.gatherPoints (lb, T, mb, cb);
      for (const auto& x : ma)
        for (const auto& y : mb)
          if ((x - y).norm () < threshold)
            return 1.0;
      return 0.0;
    };
    TraversalParams tp;
    tp.mode = mode;
    tp.exhaustive = true;
    return detail::traverseHierarchies (ba, bb, T, tp, leaf);
  };
  // Brute force: the clouds do come within the threshold.
  double dmin = 1e9;
  for (const auto& x : a.means)
    for (const auto& y : b.means)
      dmin = std::min (dmin, (x - y).norm ());
  ASSERT_NEAR (dmin, std::hypot (0.0125, 0.005), 1e-12);

  for (TraversalMode mode : {TraversalMode::ExpectedWeight, TraversalMode::ExpandedBV, TraversalMode::Stochastic})
  {
    const TraversalResult with = run (0.02, mode);
    const TraversalResult without = run (0.0, mode);
    EXPECT_EQ (with.probability, 1.0) << static_cast<int> (mode);
    EXPECT_FALSE (with.no_leaf_tested);
    EXPECT_EQ (without.probability, 0.0) << static_cast<int> (mode);
    EXPECT_TRUE (without.no_leaf_tested) << "the children of A's root are disjoint from B";
    EXPECT_EQ (without.leaf_pairs_tested, 0u);
    EXPECT_GE (without.disjoint_pairs, 2u);
  }
}

class BVHTraversalBruteForce : public ::testing::TestWithParam<BVHParams::SplitStyle>
{
};

TEST_P (BVHTraversalBruteForce, MatchesAllPairs)
{
  // Leaf test P = max over point pairs Phi((r - d) / sigma_f). Exhaustive ExpectedWeight with
  // rho_min = 0 and boxes grown by margin m: a pair closer than 2m has overlapping boxes all
  // the way up (every ancestor box contains its points), so it is reached with rho = 1. Hence
  // hierarchy == brute force when the closest pair is within 2m, and in all cases
  // 0 <= brute - hierarchy <= Phi((r - 2m) / sigma_f).
  BVHParams params;
  params.split_style = GetParam ();
  const double sigma_f = 0.01, margin = 0.04;
  const double slack = Phi ((GaussianPairLeafTest::kContactRadius - 2.0 * margin) / sigma_f);
  ProbabilisticBVH a (shapeCloud (Shape::Sphere, 400, 21, 0.003), params);
  ProbabilisticBVH b (shapeCloud (Shape::Box, 300, 22, 0.003), params);
  std::mt19937_64 rng (23);
  int colliding = 0, free = 0;
  for (int trial = 0; trial < 60; ++trial)
  {
    const Eigen::Isometry3d T = randomPose (rng, trial % 2 ? 1.2 : 0.5);
    double dmin = 0.0;
    const double brute = bruteGaussianPair (a, b, T, sigma_f, &dmin);
    GaussianPairLeafTest leaf (a, b, T, sigma_f);
    const TraversalResult r = detail::traverseHierarchies (a, b, T, exhaustiveExpectedWeight (margin), leaf);
    EXPECT_LE (r.probability, brute + 1e-15) << "trial " << trial;
    EXPECT_GE (r.probability, brute - slack) << "trial " << trial;
    if (dmin <= 2.0 * margin)
    {
      EXPECT_EQ (r.probability, brute) << "trial " << trial;
      EXPECT_EQ (r.max_reach_weight, 1.0);
    }
    if (brute > 0.5)
      ++colliding;
    if (brute < 1e-6)
      ++free;
    EXPECT_FALSE (r.lower_bound);

    // Every leaf pair is visited when the margin exceeds everything: exact for any pose.
    GaussianPairLeafTest leaf_all (a, b, T, sigma_f);
    const TraversalResult all = detail::traverseHierarchies (a, b, T, exhaustiveExpectedWeight (10.0), leaf_all);
    EXPECT_EQ (all.probability, brute) << "trial " << trial;
    EXPECT_EQ (all.leaf_pairs_tested, a.leafCount () * b.leafCount ());
    EXPECT_EQ (all.disjoint_pairs, 0u);

    // Default parameters can only under-estimate.
    GaussianPairLeafTest leaf_def (a, b, T, sigma_f);
    const TraversalResult def = detail::traverseHierarchies (a, b, T, TraversalParams (), leaf_def);
    EXPECT_LE (def.probability, brute + 1e-15);
  }
  EXPECT_GT (colliding, 5);
  EXPECT_GT (free, 5);
}

INSTANTIATE_TEST_SUITE_P (SplitStyles, BVHTraversalBruteForce,
                          ::testing::Values (BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree),
                          [] (const ::testing::TestParamInfo<BVHParams::SplitStyle>& info) {
                            return std::string (info.param == BVHParams::SplitStyle::Pca ? "Pca" : "Octree");
                          });

TEST (BVHTraversal, StochasticRepeatsWithSeedAndMeanBoundsExpectedWeight)
{
  // Two configurations: (0) noisy spheres 3 cm apart, whose closest leaves still overlap
  // (contact radius 3 cm); (1) spheres 12 cm apart with a 20 cm contact radius, where the
  // maximum is reached through leakage only (rho < 1), so that the two modes really differ.
  // Whether (1) holds depends on the draw: at a 12 cm gap the corners of tilted leaf boxes on
  // the two spheres may or may not overlap (over 20 seed pairs, 6 reach the maximum with
  // rho = 1). Its seeds are the first pair for which it holds, and the expectations on
  // ew.max_reach_weight and ew.probability below check that it still does.
  struct Config
  {
    double point_sigma;
    double gap;
    double radius;  // contact radius r of the leaf test
    std::uint64_t seed_a, seed_b;
  };
  for (const Config cfg : {Config{0.02, 0.03, 0.03, 31, 32}, Config{0.01, 0.12, 0.2, 33, 34}})
  {
    SCOPED_TRACE ("point sigma " + std::to_string (cfg.point_sigma));
    ProbabilisticBVH a (shapeCloud (Shape::Sphere, 300, cfg.seed_a, cfg.point_sigma));
    ProbabilisticBVH b (shapeCloud (Shape::Sphere, 300, cfg.seed_b, cfg.point_sigma));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
    T.translation () = Eigen::Vector3d (1.0 + cfg.gap, 0.0, 0.0);
    const double sigma_f = 0.01;

    TraversalParams sp;
    sp.mode = TraversalMode::Stochastic;
    sp.exhaustive = true;
    sp.rho_min = 0.0;
    sp.seed = 42;
    GaussianPairLeafTest l1 (a, b, T, sigma_f), l2 (a, b, T, sigma_f);
    l1.r = l2.r = cfg.radius;
    const TraversalResult r1 = detail::traverseHierarchies (a, b, T, sp, l1);
    const TraversalResult r2 = detail::traverseHierarchies (a, b, T, sp, l2);
    EXPECT_EQ (r1, r2);
    EXPECT_GT (r1.disjoint_pairs, 0u);

    // Different seeds visit different pairs.
    std::set<std::size_t> visited_counts;
    double sum = 0.0;
    const int runs = 1000;
    for (int s = 0; s < runs; ++s)
    {
      sp.seed = static_cast<std::uint64_t> (s);
      GaussianPairLeafTest l (a, b, T, sigma_f);
      l.r = cfg.radius;
      const TraversalResult r = detail::traverseHierarchies (a, b, T, sp, l);
      visited_counts.insert (r.node_pairs_tested);
      sum += r.probability;
      if (!r.no_leaf_tested)
      {
        EXPECT_EQ (r.max_reach_weight, 1.0);
      }
    }
    EXPECT_GT (visited_counts.size (), 1u);

    // METHOD.md 11.7: mean of Stochastic >= ExpectedWeight - 0.01 (exhaustive, rho_min = 0).
    GaussianPairLeafTest le (a, b, T, sigma_f);
    le.r = cfg.radius;
    const TraversalResult ew = detail::traverseHierarchies (a, b, T, exhaustiveExpectedWeight (0.0), le);
    EXPECT_GT (ew.disjoint_pairs, 0u);
    EXPECT_GE (sum / runs, ew.probability - 0.01);
    if (cfg.point_sigma < 0.02)
    {
      EXPECT_LT (ew.max_reach_weight, 1.0) << "reached through leakage only";
      EXPECT_GT (ew.probability, 0.02) << "and large against the 0.01 tolerance";
    }
    // Deterministic: the same twice.
    GaussianPairLeafTest le2 (a, b, T, sigma_f);
    le2.r = cfg.radius;
    EXPECT_EQ (detail::traverseHierarchies (a, b, T, exhaustiveExpectedWeight (0.0), le2), ew);
  }
}

TEST (BVHTraversal, ExpectedWeightWeightsAreProductsOfQ)
{
  // Two single-point hierarchies with disjoint boxes: rho = q = 1 - Pcov(a) Pcov(b), and the
  // leaf test sees it.
  UncertainCloud ca, cb;
  ca.means = {Eigen::Vector3d (0, 0, 0)};
  ca.covariances = {Eigen::Matrix3d::Identity () * 1e-4};
  cb.means = {Eigen::Vector3d (0.05, 0, 0)};
  cb.covariances = {Eigen::Matrix3d::Identity () * 1e-4};
  ProbabilisticBVH a (ca), b (cb);
  const double q = 1.0 - a.node (0).coverage () * b.node (0).coverage ();
  double seen = -1.0;
  auto leaf = [&] (const Node&, const Node&, double rho) {
    seen = rho;
    return 0.8;
  };
  TraversalParams tp;
  const TraversalResult r = detail::traverseHierarchies (a, b, Eigen::Isometry3d::Identity (), tp, leaf);
  // Each node's leakage is 2 Phi(-h / s), about 2 Phi(-1): the box's half extent h is the
  // point's standard deviation s rounded up to a float (OrientedBox::setHalfExtents); kept in
  // single precision.
  const double h = a.node (0).box.half_extents (0);
  const double s = std::sqrt (a.covariances ()[0].matrix () (0, 0));
  const double leak = static_cast<float> (2.0 * Phi (-h / s));
  EXPECT_NEAR (h / s, 1.0, 1e-6);
  EXPECT_NEAR (q, 1.0 - (1.0 - leak) * (1.0 - leak), 1e-12);
  EXPECT_DOUBLE_EQ (seen, q);
  EXPECT_DOUBLE_EQ (r.probability, 0.8 * q);
  EXPECT_DOUBLE_EQ (r.max_reach_weight, q);
  EXPECT_DOUBLE_EQ (r.max_leaf_probability, 0.8);
  EXPECT_EQ (r.disjoint_pairs, 1u);
  // rho_min above q prunes it.
  tp.rho_min = q + 1e-9;
  const TraversalResult pruned = detail::traverseHierarchies (a, b, Eigen::Isometry3d::Identity (), tp, leaf);
  EXPECT_TRUE (pruned.no_leaf_tested);
  EXPECT_EQ (pruned.pruned_pairs, 1u);
  EXPECT_EQ (pruned.probability, 0.0);
  // ExpandedBV with k = 3 (grown by 2 sigma more each): 0.01 + 0.02 = 0.03 > 0.025 -> overlap.
  tp.mode = TraversalMode::ExpandedBV;
  const TraversalResult expanded = detail::traverseHierarchies (a, b, Eigen::Isometry3d::Identity (), tp, leaf);
  EXPECT_EQ (expanded.disjoint_pairs, 0u);
  EXPECT_DOUBLE_EQ (expanded.probability, 0.8);
  tp.expanded_k_sigma = 1.0;  // no growth: disjoint, pruned without leakage
  const TraversalResult tight = detail::traverseHierarchies (a, b, Eigen::Isometry3d::Identity (), tp, leaf);
  EXPECT_TRUE (tight.no_leaf_tested);
  EXPECT_EQ (tight.pruned_pairs, 1u);
}

TEST (BVHTraversal, EarlyStopGivesLowerBound)
{
  const UncertainCloud c = shapeCloud (Shape::Box, 500, 41);
  ProbabilisticBVH a (c), b (c);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
  auto always = [] (const Node&, const Node&, double) { return 0.9; };
  TraversalParams tp;
  tp.stop_probability = 0.5;
  const TraversalResult stopped = detail::traverseHierarchies (a, b, I, tp, always);
  EXPECT_TRUE (stopped.lower_bound);
  EXPECT_EQ (stopped.leaf_pairs_tested, 1u);
  EXPECT_DOUBLE_EQ (stopped.probability, 0.9);
  tp.exhaustive = true;
  const TraversalResult full = detail::traverseHierarchies (a, b, I, tp, always);
  EXPECT_FALSE (full.lower_bound);
  EXPECT_GT (full.leaf_pairs_tested, 1u);
  EXPECT_DOUBLE_EQ (full.probability, 0.9);
  tp.exhaustive = false;
  tp.stop_probability = 0.95;  // never exceeded
  const TraversalResult unstopped = detail::traverseHierarchies (a, b, I, tp, always);
  EXPECT_FALSE (unstopped.lower_bound);
  EXPECT_EQ (unstopped.leaf_pairs_tested, full.leaf_pairs_tested);
  // skip_dominated: same value, fewer leaf tests.
  auto graded = [&] (const Node& la, const Node& lb, double) { return 0.001 * ((la.begin + lb.begin) % 500); };
  tp.exhaustive = true;
  const TraversalResult g_full = detail::traverseHierarchies (a, b, I, tp, graded);
  tp.skip_dominated = true;
  const TraversalResult g_skip = detail::traverseHierarchies (a, b, I, tp, graded);
  EXPECT_EQ (g_skip.probability, g_full.probability);
  EXPECT_LE (g_skip.leaf_pairs_tested, g_full.leaf_pairs_tested);
}

// max_leaf_tests caps the leaf tests: the traversal stops before the one past the cap, flags it,
// and its maximum is a lower bound of the uncapped one.
TEST (BVHTraversal, LeafTestBudgetStopsWithALowerBound)
{
  const UncertainCloud c = shapeCloud (Shape::Box, 500, 41);
  ProbabilisticBVH a (c), b (c);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
  auto graded = [&] (const Node& la, const Node& lb, double) { return 0.001 * ((la.begin + lb.begin) % 500); };
  TraversalParams tp;
  tp.exhaustive = true;
  const TraversalResult full = detail::traverseHierarchies (a, b, I, tp, graded);
  ASSERT_GT (full.leaf_pairs_tested, 10u);
  EXPECT_FALSE (full.budget_exhausted);
  for (const std::size_t cap : {std::size_t (1), std::size_t (10), full.leaf_pairs_tested - 1})
  {
    SCOPED_TRACE (cap);
    tp.max_leaf_tests = cap;
    const TraversalResult capped = detail::traverseHierarchies (a, b, I, tp, graded);
    EXPECT_EQ (capped.leaf_pairs_tested, cap);
    EXPECT_TRUE (capped.budget_exhausted);
    EXPECT_TRUE (capped.lower_bound);
    EXPECT_LE (capped.probability, full.probability);
  }
  tp.max_leaf_tests = full.leaf_pairs_tested;  // exactly enough: not exhausted
  const TraversalResult enough = detail::traverseHierarchies (a, b, I, tp, graded);
  EXPECT_FALSE (enough.budget_exhausted);
  EXPECT_FALSE (enough.lower_bound);
  EXPECT_EQ (enough.probability, full.probability);
}

// Children are visited nearest first: two clouds that touch at one end meet there first.
TEST (BVHTraversal, NearestLeafPairsComeFirst)
{
  UncertainCloud sa, sb;
  for (int i = 0; i < 400; ++i)
  {
    // A rod along x from 0 to 4; B the same rod, shifted to start where A ends.
    const double x = 0.01 * i;
    sa.means.emplace_back (x, 0.0, 0.0);
    sb.means.emplace_back (x + 3.995, 0.0, 0.0);
  }
  sa.covariances.assign (sa.means.size (), Eigen::Matrix3d::Identity () * 1e-6);
  sb.covariances = sa.covariances;
  ProbabilisticBVH a (sa), b (sb);
  std::vector<double> first_gap;
  auto record = [&] (const Node& la, const Node& lb, double) {
    first_gap.push_back ((la.box.center - lb.box.center).norm ());
    return 0.0;
  };
  TraversalParams tp;
  tp.rho_min = 0.0;  // reach every pair
  tp.exhaustive = true;
  detail::traverseHierarchies (a, b, Eigen::Isometry3d::Identity (), tp, record);
  ASSERT_GT (first_gap.size (), 4u);
  // The first leaf pair is the closest of all.
  EXPECT_EQ (first_gap.front (), *std::min_element (first_gap.begin (), first_gap.end ()));
  EXPECT_LT (first_gap.front (), 0.5);
}

TEST (BVHTraversal, ThreadsGiveSerialAnswers)
{
  ProbabilisticBVH a (shapeCloud (Shape::Sphere, 2000, 51, 0.005));
  ProbabilisticBVH b (shapeCloud (Shape::NoisyPlane, 1500, 52, 0.005));
  std::mt19937_64 rng (53);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 16; ++i)
  {
    Eigen::Isometry3d T = randomPose (rng, 0.2);
    T.translation () += Eigen::Vector3d (0.0, 0.0, 0.45);
    poses.push_back (T);
  }
  TraversalParams tp;
  tp.exhaustive = true;
  auto query = [&] (const Eigen::Isometry3d& T, TraversalMode mode) {
    TraversalParams p = tp;
    p.mode = mode;
    p.seed = 9;
    GaussianPairLeafTest leaf (a, b, T, 0.01);
    return detail::traverseHierarchies (a, b, T, p, leaf);
  };
  std::vector<TraversalResult> serial;
  for (const auto& T : poses)
  {
    serial.push_back (query (T, TraversalMode::ExpectedWeight));
    serial.push_back (query (T, TraversalMode::Stochastic));
  }
  std::vector<std::vector<TraversalResult>> parallel (4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back ([&, t] {
      // Each thread runs every pose, starting at a different one.
      parallel[t].resize (serial.size ());
      for (std::size_t k = 0; k < poses.size (); ++k)
      {
        const std::size_t i = (k + 4 * t) % poses.size ();
        parallel[t][2 * i] = query (poses[i], TraversalMode::ExpectedWeight);
        parallel[t][2 * i + 1] = query (poses[i], TraversalMode::Stochastic);
      }
    });
  for (auto& th : threads)
    th.join ();
  std::size_t nonzero = 0;
  for (std::size_t i = 0; i < serial.size (); ++i)
  {
    nonzero += serial[i].probability > 0.0;
    for (int t = 0; t < 4; ++t)
      EXPECT_EQ (parallel[t][i], serial[i]) << "thread " << t << " query " << i;
  }
  EXPECT_GT (nonzero, 4u);
}

TEST (BVHTraversal, PoseEqualsPretransformedRebuild)
{
  // METHOD.md 11.6 relative pose: traversal with T_a_b equals traversal against B's cloud moved
  // by T_a_b and rebuilt, with the identity.
  const UncertainCloud ca = shapeCloud (Shape::Sphere, 600, 61, 0.004);
  const UncertainCloud cb = shapeCloud (Shape::NoisyPlane, 500, 62, 0.004);
  ProbabilisticBVH a (ca), b (cb);
  std::mt19937_64 rng (63);
  int collisions = 0;
  for (int trial = 0; trial < 10; ++trial)
  {
    // The plane patch tangent to the sphere, pushed in (crossing) or out by delta.
    Eigen::Isometry3d T = randomPose (rng, 0.0);
    const double delta = 0.02 * (trial - 5);
    T.translation () = (0.5 + delta) * T.linear ().col (2);
    ProbabilisticBVH b_moved (transformCloud (cb, T));
    const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
    TraversalParams tp;
    tp.exhaustive = true;
    GaussianPairLeafTest l1 (a, b, T, 0.01), l2 (a, b_moved, I, 0.01);
    const TraversalResult r1 = detail::traverseHierarchies (a, b, T, tp, l1);
    const TraversalResult r2 = detail::traverseHierarchies (a, b_moved, I, tp, l2);
    // The moved cloud's covariances are rotated and then stored as float (relative error
    // 2^-24), so the two agree to about 1e-7, not to rounding.
    EXPECT_NEAR (r1.probability, r2.probability, 1e-6) << "trial " << trial;
    EXPECT_EQ (r1.probability > 0.5, r2.probability > 0.5);
    EXPECT_EQ (r1.leaf_pairs_tested, r2.leaf_pairs_tested);
    EXPECT_EQ (r1.disjoint_pairs, r2.disjoint_pairs);
    // Leakage does not depend on the pose (node order may differ: an eigenvector sign flip
    // swaps siblings, so compare the sorted values).
    ASSERT_EQ (b.nodes ().size (), b_moved.nodes ().size ());
    std::vector<double> leak, leak_moved;
    for (std::size_t i = 0; i < b.nodes ().size (); ++i)
    {
      leak.push_back (b.nodes ()[i].leakage);
      leak_moved.push_back (b_moved.nodes ()[i].leakage);
    }
    std::sort (leak.begin (), leak.end ());
    std::sort (leak_moved.begin (), leak_moved.end ());
    for (std::size_t i = 0; i < leak.size (); ++i)
      EXPECT_NEAR (leak[i], leak_moved[i], 1e-6);
    collisions += r1.probability > 0.5;
  }
  EXPECT_GT (collisions, 0);
  EXPECT_LT (collisions, 10);
}

TEST (BVHTraversal, CountersAndFlags)
{
  const UncertainCloud c = shapeCloud (Shape::Sphere, 300, 71, 0.005);
  ProbabilisticBVH a (c), b (c), empty;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
  auto zero = [] (const Node&, const Node&, double) { return 0.0; };
  // An empty side: nothing visited.
  const TraversalResult e1 = detail::traverseHierarchies (a, empty, I, TraversalParams (), zero);
  const TraversalResult e2 = detail::traverseHierarchies (empty, b, I, TraversalParams (), zero);
  for (const auto& r : {e1, e2})
  {
    EXPECT_TRUE (r.no_leaf_tested);
    EXPECT_EQ (r.probability, 0.0);
    EXPECT_EQ (r.node_pairs_tested, 0u);
    EXPECT_EQ (r.max_node_a, -1);
  }
  // Leaves that all return 0: a leaf was tested, value 0, ids set.
  const TraversalResult z = detail::traverseHierarchies (a, b, I, TraversalParams (), zero);
  EXPECT_FALSE (z.no_leaf_tested);
  EXPECT_EQ (z.probability, 0.0);
  EXPECT_GE (z.max_node_a, 0);
  EXPECT_TRUE (a.node (z.max_node_a).isLeaf ());
  EXPECT_TRUE (b.node (z.max_node_b).isLeaf ());
  EXPECT_LE (z.leaf_pairs_tested + z.pruned_pairs, z.node_pairs_tested);
  EXPECT_LE (z.disjoint_pairs, z.node_pairs_tested);
  // NaN leaf results are ignored and counted.
  auto nan = [] (const Node&, const Node&, double) { return std::numeric_limits<double>::quiet_NaN (); };
  const TraversalResult n = detail::traverseHierarchies (a, b, I, TraversalParams (), nan);
  EXPECT_TRUE (n.no_leaf_tested);
  EXPECT_EQ (n.probability, 0.0);
  EXPECT_EQ (n.invalid_leaf_results, n.leaf_pairs_tested);
  EXPECT_GT (n.leaf_pairs_tested, 0u);
  // The max pair is reported by id.
  auto pick = [&] (const Node& la, const Node& lb, double) {
    return (&la == &a.node (a.nodes ().size () - 1) && &lb == &b.node (b.nodes ().size () - 1)) ? 0.3 : 0.1;
  };
  TraversalParams tp;
  tp.box_margin = 10.0;
  const TraversalResult pr = detail::traverseHierarchies (a, b, I, tp, pick);
  EXPECT_EQ (pr.max_node_a, static_cast<std::int32_t> (a.nodes ().size () - 1));
  EXPECT_EQ (pr.max_node_b, static_cast<std::int32_t> (b.nodes ().size () - 1));
  EXPECT_DOUBLE_EQ (pr.probability, 0.3);
  // Bad inputs.
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity ();
  scaled.linear () *= 1.1;
  EXPECT_THROW (detail::traverseHierarchies (a, b, scaled, TraversalParams (), zero), pcl::BadArgumentException);
  TraversalParams bad;
  bad.rho_min = 2.0;
  EXPECT_THROW (detail::traverseHierarchies (a, b, I, bad, zero), pcl::BadArgumentException);
  bad = TraversalParams ();
  bad.stop_probability = -0.1;
  EXPECT_THROW (bad.validate (), pcl::BadArgumentException);
  bad = TraversalParams ();
  bad.box_margin = -1.0;
  EXPECT_THROW (bad.validate (), pcl::BadArgumentException);
  bad = TraversalParams ();
  bad.expanded_k_sigma = std::numeric_limits<double>::quiet_NaN ();
  EXPECT_THROW (bad.validate (), pcl::BadArgumentException);
}

// TraversalParams::only_a: with a set of A's leaves and their ancestors marked, the traversal
// visits exactly the whole traversal's pairs of those leaves, in the whole traversal's order
// (the surface layer's capped enumeration relies on both), for the expanded mode it uses and the
// default one, with and without the nearest-first order.
TEST (BVHTraversal, OnlyAVisitsTheMarkedLeavesPairsInTheWholeTraversalsOrder)
{
  const ProbabilisticBVH a (shapeCloud (Shape::Sphere, 1500, 31, 0.003));
  const ProbabilisticBVH b (shapeCloud (Shape::NoisyPlane, 2000, 32, 0.003));
  std::vector<std::int32_t> parent (a.nodes ().size (), -1), leaves;
  for (std::size_t id = 0; id < a.nodes ().size (); ++id)
    if (a.nodes ()[id].isLeaf ())
      leaves.push_back (static_cast<std::int32_t> (id));
    else
      for (int c = 0; c < a.nodes ()[id].num_children; ++c)
        parent[static_cast<std::size_t> (a.nodes ()[id].first_child + c)] = static_cast<std::int32_t> (id);
  ASSERT_GT (leaves.size (), 40u);
  std::mt19937_64 rng (33);
  std::size_t compared = 0;
  for (int trial = 0; trial < 12; ++trial)
  {
    const Eigen::Isometry3d T = randomPose (rng, 0.3);
    TraversalParams params;
    params.exhaustive = true;
    params.skip_dominated = false;
    params.box_margin = 0.02;
    if (trial % 2)
    {
      params.mode = TraversalMode::ExpandedBV;
      params.expanded_k_sigma = 3.0;
      params.nearest_first = false;
    }
    using Pairs = std::vector<std::pair<const Node*, const Node*>>;
    auto collect = [&] (const TraversalParams& p) {
      Pairs pairs;
      detail::traverseHierarchies (a, b, T, p, [&] (const Node& la, const Node& lb, double) {
        pairs.emplace_back (&la, &lb);
        return 0.0;
      });
      return pairs;
    };
    const Pairs all = collect (params);
    // A batch of consecutive leaves (by id), as the capped enumeration takes them.
    const std::size_t first = static_cast<std::size_t> (trial) * leaves.size () / 16, last = first + leaves.size () / 8;
    std::vector<char> marked (a.nodes ().size (), 0);
    for (std::size_t k = first; k < last; ++k)
      for (std::int32_t id = leaves[k]; id >= 0; id = parent[static_cast<std::size_t> (id)])
        marked[static_cast<std::size_t> (id)] = 1;
    Pairs expected;
    for (const auto& p : all)
      if (marked[static_cast<std::size_t> (p.first - a.nodes ().data ())])
        expected.push_back (p);
    TraversalParams only = params;
    only.only_a = &marked;
    const Pairs got = collect (only);
    EXPECT_EQ (got, expected) << "trial " << trial;
    EXPECT_LT (got.size (), all.size ()) << "trial " << trial;
    compared += expected.size ();
  }
  EXPECT_GT (compared, 100u);  // the batches met pairs, not only empty sets
}
