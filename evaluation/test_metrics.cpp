// SPDX-License-Identifier: BSD-3-Clause
#include "metrics.h"
#include "primitives.h"

#include <pcl/kdtree/kdtree_flann.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <vector>

namespace ev = pcl_probcollision_eval;

namespace
{
const double kNaN = std::numeric_limits<double>::quiet_NaN ();

// The pairwise definition of AUC, O(n^2): the reference for the rank-based one.
double
pairwiseAuc (const std::vector<double>& score, const std::vector<bool>& positive)
{
  double wins = 0.0;
  double pairs = 0.0;
  for (std::size_t i = 0; i < score.size (); ++i)
    for (std::size_t j = 0; j < score.size (); ++j)
      if (positive[i] && !positive[j])
      {
        wins += score[i] > score[j] ? 1.0 : (score[i] == score[j] ? 0.5 : 0.0);
        pairs += 1.0;
      }
  return wins / pairs;
}

Eigen::Vector3d
toVector (const pcl::PointXYZ& p)
{
  return {p.x, p.y, p.z};
}

// Smallest distance between a point of `b` and a point of `a` (exact nearest-neighbour search).
double
minPairDistance (const ev::PrimitiveCloud::ConstPtr& a, const ev::PrimitiveCloud& b)
{
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud (a);
  std::vector<int> index (1);
  std::vector<float> sq (1);
  double best = std::numeric_limits<double>::infinity ();
  for (const pcl::PointXYZ& p : b.points)
    if (tree.nearestKSearch (p, 1, index, sq) == 1)
      best = std::min (best, (toVector (a->points[index[0]]) - toVector (p)).norm ());
  return best;
}

ev::MeanStd
residualStats (const ev::PrimitiveCloud& cloud, const std::function<double (const Eigen::Vector3d&)>& residual)
{
  std::vector<double> r;
  for (const pcl::PointXYZ& p : cloud.points)
    r.push_back (residual (toVector (p)));
  return ev::meanStd (r);
}
} // namespace

// ---------------------------------------------------------------------------------------------
// Metrics

TEST (RocAuc, PerfectReversedAndTiedScores)
{
  const std::vector<bool> label{false, false, true, true};
  EXPECT_DOUBLE_EQ (ev::rocAuc ({0.1, 0.2, 0.8, 0.9}, label), 1.0);
  EXPECT_DOUBLE_EQ (ev::rocAuc ({0.9, 0.8, 0.2, 0.1}, label), 0.0);
  EXPECT_DOUBLE_EQ (ev::rocAuc ({0.5, 0.5, 0.5, 0.5}, label), 0.5);
}

TEST (RocAuc, HandComputedExamples)
{
  // Positives 0.35 and 0.8 against negatives 0.1 and 0.4: 3 of the 4 pairs ordered right.
  EXPECT_DOUBLE_EQ (ev::rocAuc ({0.1, 0.4, 0.35, 0.8}, {false, false, true, true}), 0.75);
  // Positives 0.5 and 0.9 against negatives 0.5, 0.2, 0.5: 0.5 scores 1/2 + 1 + 1/2, 0.9 scores 3.
  EXPECT_DOUBLE_EQ (ev::rocAuc ({0.5, 0.5, 0.2, 0.9, 0.5}, {true, false, false, true, false}), 5.0 / 6.0);
  // Yes/no scores: a classifier with true-positive rate 2/3 and false-positive rate 1/4 gives
  // (1 + TPR - FPR) / 2.
  EXPECT_DOUBLE_EQ (ev::rocAuc ({1, 1, 0, 1, 0, 0, 0}, {true, true, true, false, false, false, false}),
                    (1.0 + 2.0 / 3.0 - 0.25) / 2.0);
}

TEST (RocAuc, MatchesThePairwiseDefinitionWithManyTies)
{
  std::mt19937_64 rng (42);
  std::vector<double> score;
  std::vector<bool> label;
  for (int i = 0; i < 300; ++i)
  {
    score.push_back (static_cast<double> (rng () % 7) / 6.0);  // heavy ties
    label.push_back (rng () % 3 == 0);
  }
  EXPECT_NEAR (ev::rocAuc (score, label), pairwiseAuc (score, label), 1e-12);
}

