// SPDX-License-Identifier: BSD-3-Clause
// CollisionRequest (collision_request.h): the documented defaults, validate() naming the member
// out of range, and operator== over every member.
#include <pcl_probcollision/collision_request.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

using namespace pcl_probcollision;

namespace
{
/** \brief A named change to a request: what validate() must name, or what operator== must see. */
struct Change
{
  std::string name;
  std::function<void (CollisionRequest&)> apply;
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();
constexpr double kInf = std::numeric_limits<double>::infinity ();
} // namespace

TEST (CollisionRequest, DefaultsAreTheDocumentedOnes)
{
  const CollisionRequest r;
  EXPECT_EQ (r.free_below, 0.1);       // METHOD.md 7, A = 0.9
  EXPECT_EQ (r.collision_above, 0.9);  // B = 0.1
  EXPECT_FALSE (r.exhaustive);
  EXPECT_FALSE (r.per_point);
  EXPECT_FALSE (r.enable_timings);
  EXPECT_EQ (r.traversal, TraversalMode::ExpectedWeight);
  EXPECT_EQ (r.rho_min, 1e-3);
  EXPECT_EQ (r.seed, 1u);
  EXPECT_EQ (r.expanded_k_sigma, 3.0);
  EXPECT_FALSE (r.defer_kernel_fits);
  EXPECT_FALSE (r.distance);  // no nearest-sample search unless asked
  // The leaf-pair classifier: Ladder, Robust, kappa = 0.9, C = 1000 (README, "Defaults").
  EXPECT_EQ (r.classifier.kernel, KernelMode::Ladder);
  EXPECT_EQ (r.classifier.training, TrainingMode::Robust);
  EXPECT_EQ (r.classifier.confidence, 0.9);
  EXPECT_EQ (r.classifier.C, 1000.0);
  EXPECT_NO_THROW (r.validate ());
}

TEST (CollisionRequest, ValidateNamesTheMemberOutOfRangeAndItsValue)
{
  const std::vector<Change> cases = {
      {"free_below -0.1", [] (CollisionRequest& r) { r.free_below = -0.1; }},
      {"free_below 0.6", [] (CollisionRequest& r) { r.free_below = 0.6; }},
      {"free_below nan", [] (CollisionRequest& r) { r.free_below = kNaN; }},
      {"collision_above 0.4", [] (CollisionRequest& r) { r.collision_above = 0.4; }},
      {"collision_above 1.1", [] (CollisionRequest& r) { r.collision_above = 1.1; }},
      {"collision_above nan", [] (CollisionRequest& r) { r.collision_above = kNaN; }},
      {"rho_min -0.5", [] (CollisionRequest& r) { r.rho_min = -0.5; }},
      {"rho_min 2", [] (CollisionRequest& r) { r.rho_min = 2.0; }},
      {"rho_min nan", [] (CollisionRequest& r) { r.rho_min = kNaN; }},
      {"expanded_k_sigma -1", [] (CollisionRequest& r) { r.expanded_k_sigma = -1.0; }},
      {"expanded_k_sigma inf", [] (CollisionRequest& r) { r.expanded_k_sigma = kInf; }},
      {"expanded_k_sigma nan", [] (CollisionRequest& r) { r.expanded_k_sigma = kNaN; }},
      {"traversal mode 7", [] (CollisionRequest& r) { r.traversal = static_cast<TraversalMode> (7); }},
      // The classifier's own check runs too, and names its parameter.
      {"C 0", [] (CollisionRequest& r) { r.classifier.C = 0.0; }},
      {"confidence 0.4", [] (CollisionRequest& r) { r.classifier.confidence = 0.4; }},
  };
  for (const Change& c : cases)
  {
    CollisionRequest r;
    c.apply (r);
    try
    {
      r.validate ();
      ADD_FAILURE () << c.name << " did not throw";
    }
    catch (const pcl::BadArgumentException& e)
    {
      EXPECT_NE (std::string (e.what ()).find (c.name), std::string::npos) << c.name << ": " << e.what ();
    }
  }
}

// The two ways of combining the surface layer with the separators exclude each other; either
// alone is accepted.
TEST (CollisionRequest, ValidateRefusesPooledWithLadder)
{
  CollisionRequest r;
  r.surface = r.surface_pooled = r.surface_ladder = true;
  try
  {
    r.validate ();
    FAIL () << "surface_pooled with surface_ladder did not throw";
  }
  catch (const pcl::BadArgumentException& e)
  {
    EXPECT_NE (std::string (e.what ()).find ("surface_pooled and surface_ladder"), std::string::npos) << e.what ();
  }
  r.surface_pooled = false;
  EXPECT_NO_THROW (r.validate ());
  r.surface_pooled = true;
  r.surface_ladder = false;
  EXPECT_NO_THROW (r.validate ());
}

// surface_pooled, surface_ladder and surface_calibrated act on the surface layer's answer: without
// surface they would change nothing, and the separators would answer a request that names it.
TEST (CollisionRequest, ValidateRefusesSurfaceSwitchesWithoutSurface)
{
  const std::vector<std::pair<std::string, bool CollisionRequest::*>> switches = {
      {"surface_pooled", &CollisionRequest::surface_pooled},
      {"surface_ladder", &CollisionRequest::surface_ladder},
      {"surface_calibrated", &CollisionRequest::surface_calibrated}};
  for (const auto& [name, member] : switches)
  {
    CollisionRequest r;
    r.*member = true;
    try
    {
      r.validate ();
      ADD_FAILURE () << name << " without surface did not throw";
    }
    catch (const pcl::BadArgumentException& e)
    {
      EXPECT_NE (std::string (e.what ()).find (name + " needs surface"), std::string::npos) << e.what ();
    }
    r.surface = true;
    EXPECT_NO_THROW (r.validate ()) << name;
  }
  // The surface layer's cap caps nothing without it.
  CollisionRequest capped;
  capped.max_surface_pairs = 64;
  try
  {
    capped.validate ();
    ADD_FAILURE () << "max_surface_pairs without surface did not throw";
  }
  catch (const pcl::BadArgumentException& e)
  {
    EXPECT_NE (std::string (e.what ()).find ("max_surface_pairs needs surface"), std::string::npos) << e.what ();
  }
  capped.surface = true;
  EXPECT_NO_THROW (capped.validate ());
}

TEST (CollisionRequest, ValidateMessageCarriesTheMethodPrefix)
{
  CollisionRequest r;
  r.rho_min = 2.0;
  try
  {
    r.validate ();
    FAIL () << "rho_min 2 did not throw";
  }
  catch (const pcl::BadArgumentException& e)
  {
    EXPECT_NE (std::string (e.what ()).find ("[pcl_probcollision::CollisionRequest::validate] rho_min 2"),
               std::string::npos)
        << e.what ();
  }
}

TEST (CollisionRequest, ValidateNamesTheFirstMemberOutOfRange)
{
  CollisionRequest r;
  r.free_below = 0.7;   // checked first
  r.rho_min = -1.0;     // checked later
  try
  {
    r.validate ();
    FAIL () << "did not throw";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("free_below 0.7"), std::string::npos) << what;
    EXPECT_EQ (what.find ("rho_min"), std::string::npos) << what;
  }
}

