// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/detail/input_checks.h>
#include <pcl_probcollision/detail/obb.h>
#include <pcl_probcollision/normal_distribution.h>

#include <pcl/exceptions.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Traversal parameters (METHOD.md 8.7). Their defaults are CollisionRequest's: the
  * constructor maps a request, the one place where a query's settings become the
  * traversal's. */
struct TraversalParams
{
  /** \brief The traversal of `request` (default: CollisionRequest's defaults). */
  explicit TraversalParams (const CollisionRequest& request = CollisionRequest ())
    : mode (request.traversal), rho_min (request.rho_min),
      // In decision mode a contribution above collision_above makes InCollision final (METHOD.md 7).
      stop_probability (request.collision_above), exhaustive (request.exhaustive), seed (request.seed),
      expanded_k_sigma (request.expanded_k_sigma), max_leaf_tests (request.max_leaf_fits)
  {}

  /** \brief Traversal mode (CollisionRequest::traversal). */
  TraversalMode mode;
  /** \brief ExpectedWeight: prune a pair whose reach weight drops below this, [0, 1]. With 0
    * nothing is pruned, even pairs of weight 0. */
  double rho_min;
  /** \brief Stop as soon as one contribution exceeds this (unless exhaustive), [0, 1]. */
  double stop_probability;
  /** \brief Visit every reachable leaf pair, never stop early. */
  bool exhaustive;
  /** \brief Stochastic: seed of the per-call std::mt19937_64. */
  std::uint64_t seed;
  /** \brief Extra margin added to every half extent of both boxes in the disjointness test, in
    * all modes (metres, >= 0). */
  double box_margin = 0.0;
  /** \brief ExpandedBV: boxes are grown by (expanded_k_sigma - k_sigma of the build) times the
    * node's largest point standard deviation along each axis (when positive); >= 0. */
  double expanded_k_sigma;
  /** \brief Prune any pair whose reach weight cannot beat the current maximum (rho <= max).
    * Same probability, fewer leaf tests; off by default because a leaf test that records
    * contacts then misses some. Assumes the leaf test returns values in [0, 1]. */
  bool skip_dominated = false;
  /** \brief Stop before the leaf test that would exceed this many (0 = no cap). */
  std::size_t max_leaf_tests = 0;
  /** \brief Visit an opened node's children nearest the other node first (default), else in
    * storage order. Only the order of the leaf tests changes; a traversal that visits every
    * pair (the surface layer's enumeration) gains nothing from it. */
  bool nearest_first = true;
  /** \brief When set (one entry per node of A), an opened node of A pushes only its children
    * whose entry is non-zero, so the traversal visits the pairs of those subtrees alone, in the
    * order the whole traversal visits them (a depth-first order keeps its relative order when
    * subtrees are left out). The surface layer's capped enumeration marks a batch of A's leaves
    * and their ancestors. */
  const std::vector<char>* only_a = nullptr;

  /** \brief Throws pcl::BadArgumentException naming the first parameter out of range. */
  void
  validate () const
  {
    if (mode != TraversalMode::Stochastic && mode != TraversalMode::ExpectedWeight &&
        mode != TraversalMode::ExpandedBV)
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::detail::TraversalParams::validate] mode "
                               << static_cast<int> (mode) << " is unknown");
    if (!(rho_min >= 0.0 && rho_min <= 1.0))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::detail::TraversalParams::validate] rho_min "
                               << rho_min << " outside [0, 1]");
    if (!(stop_probability >= 0.0 && stop_probability <= 1.0))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::detail::TraversalParams::validate] stop_probability "
                               << stop_probability << " outside [0, 1]");
    if (!(box_margin >= 0.0) || !std::isfinite (box_margin))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::detail::TraversalParams::validate] box_margin "
                               << box_margin << " must be finite and >= 0");
    if (!(expanded_k_sigma >= 0.0) || !std::isfinite (expanded_k_sigma))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::detail::TraversalParams::validate] expanded_k_sigma "
                               << expanded_k_sigma << " must be finite and >= 0");
  }
};

