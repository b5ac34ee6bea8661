// SPDX-License-Identifier: BSD-3-Clause
#include "surface_test.h"

#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/detail/bvh_traversal.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
/** \brief Boxes are grown to this many point standard deviations to find the leaf pairs within
  * reach (besides one sample spacing, see surfaceTest): beyond it P_in < Phi(-3). */
constexpr double kReachSigmas = 3.0;
/** \brief Samples of the other surface that define its local implicit surface at a point. */
constexpr int kSurfaceNeighbours = 8;
/** \brief The spread of where a surface ends (or bends) between samples, per unit of distance
  * from the nearest sample, up to one spacing: an edge anywhere within one spacing, uniformly,
  * has a standard deviation of 1 / sqrt(12) = 0.29 spacing. Derived, not fitted. */
constexpr double kDiscretisationPerDistance = 0.288675;
/** \brief Holes are bridged up to this many sample spacings from the nearest sample (holes up
  * to twice as wide: an occlusion shadow); farther, the surface has ended and the point is
  * outside by its distance to that sample. */
constexpr double kBridgeSpacings = 6.0;
/** \brief Robust reweighting rounds of the implicit surface (RIMLS, Oeztireli et al. 2009):
  * samples across a crease, whose plane disagrees with the local surface, lose their weight. */
constexpr int kRobustRounds = 3;

/** \brief One sample of the other surface, in A's local frame. */
struct Sample
{
  Eigen::Vector3d position;
  Eigen::Vector3d normal;
  double spacing;
  double variance;  ///< the sample's variance along its own normal
};

/** \brief Per-thread buffers: a query allocates nothing once they have grown. */
struct Scratch
{
  std::vector<std::uint32_t> pooled, cached;  ///< stamps per point of the surface's model
  std::vector<Sample> cache;                  ///< the surface's samples mapped into A's frame
  std::vector<int> pool;
  std::uint32_t stamp = 0;
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;

  void
  prepare (std::size_t n)
  {
    if (pooled.size () < n)
    {
      pooled.assign (n, 0);
      cached.assign (n, 0);
      cache.resize (n);
      stamp = 0;
    }
  }
  std::uint32_t
  next ()
  {
    if (++stamp == 0)
    {
      std::fill (pooled.begin (), pooled.end (), 0);
      std::fill (cached.begin (), cached.end (), 0);
      stamp = 1;
    }
    return stamp;
  }
};

/** \brief The local signed distance of x to a surface given by its nearby samples. */
struct Evaluation
{
  double distance = 0.0, sigma = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero ();
};

/** \brief x against the pool: implicit surface f(x) = sum w_j n_j . (x - p_j) / sum w_j of the
  * nearest samples (Kolluri's IMLS), with robust weights; variance from the query point's own
  * covariance along the normal (variance_of), the fit's error and the discretisation. */