// free_below = 0 left nothing Free (P = 0 read contact) and collision_above = 1 nothing
// InCollision (P = 1 read contact), both in range (a probe, 2026-12-04): the ranges are (0, 0.5]
// and [0.5, 1) now, so that every verdict can be reached; thresholdsError() holds the rule and
// its words, which pcd_collision's -thresholds prints too.
TEST (CollisionRequest, ThresholdsThatLeaveAVerdictUnreachableAreRefused)
{
  const std::vector<std::pair<Change, std::string>> cases = {
      {{"free_below 0", [] (CollisionRequest& r) { r.free_below = 0.0; }},
       "free_below 0 outside (0, 0.5] (P < free_below is free: every verdict must be reachable)"},
      {{"free_below -0", [] (CollisionRequest& r) { r.free_below = -0.0; }}, "free_below -0 outside (0, 0.5]"},
      {{"collision_above 1", [] (CollisionRequest& r) { r.collision_above = 1.0; }},
       "collision_above 1 outside [0.5, 1) (P > collision_above is collision: every verdict must be reachable)"},
  };
  for (const auto& [c, words] : cases)
  {
    CollisionRequest r;
    c.apply (r);
    EXPECT_EQ (r.thresholdsError ().rfind (words, 0), 0u) << c.name << ": " << r.thresholdsError ();
    try
    {
      r.validate ();
      ADD_FAILURE () << c.name << " did not throw";
    }
    catch (const pcl::BadArgumentException& e)
    {
      EXPECT_NE (std::string (e.what ()).find ("[pcl_probcollision::CollisionRequest::validate] " + words), std::string::npos)
          << e.what ();
    }
  }
  EXPECT_EQ (CollisionRequest ().thresholdsError (), "");
}