/** \brief What one traversal produced (METHOD.md 6.3). */
struct TraversalResult
{
  /** \brief Maximum leaf contribution (rho * P_leaf; P_leaf in Stochastic mode); 0 when no
    * leaf pair gave a valid value. */
  double probability = 0.0;
  /** \brief True when the traversal stopped early at stop_probability: probability is then a
    * lower bound of the exhaustive value. */
  bool lower_bound = false;
  /** \brief True when the traversal stopped at max_leaf_tests with pairs left (lower_bound is
    * then set too). */
  bool budget_exhausted = false;
  /** \brief True when no leaf test returned a valid (non-NaN) value. */
  bool no_leaf_tested = true;
  /** \brief Leaf ids (in A and B) of the maximum contribution, -1 when none. */
  std::int32_t max_node_a = -1;
  std::int32_t max_node_b = -1;
  /** \brief Reach weight of the maximum (1 in Stochastic and ExpandedBV mode); NaN when none. */
  double max_reach_weight = std::numeric_limits<double>::quiet_NaN ();
  /** \brief P_leaf of the maximum, before the reach weight; NaN when none. */
  double max_leaf_probability = std::numeric_limits<double>::quiet_NaN ();
  /** \brief Box pairs tested for disjointness. */
  std::size_t node_pairs_tested = 0;
  /** \brief Box pairs found disjoint. */
  std::size_t disjoint_pairs = 0;
  /** \brief Leaf tests run. */
  std::size_t leaf_pairs_tested = 0;
  /** \brief Pairs dropped: rho < rho_min, a failed draw, disjoint in ExpandedBV, or dominated. */
  std::size_t pruned_pairs = 0;
  /** \brief Leaf tests that returned NaN (ignored for the maximum). */
  std::size_t invalid_leaf_results = 0;

  bool
  operator== (const TraversalResult& o) const
  {
    auto same = [] (double x, double y) { return x == y || (std::isnan (x) && std::isnan (y)); };
    return probability == o.probability && lower_bound == o.lower_bound && budget_exhausted == o.budget_exhausted &&
           no_leaf_tested == o.no_leaf_tested && max_node_a == o.max_node_a &&
           max_node_b == o.max_node_b && same (max_reach_weight, o.max_reach_weight) &&
           same (max_leaf_probability, o.max_leaf_probability) &&
           node_pairs_tested == o.node_pairs_tested && disjoint_pairs == o.disjoint_pairs &&
           leaf_pairs_tested == o.leaf_pairs_tested && pruned_pairs == o.pruned_pairs &&
           invalid_leaf_results == o.invalid_leaf_results;
  }
  bool operator!= (const TraversalResult& o) const { return !(*this == o); }
};