template <typename VarianceOf>
bool
evaluate (const Eigen::Vector3d& x, const std::vector<int>& pool, const std::vector<Sample>& samples,
          const VarianceOf& variance_of, Evaluation& out)
{
  std::array<int, kSurfaceNeighbours> nearest;
  std::array<double, kSurfaceNeighbours> d2;
  int found = 0;
  for (const int j : pool)
  {
    const double d = (samples[static_cast<std::size_t> (j)].position - x).squaredNorm ();
    if (found == kSurfaceNeighbours && d >= d2[kSurfaceNeighbours - 1])
      continue;
    int slot = found < kSurfaceNeighbours ? found++ : kSurfaceNeighbours - 1;
    while (slot > 0 && d2[static_cast<std::size_t> (slot - 1)] > d)
    {
      d2[static_cast<std::size_t> (slot)] = d2[static_cast<std::size_t> (slot - 1)];
      nearest[static_cast<std::size_t> (slot)] = nearest[static_cast<std::size_t> (slot - 1)];
      --slot;
    }
    d2[static_cast<std::size_t> (slot)] = d;
    nearest[static_cast<std::size_t> (slot)] = j;
  }
  if (found == 0)
    return false;
  const Sample& first = samples[static_cast<std::size_t> (nearest[0])];
  const double h = std::max (first.spacing, 1e-12);
  // Tangential distance to the nearest sample: how far the surface is extrapolated.
  const Eigen::Vector3d offset = x - first.position;
  const double along = first.normal.dot (offset);
  const double tangential = std::sqrt (std::max (0.0, offset.squaredNorm () - along * along));
  if (tangential > kBridgeSpacings * h)
  {
    // Past the surface's edge: outside, by the distance to its last sample.
    out.distance = offset.norm ();
    out.normal = offset / std::max (out.distance, 1e-300);
    out.sigma = std::sqrt (variance_of (out.normal) + first.variance) + kDiscretisationPerDistance * h;
    return true;
  }
  std::array<double, kSurfaceNeighbours> base, r, w;
  for (int j = 0; j < found; ++j)
  {
    const Sample& s = samples[static_cast<std::size_t> (nearest[static_cast<std::size_t> (j)])];
    base[static_cast<std::size_t> (j)] = std::exp (-(d2[static_cast<std::size_t> (j)] - d2[0]) / (h * h));
    r[static_cast<std::size_t> (j)] = s.normal.dot (x - s.position);
    w[static_cast<std::size_t> (j)] = base[static_cast<std::size_t> (j)];
  }
  // Residual scale of the robust weights: half a spacing plus the samples' noise.
  const double scale = 0.5 * h + 3.0 * std::sqrt (std::max (first.variance, 0.0));
  double f = 0.0;
  for (int round = 0; round < kRobustRounds; ++round)
  {
    double num = 0.0, den = 0.0;
    for (int j = 0; j < found; ++j)
    {
      num += w[static_cast<std::size_t> (j)] * r[static_cast<std::size_t> (j)];
      den += w[static_cast<std::size_t> (j)];
    }
    f = num / den;
    for (int j = 0; j < found; ++j)
    {
      const double e = (r[static_cast<std::size_t> (j)] - f) / scale;
      w[static_cast<std::size_t> (j)] = base[static_cast<std::size_t> (j)] * std::exp (-e * e);
    }
    w[0] = std::max (w[0], 1e-12);  // the nearest sample always counts
  }
  double den = 0.0, fit_var = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero ();
  for (int j = 0; j < found; ++j)
  {
    const Sample& s = samples[static_cast<std::size_t> (nearest[static_cast<std::size_t> (j)])];
    const double wj = w[static_cast<std::size_t> (j)];
    den += wj;
    fit_var += wj * wj * s.variance;
    normal += wj * s.normal;
  }
  fit_var /= den * den;
  const double norm = normal.norm ();
  out.normal = norm > 0.0 ? Eigen::Vector3d (normal / norm) : first.normal;
  // Where the surface runs between samples is uncertain within one spacing of the last one;
  // a bridged hole continues the fitted plane.
  const double disc = kDiscretisationPerDistance * std::min (tangential, h);
  out.distance = f;
  out.sigma = std::sqrt (variance_of (out.normal) + fit_var + disc * disc);
  return true;
}

/** \brief The points of `query` (mapped by T_q into A's frame) against `surface` (mapped by
  * T_s), leaf by leaf: groups[i] = (query leaf, surface leaf) sorted by query leaf. */