TEST (CollisionRequest, ValidateAcceptsTheRangeEnds)
{
  const std::vector<Change> cases = {
      {"free_below 1e-12", [] (CollisionRequest& r) { r.free_below = 1e-12; }},
      {"free_below 0.5", [] (CollisionRequest& r) { r.free_below = 0.5; }},
      {"collision_above 0.5", [] (CollisionRequest& r) { r.collision_above = 0.5; }},
      {"collision_above 1 - 1e-12", [] (CollisionRequest& r) { r.collision_above = 1.0 - 1e-12; }},
      {"free_below = collision_above = 0.5",
       [] (CollisionRequest& r) { r.free_below = r.collision_above = 0.5; }},
      {"rho_min 0", [] (CollisionRequest& r) { r.rho_min = 0.0; }},
      {"rho_min 1", [] (CollisionRequest& r) { r.rho_min = 1.0; }},
      {"expanded_k_sigma 0", [] (CollisionRequest& r) { r.expanded_k_sigma = 0.0; }},
      {"traversal Stochastic", [] (CollisionRequest& r) { r.traversal = TraversalMode::Stochastic; }},
      {"traversal ExpandedBV", [] (CollisionRequest& r) { r.traversal = TraversalMode::ExpandedBV; }},
  };
  for (const Change& c : cases)
  {
    CollisionRequest r;
    c.apply (r);
    EXPECT_NO_THROW (r.validate ()) << c.name;
  }
}

TEST (CollisionRequest, EqualityComparesEveryMember)
{
  EXPECT_TRUE (CollisionRequest () == CollisionRequest ());
  EXPECT_FALSE (CollisionRequest () != CollisionRequest ());
  const std::vector<Change> cases = {
      {"free_below", [] (CollisionRequest& r) { r.free_below = 0.2; }},
      {"collision_above", [] (CollisionRequest& r) { r.collision_above = 0.8; }},
      {"exhaustive", [] (CollisionRequest& r) { r.exhaustive = true; }},
      {"per_point", [] (CollisionRequest& r) { r.per_point = true; }},
      {"enable_timings", [] (CollisionRequest& r) { r.enable_timings = true; }},
      {"traversal", [] (CollisionRequest& r) { r.traversal = TraversalMode::Stochastic; }},
      {"rho_min", [] (CollisionRequest& r) { r.rho_min = 1e-4; }},
      {"seed", [] (CollisionRequest& r) { r.seed = 2; }},
      {"expanded_k_sigma", [] (CollisionRequest& r) { r.expanded_k_sigma = 2.0; }},
      {"defer_kernel_fits", [] (CollisionRequest& r) { r.defer_kernel_fits = true; }},
      {"max_leaf_fits", [] (CollisionRequest& r) { r.max_leaf_fits = 7; }},
      {"max_surface_pairs", [] (CollisionRequest& r) { r.max_surface_pairs = 7; }},
      {"surface", [] (CollisionRequest& r) { r.surface = true; }},
      {"surface_pooled", [] (CollisionRequest& r) { r.surface_pooled = true; }},
      {"surface_ladder", [] (CollisionRequest& r) { r.surface_ladder = true; }},
      {"surface_calibrated", [] (CollisionRequest& r) { r.surface_calibrated = true; }},
      {"distance", [] (CollisionRequest& r) { r.distance = true; }},
      {"classifier.C", [] (CollisionRequest& r) { r.classifier.C = 10.0; }},
      {"classifier.kernel", [] (CollisionRequest& r) { r.classifier.kernel = KernelMode::Linear; }},
      {"classifier.loss", [] (CollisionRequest& r) { r.classifier.loss = Loss::Huber; }},
      {"classifier.exact_points_in_maximum",
       [] (CollisionRequest& r) { r.classifier.exact_points_in_maximum = true; }},
  };
  for (const Change& c : cases)
  {
    CollisionRequest changed;
    c.apply (changed);
    const CollisionRequest copy = changed;
    EXPECT_FALSE (changed == CollisionRequest ()) << c.name;
    EXPECT_FALSE (CollisionRequest () == changed) << c.name;
    EXPECT_TRUE (changed != CollisionRequest ()) << c.name;
    EXPECT_TRUE (copy == changed) << c.name;
    EXPECT_FALSE (copy != changed) << c.name;
  }
}