/** \brief Simultaneous descent of two hierarchies under a rigid transform (METHOD.md 8.5, 6.3).
  *
  * Hierarchy A stays in its frame; B's boxes are mapped into A's frame by T_a_b on the fly
  * (points are never transformed here). From the pair of roots:
  * - the boxes are tested with the 15-axis test (both grown by box_margin, and in ExpandedBV
  *   mode by the extra k_sigma);
  * - a disjoint pair continues with probability / weight q = 1 - P_cov(a) P_cov(b) according to
  *   the mode (leaf pairs included), and is pruned otherwise;
  * - two leaves: the leaf test runs and contributes rho * P_leaf;
  * - otherwise the node that is not a leaf is opened; if both are internal, the one with the
  *   larger half diagonal |half_extents| (ties: A). The volume is not used because flat
  *   surface patches have almost none.
  * Depth-first (iterative stack, no recursion); the opened node's children are visited nearest
  * first (box centre to the other node's box centre), ties in storage order.
  *
  * \param[in] bvh_a hierarchy of cloud A (its frame is the query frame)
  * \param[in] bvh_b hierarchy of cloud B
  * \param[in] T_a_b rigid transform mapping B-frame points into A's frame
  * \param[in] params traversal parameters (validated; throws pcl::BadArgumentException)
  * \param[in] leaf_test callable double(const ProbabilisticBVH::Node& leaf_a,
  *            const ProbabilisticBVH::Node& leaf_b, double reach_weight) returning P_leaf in
  *            [0, 1] for the two leaves (NaN = failed, ignored and counted). It receives the
  *            nodes in their own frames: it maps B's points itself, for instance with
  *            bvh_b.gatherPoints(leaf_b, T_a_b, means, covariances), and A's with
  *            bvh_a.gatherPoints(leaf_a, ...). It may be stateful (it is called through a
  *            forwarding reference, never copied). reach_weight is rho (1 in Stochastic and
  *            ExpandedBV mode).
  * \return the maximum contribution and counters; an empty hierarchy gives probability 0 with
  *         no_leaf_tested set.
  * \throws pcl::BadArgumentException when params are invalid or T_a_b is not rigid within
  *         kRotationTolerance (rigidPose() makes a rounded rotation one).
  * \note Thread safety: reentrant; any number of calls may share the two hierarchies (each call
  *       owns its stack and generator). The leaf test must be safe for its own use.
  */
