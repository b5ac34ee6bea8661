// SPDX-License-Identifier: BSD-3-Clause
// Reliability (issue #7): the library API under bad input, numerical stress, concurrency and load.
// Every case has a documented outcome in docs/RELIABILITY.md: a clear failure (compute() false,
// status and message, NaN probability, Unknown verdict) or a correct answer in [0, 1].
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl/common/point_tests.h>

#include <gtest/gtest.h>

#include "sanitized_build.h"
#include "scenes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

using namespace pcl_probcollision;
using pcl_probcollision_test::patch;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace
{
// Sanitized builds (CI's ASan and TSan steps) run smaller workloads of the same tests: the
// contracts are the same, instrumented code is 10-50x slower.
#ifdef PCL_PC_SANITIZED
constexpr std::size_t kBatchPoses = 12000;
constexpr double kFarPatch = 0.5;  // side of the far-from-the-origin patch, metres
#else
constexpr std::size_t kBatchPoses = 100000;
constexpr double kFarPatch = 1.0;
#endif
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN ();
constexpr float kInf = std::numeric_limits<float>::infinity ();

/** The contract of every result: a success is a finite P in [0, 1] with its verdict; a failure is
  * NaN, Unknown and a message. No other field is non-finite except documented "not computed" NaN. */
void
expectSane (const CollisionResult& r, bool ok, const CollisionRequest& rq = CollisionRequest ())
{
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
  EXPECT_EQ (r.verdict, verdictFor (r.probability, rq));
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

struct Query
{
  bool ok = false;
  CollisionResult r;
};

Query
query (const Cloud::Ptr& a, const Cloud::Ptr& b, double sigma, CollisionRequest rq = CollisionRequest (),
       const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity (), const BVHParams& hierarchy = BVHParams ())
{
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setHierarchyParams (hierarchy);
  pc.setInputCloud (a);
  pc.setTargetCloud (b);
  if (sigma > 0)
  {
    pc.setInputNoise (SensorNoiseModel::isotropic (sigma));
    pc.setTargetNoise (SensorNoiseModel::isotropic (sigma));
  }
  pc.setRequest (rq);
  Query q;
  q.ok = pc.compute (pose, q.r);
  return q;
}

std::size_t
residentBytes ()
{
  long pages_total = 0, pages_resident = 0;
  std::FILE* f = std::fopen ("/proc/self/statm", "r");
  if (!f)
    return 0;
  if (std::fscanf (f, "%ld %ld", &pages_total, &pages_resident) != 2)
    pages_resident = 0;
  std::fclose (f);
  return static_cast<std::size_t> (pages_resident) * static_cast<std::size_t> (::sysconf (_SC_PAGESIZE));
}
} // namespace

// ---------------------------------------------------------------------------------------------
// Bad input matrix through ProbabilisticCollision<PointXYZ>.

TEST (Reliability, EmptyCloudsFailClearly)
{
  Cloud::Ptr empty (new Cloud);
  const auto full = patch (0.1, 0.01, 0.0, 0.0, 1);
  for (const auto& [a, b] : {std::pair (empty, full), std::pair (full, empty), std::pair (empty, empty)})
  {
    const Query q = query (a, b, 0.002);
    EXPECT_FALSE (q.ok);
    expectSane (q.r, false);
    EXPECT_EQ (q.r.status, CollisionResult::Status::InvalidInput);
  }
  // As a filter: the output is cleared, never stale.
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (full);
  pc.setTargetCloud (empty);
  Cloud out = *full;
  pc.filter (out);
  EXPECT_TRUE (out.empty ());
}

TEST (Reliability, AllNaNOrganizedCloudFailsWithNoFinitePoint)
{
  Cloud::Ptr holes (new Cloud (640, 480, pcl::PointXYZ (kNaN, kNaN, kNaN)));
  holes->is_dense = false;
  const Query q = query (patch (0.1, 0.01, 0.0, 0.0, 2), holes, 0.002);
  EXPECT_FALSE (q.ok);
  expectSane (q.r, false);
  EXPECT_NE (q.r.message.find ("no finite point"), std::string::npos) << q.r.message;
  EXPECT_NE (q.r.message.find ("307200"), std::string::npos) << q.r.message;
}

TEST (Reliability, PartlyNaNOrganizedCloudSkipsHolesAndKeepsTheLayout)
{
  // 640 x 480, a 0.2 m patch of 100 x 100 pixels in the middle with 1 in 7 pixels a hole (NaN or
  // Inf), everything else NaN: the answer equals the same cloud with the holes removed.
  Cloud::Ptr organized (new Cloud (640, 480, pcl::PointXYZ (kNaN, kNaN, kNaN)));
  organized->is_dense = false;
  Cloud::Ptr dense (new Cloud);
  std::mt19937 rng (3);
  std::normal_distribution<double> noise (0.0, 0.0005);
  std::size_t holes = 0;
  for (int v = 190; v < 290; ++v)
    for (int u = 270; u < 370; ++u)
    {
      const pcl::PointXYZ p (static_cast<float> ((u - 320) * 0.002), static_cast<float> ((v - 240) * 0.002),
                             static_cast<float> (noise (rng)));
      if ((u * 31 + v * 17) % 7 == 0)
      {
        (*organized) (u, v) = (u % 2) ? pcl::PointXYZ (kInf, 0.f, 0.f) : pcl::PointXYZ (kNaN, kNaN, kNaN);
        ++holes;
        continue;
      }
      (*organized) (u, v) = p;
      dense->push_back (p);
    }
  const auto b = patch (0.05, 0.005, 0.004, 0.0, 4);
  CollisionRequest rq;
  rq.exhaustive = true;
  rq.per_point = true;
  const Query with_holes = query (organized, b, 0.002, rq);
  const Query removed = query (dense, b, 0.002, rq);
  ASSERT_TRUE (with_holes.ok) << with_holes.r.message;
  ASSERT_TRUE (removed.ok) << removed.r.message;
  expectSane (with_holes.r, true, rq);
  EXPECT_EQ (with_holes.r.points_a, dense->size ());
  EXPECT_EQ (with_holes.r.points_skipped_nonfinite, organized->size () - dense->size ());
  EXPECT_GT (holes, 1000u);
  EXPECT_EQ (with_holes.r.probability, removed.r.probability);
  ASSERT_EQ (with_holes.r.probabilities_a.size (), organized->size ());
  for (std::size_t i = 0; i < organized->size (); ++i)
  {
    if (!pcl::isXYZFinite ((*organized)[i]))
    {
      EXPECT_TRUE (std::isnan (with_holes.r.probabilities_a[i])) << i;
    }
  }
  // The filter keeps the 640 x 480 layout.
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (organized);
  pc.setTargetCloud (b);
  pc.setInputNoise (SensorNoiseModel::isotropic (0.002));
  pc.setTargetNoise (SensorNoiseModel::isotropic (0.002));
  pc.setKeepOrganized (true);
  Cloud out;
  pc.filter (out);
  EXPECT_EQ (out.width, 640u);
  EXPECT_EQ (out.height, 480u);
}

TEST (Reliability, InfCoordinatesAreSkippedLikeNaN)
{
  auto a = patch (0.1, 0.01, 0.0, 0.0, 5);
  const auto b = patch (0.1, 0.01, 0.006, 0.0, 6);
  auto holes = pcl::make_shared<Cloud> (*a);
  (*holes)[7].x = kInf;
  (*holes)[20].z = -kInf;
  (*holes)[33].y = kNaN;
  holes->is_dense = false;
  const Query with_inf = query (holes, b, 0.002);
  ASSERT_TRUE (with_inf.ok) << with_inf.r.message;
  expectSane (with_inf.r, true);
  EXPECT_EQ (with_inf.r.points_skipped_nonfinite, 3u);
  EXPECT_EQ (with_inf.r.points_a, a->size () - 3);
  // An all-Inf cloud is "no finite point".
  Cloud::Ptr inf (new Cloud);
  inf->resize (50, pcl::PointXYZ (kInf, -kInf, kInf));
  inf->is_dense = false;
  const Query all_inf = query (a, inf, 0.002);
  EXPECT_FALSE (all_inf.ok);
  expectSane (all_inf.r, false);
  // A dense-flagged cloud that lies (is_dense = true with NaN inside) is still handled.
  auto liar = pcl::make_shared<Cloud> (*a);
  (*liar)[0].x = kNaN;
  liar->is_dense = true;
  const Query lied = query (liar, b, 0.002);
  ASSERT_TRUE (lied.ok) << lied.r.message;
  expectSane (lied.r, true);
  EXPECT_EQ (lied.r.points_skipped_nonfinite, 1u);
}

// Tiny clouds: fewer points than k = 10. With sensor noise each point is a proper Gaussian, so the
// answer is analytic for two single points (STYLE.md 7): P = Phi(-d / (sigma sqrt 2)) up to the
// discretisation term, which is zero for a single point.
TEST (Reliability, SinglePointAndTwoPointCloudsGiveAnswers)
{
  const double sigma = 0.002;
  Cloud::Ptr one (new Cloud);
  one->push_back (pcl::PointXYZ (0.f, 0.f, 0.f));
  Cloud::Ptr far (new Cloud);
  far->push_back (pcl::PointXYZ (0.f, 0.f, 0.05f));
  Cloud::Ptr same (new Cloud);
  same->push_back (pcl::PointXYZ (0.f, 0.f, 0.f));
  CollisionRequest rq;
  rq.exhaustive = true;
  const Query q_far = query (one, far, sigma, rq);
  ASSERT_TRUE (q_far.ok) << q_far.r.message;
  expectSane (q_far.r, true, rq);
  EXPECT_EQ (q_far.r.verdict, Verdict::Free) << q_far.r.probability;
  const Query q_same = query (one, same, sigma, rq);
  ASSERT_TRUE (q_same.ok) << q_same.r.message;
  expectSane (q_same.r, true, rq);
  EXPECT_NE (q_same.r.verdict, Verdict::Free) << q_same.r.probability;

  Cloud::Ptr two (new Cloud);
  two->push_back (pcl::PointXYZ (0.f, 0.f, 0.f));
  two->push_back (pcl::PointXYZ (0.01f, 0.f, 0.f));
  Cloud::Ptr two_far (new Cloud);
  two_far->push_back (pcl::PointXYZ (0.f, 0.f, 0.05f));
  two_far->push_back (pcl::PointXYZ (0.01f, 0.f, 0.05f));
  const Query q2 = query (two, two_far, sigma, rq);
  ASSERT_TRUE (q2.ok) << q2.r.message;
  expectSane (q2.r, true, rq);
  EXPECT_EQ (q2.r.verdict, Verdict::Free);
  const Query q2_same = query (two, two, sigma, rq);
  ASSERT_TRUE (q2_same.ok) << q2_same.r.message;
  expectSane (q2_same.r, true, rq);
  EXPECT_NE (q2_same.r.verdict, Verdict::Free);

  // Without any sensor noise a single point has no covariance at all (no neighbour): it is
  // still a valid, exact point.
  const Query exact = query (one, far, 0.0, rq);
  if (exact.ok)
  {
    expectSane (exact.r, true, rq);
    EXPECT_EQ (exact.r.verdict, Verdict::Free);
  }
  else
    expectSane (exact.r, false);
}

TEST (Reliability, IdenticalCollinearAndCoplanarCloudsHaveSingularCovariances)
{
  const double sigma = 0.002;
  CollisionRequest rq;
  rq.exhaustive = true;
  rq.per_point = true;
  const auto plane = patch (0.1, 0.01, 0.0, 0.0, 7);
  Cloud::Ptr identical (new Cloud);
  identical->resize (500, pcl::PointXYZ (0.f, 0.f, 0.05f));
  Cloud::Ptr line (new Cloud);
  for (int i = 0; i < 200; ++i)
    line->push_back (pcl::PointXYZ (static_cast<float> (-0.05 + i * 0.0005), 0.f, 0.05f));
  Cloud::Ptr line_touching (new Cloud);
  for (int i = 0; i < 200; ++i)
    line_touching->push_back (pcl::PointXYZ (static_cast<float> (-0.05 + i * 0.0005), 0.f, 0.f));
  for (const double s : {sigma, 0.0})
  {
    SCOPED_TRACE (s);
    // Clear of the plane by 5 cm (25 sigma): free, whatever the degeneracy.
    for (const auto& degenerate : {identical, line})
    {
      const Query q = query (degenerate, plane, s, rq);
      ASSERT_TRUE (q.ok) << q.r.message;
      expectSane (q.r, true, rq);
      EXPECT_EQ (q.r.verdict, Verdict::Free) << q.r.probability;
      const Query swapped = query (plane, degenerate, s, rq);
      ASSERT_TRUE (swapped.ok) << swapped.r.message;
      expectSane (swapped.r, true, rq);
      EXPECT_EQ (swapped.r.verdict, Verdict::Free) << swapped.r.probability;
    }
    // A line lying in the plane: never free.
    const Query touching = query (line_touching, plane, s, rq);
    ASSERT_TRUE (touching.ok) << touching.r.message;
    expectSane (touching.r, true, rq);
    EXPECT_NE (touching.r.verdict, Verdict::Free) << touching.r.probability;
    // Two identical coplanar sheets: never free.
    const Query coplanar = query (plane, plane, s, rq);
    ASSERT_TRUE (coplanar.ok) << coplanar.r.message;
    expectSane (coplanar.r, true, rq);
    EXPECT_NE (coplanar.r.verdict, Verdict::Free) << coplanar.r.probability;
  }
}

TEST (Reliability, DuplicatedPointsKeepTheVerdicts)
{
  const double sigma = 0.002;
  const auto a = patch (0.1, 0.01, 0.0, 0.0005, 8);
  auto doubled = pcl::make_shared<Cloud> (*a);
  *doubled += *a;
  for (const double gap : {0.03, 0.0})
  {
    const auto b = patch (0.1, 0.01, gap, 0.0005, 9);
    const Query once = query (a, b, sigma);
    const Query twice = query (doubled, b, sigma);
    ASSERT_TRUE (once.ok && twice.ok);
    expectSane (once.r, true);
    expectSane (twice.r, true);
    EXPECT_EQ (twice.r.points_a, 2 * a->size ());
    EXPECT_EQ (once.r.verdict, twice.r.verdict) << gap << ": " << once.r.probability << " vs " << twice.r.probability;
  }
}

// ---------------------------------------------------------------------------------------------
// Numerical robustness.

// PointXYZ is float: at 1e5 m its resolution is 1/128 m. A grid on multiples of 1/64 m keeps every
// coordinate exact after the shift, so any difference comes from the library's own arithmetic.
TEST (Reliability, FarFromTheOriginGivesTheSameAnswerAsAtTheOrigin)
{
  const double h = 1.0 / 64;
  const Eigen::Vector3d offset (1e5, -1e5, 1e5);
  CollisionRequest rq;
  rq.exhaustive = true;
  for (const double gap : {4 * h, 0.0})
  {
    SCOPED_TRACE (gap);
    const auto a0 = patch (kFarPatch, h, 0.0, 0.0, 10);
    const auto b0 = patch (kFarPatch / 2, h, gap, 0.0, 11);
    const auto a1 = patch (kFarPatch, h, 0.0, 0.0, 10, offset);
    const auto b1 = patch (kFarPatch / 2, h, gap, 0.0, 11, offset);
    for (std::size_t i = 0; i < a0->size (); ++i)
      ASSERT_EQ ((*a1)[i].x - static_cast<float> (offset.x ()), (*a0)[i].x);
    const Query near = query (a0, b0, 0.01, rq);
    const Query far = query (a1, b1, 0.01, rq);
    ASSERT_TRUE (near.ok && far.ok) << near.r.message << far.r.message;
    expectSane (near.r, true, rq);
    expectSane (far.r, true, rq);
    EXPECT_NEAR (near.r.probability, far.r.probability, 1e-6);
    EXPECT_EQ (near.r.verdict, far.r.verdict);
  }
}

TEST (Reliability, ReorderingThePointsKeepsTheProbability)
{
  CollisionRequest rq;
  rq.exhaustive = true;
  for (const double gap : {0.02, 0.004, 0.0})
  {
    SCOPED_TRACE (gap);
    const auto a = patch (0.1, 0.005, 0.0, 0.0007, 14);
    const auto b = patch (0.08, 0.005, gap, 0.0007, 15);
    auto a_shuffled = pcl::make_shared<Cloud> (*a);
    auto b_shuffled = pcl::make_shared<Cloud> (*b);
    std::mt19937 rng (16);
    std::shuffle (a_shuffled->begin (), a_shuffled->end (), rng);
    std::shuffle (b_shuffled->begin (), b_shuffled->end (), rng);
    const Query q0 = query (a, b, 0.002, rq);
    const Query q1 = query (a_shuffled, b_shuffled, 0.002, rq);
    ASSERT_TRUE (q0.ok && q1.ok);
    expectSane (q0.r, true, rq);
    expectSane (q1.r, true, rq);
    EXPECT_NEAR (q0.r.probability, q1.r.probability, 1e-6);
    EXPECT_EQ (q0.r.verdict, q1.r.verdict);
  }
}

// Tiny objects (1e-4 m) with proportionally tiny noise behave like their scaled-up selves.
TEST (Reliability, TinyObjectsGetTheirVerdicts)
{
  const double s = 1e-4;
  CollisionRequest rq;
  rq.exhaustive = true;
  BVHParams hierarchy;
  hierarchy.sigma_max = 0.05 * s;  // the hierarchy thresholds are in data units too
  const auto a = patch (s, s / 10, 0.0, 0.0, 17);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
  const Query clear = query (a, patch (s, s / 10, 0.5 * s, 0.0, 18), 0.02 * s, rq, I, hierarchy);
  const Query touching = query (a, patch (s, s / 10, 0.0, 0.0, 19), 0.02 * s, rq, I, hierarchy);
  ASSERT_TRUE (clear.ok && touching.ok) << clear.r.message << touching.r.message;
  expectSane (clear.r, true, rq);
  expectSane (touching.r, true, rq);
  EXPECT_EQ (clear.r.verdict, Verdict::Free) << clear.r.probability;
  EXPECT_NE (touching.r.verdict, Verdict::Free) << touching.r.probability;
}

// Millimetres against metres is a user error the library cannot see in either cloud alone. A 2 cm
// vertical plate stuck through a 1 m table at x = 0.3 m collides. Given in millimetres (x = 300)
// against the table in metres, the same numbers put the plate 300 units away: "free", a plausible
// wrong answer. Documented outcome: the library answers for the numbers given, the user must
// convert (docs/RELIABILITY.md), and the CLI warns when the two sizes differ by over 100x
// (test_cli_reliability).
TEST (Reliability, MixedUnitsAnswerForTheNumbersGivenAndConvertingFixesIt)
{
  Cloud::Ptr plate_m (new Cloud);
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      plate_m->push_back (pcl::PointXYZ (static_cast<float> (0.3 - 0.01 + 0.002 * i), 0.f,
                                         static_cast<float> (-0.01 + 0.002 * j)));
  auto plate_mm = pcl::make_shared<Cloud> (*plate_m);
  for (auto& p : plate_mm->points)
    p.getVector3fMap () *= 1000.0f;
  const auto table_m = patch (1.0, 0.02, 0.0, 0.0, 21);
  const Query right = query (plate_m, table_m, 0.002);
  const Query mixed = query (plate_mm, table_m, 0.002);
  ASSERT_TRUE (right.ok && mixed.ok) << right.r.message << mixed.r.message;
  expectSane (right.r, true);
  expectSane (mixed.r, true);
  EXPECT_NE (right.r.verdict, Verdict::Free) << right.r.probability;
  EXPECT_EQ (mixed.r.verdict, Verdict::Free) << mixed.r.probability;
}

// Regression (fuzz/fuzz_collide): finite coordinates near FLT_MAX crashed FLANN's kd-tree build
// (assertion in KDTreeSingleIndex::middleSplit). Beyond +-1e15 units the query now fails clearly.
TEST (Reliability, HugeFiniteCoordinatesFailClearly)
{
  const auto a = patch (0.1, 0.01, 0.0, 0.0, 30);
  Cloud::Ptr huge (new Cloud);
  huge->push_back (pcl::PointXYZ (3.0e38f, 0.f, 0.f));
  huge->push_back (pcl::PointXYZ (3.2e38f, 0.f, 0.f));
  huge->push_back (pcl::PointXYZ (3.3e38f, 1.f, 0.f));
  const Query q = query (a, huge, 0.002);
  EXPECT_FALSE (q.ok);
  expectSane (q.r, false);
  EXPECT_NE (q.r.message.find ("beyond the supported coordinate range"), std::string::npos) << q.r.message;
  EXPECT_NE (q.r.message.find ("target point 0"), std::string::npos) << q.r.message;
  // Just inside the range: an answer (far apart: free).
  Cloud::Ptr big (new Cloud);
  big->push_back (pcl::PointXYZ (1e14f, 0.f, 0.f));
  big->push_back (pcl::PointXYZ (1e14f, 1e14f, 0.f));
  const Query inside = query (a, big, 0.002);
  ASSERT_TRUE (inside.ok) << inside.r.message;
  expectSane (inside.r, true);
  EXPECT_EQ (inside.r.verdict, Verdict::Free);
}

TEST (Reliability, NonFiniteOrNonRigidPosesFail)
{
  const auto a = patch (0.1, 0.01, 0.0, 0.0, 22);
  const auto b = patch (0.1, 0.01, 0.05, 0.0, 23);
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity ();
  nan_pose.translation ().x () = std::nan ("");
  Eigen::Isometry3d inf_pose = Eigen::Isometry3d::Identity ();
  inf_pose.translation ().z () = std::numeric_limits<double>::infinity ();
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity ();
  scaled.linear () *= 1.5;
  for (const auto& pose : {nan_pose, inf_pose, scaled})
  {
    const Query q = query (a, b, 0.002, CollisionRequest (), pose);
    EXPECT_FALSE (q.ok);
    expectSane (q.r, false);
  }
  // Finite but absurd translations (beyond +-1e15) fail clearly. Regression (fuzz/fuzz_collide,
  // fuzz/regressions/slow-query-timeout-611fdb8a.bin): a 1e308 translation overflowed inside the
  // traversal and the query ran for minutes.
  for (const double t : {1e30, 1e308})
  {
    const Query far = query (a, b, 0.002, CollisionRequest (),
                             Eigen::Isometry3d (Eigen::Translation3d (t, -t, t)));
    EXPECT_FALSE (far.ok);
    expectSane (far.r, false);
    EXPECT_NE (far.r.message.find ("beyond the supported range"), std::string::npos) << far.r.message;
  }
  // 1e6 m away: free.
  const Query away = query (a, b, 0.002, CollisionRequest (), Eigen::Isometry3d (Eigen::Translation3d (1e6, 0, 0)));
  ASSERT_TRUE (away.ok) << away.r.message;
  expectSane (away.r, true);
  EXPECT_EQ (away.r.verdict, Verdict::Free);
}

// ---------------------------------------------------------------------------------------------
// Concurrency and load. Hierarchies are built from UncertainCloud directly (no FLANN, no
// OpenMP), so that ThreadSanitizer sees only our code; the CI runs these under TSan.

// A batch of 100,000 poses through one ProbabilisticCollision: memory does not grow per query,
// and spot-checked results equal fresh single queries. RSS is compared between 10,000 and 100,000
// queries (after the warm-up that sizes every buffer); sanitizer builds keep freed memory in
// quarantine, so the RSS bound is only asserted in plain builds.
TEST (Reliability, HundredThousandPoseBatchRunsInBoundedMemory)
{
  const auto a = patch (0.04, 0.01, 0.0, 0.0005, 27);
  const auto b = patch (0.1, 0.01, 0.0, 0.0005, 28);
  ProbabilisticCollision<pcl::PointXYZ> pc;
  pc.setInputCloud (a);
  pc.setTargetCloud (b);
  pc.setInputNoise (SensorNoiseModel::isotropic (0.002));
  pc.setTargetNoise (SensorNoiseModel::isotropic (0.002));
  auto poseOf = [] (std::size_t i) {
    // Deterministic sweep: heights from 3 cm above to 1 cm below, shifted sideways.
    const double t = static_cast<double> (i % 1000) / 1000.0;
    return Eigen::Isometry3d (Eigen::Translation3d (0.03 * std::sin (i * 0.37), 0.03 * std::cos (i * 0.23), 0.03 - 0.04 * t) *
                              Eigen::AngleAxisd (0.001 * static_cast<double> (i % 997), Eigen::Vector3d::UnitZ ()));
  };
  const std::size_t n = kBatchPoses;
  std::size_t rss_warm = 0, counts[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < n; ++i)
  {
    CollisionResult r;
    ASSERT_TRUE (pc.compute (poseOf (i), r)) << i << ": " << r.message;
    ASSERT_TRUE (r.probability >= 0.0 && r.probability <= 1.0) << i;
    ++counts[static_cast<int> (r.verdict)];
    if (i == 10000)
      rss_warm = residentBytes ();
    if (i % 9973 == 0)
    {
      const Query single = query (a, b, 0.002, CollisionRequest (), poseOf (i));
      ASSERT_TRUE (single.ok);
      EXPECT_EQ (single.r.probability, r.probability) << i;
      EXPECT_EQ (single.r.verdict, r.verdict) << i;
    }
  }
  const std::size_t rss_end = residentBytes ();
  EXPECT_EQ (counts[0], 0u);
  EXPECT_GT (counts[static_cast<int> (Verdict::Free)], 0u);
  EXPECT_GT (counts[static_cast<int> (Verdict::InCollision)], 0u);
  std::printf ("%zu poses: RSS %.1f MiB after 10000, %.1f MiB at the end\n", n, rss_warm / 1048576.0,
               rss_end / 1048576.0);
#ifndef PCL_PC_SANITIZED
  ASSERT_GT (rss_warm, 0u);
  EXPECT_LT (rss_end, rss_warm + 4u * 1048576u) << "memory grew by " << (rss_end - rss_warm) << " bytes";
#endif
}
