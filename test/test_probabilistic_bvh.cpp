// SPDX-License-Identifier: BSD-3-Clause
// Tests of the epsilon-overlap hierarchy (METHOD.md 8), its leakage (8.4, 11.7), the OBB
// separating-axis test (8.3) and the simultaneous traversal (8.5, 6.3, 11.7). Oracles: brute
// force over all point pairs, analytic leakage values, and boxes separated or overlapping by
// construction. Leaf tests here are simple geometric ones, not the robust classifier.
#include <pcl_probcollision/detail/bvh_traversal.h>
#include <pcl_probcollision/detail/leakage.h>
#include <pcl_probcollision/detail/obb.h>
#include <pcl_probcollision/probabilistic_bvh.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include "scenes.h"
#include "seeded_draws.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

using namespace pcl_probcollision;
using detail::OrientedBox;
using detail::TraversalParams;
using detail::TraversalResult;
using Node = ProbabilisticBVH::Node;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::Phi;
using pcl_probcollision_test::randomPose;
using pcl_probcollision_test::randomRotation;
using pcl_probcollision_test::Shape;
using pcl_probcollision_test::shapeCloud;
using pcl_probcollision_test::shapeName;
using pcl_probcollision_test::transformCloud;

namespace
{
std::vector<int>
distinctPoints (const ProbabilisticBVH& bvh, const Node& node)
{
  const auto span = bvh.indices (node);
  std::vector<int> v (span.begin (), span.end ());
  std::sort (v.begin (), v.end ());
  v.erase (std::unique (v.begin (), v.end ()), v.end ());
  return v;
}

double
cloudScale (const UncertainCloud& c)
{
  double s = 1.0;
  for (const auto& x : c.means)
    s = std::max (s, x.cwiseAbs ().maxCoeff ());
  return s;
}

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

// Vertex-projection separating-axis check in frame A: an independent implementation of the
// SAT over the 15 candidate axes. Returns the largest normalised gap over the axes (> 0:
// separated by that much; < 0: every axis overlaps by at least |gap|).
double
bruteSeparationGap (const OrientedBox& a, const OrientedBox& b_in_a)
{
  const Eigen::Matrix<double, 3, 8> ca = a.corners ();
  const Eigen::Matrix<double, 3, 8> cb = b_in_a.corners ();
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i)
  {
    axes.push_back (a.axes.col (i));
    axes.push_back (b_in_a.axes.col (i));
    for (int j = 0; j < 3; ++j)
    {
      const Eigen::Vector3d c = a.axes.col (i).cross (b_in_a.axes.col (j));
      if (c.norm () > 1e-6)
        axes.push_back (c.normalized ());
    }
  }
  double best = -std::numeric_limits<double>::infinity ();
  for (const auto& L : axes)
  {
    const Eigen::Matrix<double, 1, 8> pa = L.transpose () * ca;
    const Eigen::Matrix<double, 1, 8> pb = L.transpose () * cb;
    const double gap = std::max (pb.minCoeff () - pa.maxCoeff (), pa.minCoeff () - pb.maxCoeff ());
    best = std::max (best, gap);
  }
  return best;
}