template <typename LeafTest>
TraversalResult
traverseHierarchies (const ProbabilisticBVH& bvh_a, const ProbabilisticBVH& bvh_b,
                     const Eigen::Isometry3d& T_a_b, const TraversalParams& params,
                     LeafTest&& leaf_test)
{
  params.validate ();
  const std::string pose_error = poseError (T_a_b, "T_a_b");
  if (!pose_error.empty ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::detail::traverseHierarchies] " << pose_error);
  // The leaf test maps points by the same pose: a rounded rotation must be made one by the
  // caller (collide() does), not here alone.
  if (!(rotationDeparture (T_a_b) <= kRotationTolerance))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::detail::traverseHierarchies] pose T_a_b departs from a rotation by "
                                                         << rotationDeparture (T_a_b) << ": pass detail::rigidPose (T_a_b)");
  TraversalResult result;
  if (bvh_a.empty () || bvh_b.empty ())
    return result;

  using Node = ProbabilisticBVH::Node;
  const std::vector<Node>& nodes_a = bvh_a.nodes ();
  const std::vector<Node>& nodes_b = bvh_b.nodes ();
  const bool expanded = params.mode == TraversalMode::ExpandedBV;
  const bool stochastic = params.mode == TraversalMode::Stochastic;
  const double grow_a = expanded ? std::max (0.0, params.expanded_k_sigma - bvh_a.params ().k_sigma) : 0.0;
  const double grow_b = expanded ? std::max (0.0, params.expanded_k_sigma - bvh_b.params ().k_sigma) : 0.0;
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant (params.box_margin);

  struct Entry
  {
    std::int32_t a;
    std::int32_t b;
    double rho;
    double distance;  ///< squared distance between the two box centres, for the visiting order
  };
  std::vector<Entry> stack;
  stack.reserve (256);
  stack.push_back ({ProbabilisticBVH::rootId (), ProbabilisticBVH::rootId (), 1.0, 0.0});
  std::mt19937_64 rng (params.seed);
  const Eigen::Isometry3d T_b_a = T_a_b.inverse (Eigen::Isometry);
  double best = -std::numeric_limits<double>::infinity ();

  while (!stack.empty ())
  {
    const Entry e = stack.back ();
    stack.pop_back ();
    double rho = e.rho;
    // The weight only shrinks below this pair: dominated already, no box test needed.
    if (params.skip_dominated && rho <= best)
    {
      ++result.pruned_pairs;
      continue;
    }
    const Node& na = nodes_a[static_cast<std::size_t> (e.a)];
    const Node& nb = nodes_b[static_cast<std::size_t> (e.b)];

    ++result.node_pairs_tested;
    const Eigen::Vector3d extra_a = margin + grow_a * na.max_sigma.cast<double> ();
    const Eigen::Vector3d extra_b = margin + grow_b * nb.max_sigma.cast<double> ();
    if (disjointInflated (na.box, extra_a, nb.box, extra_b, T_a_b))
    {
      ++result.disjoint_pairs;
      if (expanded)
      {
        ++result.pruned_pairs;
        continue;
      }
      const double q = 1.0 - na.coverage () * nb.coverage ();
      if (stochastic)
      {
        if (!(uniformUnit (rng) < q))
        {
          ++result.pruned_pairs;
          continue;
        }
      }
      else
      {
        rho *= q;
        if (rho < params.rho_min)
        {
          ++result.pruned_pairs;
          continue;
        }
      }
    }
    if (params.skip_dominated && rho <= best)
    {
      ++result.pruned_pairs;
      continue;
    }

    const bool leaf_a = na.isLeaf ();
    const bool leaf_b = nb.isLeaf ();
    if (leaf_a && leaf_b)
    {
      if (params.max_leaf_tests > 0 && result.leaf_pairs_tested >= params.max_leaf_tests)
      {
        result.budget_exhausted = true;
        result.lower_bound = true;
        break;
      }
      ++result.leaf_pairs_tested;
      const double p = leaf_test (na, nb, rho);
      if (std::isnan (p))
      {
        ++result.invalid_leaf_results;
        continue;
      }
      const double contribution = rho * p;
      if (contribution > best)
      {
        best = contribution;
        result.max_node_a = e.a;
        result.max_node_b = e.b;
        result.max_reach_weight = rho;
        result.max_leaf_probability = p;
      }
      if (!params.exhaustive && contribution > params.stop_probability)
      {
        result.lower_bound = true;
        break;
      }
      continue;
    }

    const bool open_a =
        !leaf_a && (leaf_b || na.box.halfDiagonalSquared () >= nb.box.halfDiagonalSquared ());
    // Children nearest the other node first: in decision mode the pair that decides a
    // collision is then met early (at high noise, thousands of overlapping pairs precede it
    // in storage order). The maximum of a full traversal does not depend on the order.
    const std::size_t first = stack.size ();
    if (open_a)
    {
      const Eigen::Vector3d other = T_a_b * nb.box.center;
      for (std::int32_t c = na.first_child + na.num_children; c-- > na.first_child;)
        if (!params.only_a || (*params.only_a)[static_cast<std::size_t> (c)])
          stack.push_back ({c, e.b, rho,
                            params.nearest_first ? (nodes_a[static_cast<std::size_t> (c)].box.center - other).squaredNorm () : 0.0});
    }
    else
    {
      const Eigen::Vector3d other = T_b_a * na.box.center;
      for (std::int32_t c = nb.first_child + nb.num_children; c-- > nb.first_child;)
        stack.push_back ({e.a, c, rho,
                          params.nearest_first ? (nodes_b[static_cast<std::size_t> (c)].box.center - other).squaredNorm () : 0.0});
    }
    // Farthest pushed first, nearest popped first; ties keep the first child on top. An
    // insertion sort (stable, at most eight entries, no allocation: std::stable_sort asks for
    // a buffer on every call).
    if (params.nearest_first)
      for (std::size_t i = first + 1; i < stack.size (); ++i)
        for (std::size_t j = i; j > first && stack[j - 1].distance < stack[j].distance; --j)
          std::swap (stack[j - 1], stack[j]);
  }

  if (result.max_node_a >= 0)
  {
    result.no_leaf_tested = false;
    result.probability = std::max (0.0, best);
  }
  return result;
}
} // namespace detail
} // namespace pcl_probcollision
