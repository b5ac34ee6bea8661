// SPDX-License-Identifier: BSD-3-Clause
// Batch queries over many poses on several threads (issue #8): collideBatch() and
// ProbabilisticCollision::computeBatch() answer every pose exactly as the single query does,
// whatever the thread count. Tests named *Concurrent* run under ThreadSanitizer in CI
// (scripts/ci-reliability.sh); their hierarchies are built before any thread starts.
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "sanitized_build.h"
#include "scenes.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace pcl_probcollision;
using pcl_probcollision_test::jitteredGrid;
using pcl_probcollision_test::patchWithHole;
using pcl_probcollision_test::poseSweep;

namespace
{
#ifdef PCL_PC_SANITIZED
constexpr int kPoses = 9;  // instrumented code is 10-50x slower; still three poses per thread
#else
constexpr int kPoses = 30;
#endif

template <typename T>
bool
sameBits (const T& x, const T& y)
{
  return std::memcmp (&x, &y, sizeof (T)) == 0;
}

bool
sameBits (const std::vector<float>& x, const std::vector<float>& y)
{
  return x.size () == y.size () && (x.empty () || std::memcmp (x.data (), y.data (), x.size () * sizeof (float)) == 0);
}

/** Every field but the timings, bit for bit (NaN payloads included). */
void
expectSameResult (const CollisionResult& want, const CollisionResult& got, const std::string& where)
{
  SCOPED_TRACE (where);
  EXPECT_EQ (want.status, got.status);
  EXPECT_EQ (want.message, got.message);
  EXPECT_EQ (want.verdict, got.verdict);
  EXPECT_TRUE (sameBits (want.probability, got.probability)) << want.probability << " vs " << got.probability;
  EXPECT_EQ (want.lower_bound, got.lower_bound);
  EXPECT_EQ (want.no_leaf_tested, got.no_leaf_tested);
  EXPECT_EQ (want.witness_side, got.witness_side);
  EXPECT_EQ (want.witness_index, got.witness_index);
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_TRUE (sameBits (want.witness_point[k], got.witness_point[k])) << k;
    EXPECT_TRUE (sameBits (want.witness_normal[k], got.witness_normal[k])) << k;
  }
  EXPECT_EQ (want.points_a, got.points_a);
  EXPECT_EQ (want.points_b, got.points_b);
  EXPECT_EQ (want.points_skipped_nonfinite, got.points_skipped_nonfinite);
  EXPECT_EQ (want.bv_tests, got.bv_tests);
  EXPECT_EQ (want.leaf_pairs_tested, got.leaf_pairs_tested);
  EXPECT_EQ (want.kernel_leaf_pairs, got.kernel_leaf_pairs);
  EXPECT_EQ (want.degenerate_leaf_pairs, got.degenerate_leaf_pairs);
  EXPECT_EQ (want.classifier_iterations, got.classifier_iterations);
  EXPECT_TRUE (sameBits (want.probabilities_a, got.probabilities_a));
  EXPECT_TRUE (sameBits (want.probabilities_b, got.probabilities_b));
}

/** How many results have each verdict, indexed by Verdict. */
std::vector<int>
verdictCounts (const std::vector<CollisionResult>& results)
{
  std::vector<int> counts (4, 0);
  for (const CollisionResult& r : results)
    ++counts[static_cast<int> (r.verdict)];
  return counts;
}
} // namespace