OrientedBox
randomBox (std::mt19937_64& rng, bool allow_flat)
{
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  std::uniform_real_distribution<double> h (0.0, 1.0);
  OrientedBox b;
  b.center = draw3 (u, rng);
  b.axes = randomRotation (rng);
  b.half_extents = draw3 (h, rng);
  if (allow_flat && h (rng) < 0.3)
    b.half_extents (static_cast<int> (3 * h (rng)) % 3) = 0.0;
  return b;
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

// ---------------------------------------------------------------------------------------------
// Parameters and input validation

TEST (BVHParams, DefaultsMatchMethod)
{
  const BVHParams p;
  EXPECT_EQ (p.split_style, BVHParams::SplitStyle::Pca);
  EXPECT_EQ (p.n_max, 20);
  EXPECT_EQ (p.n_min, 8);
  EXPECT_DOUBLE_EQ (p.sigma_max, 0.05);
  EXPECT_DOUBLE_EQ (p.epsilon, 0.02);
  EXPECT_DOUBLE_EQ (p.k_sigma, 1.0);
  EXPECT_NO_THROW (p.validate ());
}

TEST (BVHParams, ValidateRejectsEachParameterByName)
{
  auto message = [] (const BVHParams& p) -> std::string {
    try
    {
      p.validate ();
    }
    catch (const pcl::BadArgumentException& e)
    {
      return e.detailedMessage ();
    }
    return "";
  };
  BVHParams p;
  p.n_max = 0;
  EXPECT_NE (message (p).find ("n_max 0"), std::string::npos) << message (p);
  p = BVHParams ();
  p.n_min = 21;
  EXPECT_NE (message (p).find ("n_min 21"), std::string::npos) << message (p);
  p = BVHParams ();
  p.n_min = 0;
  EXPECT_NE (message (p).find ("n_min 0"), std::string::npos);
  p = BVHParams ();
  p.sigma_max = -0.1;
  EXPECT_NE (message (p).find ("sigma_max -0.1"), std::string::npos);
  p = BVHParams ();
  p.epsilon = 0.5;
  EXPECT_NE (message (p).find ("epsilon 0.5"), std::string::npos);
  p = BVHParams ();
  p.epsilon = std::numeric_limits<double>::quiet_NaN ();
  EXPECT_NE (message (p).find ("epsilon"), std::string::npos);
  p = BVHParams ();
  p.k_sigma = -1.0;
  EXPECT_NE (message (p).find ("k_sigma -1"), std::string::npos);
  p = BVHParams ();
  p.k_sigma = std::numeric_limits<double>::infinity ();
  EXPECT_THROW (p.validate (), pcl::BadArgumentException);
}

TEST (ProbabilisticBVH, BadInputThrowsAndKeepsPreviousHierarchy)
{
  ProbabilisticBVH bvh;
  ASSERT_TRUE (bvh.build (shapeCloud (Shape::Box, 50, 1)));
  const std::size_t nodes_before = bvh.nodes ().size ();

  UncertainCloud bad = shapeCloud (Shape::Box, 10, 2);
  bad.covariances.pop_back ();
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  bad = shapeCloud (Shape::Box, 10, 2);
  bad.means[3].y () = std::numeric_limits<double>::quiet_NaN ();
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  bad = shapeCloud (Shape::Box, 10, 2);
  bad.covariances[4] (1, 2) = std::numeric_limits<double>::infinity ();
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  bad = shapeCloud (Shape::Box, 10, 2);
  bad.area_weights[5] = -1.0;
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  bad = shapeCloud (Shape::Box, 10, 2);
  bad.area_weights.pop_back ();
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  bad = shapeCloud (Shape::Box, 10, 2);
  bad.source_indices.push_back (7);
  EXPECT_THROW (bvh.build (bad), pcl::BadArgumentException);

  BVHParams p;
  p.epsilon = -0.1;
  EXPECT_THROW (bvh.build (shapeCloud (Shape::Box, 10, 2), p), pcl::BadArgumentException);

  EXPECT_EQ (bvh.size (), 50u);
  EXPECT_EQ (bvh.nodes ().size (), nodes_before);
}

// ---------------------------------------------------------------------------------------------
// Construction invariants over shapes, sizes and split styles

class BVHInvariants
  : public ::testing::TestWithParam<std::tuple<Shape, std::size_t, BVHParams::SplitStyle>>
{
};

TEST_P (BVHInvariants, Hold)
{
  const Shape shape = std::get<0> (GetParam ());
  const std::size_t n = std::get<1> (GetParam ());
  BVHParams params;
  params.split_style = std::get<2> (GetParam ());
  const UncertainCloud cloud = shapeCloud (shape, n, 1000 + n);
  ProbabilisticBVH bvh;
  ASSERT_TRUE (bvh.build (cloud, params));
  ASSERT_FALSE (bvh.empty ());
  const auto& nodes = bvh.nodes ();
  const double tol = 1e-9 * cloudScale (cloud);

  // Root holds every point; the stored cloud is the input.
  EXPECT_EQ (bvh.size (), n);
  EXPECT_EQ (nodes[0].num_points, static_cast<std::int32_t> (n));
  EXPECT_EQ (bvh.means (), cloud.means);
  ASSERT_EQ (bvh.covariances ().size (), n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Matrix3d sym = 0.5 * (cloud.covariances[i] + cloud.covariances[i].transpose ());
    EXPECT_EQ ((bvh.covariances ()[i].matrix () - sym).cwiseAbs ().maxCoeff (), 0.0) << i;
    const Eigen::Vector3d a = Eigen::Vector3d (0.3, -0.5, 0.8).normalized ();
    EXPECT_NEAR (bvh.covariances ()[i].quadratic (a), a.dot (sym * a), 1e-12 * sym.norm ()) << i;
  }

  std::vector<int> covered (n, 0);
  std::size_t leaves = 0, stored = 0;
  int max_depth = 0;
  for (std::size_t id = 0; id < nodes.size (); ++id)
  {
    const Node& nd = nodes[id];
    SCOPED_TRACE ("node " + std::to_string (id));
    max_depth = std::max (max_depth, nd.depth);
    const std::vector<int> pts = distinctPoints (bvh, nd);
    ASSERT_EQ (pts.size (), static_cast<std::size_t> (nd.num_points));

    // The box: a rotation, non-negative extents, and equal to a refit on the node's points.
    EXPECT_NEAR ((nd.box.axes.transpose () * nd.box.axes - Eigen::Matrix3d::Identity ()).norm (), 0.0, 1e-12);
    EXPECT_NEAR (nd.box.axes.determinant (), 1.0, 1e-12);
    EXPECT_TRUE ((nd.box.half_extents.array () >= 0.0).all ());
    const OrientedBox refit = detail::fitOrientedBox (nd.box.axes, cloud.means.data (), cloud.covariances.data (),
                                                      pts.data (), pts.size (), params.k_sigma);
    EXPECT_LE ((refit.center - nd.box.center).norm (), tol);
    EXPECT_LE ((refit.half_extents - nd.box.half_extents).norm (), tol);

    // Every point with its k_sigma band lies inside the node's box (means first).
    double leak_num = 0.0, leak_den = 0.0;
    for (int j : pts)
    {
      EXPECT_TRUE (nd.box.contains (cloud.means[j], tol)) << "point " << j;
      for (int k = 0; k < 3; ++k)
      {
        const Eigen::Vector3d a = nd.box.axes.col (k);
        const double s = std::sqrt (std::max (0.0, a.dot (cloud.covariances[j] * a)));
        EXPECT_LE (std::abs (a.dot (cloud.means[j] - nd.box.center)) + params.k_sigma * s,
                   nd.box.half_extents (k) + tol);
        EXPECT_LE (s, nd.max_sigma (k) * (1.0 + 1e-6) + 1e-15);
      }
      const double w = cloud.area_weights[j];
      leak_num += w * detail::pointOutsideProbability (nd.box, cloud.means[j], cloud.covariances[j]);
      leak_den += w;
    }
    // Leakage oracle: the weighted mean of the per-point function on the node's own box.
    EXPECT_NEAR (nd.leakage, leak_num / leak_den, 1e-9);
    EXPECT_GE (nd.leakage, 0.0);
    EXPECT_LE (nd.leakage, 1.0);
    EXPECT_NEAR (nd.coverage (), 1.0 - nd.leakage, 0.0);
    EXPECT_GE (nd.variation, 0.0f);
    EXPECT_LE (nd.variation, 1.0f / 3.0f + 1e-6f);

    if (nd.isLeaf ())
    {
      ++leaves;
      stored += static_cast<std::size_t> (nd.end - nd.begin);
      EXPECT_EQ (nd.end - nd.begin, nd.num_points) << "a leaf holds each point once";
      for (int j : pts)
        covered[j] = 1;
      const std::size_t m = pts.size ();
      switch (nd.leaf_reason)
      {
        case ProbabilisticBVH::LeafReason::StopRule:
          EXPECT_LE (m, static_cast<std::size_t> (params.n_max));
          EXPECT_LE (nd.variation, params.sigma_max);
          break;
        case ProbabilisticBVH::LeafReason::MinSize:
          EXPECT_LE (m, static_cast<std::size_t> (params.n_min));
          break;
        case ProbabilisticBVH::LeafReason::NoProgress: break;
        case ProbabilisticBVH::LeafReason::NotLeaf: ADD_FAILURE () << "leaf flagged NotLeaf"; break;
      }
      // Random clouds have no coincident projections: every wanted split succeeds.
      EXPECT_NE (nd.leaf_reason, ProbabilisticBVH::LeafReason::NoProgress);
      continue;
    }

    // Internal node: children partition the node's points with overlap, each strictly smaller.
    EXPECT_EQ (nd.leaf_reason, ProbabilisticBVH::LeafReason::NotLeaf);
    EXPECT_TRUE (nd.num_points > params.n_max || nd.variation > params.sigma_max);
    EXPECT_GT (nd.num_points, params.n_min);
    if (params.split_style == BVHParams::SplitStyle::Pca)
      EXPECT_EQ (nd.num_children, 2);
    else
      EXPECT_TRUE (nd.num_children >= 2 && nd.num_children <= 8);
    std::set<int> uni;
    std::vector<std::vector<int>> child_pts;
    for (int c = 0; c < nd.num_children; ++c)
    {
      const Node& ch = nodes[nd.first_child + c];
      EXPECT_EQ (ch.depth, nd.depth + 1);
      child_pts.push_back (distinctPoints (bvh, ch));
      EXPECT_LT (child_pts.back ().size (), pts.size ());
      EXPECT_TRUE (std::includes (pts.begin (), pts.end (), child_pts.back ().begin (), child_pts.back ().end ()));
      uni.insert (child_pts.back ().begin (), child_pts.back ().end ());
      EXPECT_GE (ch.begin, nd.begin);
      EXPECT_LE (ch.end, nd.end);
    }
    EXPECT_EQ (uni.size (), pts.size ());

    if (params.split_style == BVHParams::SplitStyle::Pca)
    {
      // Overlap band (METHOD.md 8.2): recompute the split value s and extent L along axis 0,
      // then left = {p <= s + eps L}, right = {p >= s - eps L}, with eps = epsilon, or 0 when
      // epsilon would have put every point in one child.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero ();
      for (int j : pts)
        mean += cloud.means[j];
      mean /= static_cast<double> (pts.size ());
      std::vector<double> p;
      for (int j : pts)
        p.push_back (nd.box.axes.col (0).dot (cloud.means[j] - mean));
      double s = 0.0;
      for (double v : p)
        s += v;
      s /= static_cast<double> (p.size ());
      const double L = *std::max_element (p.begin (), p.end ()) - *std::min_element (p.begin (), p.end ());
      auto expected = [&] (double eps, std::vector<int>& left, std::vector<int>& right) {
        for (std::size_t i = 0; i < pts.size (); ++i)
        {
          if (p[i] <= s + eps * L)
            left.push_back (pts[i]);
          if (p[i] >= s - eps * L)
            right.push_back (pts[i]);
        }
      };
      std::vector<int> l_eps, r_eps, l_0, r_0;
      expected (params.epsilon, l_eps, r_eps);
      expected (0.0, l_0, r_0);
      const bool eps_progress = l_eps.size () < pts.size () && r_eps.size () < pts.size ();
      if (eps_progress)
      {
        EXPECT_EQ (child_pts[0], l_eps);
        EXPECT_EQ (child_pts[1], r_eps);
      }
      else
      {
        EXPECT_EQ (child_pts[0], l_0);
        EXPECT_EQ (child_pts[1], r_0);
      }
    }
  }
  for (std::size_t j = 0; j < n; ++j)
    EXPECT_EQ (covered[j], 1) << "point " << j << " in no leaf";

  // Counters agree with the nodes.
  EXPECT_EQ (bvh.leafCount (), leaves);
  EXPECT_EQ (bvh.storedPoints (), stored);
  EXPECT_EQ (bvh.pointIndices ().size (), stored);
  EXPECT_EQ (bvh.depth (), max_depth + 1);
  EXPECT_EQ (nodes[0].begin, 0);
  EXPECT_EQ (static_cast<std::size_t> (nodes[0].end), stored);
  // Means, packed covariances (48 bytes) and source indices; the area weights are not kept.
  const std::size_t floor_bytes = n * (sizeof (Eigen::Vector3d) + sizeof (PackedCovariance) + sizeof (int)) +
                                  nodes.size () * sizeof (Node) + stored * sizeof (int);
  EXPECT_GE (bvh.bytes (), floor_bytes);
  EXPECT_LE (bvh.bytes (), floor_bytes + sizeof (ProbabilisticBVH));

  // Storage bound from the issue: stored <= n (1 + ln(n / n_max)) once n >= n_max.
  if (n >= static_cast<std::size_t> (params.n_max))
    EXPECT_LE (static_cast<double> (stored),
               static_cast<double> (n) * (1.0 + std::log (static_cast<double> (n) / params.n_max)));
  else
    EXPECT_EQ (stored, n);
  RecordProperty ("stored_per_point", std::to_string (static_cast<double> (stored) / n));
  RecordProperty ("bytes_per_point", std::to_string (static_cast<double> (bvh.bytes ()) / n));
}

INSTANTIATE_TEST_SUITE_P (
    ShapesSizesStyles, BVHInvariants,
    ::testing::Combine (::testing::Values (Shape::Box, Shape::Sphere, Shape::NoisyPlane),
                        ::testing::Values (std::size_t (1), std::size_t (2), std::size_t (7), std::size_t (100),
                                           std::size_t (10000)),
                        ::testing::Values (BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree)),
    [] (const ::testing::TestParamInfo<BVHInvariants::ParamType>& info) {
      return std::string (shapeName (std::get<0> (info.param))) + "_" +
             std::to_string (std::get<1> (info.param)) + "_" +
             (std::get<2> (info.param) == BVHParams::SplitStyle::Pca ? "Pca" : "Octree");
    });

TEST (ProbabilisticBVH, OctreeChildrenAreCellsOfTheParentAxes)
{
  // Every child of an octree node sits on one side (grown by eps L) of the node's mean along
  // each principal axis it splits.
  BVHParams params;
  params.split_style = BVHParams::SplitStyle::Octree;
  const UncertainCloud cloud = shapeCloud (Shape::Box, 2000, 77);
  ProbabilisticBVH bvh (cloud, params);
  std::size_t eight = 0;
  for (const Node& nd : bvh.nodes ())
  {
    if (nd.isLeaf ())
      continue;
    eight += nd.num_children == 8;
    const std::vector<int> pts = distinctPoints (bvh, nd);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero ();
    for (int j : pts)
      mean += cloud.means[j];
    mean /= static_cast<double> (pts.size ());
    Eigen::Vector3d lo = Eigen::Vector3d::Constant (1e300), hi = -lo;
    for (int j : pts)
    {
      const Eigen::Vector3d q = nd.box.axes.transpose () * (cloud.means[j] - mean);
      lo = lo.cwiseMin (q);
      hi = hi.cwiseMax (q);
    }
    const Eigen::Vector3d band = params.epsilon * (hi - lo) + Eigen::Vector3d::Constant (1e-12);
    for (int c = 0; c < nd.num_children; ++c)
    {
      const std::vector<int> cp = distinctPoints (bvh, bvh.node (nd.first_child + c));
      Eigen::Vector3d clo = Eigen::Vector3d::Constant (1e300), chi = -clo;
      for (int j : cp)
      {
        const Eigen::Vector3d q = nd.box.axes.transpose () * (cloud.means[j] - mean);
        clo = clo.cwiseMin (q);
        chi = chi.cwiseMax (q);
      }
      // Mean projection is 0 up to rounding: a cell lies below +band or above -band.
      for (int k = 0; k < 3; ++k)
        EXPECT_TRUE (chi (k) <= band (k) || clo (k) >= -band (k)) << "axis " << k;
    }
  }
  EXPECT_GT (eight, 0u);
}

// ---------------------------------------------------------------------------------------------
// Variation and leakage oracles (METHOD.md 11.7)

TEST (ProbabilisticBVH, VariationOracles)
{
  // A tilted planar patch: sigma_n = 0 (up to rounding).
  std::mt19937_64 rng (5);
  std::uniform_real_distribution<double> u (-0.5, 0.5);
  const Eigen::Matrix3d R = randomRotation (rng);
  UncertainCloud plane;
  for (int i = 0; i < 500; ++i)
  {
    const double px = u (rng);
    plane.means.push_back (R * Eigen::Vector3d (px, u (rng), 0.0) + Eigen::Vector3d (3, -2, 1));
    plane.covariances.push_back (Eigen::Matrix3d::Identity () * 1e-6);
  }
  ProbabilisticBVH bvh_plane (plane);
  for (const Node& nd : bvh_plane.nodes ())
    EXPECT_LT (nd.variation, 1e-12f);
  // The normal of the patch is box axis 2 (e1).
  EXPECT_NEAR (std::abs (bvh_plane.node (0).box.axes.col (2).dot (R.col (2))), 1.0, 1e-9);

  // Uniform in a cube: sigma_n -> 1/3. Sample variances of 10^4 uniform points have relative
  // standard deviation sqrt(0.8 / 10^4) = 0.009, so sigma_n is within 0.015 of 1/3.
  const UncertainCloud cube = shapeCloud (Shape::Box, 10000, 6);
  ProbabilisticBVH bvh_cube (cube);
  EXPECT_NEAR (bvh_cube.node (0).variation, 1.0 / 3.0, 0.015);
  EXPECT_LE (bvh_cube.node (0).variation, 1.0 / 3.0 + 1e-7);
}

TEST (Leakage, PointOracles)
{
  // Box [-0.05, 0.05]^3, isotropic sigma = 0.01 (METHOD.md 11.7).
  OrientedBox box;
  box.half_extents = Eigen::Vector3d::Constant (0.05);
  const Eigen::Matrix3d cov = Eigen::Matrix3d::Identity () * 1e-4;
  // Centre: 2 Phi(-5) = 5.733e-7 (exact form; relative accuracy).
  const double centre = detail::pointOutsideProbability (box, Eigen::Vector3d::Zero (), cov);
  EXPECT_NEAR (centre, 2.0 * Phi (-5.0), 1e-15);
  EXPECT_NEAR (centre, 5.733e-7, 1e-10);
  // 0.01 inside a face: Phi(-1) + Phi(-9) = 0.158655.
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0, 0.04), cov), 0.158655, 1e-6);
  // On a face: 0.5 + Phi(-10) ~ 0.5.
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (0.05, 0, 0), cov), 0.5, 1e-12);
  // Union bound at the centre: 3 * 2 Phi(-5).
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d::Zero (), cov, detail::LeakageBound::UnionBound),
               6.0 * Phi (-5.0), 1e-15);
  // Rotating box and point together changes nothing.
  std::mt19937_64 rng (3);
  Eigen::Isometry3d T = randomPose (rng, 2.0);
  const OrientedBox moved = box.transformed (T);
  EXPECT_NEAR (detail::pointOutsideProbability (moved, T * Eigen::Vector3d (0, 0, 0.04),
                                                T.linear () * cov * T.linear ().transpose ()),
               0.158655, 1e-6);
  // Zero covariance: the indicator of being outside.
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0.05, 0, 0), Eigen::Matrix3d::Zero ()), 0.0);
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0.0501, 0, 0), Eigen::Matrix3d::Zero ()), 1.0);
  // Degenerate along one axis only: that slab is an indicator, the others are Gaussian.
  Eigen::Matrix3d flat = Eigen::Vector3d (1e-4, 1e-4, 0.0).asDiagonal ();
  EXPECT_NEAR (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0.04, 0.0), flat), 0.158655, 1e-6);
  EXPECT_EQ (detail::pointOutsideProbability (box, Eigen::Vector3d (0, 0, 0.06), flat), 1.0);
}

