// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/detail/huge_pages.h>
#include <pcl_probcollision/detail/node_kernels.h>
#include <pcl_probcollision/detail/parallel.h>
#include <pcl_probcollision/detail/principal_axes.h>

#include <pcl/exceptions.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

namespace pcl_probcollision
{
void
BVHParams::validate () const
{
  if (split_style != SplitStyle::Pca && split_style != SplitStyle::Octree)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] split_style "
                             << static_cast<int> (split_style) << " is not Pca or Octree");
  if (n_max < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] n_max " << n_max
                                                                          << " must be >= 1");
  if (n_min < 1 || n_min > n_max)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] n_min "
                             << n_min << " outside [1, n_max = " << n_max << "]"
                             << (n_min > n_max && n_max >= 1 ? ": set n_min too when lowering n_max (pcd_collision's -nmax N "
                                                               "sets it to min(8, N))"
                                                             : ""));
  if (!(sigma_max >= 0.0) || !std::isfinite (sigma_max))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] sigma_max "
                             << sigma_max << " must be finite and >= 0");
  if (!(epsilon >= 0.0 && epsilon < 0.5))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] epsilon " << epsilon
                                                                            << " outside [0, 0.5)");
  if (!(k_sigma >= 0.0) || !std::isfinite (k_sigma))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] k_sigma "
                             << k_sigma << " must be finite and >= 0");
  if (!(noise_stop >= 0.0) || !std::isfinite (noise_stop))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] noise_stop "
                             << noise_stop << " must be finite and >= 0");
  if (n_noise_max < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] n_noise_max " << n_noise_max
                                                                                << " must be >= 1");
  if (leakage_bound != LeakageBound::MinSlab && leakage_bound != LeakageBound::UnionBound)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::BVHParams::validate] leakage_bound "
                             << static_cast<int> (leakage_bound)
                             << " is not MinSlab or UnionBound");
}

namespace
{
// Largest accepted cloud: stored indices (with duplication) and node ranges are int32.
constexpr std::size_t kMaxPoints = std::size_t (1) << 28;

/** \brief Throws for what build() refuses. The covariances are counted by `covariances` and
  * tested by finiteCovariance(i), wherever they are held (cloud.covariances, or packed). */
template <typename FiniteCovariance>
void
validateCloud (const UncertainCloud& cloud, std::size_t covariances, FiniteCovariance finiteCovariance)
{
  const std::size_t n = cloud.means.size ();
  if (covariances != n)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::build] " << covariances
                             << " covariances for " << n << " means");
  if (!cloud.area_weights.empty () && cloud.area_weights.size () != n)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::build] " << cloud.area_weights.size ()
                             << " area weights for " << n << " means");
  if (!cloud.source_indices.empty () && cloud.source_indices.size () != n)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::build] "
                             << cloud.source_indices.size () << " source indices for " << n
                             << " means");
  if (n > kMaxPoints)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::build] " << n
                             << " points exceed the limit of " << kMaxPoints);
  for (std::size_t i = 0; i < n; ++i)
  {
    if (!cloud.means[i].allFinite ())
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::ProbabilisticBVH::build] point "
                               << i << " has a non-finite mean (" << cloud.means[i].x () << ", "
                               << cloud.means[i].y () << ", " << cloud.means[i].z () << ")");
    if (!finiteCovariance (i))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::ProbabilisticBVH::build] point "
                               << i << " has a non-finite covariance");
    if (!cloud.area_weights.empty () &&
        (!(cloud.area_weights[i] >= 0.0) || !std::isfinite (cloud.area_weights[i])))
      PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                           "[pcl_probcollision::ProbabilisticBVH::build] point "
                               << i << " has area weight " << cloud.area_weights[i]
                               << " (must be finite and >= 0)");
  }
}

struct BuildTask
{
  std::int32_t node;
  std::int32_t depth;
  std::vector<int> points;
};

// Split value along one projection: the mean (FCL's rule); the median when rounding leaves a
// strict side empty; the mid-range as the last resort. Requires max > min; pmin and pmax are the
// projection's minimum and maximum, so that a value has points strictly on both sides when
// pmin < value < pmax.
double
splitValue (const std::vector<double>& p, double pmin, double pmax, std::vector<double>& tmp)
{
  const std::size_t m = p.size ();
  double sum = 0.0;
  for (double v : p)
    sum += v;
  double s = sum / static_cast<double> (m);
  const auto both_sides = [&] (double v) { return pmin < v && v < pmax; };
  if (both_sides (s))
    return s;
  tmp.assign (p.begin (), p.end ());
  std::nth_element (tmp.begin (), tmp.begin () + m / 2, tmp.end ());
  s = tmp[m / 2];
  if (both_sides (s))
    return s;
  return 0.5 * (pmin + pmax);
}