void
testSide (const CloudModel& query, const Eigen::Isometry3d& T_q, const CloudModel& surface, const Eigen::Isometry3d& T_s,
          const std::vector<std::pair<std::int32_t, std::int32_t>>& groups, Scratch& scratch, int side,
          std::vector<float>* per_point, double stop_z, SurfaceAnswer& answer, double& best_z)
{
  const ProbabilisticBVH& q_bvh = query.hierarchy ();
  const ProbabilisticBVH& s_bvh = surface.hierarchy ();
  const SurfaceModel& s_model = surface.surface ();
  const Eigen::Matrix3d R_q = T_q.linear ();
  const Eigen::Matrix3d R_s = T_s.linear ();
  scratch.prepare (s_bvh.size ());
  const std::uint32_t cache_stamp = scratch.next ();
  for (std::size_t g = 0; g < groups.size ();)
  {
    if (best_z < stop_z)
    {
      answer.stopped_early = true;
      return;
    }
    const std::int32_t q_leaf = groups[g].first;
    // The pool: every sample of the surface leaves paired with this query leaf, once.
    const std::uint32_t pool_stamp = scratch.next ();
    scratch.pool.clear ();
    for (; g < groups.size () && groups[g].first == q_leaf; ++g)
      for (const int j : s_bvh.indices (s_bvh.node (groups[g].second)))
      {
        const std::size_t sj = static_cast<std::size_t> (j);
        if (scratch.pooled[sj] == pool_stamp || s_model.normals ()[sj].isZero ())
          continue;
        scratch.pooled[sj] = pool_stamp;
        if (scratch.cached[sj] != cache_stamp)
        {
          scratch.cached[sj] = cache_stamp;
          const Eigen::Vector3d n = s_model.normals ()[sj].cast<double> ();
          scratch.cache[sj] = {T_s * s_bvh.means ()[sj], R_s * n, s_model.spacing ()[sj],
                               std::max (0.0, s_bvh.covariances ()[sj].quadratic (n))};
        }
        scratch.pool.push_back (j);
      }
    if (scratch.pool.empty ())
      continue;
    for (const int i : q_bvh.indices (q_bvh.node (q_leaf)))
    {
      const std::size_t qi = static_cast<std::size_t> (i);
      const Eigen::Vector3d x = T_q * q_bvh.means ()[qi];
      const PackedCovariance& cov = q_bvh.covariances ()[qi];
      Evaluation e;
      if (!evaluate (x, scratch.pool, scratch.cache,
                     [&] (const Eigen::Vector3d& n) { return std::max (0.0, cov.quadratic (R_q.transpose () * n)); }, e))
        continue;
      ++answer.points_tested;
      const double sigma = std::max (e.sigma, 1e-300);
      const double z = e.distance / sigma;
      if (per_point)
      {
        float& slot = (*per_point)[qi];
        const float p = static_cast<float> (normalCdf (-z));
        if (std::isnan (slot) || p > slot)
          slot = p;
      }
      if (z < best_z)
      {
        best_z = z;
        answer.reached = true;
        answer.signed_distance = e.distance;
        answer.signed_distance_std = e.sigma;
        answer.witness_side = side;
        answer.witness_index = i;
        answer.witness_point = x;
        // Toward A's side: the other surface's outward normal points away from it.
        answer.witness_normal = side > 0 ? e.normal : Eigen::Vector3d (-e.normal);
      }
    }
  }
}

/** \brief Distance from x (in `model`'s local frame) to its nearest sample. */
double
nearestSampleDistance (const CloudModel& model, const Eigen::Vector3d& x)
{
  double best = std::numeric_limits<double>::infinity ();
  for (const Eigen::Vector3d& p : model.hierarchy ().means ())
    best = std::min (best, (p - x).squaredNorm ());
  return std::sqrt (best);
}
} // namespace

