// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/uncertain_points.h>
#include <pcl_probcollision/detail/leakage.h>
#include <pcl_probcollision/detail/obb.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace pcl_probcollision
{
/** \brief Parameters of the epsilon-overlap hierarchy, with their defaults (METHOD.md 8.7). */
struct BVHParams
{
  /** \brief How a node is divided (METHOD.md 8.1). */
  enum class SplitStyle
  {
    Pca,    ///< two children along the longest principal axis e3, at the mean projection
    Octree  ///< up to eight children on the node's principal axes, at the mean; empty cells dropped
  };
  /** \brief How the per-axis slab probabilities combine into a point's outside probability. */
  using LeakageBound = detail::LeakageBound;

  /** \brief Split style; Pca by default. */
  SplitStyle split_style = SplitStyle::Pca;
  /** \brief A node with more points than n_max is split (>= 1). */
  int n_max = 20;
  /** \brief n_min's default. */
  static constexpr int kDefaultNMin = 8;
  /** \brief A node with at most n_min points is never split, whatever its variation
    * (1 <= n_min <= n_max). Default 8; lowering n_max below it needs n_min lowered too
    * (nMinFor()). */
  int n_min = kDefaultNMin;
  /** \brief n_min for an n_max set without one: min(8, n_max), so that an n_max below the
    * default n_min stays valid. The one rule of pcd_collision's -nmax N and of Python's
    * CloudModelParams(n_max=N) without n_min. */
  static int nMinFor (int n_max) { return n_max < kDefaultNMin ? n_max : kDefaultNMin; }
  /** \brief A node whose variation lambda_1 / (lambda_1 + lambda_2 + lambda_3) exceeds this is
    * split (dimensionless, >= 0; values >= 1/3 disable the variation rule). */
  double sigma_max = 0.05;
  /** \brief Sibling overlap as a fraction of the parent's extent L along the split axis:
    * left = {p <= s + epsilon L}, right = {p >= s - epsilon L} (dimensionless, [0, 0.5)).
    * A split whose overlap would store more than half of the node's points twice is made
    * without overlap (so a large epsilon cannot make the hierarchy grow exponentially). */
  double epsilon = 0.02;
  /** \brief Box inflation in point standard deviations along each box axis (>= 0). */
  double k_sigma = 1.0;
  /** \brief MinSlab (default, METHOD.md 8.4) or the UnionBound variant. */
  LeakageBound leakage_bound = LeakageBound::MinSlab;
  /** \brief Resolution tied to the noise (issue #17 item 1): a node of at most n_noise_max
    * points whose extent along its longest principal axis e3 (the means' range) is at most
    * noise_stop times the median standard deviation of its points along e3 is not split: its
    * halves would lie within about noise_stop / 2 point sigmas of each other, closer than the
    * noise can tell apart. In point standard deviations, finite and >= 0; 0 (default) is off.
    * Checked after the n_max / sigma_max and n_min rules, so it only turns would-be splits into
    * leaves (LeafReason::NoiseStop). */
  double noise_stop = 0.0;
  /** \brief Largest node that noise_stop may keep whole (>= 1): bounds the points of a leaf,
    * hence the cost of one leaf test. Default 160 (8 times the default n_max). */
  int n_noise_max = 160;

  /** \brief Throws pcl::BadArgumentException naming the first parameter out of range and its
    * value. */
  void validate () const;

  /** \brief Member-wise equality. */
  bool operator== (const BVHParams& o) const
  {
    return split_style == o.split_style && n_max == o.n_max && n_min == o.n_min &&
           sigma_max == o.sigma_max && epsilon == o.epsilon && k_sigma == o.k_sigma &&
           leakage_bound == o.leakage_bound && noise_stop == o.noise_stop && n_noise_max == o.n_noise_max;
  }
  /** \brief Member-wise inequality. */
  bool operator!= (const BVHParams& o) const { return !(*this == o); }
};

/** \brief Epsilon-overlap bounding-volume hierarchy over uncertain points, with per-node
  * leakage and coverage probabilities (Pan, Chitta and Manocha 2011, thesis Sec. 7.5;
  * METHOD.md 8.1 - 8.4). Build once per cloud, query many times under rigid motion.
  *
  * Construction is top-down on the point means. Each node gets an oriented box with axes
  * (e3, e2, e1) of its own points' covariance, inflated by k_sigma point standard deviations,
  * and the area-weighted mean probability that its points lie outside that box (leakage).
  * Siblings overlap by epsilon times the parent's extent, so points near a split are stored in
  * both children; storedPoints() counts them with this duplication. e3 and e2 point where the
  * points' third moment along them is positive, and children come lower side first: a rigid
  * motion of the cloud gives the same tree, in the same order (the order queries visit it in).
  *
  * Everything is expressed in the cloud's own frame; the traversal
  * (detail/bvh_traversal.h) maps the boxes of one hierarchy into the other's frame on the fly.
  *
  * \note Thread safety: all const methods may run concurrently on one instance (traversals
  * share hierarchies). build() and clear() must not run concurrently with anything else on the
  * same instance.
  */
class ProbabilisticBVH
{
public:
  /** \brief Shared pointer to a hierarchy. */
  using Ptr = std::shared_ptr<ProbabilisticBVH>;
  /** \brief Shared pointer to a const hierarchy (what concurrent queries share). */
  using ConstPtr = std::shared_ptr<const ProbabilisticBVH>;

  /** \brief Why a node is a leaf. */
  enum class LeafReason : std::uint8_t
  {
    NotLeaf,    ///< internal node
    StopRule,   ///< m <= n_max and variation <= sigma_max
    MinSize,    ///< the stop rule failed but m <= n_min
    NoProgress, ///< a split was wanted but could not separate the points (METHOD.md 8.2 guard),
                ///< or the node is at maxDepth()
    NoiseStop   ///< a split was wanted but the node is within the noise (BVHParams::noise_stop)
  };

  /** \brief One node. Children of a node are stored contiguously. A node is 120 bytes (the
    * nodes are most of a large cloud's model, 0.6 a point at 1,000,000 points), so the box keeps
    * two of its axes and its half extents in single precision (rounded up), the leakage is
    * single precision and the depth 16 bits, and what only the build reads (the node's distinct
    * point count and variation) is not kept: distinctPoints() and variation() recompute it. */
  struct Node
  {
    /** \brief Inflated oriented box in the cloud's frame (metres). */
    detail::OrientedBox box;
    /** \brief P_leak: area-weighted mean over the node's points of the probability of lying
      * outside box (METHOD.md 8.4), in [0, 1]; computed in double and stored in single
      * precision (a relative error of 2^-24, far below what the estimate is worth). */
    float leakage = 0.0f;
    /** \brief Per box axis, the largest point standard deviation sqrt(a^T Sigma a) (metres);
      * lets a traversal inflate the box further (ExpandedBV). */
    Eigen::Vector3f max_sigma = Eigen::Vector3f::Zero ();
    /** \brief Id of the first child, -1 for a leaf. */
    std::int32_t first_child = -1;
    /** \brief Start of the range [begin, end) into pointIndices(): for a leaf its points, for
      * an internal node the concatenation of its leaves' points (with duplicates). */
    std::int32_t begin = 0;
    /** \brief End of the range [begin, end) into pointIndices(). */
    std::int32_t end = 0;
    /** \brief Depth below the root (root = 0), at most maxDepth(). */
    std::uint16_t depth = 0;
    /** \brief Number of children: 0 (leaf), 2 (Pca) or 1..8 (Octree). */
    std::uint8_t num_children = 0;
    /** \brief Why the node is a leaf, NotLeaf for internal nodes. */
    LeafReason leaf_reason = LeafReason::NotLeaf;

    /** \brief True for a leaf. */
    bool isLeaf () const { return num_children == 0; }
    /** \brief P_cov = 1 - P_leak (METHOD.md 8.4). */
    double coverage () const { return 1.0 - leakage; }
  };

  /** \brief A read-only range of point indices (into means() and covariances()). */
  struct IndexSpan
  {
    /** \brief First index (into pointIndices()). */
    const int* data = nullptr;
    /** \brief Number of indices. */
    std::size_t size = 0;
    /** \brief Iterator to the first index. */
    const int* begin () const { return data; }
    /** \brief Iterator past the last index. */
    const int* end () const { return data + size; }
    /** \brief The i-th point index (unchecked). */
    int operator[] (std::size_t i) const { return data[i]; }
  };

  /** \brief An empty hierarchy. */
  ProbabilisticBVH () = default;

  /** \brief Builds at construction; see build(). */
  explicit ProbabilisticBVH (const UncertainCloud& cloud, const BVHParams& params = BVHParams (), int threads = 1)
  {
    build (cloud, params, threads);
  }

  /** \brief Builds the hierarchy over a copy of cloud, replacing any previous one.
    * \param[in] cloud points with covariances in one frame (metres, square metres); its
    *            area_weights (empty = equal weights) weight the leakage; it is copied
    *            (means, covariances packed in single precision and source indices are
    *            kept, see means() and covariances())
    * \param[in] params construction parameters
    * \param[in] threads threads of the build: 0 = one per hardware thread; default 1. The
    *            hierarchy is the same for any count, node ids included.
    * \return true when a hierarchy was built; false for an empty cloud, which leaves an empty
    *         hierarchy (empty() == true, no nodes).
    * \throws pcl::BadArgumentException for invalid params, a negative thread count, sizes that disagree (covariances,
    *         non-empty area_weights or source_indices not matching means), a non-finite mean
    *         or covariance, a negative or non-finite area weight, or more than 2^28 points.
    *         On throw the previous hierarchy is left untouched. */
  bool build (const UncertainCloud& cloud, const BVHParams& params = BVHParams (), int threads = 1);

  /** \brief As build(const UncertainCloud&, const BVHParams&, int), but takes the cloud over
    * instead of copying it. The cloud is moved from only after validation succeeds; on throw
    * it is left untouched. */
  bool build (UncertainCloud&& cloud, const BVHParams& params = BVHParams (), int threads = 1);

  /** \brief As build(UncertainCloud&&, const BVHParams&, int), with the covariances given
    * packed (one a point, as covariances() keeps them) instead of in cloud.covariances, which
    * must then be empty: no double-precision copy of them is made (72 bytes a point that a
    * large build would write and read once; buildCloudModel() builds this way).
    * \throws pcl::BadArgumentException as build() does, and for a non-empty cloud.covariances */
  bool build (UncertainCloud&& cloud, std::vector<PackedCovariance>&& covariances, const BVHParams& params = BVHParams (),
              int threads = 1);

  /** \brief Drops the hierarchy and the stored cloud. */
  void clear ();

  /** \brief True when there is no hierarchy (never built, cleared, or built from no points). */
  bool empty () const { return nodes_.empty (); }

  /** \brief Number of distinct points (the size of the stored cloud). */
  std::size_t size () const { return means_.size (); }

  /** \brief All nodes; the root is nodes()[0] when not empty. */
  const std::vector<Node>& nodes () const { return nodes_; }

  /** \brief Node by id, 0 <= id < nodes().size() (unchecked). */
  const Node& node (std::int32_t id) const { return nodes_[static_cast<std::size_t> (id)]; }

  /** \brief Id of the root node. */
  static constexpr std::int32_t rootId () { return 0; }

  /** \brief The deepest level a node may have; a node there is a leaf (LeafReason::NoProgress).
    * It bounds the 16-bit Node::depth on pathological input only: balanced splits of the
    * largest cloud accepted (2^28 points) take a few dozen levels. */
  static constexpr int maxDepth () { return 65535; }

  /** \brief The flat index array: leaves' point indices (into means()), leaves in depth-first
    * order, ascending within a leaf. Its length is storedPoints(). */
  const std::vector<int>& pointIndices () const { return indices_; }

  /** \brief The point indices of a node (duplicates included for internal nodes). */
  IndexSpan indices (const Node& node) const;

  /** \brief Number of distinct points of a node (m; a leaf holds each of its points once, an
    * internal node's range repeats those its children share). */
  std::size_t distinctPoints (const Node& node) const;

  /** \brief Variation sigma_n = lambda_1 / (lambda_1 + lambda_2 + lambda_3) of a node's
    * distinct means (the stop rule's, METHOD.md 8.2), in [0, 1/3]; 0 when all coincide.
    * Recomputed as the build computed it, from the node's points in the same (ascending) order:
    * the same number. */
  double variation (const Node& node) const;

  /** \brief Points stored in the leaves, counted with duplication (>= size()). */
  std::size_t storedPoints () const { return indices_.size (); }

  /** \brief Number of leaves. */
  std::size_t leafCount () const { return leaf_count_; }

  /** \brief Number of levels: 0 when empty, 1 for a single leaf. */
  int depth () const { return depth_; }

  /** \brief Memory held by this object in bytes: the stored points (means, packed covariances,
    * source indices), the nodes and the index array, by capacity. */
  std::size_t bytes () const;

  /** \brief Wall time of the hierarchy construction in the last build() (milliseconds;
    * input validation and the copy of a const cloud excluded). */
  double buildMilliseconds () const { return build_milliseconds_; }

  /** \brief The stored point means, in the cloud's own frame (index = point index of the
    * hierarchy). */
  const std::vector<Eigen::Vector3d>& means () const { return means_; }
  /** \brief The stored covariances, symmetrised and packed in single precision (each entry the
    * nearest float to the input's; exact for covariances estimated by the library, which are
    * float already). Area weights are not kept: they only weight the leakage at build time. */
  const std::vector<PackedCovariance>& covariances () const { return covariances_; }
  /** \brief The source index of every point (the built cloud's source_indices), or empty when
    * the built cloud had none or they were 0, 1, ..., n - 1 (every point kept, in order). */
  const std::vector<int>& sourceIndices () const { return source_indices_; }
  /** \brief The caller's index of point i: sourceIndices()[i], or i when there are none. */
  int sourceIndex (int i) const { return source_indices_.empty () ? i : source_indices_[static_cast<std::size_t> (i)]; }

  /** \brief The parameters of the last successful build(). */
  const BVHParams& params () const { return params_; }

  /** \brief Copies a node's points into caller-provided buffers in the cloud's own frame.
    * The buffers are resized to the node's point count (capacity is reused).
    * \param[in] node a node of this hierarchy (normally a leaf)
    * \param[out] means point means (metres)
    * \param[out] covariances point covariances (square metres)
    * \return a view over the buffers
    * \throws pcl::BadArgumentException when node's range lies outside pointIndices() */
  PointSetView gatherPoints (const Node& node, std::vector<Eigen::Vector3d>& means,
                             std::vector<Eigen::Matrix3d>& covariances) const;

  /** \brief Copies a node's points into caller-provided buffers, mapped into another frame:
    * means x -> T_dst_src x, covariances Sigma -> R Sigma R^T (R = T_dst_src.linear()),
    * symmetrised. For the leaf test of B in A's frame pass T_a_b.
    * \param[in] node a node of this hierarchy (normally a leaf)
    * \param[in] T_dst_src rigid transform from this cloud's frame to the destination frame
    * \param[out] means transformed means (metres)
    * \param[out] covariances transformed covariances (square metres)
    * \return a view over the buffers
    * \throws pcl::BadArgumentException when node's range lies outside pointIndices() */
  PointSetView gatherPoints (const Node& node, const Eigen::Isometry3d& T_dst_src,
                             std::vector<Eigen::Vector3d>& means,
                             std::vector<Eigen::Matrix3d>& covariances) const;

private:
  /** \brief The build after validation: covariances packed, or empty to pack cloud.covariances
    * here (within buildMilliseconds()). */
  bool buildValidated (UncertainCloud&& cloud, std::vector<PackedCovariance>&& covariances, const BVHParams& params,
                       std::size_t workers);

  // The points, in the cloud's own frame: 48 bytes a point, 52 with source indices.
  std::vector<Eigen::Vector3d> means_;
  std::vector<PackedCovariance> covariances_;
  std::vector<int> source_indices_;
  BVHParams params_;
  std::vector<Node> nodes_;
  std::vector<int> indices_;
  std::size_t leaf_count_ = 0;
  int depth_ = 0;
  double build_milliseconds_ = 0.0;
};
} // namespace pcl_probcollision