// The node layout its documentation promises (ProbabilisticBVH::Node).
static_assert (sizeof (ProbabilisticBVH::Node) == 120, "a hierarchy node is 120 bytes");

// Per-node geometry: everything computed from the node's own points.
struct NodeGeometry
{
  Eigen::Vector3d mean;
  Eigen::Matrix3d axes;           // columns e3, e2, e1
  double variation;
  std::vector<double> q[3];       // projections a_k^T (x - mean)
  std::vector<double> s[3];       // standard deviations sqrt(a_k^T Sigma a_k)
  Eigen::Vector3d lo, hi;         // inflated extents in box coordinates about mean
  Eigen::Vector3d s_max;          // the largest s per axis
  Eigen::Vector3d q_min, q_max;   // the range of q per axis
  std::vector<double> outside;    // a block of the points' outside probabilities (nodeLeakage's scratch)
};

/** \brief The points the build reads: means, the packed covariances the hierarchy keeps, and
  * the area weights (empty: equal) that only the leakage uses. */
struct BuildPoints
{
  const std::vector<Eigen::Vector3d>& means;
  const std::vector<PackedCovariance>& covariances;
  const std::vector<double>& area_weights;
};

/** \brief sigma_n = lambda_1 / (lambda_1 + lambda_2 + lambda_3) of ascending eigenvalues (0 when
  * they sum to 0). */
double
variationOf (const Eigen::Vector3d& lambda)
{
  const double l1 = std::max (0.0, lambda (0));
  const double sum = l1 + std::max (0.0, lambda (1)) + std::max (0.0, lambda (2));
  return sum > 0.0 ? l1 / sum : 0.0;
}

void
computeGeometry (const BuildPoints& cloud, const std::vector<int>& points, double k_sigma, NodeGeometry& g)
{
  const std::size_t m = points.size ();
  Eigen::Vector3d lambda;
  // The solver's sign of each axis is arbitrary, and it orders the children (the lower side
  // first), so the order a query visits leaves in: principalFrame's signs turn with the cloud.
  // (Visited in the solver's order, a crossing across two leaves, judged against the later one's
  // samples, moved a real stereo scene's answer between 0.998 and 0.778 as the scene was turned.)
  // e1 is e3 x e2, as the node's box stores it (OrientedBox), so the extents and the leakage
  // below are those of the stored box exactly.
  detail::principalFrame (m, [&] (std::size_t i) { return cloud.means[static_cast<std::size_t> (points[i])]; },
                          g.mean, lambda, g.axes);
  g.variation = variationOf (lambda);

  for (int k = 0; k < 3; ++k)
  {
    detail::resizeHugePages (g.q[k], m);
    detail::resizeHugePages (g.s[k], m);
  }
  detail::NodeExtents out;
  static_assert (sizeof (Eigen::Vector3d) == 3 * sizeof (double), "means are packed x, y, z");
  detail::nodeProjections (m, points.data (), cloud.means.data ()->data (), cloud.covariances.data (), g.mean, g.axes,
                           k_sigma, g.q[0].data (), g.q[1].data (), g.q[2].data (), g.s[0].data (), g.s[1].data (),
                           g.s[2].data (), out);
  g.lo = Eigen::Vector3d (out.lo);
  g.hi = Eigen::Vector3d (out.hi);
  g.s_max = Eigen::Vector3d (out.s_max);
  g.q_min = Eigen::Vector3d (out.q_min);
  g.q_max = Eigen::Vector3d (out.q_max);
}

/** \brief Points whose outside probabilities nodeLeakage() computes at a time: the sums stay in
  * point order, and no array of a large node's size is needed for them. */
constexpr std::size_t kOutsideBlock = 4096;

/** \brief P_leak of the node (METHOD.md 8.4): the (area-weighted) mean of its points' P_x
  * (detail::nodeOutside()), summed in point order. */
double
nodeLeakage (const BuildPoints& cloud, const std::vector<int>& points, NodeGeometry& g, detail::LeakageBound bound)
{
  const std::size_t m = points.size ();
  g.outside.resize (std::min (m, kOutsideBlock));
  const bool weighted = !cloud.area_weights.empty ();
  double sum_w = 0.0, sum_wp = 0.0, sum_p = 0.0;
  for (std::size_t first = 0; first < m; first += kOutsideBlock)
  {
    const std::size_t count = std::min (kOutsideBlock, m - first);
    detail::nodeOutside (count, g.q[0].data () + first, g.q[1].data () + first, g.q[2].data () + first,
                         g.s[0].data () + first, g.s[1].data () + first, g.s[2].data () + first, g.lo.data (),
                         g.hi.data (), bound, g.outside.data ());
    for (std::size_t i = 0; i < count; ++i)
    {
      const double p = g.outside[i];
      sum_p += p;
      if (weighted)
      {
        const double w = cloud.area_weights[points[first + i]];
        sum_w += w;
        sum_wp += w * p;
      }
    }
  }
  // All-zero weights in a node carry no area information: fall back to equal weights.
  double leak = (weighted && sum_w > 0.0) ? sum_wp / sum_w : sum_p / static_cast<double> (m);
  return std::min (1.0, std::max (0.0, leak));
}