// The build's tabulated tail against erfc: absolute error below 1e-11 everywhere.
TEST (Leakage, TabulatedTailMatchesErfc)
{
  double worst = 0.0;
  for (int i = -20000; i <= 24000; ++i)
  {
    const double z = i * 5.123e-4;  // not on the table's grid
    const double exact = normalCdf (-z);
    const double tab = detail::normalTailTabulated (z);
    worst = std::max (worst, std::abs (tab - exact));
    ASSERT_GE (tab, -1e-11) << z;
    ASSERT_LE (tab, 1.0 + 1e-11) << z;
  }
  EXPECT_LT (worst, 1e-11);
  EXPECT_GT (worst, 0.0);  // it is an approximation: the test would notice erfc in its place
  EXPECT_EQ (detail::normalTailTabulated (0.0), 0.5);
  EXPECT_EQ (detail::normalTailTabulated (10.0), 0.0);
  EXPECT_EQ (detail::normalTailTabulated (1e300), 0.0);
  EXPECT_EQ (detail::normalTailTabulated (-1e300), 1.0);
  EXPECT_TRUE (std::isnan (detail::normalTailTabulated (std::numeric_limits<double>::quiet_NaN ())));
}

TEST (Leakage, SinglePointNodeOracle)
{
  // One point, isotropic sigma, box inflated by k_sigma = 1: the point sits at the centre of a
  // cube of half extent sigma, so leakage = 1 - (Phi(1) - Phi(-1)) = 2 Phi(-1) = 0.317311.
  UncertainCloud c;
  c.means.push_back (Eigen::Vector3d (1, 2, 3));
  c.covariances.push_back (Eigen::Matrix3d::Identity () * 1e-4);
  ProbabilisticBVH bvh (c);
  ASSERT_EQ (bvh.nodes ().size (), 1u);
  EXPECT_NEAR (bvh.node (0).leakage, 2.0 * Phi (-1.0), 1e-12);
  EXPECT_NEAR (bvh.node (0).box.half_extents.maxCoeff (), 0.01, 1e-12);
  EXPECT_NEAR (bvh.node (0).box.half_extents.minCoeff (), 0.01, 1e-12);
  // k_sigma = 3: 2 Phi(-3).
  BVHParams p;
  p.k_sigma = 3.0;
  bvh.build (c, p);
  EXPECT_NEAR (bvh.node (0).leakage, 2.0 * Phi (-3.0), 1e-12);
}

