// SPDX-License-Identifier: BSD-3-Clause
// ProbabilisticBVH and BVHParams (probabilistic_bvh.h): the epsilon-overlap hierarchy's build
// (METHOD.md 8): parameters, invariants over shapes, sizes and split styles (boxes refitted,
// leakage recomputed point by point, the overlap band recomputed), variation oracles,
// degenerate clouds. The boxes, the leakage and the traversal have files of their own
// (test_obb.cpp, test_leakage.cpp, test_bvh_traversal.cpp).
#include <pcl_probcollision/detail/leakage.h>
#include <pcl_probcollision/detail/obb.h>
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
#include <tuple>
#include <vector>

using namespace pcl_probcollision;
using detail::OrientedBox;
using Node = ProbabilisticBVH::Node;
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

/** \brief Nodes of a and b that differ (ids, ranges, reasons, boxes, leakage), and a node
  * count mismatch counted as a difference too. */
std::size_t
differingNodes (const ProbabilisticBVH& a, const ProbabilisticBVH& b)
{
  const std::size_t n = std::min (a.nodes ().size (), b.nodes ().size ());
  std::size_t differing = std::max (a.nodes ().size (), b.nodes ().size ()) - n;
  for (std::size_t i = 0; i < n; ++i)
  {
    const Node& x = a.nodes ()[i];
    const Node& y = b.nodes ()[i];
    const bool same = x.first_child == y.first_child && x.num_children == y.num_children && x.begin == y.begin &&
                      x.end == y.end && x.depth == y.depth &&
                      x.leaf_reason == y.leaf_reason && x.leakage == y.leakage &&
                      x.max_sigma == y.max_sigma && x.box.first_axes == y.box.first_axes && x.box.center == y.box.center &&
                      x.box.half_extents == y.box.half_extents;
    differing += same ? 0 : 1;
  }
  return differing;
}

/** \brief BVHParams::noise_stop's condition recomputed from the node's own points: the means'
  * range along the box's first axis (e3) over the median point standard deviation along it. */
double
extentOverMedianSigma (const ProbabilisticBVH& bvh, const Node& node)
{
  const Eigen::Vector3d a = node.box.axes ().col (0);
  double lo = std::numeric_limits<double>::infinity (), hi = -lo;
  std::vector<double> sd;
  for (int j : distinctPoints (bvh, node))
  {
    const double p = a.dot (bvh.means ()[j]);
    lo = std::min (lo, p);
    hi = std::max (hi, p);
    sd.push_back (std::sqrt (bvh.covariances ()[j].quadratic (a)));
  }
  std::sort (sd.begin (), sd.end ());
  return (hi - lo) / sd[sd.size () / 2];
}

double
cloudScale (const UncertainCloud& c)
{
  double s = 1.0;
  for (const auto& x : c.means)
    s = std::max (s, x.cwiseAbs ().maxCoeff ());
  return s;
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
  EXPECT_DOUBLE_EQ (p.noise_stop, 0.0);
  EXPECT_EQ (p.n_noise_max, 160);
  EXPECT_NO_THROW (p.validate ());
  BVHParams q;
  q.noise_stop = 2.0;
  EXPECT_FALSE (p == q);
  q = BVHParams ();
  q.n_noise_max = 80;
  EXPECT_TRUE (p != q);
}