// A split whose epsilon overlap would store more than this share of the node's points twice is
// made without overlap instead. epsilon = 0.02 duplicates a few percent, but from epsilon = 0.2
// the children held nearly all of their parent and the hierarchy grew exponentially (1,000
// points: a million nodes; found by fuzz/fuzz_collide, docs/RELIABILITY.md).
// Small nodes may exceed the share by a few points without harm.
constexpr double kMaxOverlapShare = 0.5;
constexpr std::size_t kOverlapAllowance = 4;

bool
tooMuchOverlap (std::size_t stored, std::size_t m)
{
  const std::size_t twice = stored - m;
  return twice > kOverlapAllowance && static_cast<double> (twice) > kMaxOverlapShare * static_cast<double> (m);
}

// Pca split (METHOD.md 8.1, 8.2). Returns false when no split makes progress.
bool
splitPca (const std::vector<int>& points, const NodeGeometry& g, double epsilon,
          std::vector<double>& tmp, std::vector<std::vector<int>>& children)
{
  const std::vector<double>& p = g.q[0];
  const std::size_t m = points.size ();
  const double pmin = g.q_min (0), pmax = g.q_max (0);
  if (!(pmax > pmin))
    return false;
  const double L = pmax - pmin;
  const double s = splitValue (p, pmin, pmax, tmp);
  const double eps_try[2] = {epsilon, 0.0};
  for (int attempt = 0; attempt < (epsilon > 0.0 ? 2 : 1); ++attempt)
  {
    const double left_hi = s + eps_try[attempt] * L;
    const double right_lo = s - eps_try[attempt] * L;
    std::size_t nl = 0, nr = 0;
    for (double v : p)
    {
      nl += (v <= left_hi);
      nr += (v >= right_lo);
    }
    if (nl == m || nr == m || nl == 0 || nr == 0)
      continue;
    if (attempt == 0 && epsilon > 0.0 && tooMuchOverlap (nl + nr, m))
      continue;  // split without overlap
    // Every point is written to both children and kept where it belongs by advancing the
    // write position or not (no data-dependent branch); one spare slot takes the last writes.
    // Fresh arrays (the last children were moved away): a top node's are large.
    children.resize (2);
    detail::resizeHugePages (children[0], nl + 1);
    detail::resizeHugePages (children[1], nr + 1);
    int* left = children[0].data ();
    int* right = children[1].data ();
    std::size_t il = 0, ir = 0;
    for (std::size_t i = 0; i < m; ++i)
    {
      left[il] = points[i];
      il += p[i] <= left_hi;
      right[ir] = points[i];
      ir += p[i] >= right_lo;
    }
    children[0].resize (nl);
    children[1].resize (nr);
    return true;
  }
  return false;
}

// Relative extent below which an octree axis counts as flat (see splitOctree).
constexpr double kFlatAxisRelative = 1e-9;