TEST (RocAuc, UndefinedCasesAreNaNAndSizeMismatchThrows)
{
  EXPECT_TRUE (std::isnan (ev::rocAuc ({0.1, 0.2}, {true, true})));
  EXPECT_TRUE (std::isnan (ev::rocAuc ({0.1, 0.2}, {false, false})));
  EXPECT_TRUE (std::isnan (ev::rocAuc ({}, {})));
  EXPECT_TRUE (std::isnan (ev::rocAuc ({0.1, kNaN}, {false, true})));
  EXPECT_THROW (ev::rocAuc ({0.1}, {true, false}), std::invalid_argument);
}

TEST (BrierScore, HandExample)
{
  // (0.1^2 + 0.2^2 + 0.6^2 + 0) / 4
  EXPECT_NEAR (ev::brierScore ({0.9, 0.2, 0.6, 0.0}, {true, false, false, false}), 0.1025, 1e-15);
  EXPECT_DOUBLE_EQ (ev::brierScore ({0.5, 0.5}, {true, false}), 0.25);
  EXPECT_TRUE (std::isnan (ev::brierScore ({}, {})));
  EXPECT_THROW (ev::brierScore ({0.5}, {}), std::invalid_argument);
}

TEST (ReliabilityBins, BinsCountsMeansAndEdges)
{
  const std::vector<double> p{0.05, 0.15, 0.12, 0.95, 1.0, 0.5, kNaN, 0.1};
  const std::vector<bool> o{false, true, false, true, true, false, true, true};
  const std::vector<ev::ReliabilityBin> bins = ev::reliabilityBins (p, o);
  ASSERT_EQ (bins.size (), 10u);
  std::size_t total = 0;
  for (std::size_t b = 0; b < bins.size (); ++b)
  {
    EXPECT_DOUBLE_EQ (bins[b].lo, static_cast<double> (b) / 10.0);
    EXPECT_DOUBLE_EQ (bins[b].hi, static_cast<double> (b + 1) / 10.0);
    total += bins[b].count;
  }
  EXPECT_EQ (total, p.size () - 1);  // the NaN is in no bin
  EXPECT_EQ (bins[0].count, 1u);
  EXPECT_EQ (bins[1].count, 3u);  // 0.15, 0.12 and the edge 0.1
  EXPECT_NEAR (bins[1].mean_predicted, (0.15 + 0.12 + 0.1) / 3.0, 1e-15);
  EXPECT_NEAR (bins[1].observed, 2.0 / 3.0, 1e-15);
  EXPECT_EQ (bins[5].count, 1u);
  EXPECT_EQ (bins[9].count, 2u);  // 1.0 belongs to the last bin
  EXPECT_NEAR (bins[9].mean_predicted, 0.975, 1e-15);
  EXPECT_DOUBLE_EQ (bins[9].observed, 1.0);
  EXPECT_EQ (bins[3].count, 0u);
  EXPECT_TRUE (std::isnan (bins[3].mean_predicted));
  EXPECT_TRUE (std::isnan (bins[3].observed));
  EXPECT_THROW (ev::reliabilityBins (p, o, 0), std::invalid_argument);
}