TEST (CollideBatch, ConcurrentBatchEqualsSingleQueriesForEveryModeAndThreadCount)
{
  const CloudModel a (jitteredGrid (20, 0.005, 0.001, 1));
  const CloudModel b (jitteredGrid (24, 0.005, 0.001, 2));
  const std::vector<Eigen::Isometry3d> poses = poseSweep (kPoses, 3);
  for (const TraversalMode mode : {TraversalMode::ExpectedWeight, TraversalMode::Stochastic, TraversalMode::ExpandedBV})
  {
    CollisionRequest request;
    request.traversal = mode;
    request.seed = 77;
    request.exhaustive = true;
    request.per_point = true;
    // The reference: one collide() per pose, each drawing its own classifier.
    std::vector<CollisionResult> single (poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
      ASSERT_TRUE (collide (a, b, poses[i], request, single[i])) << single[i].message;
    const std::vector<int> counts = verdictCounts (single);
    EXPECT_GT (counts[static_cast<int> (Verdict::Free)], 0);
    EXPECT_GT (counts[static_cast<int> (Verdict::InContact)] + counts[static_cast<int> (Verdict::InCollision)], 0);
    for (const int threads : {1, 2, 3})
    {
      std::vector<CollisionResult> batch;
      EXPECT_TRUE (collideBatch (a, b, poses, request, batch, threads));
      ASSERT_EQ (batch.size (), poses.size ());
      for (std::size_t i = 0; i < poses.size (); ++i)
      {
        ASSERT_EQ (batch[i].probabilities_a.size (), a.size ());
        expectSameResult (single[i], batch[i],
                          "mode " + std::to_string (static_cast<int> (mode)) + ", threads " + std::to_string (threads) +
                              ", pose " + std::to_string (i));
      }
    }
  }
}

TEST (CollideBatch, ConcurrentBatchWithBadPosesFailsThemAndAnswersTheOthers)
{
  const CloudModel a (jitteredGrid (16, 0.005, 0.001, 4));
  const CloudModel b (jitteredGrid (16, 0.005, 0.001, 5));
  std::vector<Eigen::Isometry3d> poses = poseSweep (8, 6);
  poses[2].translation ().y () = std::numeric_limits<double>::quiet_NaN ();
  poses[5].linear () *= 1.5;
  CollisionRequest request;
  request.per_point = true;
  const RobustClassifier classifier (request.classifier);
  std::vector<CollisionResult> batch (3);  // stale content is replaced
  EXPECT_FALSE (collideBatch (a, b, poses, request, batch, 2, &classifier));
  ASSERT_EQ (batch.size (), poses.size ());
  for (std::size_t i = 0; i < poses.size (); ++i)
  {
    CollisionResult single;
    const bool ok = collide (a, b, poses[i], request, single, &classifier);
    EXPECT_EQ (ok, i != 2 && i != 5) << i;
    if (!ok)
    {
      EXPECT_EQ (batch[i].status, CollisionResult::Status::InvalidInput) << i;
      EXPECT_NE (batch[i].message.find ("pose"), std::string::npos) << batch[i].message;
      EXPECT_TRUE (std::isnan (batch[i].probability)) << i;
      EXPECT_EQ (batch[i].verdict, Verdict::Unknown) << i;
    }
    else
    {
      EXPECT_TRUE (batch[i].ok ()) << i << ": " << batch[i].message;
    }
    expectSameResult (single, batch[i], "pose " + std::to_string (i));
  }
}

TEST (CollideBatch, NegativeThreadCountThrowsNamingIt)
{
  const CloudModel a (jitteredGrid (4, 0.01, 0.001, 7));
  const std::vector<Eigen::Isometry3d> poses (2, Eigen::Isometry3d::Identity ());
  std::vector<CollisionResult> results;
  try
  {
    collideBatch (a, a, poses, CollisionRequest (), results, -1);
    FAIL () << "threads = -1 accepted";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("threads"), std::string::npos) << what;
    EXPECT_NE (what.find ("-1"), std::string::npos) << what;
  }
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (patchWithHole (4, 0.01, Eigen::Vector3d::Zero (), 8));
  pc.setTargetCloud (patchWithHole (4, 0.01, Eigen::Vector3d::Zero (), 9));
  try
  {
    pc.computeBatch (poses, results, -3);
    FAIL () << "threads = -3 accepted";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("threads = -3"), std::string::npos) << what;
  }
}

TEST (CollideBatch, EmptyPoseListGivesNoResults)
{
  const CloudModel a (jitteredGrid (4, 0.01, 0.001, 10));
  std::vector<CollisionResult> results (5);
  EXPECT_TRUE (collideBatch (a, a, {}, CollisionRequest (), results));
  EXPECT_TRUE (results.empty ());
  ProbabilisticCollision<pcl::PointXYZ> pc;  // no clouds: nothing to answer, nothing fails
  results.resize (2);
  EXPECT_TRUE (pc.computeBatch ({}, results, 2));
  EXPECT_TRUE (results.empty ());
}