// Octree split on the node's principal axes at the mean; each cell grown by epsilon times the
// parent's extent on each axis; axes along which all points project equally are not split.
bool
splitOctree (const std::vector<int>& points, const NodeGeometry& g, double epsilon,
             std::vector<double>& tmp, std::vector<std::vector<int>>& children)
{
  const std::size_t m = points.size ();
  bool active[3];
  double s[3], L[3];
  bool any = false;
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k)
  {
    lo[k] = g.q_min (k);
    hi[k] = g.q_max (k);
    L[k] = hi[k] - lo[k];
  }
  // An axis whose extent is at the rounding level of the longest one (collinear or coplanar
  // points) is not split: its "halves" would only sort rounding noise.
  const double L_max = std::max (L[0], std::max (L[1], L[2]));
  for (int k = 0; k < 3; ++k)
  {
    active[k] = hi[k] > lo[k] && L[k] > kFlatAxisRelative * L_max;
    s[k] = active[k] ? splitValue (g.q[k], lo[k], hi[k], tmp) : 0.0;
    any = any || active[k];
  }
  if (!any)
    return false;
  const double eps_try[2] = {epsilon, 0.0};
  std::vector<std::vector<int>> cells;
  for (int attempt = 0; attempt < (epsilon > 0.0 ? 2 : 1); ++attempt)
  {
    const double e = eps_try[attempt];
    cells.assign (8, std::vector<int> ());
    for (std::size_t i = 0; i < m; ++i)
    {
      // Bit k of a cell id: 0 = low side, 1 = high side of axis k.
      int low_mask = 0, high_mask = 0;
      for (int k = 0; k < 3; ++k)
      {
        const double v = g.q[k][i];
        const bool low = !active[k] || v <= s[k] + e * L[k];
        const bool high = active[k] && v >= s[k] - e * L[k];
        low_mask |= (low ? 1 : 0) << k;
        high_mask |= (high ? 1 : 0) << k;
      }
      for (int c = 0; c < 8; ++c)
      {
        bool in = true;
        for (int k = 0; k < 3 && in; ++k)
          in = ((c >> k) & 1) ? ((high_mask >> k) & 1) : ((low_mask >> k) & 1);
        if (in)
          cells[c].push_back (points[i]);
      }
    }
    bool progress = true;
    std::size_t stored = 0;
    for (const auto& c : cells)
    {
      progress = progress && c.size () < m;
      stored += c.size ();
    }
    if (!progress || (attempt == 0 && e > 0.0 && tooMuchOverlap (stored, m)))
      continue;
    children.clear ();
    for (auto& c : cells)
      if (!c.empty ())
        children.push_back (std::move (c));
    if (children.size () >= 2)
      return true;
  }
  return false;
}

/** \brief BVHParams::noise_stop's test: the means' range along e3 is at most noise_stop times the
  * median of the points' standard deviations along e3 (the median: one point with a wide
  * covariance, e.g. at an edge, should not keep a node whole). */
bool
withinNoise (const NodeGeometry& g, double noise_stop, std::vector<double>& tmp)
{
  const double L = g.q_max (0) - g.q_min (0);
  tmp.assign (g.s[0].begin (), g.s[0].end ());
  const std::size_t mid = tmp.size () / 2;
  std::nth_element (tmp.begin (), tmp.begin () + mid, tmp.end ());
  return L <= noise_stop * tmp[mid];
}

using Node = ProbabilisticBVH::Node;

/** \brief Nodes to reserve for a subtree of m points, so that its node vector is allocated once:
  * builds made 0.32-0.46 nodes a point (the room sampled at 11,540 / 49,992 / 99,993 points:
  * 5,303 / 16,445 / 32,231 nodes). A vector grown by doubling touched about twice the memory it
  * kept, and every first touch is a page fault (about 11 us in this project's VMs, detail/
  * huge_pages.h). Reserved memory never written is never touched. */
std::size_t
nodesToReserve (std::size_t m)
{
  return m / 2 + 8;
}

/** \brief Point indices to reserve for a subtree of m points: a few percent are duplicated. */
std::size_t
indicesToReserve (std::size_t m)
{
  return m + m / 4 + 8;
}

/** \brief What a worker reuses from node to node. */
struct NodeScratch
{
  NodeGeometry g;
  std::vector<double> tmp;
  std::vector<std::vector<int>> children;
};

/** \brief Fills node from its task's points (box, leakage, counts, depth) and splits them.
  * \return true when the node is split: its children's points are then in s.children, and
  *         node.num_children is set (node.first_child is left to the caller). */
bool
makeNode (const BuildPoints& points, const BVHParams& params, const BuildTask& task, Node& node, NodeScratch& s)
{
  const std::vector<int>& pts = task.points;
  const std::size_t m = pts.size ();
  NodeGeometry& g = s.g;
  computeGeometry (points, pts, params.k_sigma, g);
  node.box.setAxes (g.axes);
  node.box.center = g.mean + g.axes * (0.5 * (g.lo + g.hi));
  node.box.setHalfExtents (0.5 * (g.hi - g.lo));
  // The leakage is the stored box's, whose extents are rounded up to float.
  const Eigen::Vector3d mid = 0.5 * (g.lo + g.hi);
  g.lo = mid - node.box.halfExtents ();
  g.hi = mid + node.box.halfExtents ();
  for (int k = 0; k < 3; ++k)
    node.max_sigma (k) = static_cast<float> (g.s_max (k));
  node.leakage = static_cast<float> (nodeLeakage (points, pts, g, params.leakage_bound));
  node.depth = static_cast<std::uint16_t> (task.depth);
  node.first_child = -1;
  node.num_children = 0;

  const bool stop_rule = m <= static_cast<std::size_t> (params.n_max) && g.variation <= params.sigma_max;
  bool split = false;
  if (stop_rule)
    node.leaf_reason = ProbabilisticBVH::LeafReason::StopRule;
  else if (m <= static_cast<std::size_t> (params.n_min))
    node.leaf_reason = ProbabilisticBVH::LeafReason::MinSize;
  else if (params.noise_stop > 0.0 && m <= static_cast<std::size_t> (params.n_noise_max) &&
           withinNoise (g, params.noise_stop, s.tmp))
    node.leaf_reason = ProbabilisticBVH::LeafReason::NoiseStop;
  else if (task.depth >= ProbabilisticBVH::maxDepth ())
    node.leaf_reason = ProbabilisticBVH::LeafReason::NoProgress;
  else
  {
    split = params.split_style == BVHParams::SplitStyle::Pca ? splitPca (pts, g, params.epsilon, s.tmp, s.children)
                                                             : splitOctree (pts, g, params.epsilon, s.tmp, s.children);
    if (!split)
      node.leaf_reason = ProbabilisticBVH::LeafReason::NoProgress;
  }
  if (split)
  {
    node.leaf_reason = ProbabilisticBVH::LeafReason::NotLeaf;
    node.num_children = static_cast<std::uint8_t> (s.children.size ());
  }
  return split;
}