TEST (Percentile, LinearInterpolationBetweenClosestRanks)
{
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};  // unsorted on purpose
  EXPECT_DOUBLE_EQ (ev::percentile (v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ (ev::percentile (v, 50.0), 2.5);
  EXPECT_DOUBLE_EQ (ev::percentile (v, 90.0), 3.7);  // rank 2.7
  EXPECT_DOUBLE_EQ (ev::percentile (v, 100.0), 4.0);
  EXPECT_DOUBLE_EQ (ev::percentile ({7.0}, 99.0), 7.0);
  EXPECT_TRUE (std::isnan (ev::percentile ({}, 50.0)));
  EXPECT_THROW (ev::percentile (v, 101.0), std::invalid_argument);

  std::vector<double> times;
  for (int i = 1; i <= 101; ++i)
    times.push_back (i);
  const ev::TimeSummary s = ev::summarizeTimes (times);
  EXPECT_DOUBLE_EQ (s.median, 51.0);
  EXPECT_DOUBLE_EQ (s.p90, 91.0);
  EXPECT_DOUBLE_EQ (s.p99, 100.0);
  EXPECT_DOUBLE_EQ (s.max, 101.0);
}

TEST (MeanStd, SampleStandardDeviation)
{
  const ev::MeanStd m = ev::meanStd ({2, 4, 4, 4, 5, 5, 7, 9});
  EXPECT_DOUBLE_EQ (m.mean, 5.0);
  EXPECT_NEAR (m.std, std::sqrt (32.0 / 7.0), 1e-15);
  EXPECT_DOUBLE_EQ (ev::meanStd ({3.0}).std, 0.0);
  EXPECT_TRUE (std::isnan (ev::meanStd ({}).mean));
  // Per-group spread averaged over groups; a single-value group is skipped.
  EXPECT_NEAR (ev::meanGroupStd ({{0.0, 2.0}, {1.0, 1.0, 1.0}, {5.0}}), (std::sqrt (2.0) + 0.0) / 2.0, 1e-15);
  EXPECT_TRUE (std::isnan (ev::meanGroupStd ({{1.0}})));
}

TEST (FlipRate, MinorityShareAveragedOverPoses)
{
  // 1 of 4 against the majority; unanimous; a tie (1/2); a pose without re-samples is skipped.
  EXPECT_DOUBLE_EQ (ev::flipRate ({{true, true, true, false}, {false, false, false, false, false}, {true, false}, {}}),
                    (0.25 + 0.0 + 0.5) / 3.0);
  EXPECT_DOUBLE_EQ (ev::flipRate ({{false, true, true}}), 1.0 / 3.0);
  EXPECT_TRUE (std::isnan (ev::flipRate ({})));
  EXPECT_TRUE (std::isnan (ev::flipRate ({{}})));
}

TEST (AnyFlipRate, OneDissentFlipsThePose)
{
  // One dissent of four; unanimous; a tie; single draws and empty poses are skipped.
  EXPECT_DOUBLE_EQ (ev::anyFlipRate ({{true, true, true, false}, {false, false, false}, {true, false}, {true}, {}}),
                    2.0 / 3.0);
  EXPECT_DOUBLE_EQ (ev::anyFlipRate ({{false, false}, {true, true, true}}), 0.0);
  EXPECT_TRUE (std::isnan (ev::anyFlipRate ({{true}, {}})));
}

TEST (HiddenCollisions, ShareOfFreeAnswersThatCollide)
{
  const auto h = ev::hiddenCollisions ({true, true, true, false, true}, {false, true, false, true, false});
  EXPECT_EQ (h.free_answers, 4u);
  EXPECT_EQ (h.hidden, 1u);
  EXPECT_DOUBLE_EQ (h.rate, 0.25);
  const auto none = ev::hiddenCollisions ({false, false}, {true, false});
  EXPECT_EQ (none.free_answers, 0u);
  EXPECT_TRUE (std::isnan (none.rate));
  EXPECT_THROW (ev::hiddenCollisions ({true}, {true, false}), std::invalid_argument);
}

TEST (ReliabilityCheck, TenPointsOrTwoStandardErrorsWhicheverIsWider)
{
  // n = 30 at p = 0.5: 2 sqrt(0.25 / 30) = 0.1826 > 0.1.
  EXPECT_NEAR (ev::reliabilityTolerance (0.5, 30), 2.0 * std::sqrt (0.25 / 30.0), 1e-12);
  // n = 400 at p = 0.5: 0.05 < 0.1, the floor holds.
  EXPECT_DOUBLE_EQ (ev::reliabilityTolerance (0.5, 400), 0.1);
  EXPECT_DOUBLE_EQ (ev::reliabilityTolerance (0.0, 30), 0.1);
  EXPECT_TRUE (std::isnan (ev::reliabilityTolerance (0.5, 0)));
  ev::ReliabilityBin bin;
  bin.count = 30;
  bin.mean_predicted = 0.5;
  bin.observed = 0.68;  // 0.18 <= 0.1826
  EXPECT_TRUE (ev::reliabilityBinWithin (bin));
  bin.observed = 0.69;
  EXPECT_FALSE (ev::reliabilityBinWithin (bin));
  bin.count = 1000;
  bin.mean_predicted = 0.05;
  bin.observed = 0.15;  // exactly the floor
  EXPECT_TRUE (ev::reliabilityBinWithin (bin));
  bin.observed = 0.151;
  EXPECT_FALSE (ev::reliabilityBinWithin (bin));
  bin.count = 0;
  bin.mean_predicted = kNaN;
  bin.observed = kNaN;
  EXPECT_FALSE (ev::reliabilityBinWithin (bin));
}

TEST (SignedDistanceErrors, MedianInScaleUnitsAndCoverage)
{
  // Errors 1, 3, 0.5 (scale 1, 1, 0.5 -> 1, 3, 1); the NaN estimate is skipped by the median.
  const auto e = ev::signedDistanceErrors ({1.0, -2.0, 0.5, kNaN}, {1.0, 1.0, kNaN, 1.0}, {0.0, 1.0, 0.0, 0.0},
                                           {1.0, 1.0, 0.5, 1.0});
  EXPECT_EQ (e.count, 3u);
  EXPECT_EQ (e.total, 4u);
  EXPECT_DOUBLE_EQ (e.median_abs_error, 1.0);
  // Covered: |1| <= 2; not |3| > 2; not a NaN std; not the pose without an estimate.
  EXPECT_DOUBLE_EQ (e.coverage, 1.0 / 4.0);
  const auto none = ev::signedDistanceErrors ({kNaN}, {1.0}, {0.0}, {1.0});
  EXPECT_EQ (none.count, 0u);
  EXPECT_TRUE (std::isnan (none.median_abs_error));
  EXPECT_TRUE (std::isnan (none.coverage));
  EXPECT_THROW (ev::signedDistanceErrors ({1.0}, {1.0}, {0.0, 1.0}, {1.0}), std::invalid_argument);
}

TEST (ParetoFront, HandExample)
{
  // (time, accuracy); lower time and higher accuracy are better.
  const std::vector<double> x{1.0, 2.0, 3.0, 0.5, 2.0, 5.0, kNaN, 1.0, 5.0};
  const std::vector<double> y{0.5, 0.9, 0.8, 0.2, 0.9, 1.0, 1.0, 0.4, 0.95};
  const std::vector<bool> expected{true,  // fastest with 0.5
                                   true,  // ties with the next one: neither dominates
                                   false, // slower and worse than (2, 0.9)
                                   true,  // the fastest
                                   true,  // duplicate of (2, 0.9)
                                   true,  // the most accurate
                                   false, // NaN time
                                   false, // same time as (1, 0.5), less accurate
                                   false}; // same time as (5, 1.0), less accurate
  EXPECT_EQ (ev::paretoFront (x, y), expected);
  EXPECT_THROW (ev::paretoFront ({1.0}, {}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Primitives: closed forms

TEST (ClosedForm, HandExamples)
{
  const ev::Box unit{Eigen::Vector3d::Constant (0.5), Eigen::Vector3d::Constant (0.5)};
  EXPECT_NEAR (ev::signedDistance (unit, ev::Box{Eigen::Vector3d (2.5, 2.5, 0.5), Eigen::Vector3d::Constant (0.5)}),
               std::sqrt (2.0), 1e-15);  // apart by 1 in x and in y
  EXPECT_NEAR (ev::signedDistance (unit, ev::Box{Eigen::Vector3d (1.3, 0.6, 0.4), Eigen::Vector3d::Constant (0.5)}),
               -0.2, 1e-15);  // overlaps 0.2 in x, 0.9 in y and z
  const ev::Box tall{Eigen::Vector3d::Zero (), Eigen::Vector3d (1.0, 2.0, 3.0)};
  EXPECT_NEAR (ev::signedDistance (ev::Sphere{Eigen::Vector3d::Zero (), 0.5}, tall), -1.5, 1e-15);
  EXPECT_NEAR (ev::signedDistance (ev::Sphere{Eigen::Vector3d (4.0, 6.0, 0.0), 1.0}, tall), 4.0, 1e-15);  // 3-4-5
  EXPECT_NEAR (ev::signedDistance (ev::Sphere{Eigen::Vector3d (0, 0, 3), 1.0}, ev::Sphere{Eigen::Vector3d (4, 0, 0), 2.0}),
               2.0, 1e-15);
  const ev::PlanePatch floor{Eigen::Vector3d (0, 0, 0.1), 1.0};
  EXPECT_NEAR (ev::signedDistance (ev::Sphere{Eigen::Vector3d (0, 0, 0.3), 0.25}, floor), -0.05, 1e-15);
  EXPECT_NEAR (ev::signedDistance (ev::Cylinder{Eigen::Vector3d (0, 0, 0.12), 0.1, 0.5}, floor), 0.02, 1e-15);
  const ev::Box room{Eigen::Vector3d::Zero (), Eigen::Vector3d::Constant (2.0)};
  EXPECT_NEAR (ev::clearanceInside (room, ev::Box{Eigen::Vector3d (1.5, 0, 0), Eigen::Vector3d::Constant (0.1)}), 0.4,
               1e-15);
  // Through a vertical edge of the room: 0.3 out in x, 0.4 out in y.
  EXPECT_NEAR (ev::clearanceInside (room, ev::Box{Eigen::Vector3d (2.2, 2.3, 0), Eigen::Vector3d::Constant (0.1)}), -0.5,
               1e-15);
}

// ---------------------------------------------------------------------------------------------
// Primitives: sampling

TEST (Sampling, CountsFollowAreaOverSpacingSquared)
{
  const double s = 0.004;
  const auto expectCount = [&] (std::size_t n, double area, double rel) {
    const double expected = area / (s * s);
    EXPECT_NEAR (static_cast<double> (n), expected, rel * expected + 5.0);
  };
  const ev::Sphere sphere{Eigen::Vector3d (0.1, 0.2, 0.3), 0.07};
  EXPECT_EQ (ev::sampleSurface (sphere, s, 0.0, 1)->size (),
             static_cast<std::size_t> (std::lround (ev::surfaceArea (sphere) / (s * s))));
  const ev::Box box{Eigen::Vector3d::Zero (), Eigen::Vector3d (0.1, 0.05, 0.001)};  // a thin plate
  expectCount (ev::sampleSurface (box, s, 0.0, 2)->size (), ev::surfaceArea (box), 0.03);
  const ev::Cylinder cyl{Eigen::Vector3d::Zero (), 0.05, 0.15};
  expectCount (ev::sampleSurface (cyl, s, 0.0, 3)->size (), ev::surfaceArea (cyl), 0.03);
  const ev::PlanePatch patch{Eigen::Vector3d::Zero (), 0.2};
  expectCount (ev::sampleSurface (patch, s, 0.0, 4)->size (), ev::surfaceArea (patch), 0.01);
}

TEST (Sampling, NoiseFreePointsLieOnTheSurface)
{
  const ev::Sphere sphere{Eigen::Vector3d (0.1, 0.2, 0.3), 0.07};
  for (const pcl::PointXYZ& p : ev::sampleSurface (sphere, 0.005, 0.0, 1)->points)
    ASSERT_NEAR ((toVector (p) - sphere.center).norm (), sphere.radius, 1e-6);
  const ev::Box box{Eigen::Vector3d (0.0, 0.1, 0.0), Eigen::Vector3d (0.1, 0.05, 0.02)};
  for (const pcl::PointXYZ& p : ev::sampleSurface (box, 0.005, 0.0, 2)->points)
  {
    const Eigen::Vector3d rel = (toVector (p) - box.center).cwiseAbs ();
    ASSERT_NEAR ((rel - box.half_extents).maxCoeff (), 0.0, 1e-6);  // inside, on one face
  }
  const ev::Cylinder cyl{Eigen::Vector3d (0.0, 0.0, 0.1), 0.05, 0.15};
  for (const pcl::PointXYZ& p : ev::sampleSurface (cyl, 0.005, 0.0, 3)->points)
  {
    const Eigen::Vector3d q = toVector (p) - cyl.base_center;
    const double radial = std::hypot (q.x (), q.y ());
    const bool on_side = std::abs (radial - cyl.radius) < 1e-6 && q.z () > -1e-6 && q.z () < cyl.height + 1e-6;
    const bool on_cap = radial <= cyl.radius + 1e-6 && (std::abs (q.z ()) < 1e-6 || std::abs (q.z () - cyl.height) < 1e-6);
    ASSERT_TRUE (on_side || on_cap) << q.transpose ();
  }
}

TEST (Sampling, NoiseHasTheRequestedSigmaOnEveryAxis)
{
  const double sigma = 0.002;
  const ev::PlanePatch patch{Eigen::Vector3d (0, 0, 0.5), 0.25};
  const ev::MeanStd dz = residualStats (*ev::sampleSurface (patch, 0.004, sigma, 9),
                                        [&] (const Eigen::Vector3d& p) { return p.z () - 0.5; });
  EXPECT_NEAR (dz.mean, 0.0, 0.05 * sigma);
  EXPECT_NEAR (dz.std, sigma, 0.03 * sigma);
  // Noisy minus noise-free with the same seed is the noise itself, on all three axes.
  const ev::Sphere sphere{Eigen::Vector3d::Zero (), 0.1};
  const ev::PrimitiveCloud::Ptr clean = ev::sampleSurface (sphere, 0.003, 0.0, 5);
  const ev::PrimitiveCloud::Ptr noisy = ev::sampleSurface (sphere, 0.003, sigma, 5);
  ASSERT_EQ (clean->size (), noisy->size ());
  for (int axis = 0; axis < 3; ++axis)
  {
    std::vector<double> d;
    for (std::size_t i = 0; i < clean->size (); ++i)
      d.push_back (toVector (noisy->points[i])[axis] - toVector (clean->points[i])[axis]);
    const ev::MeanStd m = ev::meanStd (d);
    EXPECT_NEAR (m.mean, 0.0, 0.05 * sigma) << "axis " << axis;
    EXPECT_NEAR (m.std, sigma, 0.03 * sigma) << "axis " << axis;
  }
}

TEST (Sampling, DeterministicForASeed)
{
  const ev::Cylinder cyl{Eigen::Vector3d::Zero (), 0.05, 0.1};
  const ev::PrimitiveCloud::Ptr a = ev::sampleSurface (cyl, 0.004, 0.001, 77);
  const ev::PrimitiveCloud::Ptr b = ev::sampleSurface (cyl, 0.004, 0.001, 77);
  const ev::PrimitiveCloud::Ptr c = ev::sampleSurface (cyl, 0.004, 0.001, 78);
  ASSERT_EQ (a->size (), b->size ());
  for (std::size_t i = 0; i < a->size (); ++i)
    ASSERT_EQ (toVector (a->points[i]), toVector (b->points[i]));
  EXPECT_NE (toVector (a->points[0]), toVector (c->points[0]));
}

TEST (Sampling, RejectsBadArguments)
{
  const ev::Sphere sphere{Eigen::Vector3d::Zero (), 0.1};
  EXPECT_THROW (ev::sampleSurface (sphere, 0.0, 0.0, 1), std::invalid_argument);
  EXPECT_THROW (ev::sampleSurface (sphere, 0.01, -1.0, 1), std::invalid_argument);
  EXPECT_THROW (ev::sampleSurface (ev::Sphere{Eigen::Vector3d::Zero (), 0.0}, 0.01, 0.0, 1), std::invalid_argument);
  EXPECT_THROW (ev::sampleSurface (ev::Sphere{Eigen::Vector3d::Zero (), 100.0}, 1e-4, 0.0, 1), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Primitives: the W2 query set

TEST (PrimitiveQueries, ClosedFormAgreesWithNoiseFreeSamples)
{
  // Noise-free samples lie on the surfaces, so the closest pair can never be nearer than the
  // exact gap, and with stratified sampling it is less than one (coarser) spacing farther
  // (about a third of one is seen). Penetrating surfaces cross, so some pair is within that
  // tolerance too. At scale 8 the deepest penetration is 4 cm.
  for (double scale : {1.0, 8.0})
  {
    ev::PrimitiveWorkloadOptions options;
    options.sigma_scale = scale;
    options.seed = 3;
    options.quick = true;
    options.noise_free = true;
    for (const ev::PrimitiveQuery& q : ev::makePrimitiveQueries (options))
    {
      const double tol = std::max (q.spacing_a, q.spacing_b);
      const double m = minPairDistance (q.a, *q.b);
      if (q.exact_distance > 0.0)
      {
        EXPECT_GE (m, q.exact_distance - 1e-6) << q.name << " scale " << scale;
        EXPECT_LE (m, q.exact_distance + tol) << q.name << " scale " << scale;
      }
      else
      {
        EXPECT_LE (m, tol) << q.name << " scale " << scale;
      }
    }
  }
}

TEST (PrimitiveQueries, GapsSpanNearContactAndEasyOnBothSides)
{
  const double scale = 1.5;
  const double sigma = ev::kPrimitiveBaseSigma * scale;
  const std::vector<double> gaps = ev::primitiveGapsInSigma (false);
  const std::vector<ev::PrimitiveQuery> queries = ev::makePrimitiveQueries (scale, 11, false);
  ASSERT_EQ (queries.size () % gaps.size (), 0u);
  std::map<std::string, int> near, easy_free, easy_collision;
  for (std::size_t i = 0; i < queries.size (); ++i)
  {
    const ev::PrimitiveQuery& q = queries[i];
    EXPECT_DOUBLE_EQ (q.sigma, sigma);
    // Every scenario places its object so that the closed form equals the nominal gap.
    EXPECT_NEAR (q.exact_distance, gaps[i % gaps.size ()] * sigma, 1e-9) << q.name;
    EXPECT_EQ (q.exact_collision, q.exact_distance <= 0.0) << q.name;
    EXPECT_EQ (q.name.rfind (q.scenario + "/", 0), 0u) << q.name;
    near[q.scenario] += std::abs (q.exact_distance) < sigma;
    easy_free[q.scenario] += q.exact_distance > 3.0 * sigma;
    easy_collision[q.scenario] += q.exact_distance < -3.0 * sigma;
  }
  EXPECT_EQ (near.size (), 11u);
  for (const auto& [scenario, n] : near)
  {
    EXPECT_GE (n, 4) << scenario;
    EXPECT_GE (easy_free[scenario], 2) << scenario;
    EXPECT_GE (easy_collision[scenario], 1) << scenario;
  }
  // The resting contact (gap 0) reads as collision, exactly.
  const auto resting = std::find_if (queries.begin (), queries.end (),
                                     [] (const ev::PrimitiveQuery& q) { return q.name == "cylinder_plane/0s"; });
  ASSERT_NE (resting, queries.end ());
  EXPECT_EQ (resting->exact_distance, 0.0);
  EXPECT_TRUE (resting->exact_collision);
}

TEST (PrimitiveQueries, SeedChangesOnlyTheSamples)
{
  const std::vector<ev::PrimitiveQuery> a = ev::makePrimitiveQueries (1.0, 5, true);
  const std::vector<ev::PrimitiveQuery> b = ev::makePrimitiveQueries (1.0, 5, true);
  const std::vector<ev::PrimitiveQuery> c = ev::makePrimitiveQueries (1.0, 6, true);
  ASSERT_EQ (a.size (), b.size ());
  ASSERT_EQ (a.size (), c.size ());
  for (std::size_t i = 0; i < a.size (); ++i)
  {
    EXPECT_EQ (a[i].name, c[i].name);
    EXPECT_EQ (a[i].exact_distance, c[i].exact_distance);
    ASSERT_EQ (a[i].b->size (), b[i].b->size ());
    for (std::size_t k = 0; k < a[i].b->size (); ++k)
      ASSERT_EQ (toVector (a[i].b->points[k]), toVector (b[i].b->points[k])) << a[i].name;
    EXPECT_NE (toVector (a[i].b->points[0]), toVector (c[i].b->points[0])) << a[i].name;
  }
  // The fixed object is one cloud per scenario, shared by its queries.
  EXPECT_EQ (a[0].a.get (), a[1].a.get ());
  EXPECT_NE (a[0].b.get (), a[1].b.get ());
}

TEST (PrimitiveQueries, RejectsScalesOutsideTheValidRange)
{
  EXPECT_THROW (ev::makePrimitiveQueries (0.0, 1, true), std::invalid_argument);
  EXPECT_THROW (ev::makePrimitiveQueries (8.5, 1, true), std::invalid_argument);
}
