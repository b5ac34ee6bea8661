// SPDX-License-Identifier: BSD-3-Clause
// Checks shared by several test files: of a CollisionResult (the tests of collide() and of
// ProbabilisticCollision), and a classification expected to succeed (the classifier's tests).
#pragma once

#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/robust_classifier.h>

#include <gtest/gtest.h>

#include "scenes.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace pcl_probcollision_test
{
/** \brief The contract of every result (docs/RELIABILITY.md): a success is a finite P in [0, 1]
  * with the verdict verdictFor() gives it; a failure is NaN, Unknown and a message. No other
  * field is non-finite except documented "not computed" NaN. */
inline void
expectSane (const pcl_probcollision::CollisionResult& r, bool ok,
            const pcl_probcollision::CollisionRequest& rq = pcl_probcollision::CollisionRequest ())
{
  using pcl_probcollision::Verdict;
  if (!ok)
  {
    EXPECT_FALSE (r.ok ());
    EXPECT_FALSE (r.message.empty ());
    EXPECT_TRUE (std::isnan (r.probability)) << r.probability;
    EXPECT_EQ (r.verdict, Verdict::Unknown);
    return;
  }
  ASSERT_TRUE (r.ok ()) << r.message;
  ASSERT_TRUE (std::isfinite (r.probability));
  EXPECT_GE (r.probability, 0.0);
  EXPECT_LE (r.probability, 1.0);
  // A capped query (budget_exhausted) does not read free under free_below but contact, unless one
  // of two answers pooled or laddered ran in full and read free (collide.cpp).
  const Verdict by_probability = pcl_probcollision::verdictFor (r.probability, rq);
  if (r.budget_exhausted && by_probability == Verdict::Free)
    EXPECT_TRUE (r.verdict == Verdict::InContact ||
                 ((rq.surface_pooled || rq.surface_ladder) && r.verdict == Verdict::Free))
        << "P " << r.probability;
  else
    EXPECT_EQ (r.verdict, by_probability);
  EXPECT_NE (r.verdict, Verdict::Unknown);
  if (r.witness_side != 0)
  {
    EXPECT_TRUE (r.witness_point.allFinite ());
    // The normal is NaN ("not computed") when the separator's gradient collapsed at the witness
    // (RobustClassifier: coincident points, no separating direction); otherwise a unit vector.
    if (r.witness_normal.array ().isNaN ().all ())
      EXPECT_GT (r.leaf_pairs_tested, 0u);
    else
      EXPECT_NEAR (r.witness_normal.norm (), 1.0, 1e-6);
    EXPECT_GE (r.witness_index, 0);
  }
  else
  {
    EXPECT_EQ (r.witness_index, -1);
    EXPECT_TRUE (r.no_leaf_tested || r.leaf_pairs_tested > 0);
  }
  for (const auto* v : {&r.probabilities_a, &r.probabilities_b})
    for (const float p : *v)
      EXPECT_TRUE (std::isnan (p) || (p >= 0.0f && p <= 1.0f)) << p;
  for (const double t : {r.build_ms, r.query_ms})
    EXPECT_TRUE (std::isnan (t) || (std::isfinite (t) && t >= 0.0)) << t;
}

/** \brief The same object representation (NaN payloads included). */
template <typename T>
bool
sameBits (const T& x, const T& y)
{
  return std::memcmp (&x, &y, sizeof (T)) == 0;
}

inline bool
sameBits (const std::vector<float>& x, const std::vector<float>& y)
{
  return x.size () == y.size () && (x.empty () || std::memcmp (x.data (), y.data (), x.size () * sizeof (float)) == 0);
}

/** \brief Every field but the timings, bit for bit (NaN payloads included). */
inline void
expectSameResult (const pcl_probcollision::CollisionResult& want, const pcl_probcollision::CollisionResult& got,
                  const std::string& where)
{
  SCOPED_TRACE (where);
  EXPECT_EQ (want.status, got.status);
  EXPECT_EQ (want.message, got.message);
  EXPECT_EQ (want.verdict, got.verdict);
  EXPECT_TRUE (sameBits (want.probability, got.probability)) << want.probability << " vs " << got.probability;
  EXPECT_EQ (want.lower_bound, got.lower_bound);
  EXPECT_EQ (want.budget_exhausted, got.budget_exhausted);
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

/** \brief How many results have each verdict, indexed by Verdict. */
inline std::vector<int>
verdictCounts (const std::vector<pcl_probcollision::CollisionResult>& results)
{
  std::vector<int> counts (4, 0);
  for (const pcl_probcollision::CollisionResult& r : results)
    ++counts[static_cast<int> (r.verdict)];
  return counts;
}

/** \brief RobustClassifier (params).classify (a, b), expected to succeed. */
inline pcl_probcollision::ClassifierResult
classify (const pcl_probcollision::ClassifierParams& params, const ClassifierCloud& a, const ClassifierCloud& b)
{
  pcl_probcollision::ClassifierResult r;
  const pcl_probcollision::RobustClassifier classifier (params);
  EXPECT_TRUE (classifier.classify (a.view (), b.view (), r)) << r.message;
  return r;
}
} // namespace pcl_probcollision_test