/** \brief A hierarchy under construction: nodes, leaf point indices, counts. */
struct Tree
{
  std::vector<Node> nodes;
  std::vector<int> indices;
  std::size_t leaf_count = 0;
  int max_depth = -1;
};

/** \brief Builds the subtree of root (whose node, root.node, already exists in out) one node
  * at a time, depth-first, first child first: a node's children get consecutive ids when it
  * is made, and its leaves' points go to out.indices in left-to-right order, so every
  * subtree's leaves are contiguous. Internal nodes' ranges are left to the caller. */
void
buildSubtree (const BuildPoints& points, const BVHParams& params, BuildTask root, Tree& out, NodeScratch& s)
{
  std::vector<BuildTask> stack;
  stack.push_back (std::move (root));
  while (!stack.empty ())
  {
    BuildTask task = std::move (stack.back ());
    stack.pop_back ();
    Node& node = out.nodes[static_cast<std::size_t> (task.node)];
    out.max_depth = std::max (out.max_depth, task.depth);
    if (!makeNode (points, params, task, node, s))
    {
      node.begin = static_cast<std::int32_t> (out.indices.size ());
      out.indices.insert (out.indices.end (), task.points.begin (), task.points.end ());
      node.end = static_cast<std::int32_t> (out.indices.size ());
      ++out.leaf_count;
      continue;
    }
    const std::int32_t first = static_cast<std::int32_t> (out.nodes.size ());
    const std::size_t nc = s.children.size ();
    node.first_child = first;
    // `node` may dangle after this resize.
    out.nodes.resize (out.nodes.size () + nc);
    // Reverse push: the first child is processed next.
    for (std::size_t c = nc; c-- > 0;)
      stack.push_back ({first + static_cast<std::int32_t> (c), task.depth + 1, std::move (s.children[c])});
  }
}

/** \brief A node of the top of the hierarchy, which is made level by level with the nodes of a
  * level on several threads, or a subtree below it, built whole on one thread. */
struct TopPart
{
  BuildTask task;                      ///< its points (a subtree's are moved into its build)
  Node node;                           ///< a node made at the top
  std::vector<std::size_t> children;   ///< its children's parts; empty for a leaf
  bool whole = false;                  ///< built whole in `subtree`
  Tree subtree;                        ///< local ids, its root at 0; leaf ranges into its own indices
};

/** \brief The build on several threads, in parts (joinParts() joins them). The top is made
  * level by level, each level's nodes on the workers, down to nodes of at most `whole_size`
  * points, whose subtrees are then built whole, one per worker at a time. */
