// SPDX-License-Identifier: BSD-3-Clause
// CollisionResult and Verdict (collision_result.h): the verdict names, and a default result that
// says "not computed" in every field (NaN numbers, Unknown verdict, no witness, not ok).
#include <pcl_probcollision/collision_result.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace pcl_probcollision;

TEST (Verdict, NamesAreTheDocumentedWords)
{
  EXPECT_STREQ (verdictName (Verdict::Free), "free");
  EXPECT_STREQ (verdictName (Verdict::InContact), "contact");
  EXPECT_STREQ (verdictName (Verdict::InCollision), "collision");
  EXPECT_STREQ (verdictName (Verdict::Unknown), "unknown");
}

TEST (Verdict, AValueOutsideTheEnumIsNamedUnknown)
{
  EXPECT_STREQ (verdictName (static_cast<Verdict> (42)), "unknown");
}

TEST (AnsweredBy, NamesAreTheDocumentedWords)
{
  // The words of pcd_collision's JSON member answered_by (docs/CLI.md).
  EXPECT_STREQ (answeredByName (AnsweredBy::Separators), "separators");
  EXPECT_STREQ (answeredByName (AnsweredBy::SurfaceLayer), "surface");
  EXPECT_STREQ (answeredByName (AnsweredBy::Pooled), "pooled");
  EXPECT_STREQ (answeredByName (AnsweredBy::Unknown), "unknown");
  EXPECT_STREQ (answeredByName (static_cast<AnsweredBy> (42)), "unknown");
}

TEST (CollisionResult, DefaultIsNotOkAndHoldsNothingComputed)
{
  const CollisionResult r;
  EXPECT_FALSE (r.ok ());
  EXPECT_EQ (r.status, CollisionResult::Status::InvalidInput);
  EXPECT_TRUE (r.message.empty ());
  EXPECT_EQ (r.verdict, Verdict::Unknown);
  EXPECT_EQ (r.answered_by, AnsweredBy::Unknown);
  EXPECT_TRUE (std::isnan (r.probability)) << r.probability;
  EXPECT_FALSE (r.lower_bound);
  EXPECT_FALSE (r.no_leaf_tested);
  // No witness: side 0, index -1, position and normal NaN.
  EXPECT_EQ (r.witness_side, 0);
  EXPECT_EQ (r.witness_index, -1);
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_TRUE (std::isnan (r.witness_point[i])) << i;
    EXPECT_TRUE (std::isnan (r.witness_normal[i])) << i;
  }
  // No distance, nor the nearest samples CollisionRequest::distance finds.
  EXPECT_TRUE (std::isnan (r.signed_distance));
  EXPECT_TRUE (std::isnan (r.signed_distance_std));
  EXPECT_FALSE (r.sample_distance);
  EXPECT_TRUE (r.nearest_point_a.array ().isNaN ().all ());
  EXPECT_TRUE (r.nearest_point_b.array ().isNaN ().all ());
  EXPECT_EQ (r.points_a, 0u);
  EXPECT_EQ (r.points_b, 0u);
  EXPECT_EQ (r.points_skipped_nonfinite, 0u);
  EXPECT_EQ (r.bv_tests, 0u);
  EXPECT_EQ (r.leaf_pairs_tested, 0u);
  EXPECT_EQ (r.kernel_leaf_pairs, 0u);
  EXPECT_EQ (r.degenerate_leaf_pairs, 0u);
  EXPECT_EQ (r.classifier_iterations, 0u);
  // Timings are NaN unless request.enable_timings.
  EXPECT_TRUE (std::isnan (r.build_ms));
  EXPECT_TRUE (std::isnan (r.query_ms));
  EXPECT_TRUE (r.probabilities_a.empty ());
  EXPECT_TRUE (r.probabilities_b.empty ());
}

TEST (CollisionResult, OkOnlyForStatusOk)
{
  CollisionResult r;
  r.status = CollisionResult::Status::Ok;
  EXPECT_TRUE (r.ok ());
  r.status = CollisionResult::Status::NumericalFailure;
  EXPECT_FALSE (r.ok ());
  r.status = CollisionResult::Status::InvalidInput;
  EXPECT_FALSE (r.ok ());
}