TEST (CollideBatch, InvalidRequestOrPoseFailsEveryPoseLikeCollide)
{
  const CloudModel a (jitteredGrid (6, 0.01, 0.001, 11));
  std::vector<Eigen::Isometry3d> poses = poseSweep (4, 12);
  CollisionRequest bad;
  bad.rho_min = 2.0;
  for (const bool bad_pose : {false, true})
  {
    const CollisionRequest& request = bad_pose ? CollisionRequest () : bad;
    if (bad_pose)
      for (Eigen::Isometry3d& T : poses)
        T.linear () *= 2.0;  // a scale, not a rotation
    const CloudModel& b = a;
    std::vector<CollisionResult> batch;
    EXPECT_FALSE (collideBatch (a, b, poses, request, batch, 2));
    ASSERT_EQ (batch.size (), poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
    {
      CollisionResult single;
      EXPECT_FALSE (collide (a, b, poses[i], request, single));
      EXPECT_FALSE (batch[i].message.empty ());
      expectSameResult (single, batch[i], "pose " + std::to_string (i));
    }
  }
}

TEST (CollideBatch, ConcurrentComputeBatchEqualsComputePoseByPose)
{
  // A lies 0.5 m off in its own frame and the poses bring it onto B: a witness of A reported in
  // A's frame instead of B's would be far from B's patch.
  const Eigen::Vector3d offset (0.5, -0.3, 0.0);
  const auto input = patchWithHole (12, 0.008, offset, 13);
  const auto target = patchWithHole (16, 0.008, Eigen::Vector3d::Zero (), 14);
  auto configure = [&] (ProbabilisticCollision<pcl::PointXYZ>& pc) {
    pc.setInputCloud (input);
    pc.setTargetCloud (target);
    pc.setInputNoise (SensorNoiseModel::isotropic (0.002));
    pc.setTargetNoise (SensorNoiseModel::isotropic (0.002));
    CollisionRequest request;
    request.per_point = true;
    request.exhaustive = true;
    pc.setRequest (request);
  };
  std::vector<Eigen::Isometry3d> poses = poseSweep (kPoses, 15);
  for (Eigen::Isometry3d& pose : poses)
    pose = pose * Eigen::Translation3d (-offset);
  poses[1].translation ().x () = std::numeric_limits<double>::infinity ();
  poses[4].linear () = Eigen::Matrix3d (Eigen::Vector3d (1.0, 1.0, -1.0).asDiagonal ());  // a reflection

  ProbabilisticCollision<pcl::PointXYZ> one_by_one;
  configure (one_by_one);
  std::vector<CollisionResult> single (poses.size ());
  for (std::size_t i = 0; i < poses.size (); ++i)
    EXPECT_EQ (one_by_one.compute (poses[i], single[i]), i != 1 && i != 4) << i << ": " << single[i].message;
  const std::vector<int> counts = verdictCounts (single);
  EXPECT_GT (counts[static_cast<int> (Verdict::Free)], 0);
  EXPECT_GT (counts[static_cast<int> (Verdict::InContact)] + counts[static_cast<int> (Verdict::InCollision)], 0);

  for (const int threads : {1, 2})
  {
    ProbabilisticCollision<pcl::PointXYZ> batched;
    configure (batched);
    std::vector<CollisionResult> batch;
    EXPECT_FALSE (batched.computeBatch (poses, batch, threads));
    ASSERT_EQ (batch.size (), poses.size ());
    for (std::size_t i = 0; i < poses.size (); ++i)
    {
      CollisionResult want = single[i];
      if (!want.ok ())
        want.message = "pose " + std::to_string (i) + ": " + want.message;
      expectSameResult (want, batch[i], "threads " + std::to_string (threads) + ", pose " + std::to_string (i));
      if (!batch[i].ok ())
        continue;
      // Per-point values on the callers' clouds (the NaN point stays NaN), skipped points counted.
      ASSERT_EQ (batch[i].probabilities_a.size (), input->size ());
      ASSERT_EQ (batch[i].probabilities_b.size (), target->size ());
      EXPECT_TRUE (std::isnan (batch[i].probabilities_a[13]));
      EXPECT_TRUE (std::isnan (batch[i].probabilities_b[17]));
      EXPECT_EQ (batch[i].points_skipped_nonfinite, 2u);
      // The witness is in the target's frame: on or near B's patch (16 x 8 mm wide, at z = 0).
      if (batch[i].witness_side != 0)
      {
        EXPECT_LT (batch[i].witness_point.head<2> ().cwiseAbs ().maxCoeff (), 0.08) << batch[i].witness_point.transpose ();
        EXPECT_LT (std::abs (batch[i].witness_point.z ()), 0.03) << batch[i].witness_point.transpose ();
      }
    }
    EXPECT_NE (batch[4].message.find ("pose 4: "), std::string::npos) << batch[4].message;
    EXPECT_TRUE (batched.getInputModel () && batched.getTargetModel ());
  }
}