std::vector<TopPart>
buildParts (const BuildPoints& points, const BVHParams& params, BuildTask root, std::size_t whole_size,
            std::size_t workers)
{
  std::vector<NodeScratch> scratch (workers);
  std::vector<TopPart> parts (1);
  parts[0].task = std::move (root);
  std::vector<std::size_t> level {0}, wholes;
  while (!level.empty ())
  {
    std::vector<std::size_t> to_make;
    for (const std::size_t p : level)
    {
      if (parts[p].task.points.size () > whole_size)
        to_make.push_back (p);
      else
      {
        parts[p].whole = true;
        wholes.push_back (p);
      }
    }
    std::vector<std::vector<std::vector<int>>> kids (to_make.size ());
    detail::parallelFor (to_make.size (), workers, [&] (std::size_t i, std::size_t w) {
      TopPart& part = parts[to_make[i]];
      if (makeNode (points, params, part.task, part.node, scratch[w]))
      {
        kids[i] = std::move (scratch[w].children);
        part.task.points = std::vector<int> ();
      }
    });
    // Children become parts only now: `parts` must not grow while the workers hold references.
    std::vector<std::size_t> next;
    for (std::size_t i = 0; i < to_make.size (); ++i)
      for (std::vector<int>& child : kids[i])
      {
        const std::size_t id = parts.size ();
        parts.emplace_back ();
        parts[id].task = {-1, parts[to_make[i]].task.depth + 1, std::move (child)};
        parts[to_make[i]].children.push_back (id);
        next.push_back (id);
      }
    level = std::move (next);
  }

  // Largest subtrees first, so that no worker is left with a big one at the end.
  std::stable_sort (wholes.begin (), wholes.end (), [&] (std::size_t a, std::size_t b) {
    return parts[a].task.points.size () > parts[b].task.points.size ();
  });
  detail::parallelFor (wholes.size (), workers, [&] (std::size_t i, std::size_t w) {
    TopPart& part = parts[wholes[i]];
    detail::reserveHugePages (part.subtree.nodes, nodesToReserve (part.task.points.size ()));
    detail::reserveHugePages (part.subtree.indices, indicesToReserve (part.task.points.size ()));
    part.subtree.nodes.emplace_back ();
    BuildTask task = std::move (part.task);
    task.node = 0;
    buildSubtree (points, params, std::move (task), part.subtree, scratch[w]);
  });

  return parts;
}

/** \brief Joins the parts of buildParts() into out, visiting them as buildSubtree visits nodes,
  * so that the hierarchy is the one a single thread builds, node ids included. Each subtree is
  * freed once copied. */
void
joinParts (std::vector<TopPart>& parts, Tree& out)
{
  std::size_t total_nodes = 0, total_indices = 0;
  for (const TopPart& part : parts)
  {
    total_nodes += part.whole ? part.subtree.nodes.size () : 1;
    total_indices += part.whole ? part.subtree.indices.size () : part.task.points.size ();
  }
  detail::reserveHugePages (out.nodes, total_nodes);
  detail::reserveHugePages (out.indices, total_indices);
  out.nodes.emplace_back ();
  std::vector<std::pair<std::size_t, std::int32_t>> stack {{0, 0}};  // part, its node's id
  while (!stack.empty ())
  {
    const std::size_t p = stack.back ().first;
    const std::int32_t slot = stack.back ().second;
    stack.pop_back ();
    TopPart& part = parts[p];
    if (part.whole)
    {
      Tree& sub = part.subtree;
      const std::int32_t base = static_cast<std::int32_t> (out.nodes.size ());
      const std::int32_t offset = static_cast<std::int32_t> (out.indices.size ());
      const auto global = [&] (std::int32_t j) { return j == 0 ? slot : base + j - 1; };
      for (std::size_t j = 0; j < sub.nodes.size (); ++j)
      {
        Node nd = sub.nodes[j];
        if (nd.isLeaf ())
        {
          nd.begin += offset;
          nd.end += offset;
        }
        else
          nd.first_child = global (nd.first_child);
        if (j == 0)
          out.nodes[static_cast<std::size_t> (slot)] = nd;
        else
          out.nodes.push_back (nd);
      }
      out.indices.insert (out.indices.end (), sub.indices.begin (), sub.indices.end ());
      out.leaf_count += sub.leaf_count;
      out.max_depth = std::max (out.max_depth, sub.max_depth);
      sub = Tree ();
      continue;
    }
    Node nd = part.node;
    out.max_depth = std::max (out.max_depth, static_cast<int> (nd.depth));
    if (part.children.empty ())
    {
      nd.begin = static_cast<std::int32_t> (out.indices.size ());
      out.indices.insert (out.indices.end (), part.task.points.begin (), part.task.points.end ());
      nd.end = static_cast<std::int32_t> (out.indices.size ());
      ++out.leaf_count;
      out.nodes[static_cast<std::size_t> (slot)] = nd;
      part.task.points = std::vector<int> ();
      continue;
    }
    const std::int32_t first = static_cast<std::int32_t> (out.nodes.size ());
    nd.first_child = first;
    out.nodes[static_cast<std::size_t> (slot)] = nd;
    out.nodes.resize (out.nodes.size () + part.children.size ());
    for (std::size_t c = part.children.size (); c-- > 0;)
      stack.emplace_back (part.children[c], first + static_cast<std::int32_t> (c));
  }
}

// A subtree of fewer points than this is not worth a thread of its own.
constexpr std::size_t kMinWholeSize = 4096;

