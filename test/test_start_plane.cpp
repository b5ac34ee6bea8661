// SPDX-License-Identifier: BSD-3-Clause
// detail/start_plane.h: a leaf pair's start plane, assessed from the hierarchies without
// gathering, must agree with RobustClassifier::classify()'s own (collide() passes pairs over by
// it, so it may only ever say "passed over" where classify() would).
#include <pcl_probcollision/detail/start_plane.h>
#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/robust_classifier.h>

#include <gtest/gtest.h>

#include "scenes.h"

#include <cmath>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using namespace pcl_probcollision::detail;
using pcl_probcollision_test::randomSheet;

namespace
{
std::vector<const ProbabilisticBVH::Node*>
leaves (const ProbabilisticBVH& bvh)
{
  std::vector<const ProbabilisticBVH::Node*> out;
  for (const ProbabilisticBVH::Node& n : bvh.nodes ())
    if (n.isLeaf ())
      out.push_back (&n);
  return out;
}
} // namespace

// Every leaf pair of two noisy sheets (one tilted and moved, at gaps from penetrating to well
// apart, at two noise levels): where startPlaneUsable() says yes, classify() starts from the
// same plane (its passed-over maximum equals Phi(z)), and wherever passesOver() says yes for a
// threshold, classify() passes the pair over at that threshold.
TEST (StartPlane, AgreesWithTheClassifiersStartAndPassOver)
{
  const ClassifierParams params;
  const RobustClassifier classifier (params);
  std::mt19937_64 rng (17);
  std::uniform_real_distribution<double> unit (0.0, 1.0);
  std::size_t usable = 0, passed = 0, kept = 0, separable = 0;
  for (const double sigma : {0.002, 0.01})
    for (const double gap : {-0.01, 0.0, 0.005, 0.02, 0.06})
    {
      SCOPED_TRACE (::testing::Message () << "sigma " << sigma << ", gap " << gap);
      const ProbabilisticBVH a (randomSheet (300, 0.2, 0.0, sigma, 41));
      const ProbabilisticBVH b (randomSheet (300, 0.2, 0.0, sigma, 42));
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
      T.rotate (Eigen::AngleAxisd (0.3, Eigen::Vector3d (1.0, 0.5, 0.0).normalized ()));
      T.pretranslate (Eigen::Vector3d (0.03, -0.02, gap));
      std::vector<Eigen::Vector3d> ma, mb;
      std::vector<Eigen::Matrix3d> ca, cb;
      for (const ProbabilisticBVH::Node* la : leaves (a))
        for (const ProbabilisticBVH::Node* lb : leaves (b))
        {
          const double z = startPlaneZ (a, *la, b, *lb, T);
          const bool usable_start = startPlaneUsable (a, *la, b, *lb, T, params.C);
          const PointSetView va = a.gatherPoints (*la, ma, ca);
          const PointSetView vb = b.gatherPoints (*lb, T, mb, cb);
          ClassifierResult r;
          ASSERT_TRUE (classifier.classify (va, vb, r, KernelMode::Ladder, 1.0, false)) << r.message;
          if (usable_start)
          {
            ++usable;
            // Passed over at 1.0 exactly when the plane separates every point (P under 0.5).
            if (r.dominated)
            {
              ++separable;
              EXPECT_NEAR (r.probability, normalCdf (z), 1e-9 * std::max (1e-300, r.probability) + 1e-15);
            }
            else if (std::isfinite (z))
            {
              EXPECT_GE (normalCdf (z), 0.5 - 1e-12);
            }
          }
          for (int k = 0; k < 3; ++k)
          {
            const double threshold = k == 0 ? 1.0 : unit (rng) * (k == 1 ? 0.5 : 1e-3);
            if (!passesOver (a, *la, b, *lb, T, params.C, z, threshold))
            {
              ++kept;
              continue;
            }
            ++passed;
            ClassifierResult at;
            ASSERT_TRUE (classifier.classify (va, vb, at, KernelMode::Ladder, threshold, false)) << at.message;
            EXPECT_TRUE (at.dominated) << "passesOver() said yes where classify() fits (threshold " << threshold
                                       << ", z " << z << ")";
          }
        }
    }
  // Both branches exercised, on enough pairs to mean something.
  EXPECT_GT (usable, 1000u);
  EXPECT_GT (separable, 100u);
  EXPECT_GT (passed, 100u);
  EXPECT_GT (kept, 100u);
}

// Coinciding means give no plane: z is +inf and the pair is never passed over.
TEST (StartPlane, CoincidingMeansAreNeverPassedOver)
{
  const ProbabilisticBVH a (randomSheet (40, 0.05, 0.0, 0.002, 5));
  const ProbabilisticBVH::Node& root = a.nodes ().front ();
  const double z = startPlaneZ (a, root, a, root, Eigen::Isometry3d::Identity ());
  EXPECT_TRUE (std::isinf (z) && z > 0.0);
  EXPECT_FALSE (startPlaneUsable (a, root, a, root, Eigen::Isometry3d::Identity (), 1000.0));
  EXPECT_FALSE (passesOver (a, root, a, root, Eigen::Isometry3d::Identity (), 1000.0, z, 1.0));
}

// With a small C the bisector's |w|^2 / 2 outweighs theta = 0's hinge losses when the patches lie
// close against their width: classify() then starts from theta = 0 and fits the pair, however
// clearly the bisector separates it, and startPlaneUsable() must say no.
TEST (StartPlane, APlaneTheClassifierWouldNotStartFromIsNotUsable)
{
  ClassifierParams params;
  params.C = 1.0;
  const RobustClassifier classifier (params);
  const ProbabilisticBVH a (randomSheet (30, 0.2, 0.0, 1e-4, 7));
  const ProbabilisticBVH b (randomSheet (30, 0.2, 0.0, 1e-4, 8));
  const Eigen::Isometry3d T (Eigen::Translation3d (0.0, 0.0, -0.05));
  const ProbabilisticBVH::Node& ra = a.nodes ()[ProbabilisticBVH::rootId ()];
  const ProbabilisticBVH::Node& rb = b.nodes ()[ProbabilisticBVH::rootId ()];
  const double z = startPlaneZ (a, ra, b, rb, T);
  EXPECT_LT (normalCdf (z), 1e-6) << "the bisector separates the two sheets clearly";
  EXPECT_TRUE (mayPassOver (z, 1.0));
  EXPECT_FALSE (startPlaneUsable (a, ra, b, rb, T, params.C));
  EXPECT_FALSE (passesOver (a, ra, b, rb, T, params.C, z, 1.0));
  std::vector<Eigen::Vector3d> ma, mb;
  std::vector<Eigen::Matrix3d> ca, cb;
  ClassifierResult r;
  ASSERT_TRUE (classifier.classify (a.gatherPoints (ra, ma, ca), b.gatherPoints (rb, T, mb, cb), r, KernelMode::Ladder, 1.0));
  EXPECT_FALSE (r.dominated) << "classify() starts from theta = 0 here and fits";
  // The same sheets with the default C: the plane is usable and both pass the pair over.
  EXPECT_TRUE (startPlaneUsable (a, ra, b, rb, T, ClassifierParams ().C));
  EXPECT_TRUE (passesOver (a, ra, b, rb, T, ClassifierParams ().C, z, 1.0));
}