TEST (Leakage, AreaWeightsWeightTheMean)
{
  // Two points in one leaf: one exact (P_x = 0), one noisy; weights move the node's leakage.
  UncertainCloud c;
  c.means = {Eigen::Vector3d (0, 0, 0), Eigen::Vector3d (1, 0, 0)};
  c.covariances = {Eigen::Matrix3d::Zero (), Eigen::Matrix3d::Identity () * 1e-4};
  ProbabilisticBVH equal (c);
  const double p_noisy = detail::pointOutsideProbability (equal.node (0).box, c.means[1], c.covariances[1]);
  EXPECT_GT (p_noisy, 0.1);
  EXPECT_NEAR (equal.node (0).leakage, 0.5 * p_noisy, 1e-12);
  c.area_weights = {3.0, 1.0};
  ProbabilisticBVH weighted (c);
  EXPECT_NEAR (weighted.node (0).leakage, 0.25 * p_noisy, 1e-12);
  c.area_weights = {0.0, 0.0};  // no area information: equal weights
  ProbabilisticBVH zero (c);
  EXPECT_NEAR (zero.node (0).leakage, 0.5 * p_noisy, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// OBB separating-axis test

TEST (OrientedBox, SeparatedByConstructionAreDisjoint)
{
  std::mt19937_64 rng (11);
  std::uniform_real_distribution<double> gap_dist (1e-3, 0.5);
  std::normal_distribution<double> g (0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    Eigen::Isometry3d T = randomPose (rng, 1.0);
    // Push B along a random direction n until its support leaves A's by `gap`.
    const Eigen::Vector3d n = draw3 (g, rng).normalized ();
    const OrientedBox b_in_a = b.transformed (T);
    const double top_a = n.dot (a.center) + (a.axes.transpose () * n).cwiseAbs ().dot (a.half_extents);
    const double bottom_b = n.dot (b_in_a.center) - (b_in_a.axes.transpose () * n).cwiseAbs ().dot (b.half_extents);
    const double gap = gap_dist (rng);
    T.translation () += (top_a - bottom_b + gap) * n;
    EXPECT_TRUE (detail::disjoint (a, b, T)) << "trial " << trial;
    // Growing both boxes by m raises each support by at most sqrt(3) m.
    EXPECT_TRUE (detail::disjoint (a, b, T, gap / (4.0 * std::sqrt (3.0)))) << "trial " << trial;
    // Growing them past the gap along n makes them overlap on that axis; a large margin
    // overlaps on every axis.
    EXPECT_FALSE (detail::disjoint (a, b, T, 10.0)) << "trial " << trial;
    // Symmetry: B against A under the inverse pose.
    EXPECT_TRUE (detail::disjoint (b, a, T.inverse ())) << "trial " << trial;
  }
}

TEST (OrientedBox, OverlappingByConstructionAreNotDisjoint)
{
  std::mt19937_64 rng (12);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    // A point of B (its local coordinates) placed on a point of A: they share it.
    const Eigen::Vector3d pa = a.center + a.axes * draw3 (u, rng).cwiseProduct (a.half_extents);
    const Eigen::Vector3d pb = b.center + b.axes * draw3 (u, rng).cwiseProduct (b.half_extents);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
    T.linear () = randomRotation (rng);
    T.translation () = pa - T.linear () * pb;
    ASSERT_TRUE (a.contains (T * pb, 1e-12));
    EXPECT_FALSE (detail::disjoint (a, b, T)) << "trial " << trial;
    EXPECT_FALSE (detail::disjoint (b, a, T.inverse ())) << "trial " << trial;
  }
  // Degenerate: two zero-thickness squares crossing at right angles, and two collinear
  // segments sharing a piece.
  OrientedBox sq_a, sq_b;
  sq_a.half_extents = Eigen::Vector3d (1, 1, 0);
  sq_b.half_extents = Eigen::Vector3d (1, 1, 0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.linear () = Eigen::AngleAxisd (M_PI / 2, Eigen::Vector3d::UnitX ()).toRotationMatrix ();
  EXPECT_FALSE (detail::disjoint (sq_a, sq_b, T));
  OrientedBox seg;
  seg.half_extents = Eigen::Vector3d (1, 0, 0);
  T = Eigen::Isometry3d::Identity ();
  T.translation () = Eigen::Vector3d (1.5, 0, 0);
  EXPECT_FALSE (detail::disjoint (seg, seg, T));
  T.translation () = Eigen::Vector3d (2.5, 0, 0);
  EXPECT_TRUE (detail::disjoint (seg, seg, T));
}

TEST (OrientedBox, AgreesWithVertexProjectionOracle)
{
  // Random poses near contact; compared with an independent vertex-projection SAT wherever the
  // decision is clear by more than 1e-6 (near-ties are not a property of either algorithm).
  std::mt19937_64 rng (13);
  int separated = 0, overlapping = 0;
  for (int trial = 0; trial < 5000; ++trial)
  {
    const OrientedBox a = randomBox (rng, true);
    const OrientedBox b = randomBox (rng, true);
    const Eigen::Isometry3d T = randomPose (rng, 1.5);
    const double gap = bruteSeparationGap (a, b.transformed (T));
    const bool sat = detail::disjoint (a, b, T);
    if (gap > 1e-6)
    {
      ++separated;
      EXPECT_TRUE (sat) << "trial " << trial << " gap " << gap;
    }
    else if (gap < -1e-6)
    {
      ++overlapping;
      EXPECT_FALSE (sat) << "trial " << trial << " gap " << gap;
      // A sampled point of B inside A can only happen for overlapping boxes.
    }
    // Margin m is the same as growing the boxes.
    OrientedBox ag = a, bg = b;
    ag.half_extents.array () += 0.1;
    bg.half_extents.array () += 0.1;
    const double gap_m = bruteSeparationGap (ag, bg.transformed (T));
    if (std::abs (gap_m) > 1e-6)
    {
      EXPECT_EQ (detail::disjoint (a, b, T, 0.1), gap_m > 0) << "trial " << trial;
    }
  }
  EXPECT_GT (separated, 500);
  EXPECT_GT (overlapping, 500);
}

TEST (OrientedBox, SampledCommonPointImpliesOverlap)
{
  // Dense sampling can only prove overlap: any sample of B inside A forbids "disjoint".
  std::mt19937_64 rng (14);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  int proven = 0;
  for (int trial = 0; trial < 500; ++trial)
  {
    const OrientedBox a = randomBox (rng, false);
    const OrientedBox b = randomBox (rng, false);
    const Eigen::Isometry3d T = randomPose (rng, 1.5);
    bool common = false;
    for (int s = 0; s < 400 && !common; ++s)
    {
      const Eigen::Vector3d pb = b.center + b.axes * draw3 (u, rng).cwiseProduct (b.half_extents);
      common = a.contains (T * pb);
    }
    if (common)
    {
      ++proven;
      EXPECT_FALSE (detail::disjoint (a, b, T)) << "trial " << trial;
    }
  }
  EXPECT_GT (proven, 50);
}

TEST (OrientedBox, FitContainsInflatedPoints)
{
  std::mt19937_64 rng (15);
  const UncertainCloud c = shapeCloud (Shape::Sphere, 200, 16, 0.01);
  const Eigen::Matrix3d axes = randomRotation (rng);
  const OrientedBox box = detail::fitOrientedBox (axes, c.means.data (), c.covariances.data (), nullptr, c.size (), 2.0);
  for (std::size_t j = 0; j < c.size (); ++j)
    for (int k = 0; k < 3; ++k)
    {
      const Eigen::Vector3d a = axes.col (k);
      const double s = std::sqrt (a.dot (c.covariances[j] * a));
      EXPECT_LE (std::abs (a.dot (c.means[j] - box.center)) + 2.0 * s, box.half_extents (k) + 1e-12);
    }
  // Tight: on each axis some point touches each face.
  for (int k = 0; k < 3; ++k)
  {
    double top = -1e300;
    for (std::size_t j = 0; j < c.size (); ++j)
    {
      const Eigen::Vector3d a = axes.col (k);
      top = std::max (top, a.dot (c.means[j] - box.center) + 2.0 * std::sqrt (a.dot (c.covariances[j] * a)));
    }
    EXPECT_NEAR (top, box.half_extents (k), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------
// Traversal

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
  EXPECT_NEAR (q, 1.0 - (1.0 - 2.0 * Phi (-1.0)) * (1.0 - 2.0 * Phi (-1.0)), 1e-12);
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
    EXPECT_NEAR (r1.probability, r2.probability, 1e-9) << "trial " << trial;
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
      EXPECT_NEAR (leak[i], leak_moved[i], 1e-9);
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

TEST (ProbabilisticBVH, GatherAppliesTheTransform)
{
  const UncertainCloud c = shapeCloud (Shape::Box, 100, 81, 0.01);
  ProbabilisticBVH bvh (c);
  std::mt19937_64 rng (82);
  const Eigen::Isometry3d T = randomPose (rng, 3.0);
  std::vector<Eigen::Vector3d> m;
  std::vector<Eigen::Matrix3d> cv;
  m.reserve (100);
  const Eigen::Vector3d* storage = m.data ();
  for (const Node& nd : bvh.nodes ())
  {
    if (!nd.isLeaf ())
      continue;
    const PointSetView v = bvh.gatherPoints (nd, T, m, cv);
    ASSERT_EQ (v.size, static_cast<std::size_t> (nd.num_points));
    const auto idx = bvh.indices (nd);
    for (std::size_t i = 0; i < v.size; ++i)
    {
      EXPECT_LE ((v.means[i] - T * c.means[idx[i]]).norm (), 1e-12);
      EXPECT_LE ((v.covariances[i] - T.linear () * c.covariances[idx[i]] * T.linear ().transpose ()).norm (), 1e-15);
      EXPECT_EQ (v.covariances[i], v.covariances[i].transpose ());
    }
    const PointSetView own = bvh.gatherPoints (nd, m, cv);
    for (std::size_t i = 0; i < own.size; ++i)
      EXPECT_EQ (own.means[i], c.means[idx[i]]);
  }
  EXPECT_EQ (m.data (), storage) << "buffers reused, no reallocation";
  Node foreign;
  foreign.begin = 0;
  foreign.end = static_cast<std::int32_t> (bvh.storedPoints () + 1);
  EXPECT_THROW (bvh.gatherPoints (foreign, m, cv), pcl::BadArgumentException);
}

TEST (ProbabilisticBVH, FarFromTheOriginGivesTheSameTree)
{
  // A translation by 10^5 m changes neither the leaves nor the leakage (projections are taken
  // about the node mean, so large coordinates keep their precision).
  const UncertainCloud c = shapeCloud (Shape::Sphere, 3000, 91, 0.003);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.translation () = Eigen::Vector3d (1e5, -2e5, 3e5);
  ProbabilisticBVH near (c), far (transformCloud (c, T));
  ASSERT_EQ (near.nodes ().size (), far.nodes ().size ());
  EXPECT_EQ (near.pointIndices (), far.pointIndices ());
  for (std::size_t i = 0; i < near.nodes ().size (); ++i)
  {
    const Node& a = near.nodes ()[i];
    const Node& b = far.nodes ()[i];
    EXPECT_NEAR (a.leakage, b.leakage, 1e-6);
    EXPECT_LE ((a.box.half_extents - b.box.half_extents).norm (), 1e-8);
    EXPECT_LE ((T * a.box.center - b.box.center).norm (), 1e-8);
  }
}

TEST (ProbabilisticBVH, MoveBuildAndUnionBound)
{
  UncertainCloud c = shapeCloud (Shape::NoisyPlane, 800, 92, 0.004);
  const UncertainCloud copy = c;
  ProbabilisticBVH by_copy (copy);
  ProbabilisticBVH by_move;
  // A rejected build leaves the caller's cloud alone.
  BVHParams bad;
  bad.n_max = -3;
  EXPECT_THROW (by_move.build (std::move (c), bad), pcl::BadArgumentException);
  EXPECT_EQ (c.size (), 800u);
  ASSERT_TRUE (by_move.build (std::move (c)));
  EXPECT_EQ (by_move.pointIndices (), by_copy.pointIndices ());
  EXPECT_EQ (by_move.means (), copy.means);
  EXPECT_GE (by_move.buildMilliseconds (), 0.0);
  // The union bound is an upper bound of the min-slab leakage, node by node.
  BVHParams ub;
  ub.leakage_bound = BVHParams::LeakageBound::UnionBound;
  ProbabilisticBVH by_union (copy, ub);
  ASSERT_EQ (by_union.nodes ().size (), by_copy.nodes ().size ());
  std::size_t strictly = 0;
  for (std::size_t i = 0; i < by_copy.nodes ().size (); ++i)
  {
    EXPECT_GE (by_union.nodes ()[i].leakage, by_copy.nodes ()[i].leakage - 1e-15);
    strictly += by_union.nodes ()[i].leakage > by_copy.nodes ()[i].leakage;
  }
  EXPECT_GT (strictly, 0u);
}

// ---------------------------------------------------------------------------------------------
// Degenerate clouds: documented results

TEST (ProbabilisticBVH, EmptyCloudGivesEmptyHierarchy)
{
  ProbabilisticBVH bvh;
  EXPECT_TRUE (bvh.empty ());
  EXPECT_FALSE (bvh.build (UncertainCloud ()));
  EXPECT_TRUE (bvh.empty ());
  EXPECT_EQ (bvh.size (), 0u);
  EXPECT_EQ (bvh.nodes ().size (), 0u);
  EXPECT_EQ (bvh.storedPoints (), 0u);
  EXPECT_EQ (bvh.leafCount (), 0u);
  EXPECT_EQ (bvh.depth (), 0);
  // Rebuilding after a real build also empties it.
  ASSERT_TRUE (bvh.build (shapeCloud (Shape::Box, 30, 1)));
  EXPECT_FALSE (bvh.build (UncertainCloud ()));
  EXPECT_TRUE (bvh.empty ());
  bvh.build (shapeCloud (Shape::Box, 30, 1));
  bvh.clear ();
  EXPECT_TRUE (bvh.empty ());
  EXPECT_EQ (bvh.size (), 0u);
}

TEST (ProbabilisticBVH, SinglePointIsOneLeaf)
{
  UncertainCloud c;
  c.means = {Eigen::Vector3d (0.1, 0.2, 0.3)};
  c.covariances = {Eigen::Matrix3d::Zero ()};
  ProbabilisticBVH bvh (c);
  ASSERT_EQ (bvh.nodes ().size (), 1u);
  const Node& r = bvh.node (0);
  EXPECT_TRUE (r.isLeaf ());
  EXPECT_EQ (r.leaf_reason, ProbabilisticBVH::LeafReason::StopRule);
  EXPECT_EQ (r.num_points, 1);
  EXPECT_EQ (r.variation, 0.0f);
  EXPECT_EQ (r.leakage, 0.0) << "an exact point inside its box";
  EXPECT_EQ (r.box.half_extents, Eigen::Vector3d::Zero ());
  EXPECT_LE ((r.box.center - c.means[0]).norm (), 1e-15);
  EXPECT_EQ (bvh.depth (), 1);
}

TEST (ProbabilisticBVH, IdenticalPointsMakeOneNoProgressLeaf)
{
  UncertainCloud c;
  for (int i = 0; i < 100; ++i)
  {
    c.means.push_back (Eigen::Vector3d (0.1, 0.1, 0.1));
    c.covariances.push_back (Eigen::Matrix3d::Identity () * 1e-4);
  }
  for (auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    BVHParams p;
    p.split_style = style;
    ProbabilisticBVH bvh (c, p);
    ASSERT_EQ (bvh.nodes ().size (), 1u);
    EXPECT_EQ (bvh.node (0).leaf_reason, ProbabilisticBVH::LeafReason::NoProgress);
    EXPECT_EQ (bvh.node (0).num_points, 100);
    EXPECT_EQ (bvh.storedPoints (), 100u);
    EXPECT_EQ (bvh.node (0).variation, 0.0f);
    EXPECT_NEAR (bvh.node (0).leakage, 2.0 * Phi (-1.0), 1e-12);
  }
}

TEST (ProbabilisticBVH, CollinearPointsSplitAlongTheLine)
{
  UncertainCloud c;
  const Eigen::Vector3d dir = Eigen::Vector3d (1, 2, -2).normalized ();
  for (int i = 0; i < 100; ++i)
  {
    c.means.push_back (Eigen::Vector3d (5, 5, 5) + 0.01 * i * dir);
    c.covariances.push_back (Eigen::Matrix3d::Zero ());
  }
  for (auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    BVHParams p;
    p.split_style = style;
    ProbabilisticBVH bvh (c, p);
    EXPECT_GT (bvh.leafCount (), 4u);
    for (const Node& nd : bvh.nodes ())
    {
      EXPECT_LT (nd.variation, 1e-9f);
      EXPECT_NEAR (std::abs (nd.box.axes.col (0).dot (dir)), 1.0, 1e-9);
      EXPECT_LT (nd.box.half_extents.tail<2> ().maxCoeff (), 1e-12);
      if (nd.isLeaf ())
      {
        EXPECT_EQ (nd.leaf_reason, ProbabilisticBVH::LeafReason::StopRule);
        EXPECT_LE (nd.num_points, 20);
      }
      else
        EXPECT_EQ (nd.num_children, 2) << "only the line's axis is split";
    }
  }
}

TEST (ProbabilisticBVH, TwoClustersOfDuplicatesSplitOnce)
{
  // 30 copies of one point and 30 of another: one split, then two NoProgress leaves.
  UncertainCloud c;
  for (int i = 0; i < 60; ++i)
  {
    c.means.push_back (i < 30 ? Eigen::Vector3d (0, 0, 0) : Eigen::Vector3d (1, 0, 0));
    c.covariances.push_back (Eigen::Matrix3d::Zero ());
  }
  ProbabilisticBVH bvh (c);
  ASSERT_EQ (bvh.nodes ().size (), 3u);
  EXPECT_EQ (bvh.node (1).leaf_reason, ProbabilisticBVH::LeafReason::NoProgress);
  EXPECT_EQ (bvh.node (2).leaf_reason, ProbabilisticBVH::LeafReason::NoProgress);
  EXPECT_EQ (bvh.node (1).num_points + bvh.node (2).num_points, 60);
  EXPECT_EQ (bvh.storedPoints (), 60u);
}

// A large but valid epsilon must not make the hierarchy grow exponentially: splits that would
// duplicate more than half of a node's points are made without overlap (before the guard,
// 1,000 points with epsilon 0.2 made about a million nodes, and 48 points with an octree split
// and epsilon 0.49 exhausted memory).
TEST (ProbabilisticBVH, LargeEpsilonKeepsTheHierarchyLinearInSize)
{
  const UncertainCloud cloud = shapeCloud (Shape::Box, 1000, 5);
  for (const auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    BVHParams params;
    params.split_style = style;
    const ProbabilisticBVH reference (cloud, params);
    for (const double epsilon : {0.2, 0.49})
    {
      params.epsilon = epsilon;
      const ProbabilisticBVH bvh (cloud, params);
      EXPECT_LE (bvh.nodes ().size (), 4 * reference.nodes ().size ()) << "epsilon " << epsilon;
      EXPECT_LE (bvh.storedPoints (), 4 * reference.storedPoints ()) << "epsilon " << epsilon;
    }
  }
  // The default still overlaps siblings (some points stored twice).
  const ProbabilisticBVH defaults (cloud, BVHParams ());
  EXPECT_GT (defaults.storedPoints (), cloud.size ());
}