/** \brief The workers a build's `threads` asks for (0: every core); throws for a negative one. */
std::size_t
checkedThreads (int threads, const char* where)
{
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::" << where << "] threads = " << threads
                                                                  << " must be >= 0 (0: one per hardware thread)");
  return detail::threadCount (threads);
}

/** \brief validateCloud() for covariances held in cloud.covariances. */
void
validateCloud (const UncertainCloud& cloud)
{
  validateCloud (cloud, cloud.covariances.size (), [&] (std::size_t i) { return cloud.covariances[i].allFinite (); });
}
} // namespace

bool
ProbabilisticBVH::build (const UncertainCloud& cloud, const BVHParams& params, int threads)
{
  params.validate ();
  const std::size_t workers = checkedThreads (threads, "build");
  validateCloud (cloud);
  return buildValidated (UncertainCloud (cloud), {}, params, workers);
}

bool
ProbabilisticBVH::build (UncertainCloud&& cloud, const BVHParams& params, int threads)
{
  params.validate ();
  const std::size_t workers = checkedThreads (threads, "build");
  validateCloud (cloud);
  return buildValidated (std::move (cloud), {}, params, workers);
}

bool
ProbabilisticBVH::build (UncertainCloud&& cloud, std::vector<PackedCovariance>&& covariances, const BVHParams& params,
                         int threads)
{
  params.validate ();
  const std::size_t workers = checkedThreads (threads, "build");
  if (!cloud.covariances.empty ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::build] cloud.covariances holds "
                             << cloud.covariances.size () << " covariances where they are given packed: it must be empty");
  validateCloud (cloud, covariances.size (), [&] (std::size_t i) { return covariances[i].allFinite (); });
  return buildValidated (std::move (cloud), std::move (covariances), params, workers);
}

bool
ProbabilisticBVH::buildValidated (UncertainCloud&& cloud, std::vector<PackedCovariance>&& packed,
                                  const BVHParams& params, std::size_t workers)
{
  const auto t0 = std::chrono::steady_clock::now ();
  UncertainCloud copy = std::move (cloud);
  copy.means.shrink_to_fit ();
  copy.source_indices.shrink_to_fit ();
  // The covariances the hierarchy keeps and the build reads: given packed, or packed here once,
  // in chunks on the workers.
  std::vector<PackedCovariance> covariances = std::move (packed);
  if (covariances.size () != copy.size ())
  {
    detail::resizeHugePages (covariances, copy.size ());
    detail::parallelChunks (copy.size (), detail::cheapChunk (copy.size (), workers), workers,
                            [&] (std::size_t, std::size_t begin, std::size_t end) {
                              for (std::size_t i = begin; i < end; ++i)
                                covariances[i] = PackedCovariance (copy.covariances[i]);
                            });
  }
  copy.covariances = std::vector<Eigen::Matrix3d> ();
  const BuildPoints points {copy.means, covariances, copy.area_weights};
  Tree tree;
  const std::size_t n = copy.size ();

  if (n > 0)
  {
    BuildTask root {0, 0, {}};
    detail::resizeHugePages (root.points, n);
    for (std::size_t i = 0; i < n; ++i)
      root.points[i] = static_cast<int> (i);
    // Subtrees of at most whole_size points are built whole on one thread: eight per worker
    // for balance. The hierarchy does not depend on it, nor on the thread count.
    const std::size_t whole_size = std::max (kMinWholeSize, n / (8 * workers));
    if (workers > 1 && n > whole_size)
    {
      std::vector<TopPart> parts = buildParts (points, params, std::move (root), whole_size, workers);
      copy.area_weights = std::vector<double> ();  // only the leakage read them: free before the join
      joinParts (parts, tree);
    }
    else
    {
      detail::reserveHugePages (tree.nodes, nodesToReserve (n));
      detail::reserveHugePages (tree.indices, indicesToReserve (n));
      tree.nodes.emplace_back ();
      NodeScratch scratch;
      buildSubtree (points, params, std::move (root), tree, scratch);
      detail::shrinkHugePages (tree.nodes);
      detail::shrinkHugePages (tree.indices);
    }

    // Internal ranges: children have larger ids than their parent, so one backward pass.
    for (std::size_t id = tree.nodes.size (); id-- > 0;)
    {
      Node& nd = tree.nodes[id];
      if (nd.isLeaf ())
        continue;
      nd.begin = tree.nodes[static_cast<std::size_t> (nd.first_child)].begin;
      nd.end = tree.nodes[static_cast<std::size_t> (nd.first_child + nd.num_children - 1)].end;
    }
  }

  // Keep what queries read; the area weights only served the leakage above.
  means_ = std::move (copy.means);
  covariances_ = std::move (covariances);
  source_indices_ = std::move (copy.source_indices);
  // Every point kept, in order (a cloud without NaNs): sourceIndex() is i, 4 bytes a point less.
  bool identity = true;
  for (std::size_t i = 0; i < source_indices_.size () && identity; ++i)
    identity = source_indices_[i] == static_cast<int> (i);
  if (identity)
    source_indices_ = std::vector<int> ();
  params_ = params;
  nodes_ = std::move (tree.nodes);
  indices_ = std::move (tree.indices);
  leaf_count_ = tree.leaf_count;
  depth_ = tree.max_depth + 1;
  build_milliseconds_ =
      std::chrono::duration<double, std::milli> (std::chrono::steady_clock::now () - t0).count ();
  return !nodes_.empty ();
}