SurfaceAnswer
surfaceTest (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
             std::vector<float>* per_point_a, std::vector<float>* per_point_b)
{
  thread_local Scratch scratch;
  SurfaceAnswer answer;
  const ProbabilisticBVH& bvh_a = a.hierarchy ();
  const ProbabilisticBVH& bvh_b = b.hierarchy ();
  // Leaf pairs within reach: boxes grown to kReachSigmas point deviations and by one sample
  // spacing, so that a point between two sparse samples still meets their leaves.
  TraversalParams params (request);
  params.mode = TraversalMode::ExpandedBV;
  params.expanded_k_sigma = kReachSigmas;
  params.exhaustive = true;
  params.skip_dominated = false;
  params.box_margin = std::max (a.surface ().medianSpacing (), b.surface ().medianSpacing ());
  auto& pairs = scratch.pairs;
  pairs.clear ();
  const auto* nodes_a = bvh_a.nodes ().data ();
  const auto* nodes_b = bvh_b.nodes ().data ();
  const TraversalResult traversal =
      traverseHierarchies (bvh_a, bvh_b, T_a_b, params,
                           [&] (const ProbabilisticBVH::Node& la, const ProbabilisticBVH::Node& lb, double) {
                             pairs.emplace_back (static_cast<std::int32_t> (&la - nodes_a),
                                                 static_cast<std::int32_t> (&lb - nodes_b));
                             return 0.0;
                           });
  answer.bv_tests = traversal.node_pairs_tested;
  answer.leaf_pairs = pairs.size ();
  double best_z = std::numeric_limits<double>::infinity ();
  // Decision mode: once a point's P_in exceeds collision_above the verdict is final (the
  // distance is then a bound: the deepest point may not have been reached).
  const bool may_stop = !request.exhaustive && !per_point_a && !per_point_b;
  const double stop_z = may_stop ? -normalQuantile (request.collision_above) : -std::numeric_limits<double>::infinity ();
  if (!pairs.empty ())
  {
    std::sort (pairs.begin (), pairs.end ());
    testSide (a, Eigen::Isometry3d::Identity (), b, T_a_b, pairs, scratch, +1, per_point_a, stop_z, answer, best_z);
    for (auto& p : pairs)
      std::swap (p.first, p.second);
    std::sort (pairs.begin (), pairs.end ());
    if (!answer.stopped_early)
      testSide (b, T_a_b, a, Eigen::Isometry3d::Identity (), pairs, scratch, -1, per_point_b, stop_z, answer, best_z);
  }
  if (answer.reached)
  {
    answer.probability = normalCdf (-best_z);
    return answer;
  }
  // Out of reach of each other's surface: inside entirely, or apart. Only a trusted orientation
  // (the points' own normals, a viewpoint) may declare containment: a propagated one can be
  // inside out (a room seen from within), and would put everything inside.
  auto trusted = [] (const SurfaceModel& s) { return s.orientation () != NormalOrientation::Propagate; };
  const Eigen::Vector3d a0 = bvh_a.means ().front ();
  const Eigen::Vector3d a0_in_b = T_a_b.inverse () * a0;
  const Eigen::Vector3d b0 = T_a_b * bvh_b.means ().front ();
  if (trusted (b.surface ()) && b.surface ().windingNumber (bvh_b, a0_in_b) > 0.5)
  {
    answer.reached = answer.contained = true;
    answer.witness_side = 1;
    answer.witness_index = 0;
    answer.witness_point = a0;
    answer.signed_distance = -nearestSampleDistance (b, a0_in_b);
  }
  else if (trusted (a.surface ()) && a.surface ().windingNumber (bvh_a, b0) > 0.5)
  {
    answer.reached = answer.contained = true;
    answer.witness_side = -1;
    answer.witness_index = 0;
    answer.witness_point = b0;
    answer.signed_distance = -nearestSampleDistance (a, b0);
  }
  if (answer.contained)
  {
    answer.probability = 1.0;
    // The depth is measured from the nearest sample: uncertain by about one spacing.
    answer.signed_distance_std = answer.witness_side > 0 ? b.surface ().medianSpacing () : a.surface ().medianSpacing ();
    if (per_point_a && answer.witness_side > 0)
      (*per_point_a)[0] = 1.0f;
    if (per_point_b && answer.witness_side < 0)
      (*per_point_b)[0] = 1.0f;
  }
  return answer;
}
} // namespace detail
} // namespace pcl_probcollision