// n_min for an n_max given alone: min(8, n_max), the one rule of pcd_collision's -nmax and
// Python's CloudModelParams(n_max=N) (each kept its own copy of it).
TEST (BVHParams, NMinForAnNMaxGivenAlone)
{
  EXPECT_EQ (BVHParams::nMinFor (5), 5);
  EXPECT_EQ (BVHParams::nMinFor (1), 1);
  EXPECT_EQ (BVHParams::nMinFor (8), 8);
  EXPECT_EQ (BVHParams::nMinFor (40), 8);
  const BVHParams defaults;
  EXPECT_EQ (BVHParams::nMinFor (defaults.n_max), defaults.n_min);
  for (const int n_max : {1, 3, 7, 8, 9, 20, 1000})
  {
    BVHParams p;
    p.n_max = n_max;
    p.n_min = BVHParams::nMinFor (n_max);
    EXPECT_NO_THROW (p.validate ()) << "n_max " << n_max;
  }
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
  // An n_max lowered below the default n_min alone (Python's params.n_max = 5): the message says
  // what to do, not only that n_min 8 is out of range.
  p = BVHParams ();
  p.n_max = 5;
  EXPECT_NE (message (p).find ("n_min 8 outside [1, n_max = 5]: set n_min too when lowering n_max"), std::string::npos)
      << message (p);
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
  p = BVHParams ();
  p.noise_stop = -1.0;
  EXPECT_NE (message (p).find ("noise_stop -1"), std::string::npos) << message (p);
  p = BVHParams ();
  p.noise_stop = std::numeric_limits<double>::quiet_NaN ();
  EXPECT_NE (message (p).find ("noise_stop"), std::string::npos) << message (p);
  p = BVHParams ();
  p.noise_stop = std::numeric_limits<double>::infinity ();
  EXPECT_NE (message (p).find ("noise_stop"), std::string::npos) << message (p);
  p = BVHParams ();
  p.n_noise_max = 0;
  EXPECT_NE (message (p).find ("n_noise_max 0"), std::string::npos) << message (p);
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
  // Covariances exact in float, as the hierarchy keeps them (PackedCovariance), so that the
  // oracles below read what the build read.
  UncertainCloud cloud = shapeCloud (shape, n, 1000 + n);
  for (Eigen::Matrix3d& c : cloud.covariances)
    c = c.cast<float> ().cast<double> ();
  ProbabilisticBVH bvh;
  ASSERT_TRUE (bvh.build (cloud, params));
  ASSERT_FALSE (bvh.empty ());
  const auto& nodes = bvh.nodes ();
  const double tol = 1e-9 * cloudScale (cloud);

  // Root holds every point; the stored cloud is the input.
  EXPECT_EQ (bvh.size (), n);
  EXPECT_EQ (bvh.distinctPoints (nodes[0]), static_cast<std::size_t> (n));
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
    max_depth = std::max (max_depth, static_cast<int> (nd.depth));
    const std::vector<int> pts = distinctPoints (bvh, nd);
    ASSERT_EQ (pts.size (), bvh.distinctPoints (nd));

    // The box: a rotation, non-negative extents, and equal to a refit on the node's points.
    EXPECT_NEAR ((nd.box.axes ().transpose () * nd.box.axes () - Eigen::Matrix3d::Identity ()).norm (), 0.0, 1e-12);
    EXPECT_NEAR (nd.box.axes ().determinant (), 1.0, 1e-12);
    EXPECT_TRUE ((nd.box.half_extents.array () >= 0.0).all ());
    const OrientedBox refit = detail::fitOrientedBox (nd.box.axes (), cloud.means.data (), cloud.covariances.data (),
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
        const Eigen::Vector3d a = nd.box.axes ().col (k);
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
    // Stored in single precision: the recomputed value to 1e-9, then rounded to a float.
    EXPECT_NEAR (nd.leakage, leak_num / leak_den, 1e-9 + 0x1p-24 * leak_num / leak_den);
    EXPECT_GE (nd.leakage, 0.0);
    EXPECT_LE (nd.leakage, 1.0);
    EXPECT_NEAR (nd.coverage (), 1.0 - nd.leakage, 0.0);
    EXPECT_GE (bvh.variation (nd), 0.0f);
    EXPECT_LE (bvh.variation (nd), 1.0f / 3.0f + 1e-6f);

    if (nd.isLeaf ())
    {
      ++leaves;
      stored += static_cast<std::size_t> (nd.end - nd.begin);
      EXPECT_EQ (nd.end - nd.begin, static_cast<std::int32_t> (bvh.distinctPoints (nd))) << "a leaf holds each point once";
      for (int j : pts)
        covered[j] = 1;
      const std::size_t m = pts.size ();
      switch (nd.leaf_reason)
      {
        case ProbabilisticBVH::LeafReason::StopRule:
          EXPECT_LE (m, static_cast<std::size_t> (params.n_max));
          EXPECT_LE (bvh.variation (nd), params.sigma_max);
          break;
        case ProbabilisticBVH::LeafReason::MinSize:
          EXPECT_LE (m, static_cast<std::size_t> (params.n_min));
          break;
        case ProbabilisticBVH::LeafReason::NoProgress: break;
        case ProbabilisticBVH::LeafReason::NoiseStop: ADD_FAILURE () << "noise_stop is off"; break;
        case ProbabilisticBVH::LeafReason::NotLeaf: ADD_FAILURE () << "leaf flagged NotLeaf"; break;
      }
      // Random clouds have no coincident projections: every wanted split succeeds.
      EXPECT_NE (nd.leaf_reason, ProbabilisticBVH::LeafReason::NoProgress);
      continue;
    }

    // Internal node: children partition the node's points with overlap, each strictly smaller.
    EXPECT_EQ (nd.leaf_reason, ProbabilisticBVH::LeafReason::NotLeaf);
    EXPECT_TRUE (static_cast<std::int32_t> (bvh.distinctPoints (nd)) > params.n_max || bvh.variation (nd) > params.sigma_max);
    EXPECT_GT (static_cast<std::int32_t> (bvh.distinctPoints (nd)), params.n_min);
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
        p.push_back (nd.box.axes ().col (0).dot (cloud.means[j] - mean));
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
  // Means, packed covariances (48 bytes) and source indices unless they are 0 .. n - 1; the
  // area weights are not kept.
  const std::size_t floor_bytes = n * (sizeof (Eigen::Vector3d) + sizeof (PackedCovariance)) +
                                  bvh.sourceIndices ().size () * sizeof (int) + nodes.size () * sizeof (Node) +
                                  stored * sizeof (int);
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
      const Eigen::Vector3d q = nd.box.axes ().transpose () * (cloud.means[j] - mean);
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
        const Eigen::Vector3d q = nd.box.axes ().transpose () * (cloud.means[j] - mean);
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
// Variation oracles (METHOD.md 11.7)

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
    EXPECT_LT (bvh_plane.variation (nd), 1e-12f);
  // The normal of the patch is box axis 2 (e1).
  EXPECT_NEAR (std::abs (bvh_plane.node (0).box.axes ().col (2).dot (R.col (2))), 1.0, 1e-9);

  // Uniform in a cube: sigma_n -> 1/3. Sample variances of 10^4 uniform points have relative
  // standard deviation sqrt(0.8 / 10^4) = 0.009, so sigma_n is within 0.015 of 1/3.
  const UncertainCloud cube = shapeCloud (Shape::Box, 10000, 6);
  ProbabilisticBVH bvh_cube (cube);
  EXPECT_NEAR (bvh_cube.variation (bvh_cube.node (0)), 1.0 / 3.0, 0.015);
  EXPECT_LE (bvh_cube.variation (bvh_cube.node (0)), 1.0 / 3.0 + 1e-7);
}

// ---------------------------------------------------------------------------------------------
// Gathering a node's points, precision far from the origin, building by move

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
    ASSERT_EQ (v.size, bvh.distinctPoints (nd));
    const auto idx = bvh.indices (nd);
    for (std::size_t i = 0; i < v.size; ++i)
    {
      EXPECT_LE ((v.means[i] - T * c.means[idx[i]]).norm (), 1e-12);
      const Eigen::Matrix3d kept = c.covariances[idx[i]].cast<float> ().cast<double> ();  // stored as float
      EXPECT_LE ((v.covariances[i] - T.linear () * kept * T.linear ().transpose ()).norm (), 1e-15);
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

TEST (ProbabilisticBVH, TurningTheCloudGivesTheSameTree)
{
  // The children's order follows each node's axes, whose signs the eigen solver picks at random;
  // each is set by the points' third moment along it, so turning the cloud turns the tree with it:
  // the same points in the same nodes, in the same order (the order a query visits leaves in).
  for (const Shape shape : {Shape::Box, Shape::NoisyPlane})
  {
    SCOPED_TRACE (shapeName (shape));
    const UncertainCloud c = shapeCloud (shape, 3000, 93, 0.003);
    const ProbabilisticBVH base (c);
    for (int k = 0; k < 8; ++k)
    {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
      T.linear () = Eigen::AngleAxisd (0.4 + 0.7 * k, Eigen::Vector3d (1.0, -2.0 + k, 0.5 * k).normalized ()).toRotationMatrix ();
      const ProbabilisticBVH turned (transformCloud (c, T));
      ASSERT_EQ (base.nodes ().size (), turned.nodes ().size ()) << "rotation " << k;
      EXPECT_EQ (base.pointIndices (), turned.pointIndices ()) << "rotation " << k;
    }
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

// Covariances given packed (buildCloudModel's way) build the hierarchy the double ones build,
// and are checked as they are.
TEST (ProbabilisticBVH, PackedCovariancesBuildTheSameHierarchy)
{
  const UncertainCloud cloud = shapeCloud (Shape::Sphere, 20000, 94, 0.003);
  const auto packedOf = [] (const UncertainCloud& c) {
    std::vector<PackedCovariance> packed;
    for (const Eigen::Matrix3d& s : c.covariances)
      packed.emplace_back (s);
    return packed;
  };
  const auto withoutCovariances = [] (UncertainCloud c) {
    c.covariances.clear ();
    return c;
  };
  for (const int threads : {1, 2})
  {
    const ProbabilisticBVH by_matrix (cloud, BVHParams (), threads);
    ProbabilisticBVH by_packed;
    ASSERT_TRUE (by_packed.build (withoutCovariances (cloud), packedOf (cloud), BVHParams (), threads));
    ASSERT_EQ (by_packed.nodes ().size (), by_matrix.nodes ().size ());
    EXPECT_EQ (differingNodes (by_matrix, by_packed), 0u) << "threads " << threads;
    EXPECT_EQ (by_packed.pointIndices (), by_matrix.pointIndices ());
    EXPECT_EQ (by_packed.means (), by_matrix.means ());
    ASSERT_EQ (by_packed.covariances ().size (), cloud.size ());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < cloud.size (); ++i)
      differing += by_packed.covariances ()[i].matrix () != by_matrix.covariances ()[i].matrix ();
    EXPECT_EQ (differing, 0u);
  }

  ProbabilisticBVH bvh;
  ASSERT_TRUE (bvh.build (shapeCloud (Shape::Box, 50, 1)));
  const std::size_t nodes_before = bvh.nodes ().size ();
  const UncertainCloud small = shapeCloud (Shape::Box, 10, 2);
  // Covariances in both places, too few, a non-finite one: refused, the hierarchy kept.
  EXPECT_THROW (bvh.build (UncertainCloud (small), packedOf (small)), pcl::BadArgumentException);
  std::vector<PackedCovariance> short_list = packedOf (small);
  short_list.pop_back ();
  EXPECT_THROW (bvh.build (withoutCovariances (small), std::move (short_list)), pcl::BadArgumentException);
  std::vector<PackedCovariance> non_finite = packedOf (small);
  non_finite[4].yz = std::numeric_limits<float>::infinity ();
  EXPECT_THROW (bvh.build (withoutCovariances (small), std::move (non_finite)), pcl::BadArgumentException);
  EXPECT_EQ (bvh.size (), 50u);
  EXPECT_EQ (bvh.nodes ().size (), nodes_before);
  // An empty cloud, as build() takes it: an empty hierarchy.
  EXPECT_FALSE (bvh.build (UncertainCloud (), std::vector<PackedCovariance> ()));
  EXPECT_TRUE (bvh.empty ());
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

// Source indices 0, 1, ..., n - 1 are not stored (sourceIndex(i) is i); any others are.
TEST (ProbabilisticBVH, KeepsOnlySourceIndicesThatAreNotTheIdentity)
{
  UncertainCloud c = shapeCloud (Shape::Box, 10, 2);
  c.source_indices.clear ();
  for (std::size_t i = 0; i < c.means.size (); ++i)
    c.source_indices.push_back (static_cast<int> (i));
  ProbabilisticBVH identity (c);
  EXPECT_TRUE (identity.sourceIndices ().empty ());
  EXPECT_EQ (identity.sourceIndex (7), 7);
  c.source_indices[7] = 1000;
  ProbabilisticBVH other (c);
  ASSERT_EQ (other.sourceIndices ().size (), c.means.size ());
  EXPECT_EQ (other.sourceIndex (7), 1000);
  EXPECT_EQ (other.sourceIndex (6), 6);
  EXPECT_LT (identity.bytes (), other.bytes ());
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
  EXPECT_EQ (static_cast<std::int32_t> (bvh.distinctPoints (r)), 1);
  EXPECT_EQ (bvh.variation (r), 0.0f);
  EXPECT_EQ (r.leakage, 0.0) << "an exact point inside its box";
  EXPECT_EQ (r.box.half_extents, Eigen::Vector3f::Zero ());
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
    EXPECT_EQ (bvh.distinctPoints (bvh.node (0)), 100u);
    EXPECT_EQ (bvh.storedPoints (), 100u);
    EXPECT_EQ (bvh.variation (bvh.node (0)), 0.0f);
    EXPECT_FLOAT_EQ (bvh.node (0).leakage, static_cast<float> (2.0 * Phi (-1.0)));
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
      EXPECT_LT (bvh.variation (nd), 1e-9f);
      EXPECT_NEAR (std::abs (nd.box.axes ().col (0).dot (dir)), 1.0, 1e-9);
      EXPECT_LT (nd.box.half_extents.tail<2> ().maxCoeff (), 1e-12);
      if (nd.isLeaf ())
      {
        EXPECT_EQ (nd.leaf_reason, ProbabilisticBVH::LeafReason::StopRule);
        EXPECT_LE (static_cast<std::int32_t> (bvh.distinctPoints (nd)), 20);
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
  EXPECT_EQ (bvh.distinctPoints (bvh.node (1)) + bvh.distinctPoints (bvh.node (2)), 60u);
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

// The build makes the top of the tree level by level on several threads and the subtrees below
// whole: the hierarchy must be the one-thread hierarchy, node ids, boxes and leakage included.
TEST (ProbabilisticBVH, AnyThreadCountBuildsTheOneThreadHierarchy)
{
  // 40,000 points: subtrees of at most 5,000 (2 threads) or 4,096 points are built whole, so
  // several top levels are made in parallel.
  const UncertainCloud cloud = shapeCloud (Shape::Sphere, 40000, 93, 0.003);
  for (const auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    BVHParams params;
    params.split_style = style;
    const ProbabilisticBVH one (cloud, params, 1);
    ASSERT_GT (one.nodes ().size (), 1000u);
    for (const int threads : {2, 3, 8, 0})
    {
      const ProbabilisticBVH many (cloud, params, threads);
      ASSERT_EQ (many.nodes ().size (), one.nodes ().size ()) << threads;
      EXPECT_EQ (many.pointIndices (), one.pointIndices ()) << threads;
      EXPECT_EQ (many.leafCount (), one.leafCount ());
      EXPECT_EQ (many.depth (), one.depth ());
      EXPECT_EQ (differingNodes (one, many), 0u) << "threads " << threads;
    }
  }
  ProbabilisticBVH bvh;
  EXPECT_THROW (bvh.build (cloud, BVHParams (), -1), pcl::BadArgumentException);
}

// ---------------------------------------------------------------------------------------------
// BVHParams::noise_stop (issue #17 item 1): no split within the noise

namespace
{
std::size_t
countReason (const ProbabilisticBVH& bvh, ProbabilisticBVH::LeafReason reason)
{
  return static_cast<std::size_t> (std::count_if (bvh.nodes ().begin (), bvh.nodes ().end (),
                                                  [&] (const Node& nd) { return nd.leaf_reason == reason; }));
}
} // namespace

// Covariances small against the node sizes: the rule never fires and the hierarchy is the one
// built without it, node for node.
TEST (ProbabilisticBVH, NoiseStopLeavesALowNoiseHierarchyUnchanged)
{
  for (const auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    const UncertainCloud cloud = shapeCloud (Shape::Sphere, 10000, 31, 0.002);
    BVHParams params;
    params.split_style = style;
    const ProbabilisticBVH off (cloud, params);
    params.noise_stop = 4.0;
    const ProbabilisticBVH on (cloud, params);
    ASSERT_GT (off.nodes ().size (), 500u);
    EXPECT_EQ (countReason (on, ProbabilisticBVH::LeafReason::NoiseStop), 0u);
    EXPECT_EQ (differingNodes (off, on), 0u);
    EXPECT_EQ (on.pointIndices (), off.pointIndices ());
  }
}

// The same means with covariances as wide as a 160-point node: the rule keeps such nodes whole,
// exactly where its condition holds, and leaves fewer, never larger than n_noise_max.
TEST (ProbabilisticBVH, NoiseStopKeepsNodesWithinTheNoiseWhole)
{
  for (const auto style : {BVHParams::SplitStyle::Pca, BVHParams::SplitStyle::Octree})
  {
    SCOPED_TRACE (style == BVHParams::SplitStyle::Pca ? "Pca" : "Octree");
    const UncertainCloud cloud = shapeCloud (Shape::Sphere, 10000, 31, 0.2);
    BVHParams params;
    params.split_style = style;
    const ProbabilisticBVH off (cloud, params);
    params.noise_stop = 4.0;
    const ProbabilisticBVH on (cloud, params);
    EXPECT_GT (countReason (on, ProbabilisticBVH::LeafReason::NoiseStop), 0u);
    EXPECT_LT (on.leafCount (), off.leafCount () / 2);
    EXPECT_LT (on.nodes ().size (), off.nodes ().size () / 2);
    std::vector<int> covered (cloud.size (), 0);
    for (const Node& nd : on.nodes ())
    {
      if (nd.isLeaf ())
      {
        EXPECT_LE (static_cast<std::int32_t> (on.distinctPoints (nd)), params.n_noise_max);
        for (int j : on.indices (nd))
          covered[static_cast<std::size_t> (j)] = 1;
      }
      if (nd.leaf_reason == ProbabilisticBVH::LeafReason::NoiseStop)
      {
        EXPECT_GT (static_cast<std::int32_t> (on.distinctPoints (nd)), params.n_min);
        EXPECT_LE (extentOverMedianSigma (on, nd), params.noise_stop * (1.0 + 1e-9));
      }
      // An internal node the rule could have kept whole was beyond the noise.
      if (!nd.isLeaf () && static_cast<std::int32_t> (on.distinctPoints (nd)) <= params.n_noise_max)
      {
        EXPECT_GT (extentOverMedianSigma (on, nd), params.noise_stop * (1.0 - 1e-9));
      }
    }
    EXPECT_EQ (std::count (covered.begin (), covered.end (), 1), static_cast<std::ptrdiff_t> (cloud.size ()));

    // A lower cap: more leaves, none above it.
    params.n_noise_max = 40;
    const ProbabilisticBVH capped (cloud, params);
    EXPECT_GT (countReason (capped, ProbabilisticBVH::LeafReason::NoiseStop), 0u);
    EXPECT_GT (capped.leafCount (), on.leafCount ());
    for (const Node& nd : capped.nodes ())
    {
      if (nd.isLeaf ())
      {
        EXPECT_LE (static_cast<std::int32_t> (capped.distinctPoints (nd)), 40);
      }
    }
  }
}

// The rule is decided where every split is (makeNode), so the threaded build agrees with the
// serial one when it fires.
TEST (ProbabilisticBVH, NoiseStopBuildsTheSameHierarchyOnAnyThreadCount)
{
  const UncertainCloud cloud = shapeCloud (Shape::Sphere, 40000, 93, 0.1);
  // Small leaves, kept whole inside the subtrees built whole; then leaves of several thousand
  // points, kept whole among the top levels made in parallel (above 4,096 or 5,000 points).
  BVHParams small, large;
  small.noise_stop = 4.0;
  large.noise_stop = 12.0;
  large.n_noise_max = 40000;
  for (const BVHParams& params : {small, large})
  {
    const ProbabilisticBVH one (cloud, params, 1);
    ASSERT_GT (countReason (one, ProbabilisticBVH::LeafReason::NoiseStop), 4u);
    std::int32_t largest = 0;
    for (const Node& nd : one.nodes ())
      if (nd.leaf_reason == ProbabilisticBVH::LeafReason::NoiseStop)
        largest = std::max (largest, static_cast<std::int32_t> (one.distinctPoints (nd)));
    if (params.n_noise_max == 40000)
    {
      EXPECT_GT (largest, 5000);
    }
    for (const int threads : {2, 3, 0})
    {
      const ProbabilisticBVH many (cloud, params, threads);
      EXPECT_EQ (many.pointIndices (), one.pointIndices ()) << threads;
      EXPECT_EQ (differingNodes (one, many), 0u) << "threads " << threads << ", noise_stop " << params.noise_stop;
    }
  }
}