void
ProbabilisticBVH::clear ()
{
  means_ = std::vector<Eigen::Vector3d> ();
  covariances_ = std::vector<PackedCovariance> ();
  source_indices_ = std::vector<int> ();
  nodes_.clear ();
  nodes_.shrink_to_fit ();
  indices_.clear ();
  indices_.shrink_to_fit ();
  leaf_count_ = 0;
  depth_ = 0;
  build_milliseconds_ = 0.0;
}

ProbabilisticBVH::IndexSpan
ProbabilisticBVH::indices (const Node& node) const
{
  IndexSpan span;
  if (node.begin < 0 || node.end < node.begin ||
      static_cast<std::size_t> (node.end) > indices_.size ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::ProbabilisticBVH::indices] node range ["
                             << node.begin << ", " << node.end << ") outside the "
                             << indices_.size () << " stored indices");
  span.data = indices_.data () + node.begin;
  span.size = static_cast<std::size_t> (node.end - node.begin);
  return span;
}

namespace
{
/** \brief A node's distinct point indices, ascending: the points its build task held (the root's
  * are ascending and every split keeps their order). */
std::vector<int>
distinctIndices (const ProbabilisticBVH::IndexSpan& span)
{
  std::vector<int> points (span.begin (), span.end ());
  std::sort (points.begin (), points.end ());
  points.erase (std::unique (points.begin (), points.end ()), points.end ());
  return points;
}
} // namespace

std::size_t
ProbabilisticBVH::distinctPoints (const Node& node) const
{
  return node.isLeaf () ? indices (node).size : distinctIndices (indices (node)).size ();
}

double
ProbabilisticBVH::variation (const Node& node) const
{
  const std::vector<int> points = distinctIndices (indices (node));
  if (points.empty ())
    return 0.0;
  Eigen::Vector3d mean, lambda;
  Eigen::Matrix3d V;
  detail::meanAndScatter (points.size (), [&] (std::size_t i) { return means_[static_cast<std::size_t> (points[i])]; },
                          mean, lambda, V);
  return variationOf (lambda);
}

std::size_t
ProbabilisticBVH::bytes () const
{
  return sizeof (*this) + means_.capacity () * sizeof (Eigen::Vector3d) +
         covariances_.capacity () * sizeof (PackedCovariance) +
         source_indices_.capacity () * sizeof (int) + nodes_.capacity () * sizeof (Node) +
         indices_.capacity () * sizeof (int);
}

PointSetView
ProbabilisticBVH::gatherPoints (const Node& node, std::vector<Eigen::Vector3d>& means,
                                std::vector<Eigen::Matrix3d>& covariances) const
{
  const IndexSpan span = indices (node);
  means.resize (span.size);
  covariances.resize (span.size);
  for (std::size_t i = 0; i < span.size; ++i)
  {
    means[i] = means_[span[i]];
    covariances[i] = covariances_[span[i]].matrix ();
  }
  return PointSetView (means.data (), covariances.data (), span.size);
}

PointSetView
ProbabilisticBVH::gatherPoints (const Node& node, const Eigen::Isometry3d& T_dst_src,
                                std::vector<Eigen::Vector3d>& means,
                                std::vector<Eigen::Matrix3d>& covariances) const
{
  const IndexSpan span = indices (node);
  means.resize (span.size);
  covariances.resize (span.size);
  const Eigen::Matrix3d R = T_dst_src.linear ();
  const Eigen::Vector3d t = T_dst_src.translation ();
  for (std::size_t i = 0; i < span.size; ++i)
  {
    means[i].noalias () = R * means_[span[i]];
    means[i] += t;
    const Eigen::Matrix3d S = R * covariances_[span[i]].matrix () * R.transpose ();
    covariances[i] = 0.5 * (S + S.transpose ());
  }
  return PointSetView (means.data (), covariances.data (), span.size);
}
} // namespace pcl_probcollision
