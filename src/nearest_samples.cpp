// SPDX-License-Identifier: BSD-3-Clause
#include "nearest_samples.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
/** \brief A box's frame as the bound reads it: centre, axes as columns, half extents. */
struct BoxFrame
{
  Eigen::Vector3d center;
  Eigen::Matrix3d axes;
  Eigen::Vector3d half;
};

/** \brief A lower bound on the distance between two boxes given in one frame. */
double
gapLowerBound (const BoxFrame& a, const BoxFrame& b)
{
  // Projected on a unit axis L, a box is an interval about L.c of half-width sum_k h_k |L.axis_k|,
  // so any two points of the boxes differ along L by at least the gap between the intervals.
  // Along three orthonormal axes the squared gaps add up: the norm of the gaps along one box's
  // axes bounds the distance. (The largest single gap, the separating-axis test's, is looser by
  // up to sqrt(3): on the evaluation's piano in its room it visited about 770 node pairs a far
  // pose against 490, median.)
  const Eigen::Matrix3d C = a.axes.transpose () * b.axes;  // b's axes in a's box frame
  const Eigen::Matrix3d abs_c = C.cwiseAbs ();
  const Eigen::Vector3d t = a.axes.transpose () * (b.center - a.center);  // b's centre in a's box frame
  const Eigen::Vector3d gap_a = (t.cwiseAbs () - a.half - abs_c * b.half).cwiseMax (0.0);
  const Eigen::Vector3d gap_b = ((C.transpose () * t).cwiseAbs () - b.half - abs_c.transpose () * a.half).cwiseMax (0.0);
  return std::sqrt (std::max (gap_a.squaredNorm (), gap_b.squaredNorm ()));
}

/** \brief Per-thread buffers of one search: each node's frame and each of B's points mapped
  * into A's frame once (stamped, so nothing is cleared between queries). */
struct Scratch
{
  std::vector<BoxFrame> frames_a, frames_b;
  std::vector<std::uint32_t> framed_a, framed_b, mapped;
  std::vector<Eigen::Vector3d> points_b;
  std::uint32_t stamp = 0;

  std::uint32_t
  next (std::size_t nodes_a, std::size_t nodes_b, std::size_t points)
  {
    auto grow = [] (std::vector<std::uint32_t>& v, std::size_t n) {
      if (v.size () < n)
        v.resize (n, 0);
    };
    grow (framed_a, nodes_a);
    grow (framed_b, nodes_b);
    grow (mapped, points);
    frames_a.resize (std::max (frames_a.size (), nodes_a));
    frames_b.resize (std::max (frames_b.size (), nodes_b));
    points_b.resize (std::max (points_b.size (), points));
    if (++stamp == 0)
    {
      std::fill (framed_a.begin (), framed_a.end (), 0);
      std::fill (framed_b.begin (), framed_b.end (), 0);
      std::fill (mapped.begin (), mapped.end (), 0);
      stamp = 1;
    }
    return stamp;
  }
};
} // namespace

NearestSamples
nearestSamples (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b)
{
  NearestSamples out;
  if (a.empty () || b.empty ())
    return out;
  thread_local Scratch scratch;
  const std::uint32_t stamp = scratch.next (a.nodes ().size (), b.nodes ().size (), b.size ());
  auto frameA = [&] (std::int32_t id) -> const BoxFrame& {
    const std::size_t k = static_cast<std::size_t> (id);
    if (scratch.framed_a[k] != stamp)
    {
      const OrientedBox& box = a.node (id).box;
      scratch.frames_a[k] = {box.center, box.axes (), box.halfExtents ()};
      scratch.framed_a[k] = stamp;
    }
    return scratch.frames_a[k];
  };
  auto frameB = [&] (std::int32_t id) -> const BoxFrame& {
    const std::size_t k = static_cast<std::size_t> (id);
    if (scratch.framed_b[k] != stamp)
    {
      const OrientedBox& box = b.node (id).box;
      scratch.frames_b[k] = {T_a_b * box.center, T_a_b.linear () * box.axes (), box.halfExtents ()};
      scratch.framed_b[k] = stamp;
    }
    return scratch.frames_b[k];
  };
  // Best first: node pairs by the lower bound on their distance, so the search ends when the
  // nearest pair found is no farther than the next bound. Overlapping boxes all bound 0 (a room
  // around the object): among equal bounds the pair whose box centres are nearer comes first,
  // so the first leaves reached are near ones. (Depth first, the nearer child first, visited
  // about 8 times as many node pairs on the evaluation's piano in its room.)
  struct Entry
  {
    double bound, centres;  ///< the lower bound; the squared distance between the box centres
    std::int32_t a, b;
    bool operator> (const Entry& o) const { return bound > o.bound || (bound == o.bound && centres > o.centres); }
  };
  thread_local std::vector<Entry> heap;
  heap.clear ();
  double best2 = std::numeric_limits<double>::infinity ();  // squared distance of the nearest pair so far
  std::int32_t leaf_a = -1, leaf_b = -1;                    // the leaves that hold it
  auto push = [&] (std::int32_t ia, std::int32_t ib) {
    const BoxFrame& fa = frameA (ia);
    const BoxFrame& fb = frameB (ib);
    const double bound = gapLowerBound (fa, fb);
    if (bound * bound >= best2)
      return;
    heap.push_back ({bound, (fa.center - fb.center).squaredNorm (), ia, ib});
    std::push_heap (heap.begin (), heap.end (), std::greater<Entry> ());
  };
  push (ProbabilisticBVH::rootId (), ProbabilisticBVH::rootId ());
  while (!heap.empty ())
  {
    std::pop_heap (heap.begin (), heap.end (), std::greater<Entry> ());
    const Entry e = heap.back ();
    heap.pop_back ();
    if (e.bound * e.bound >= best2)
      break;  // every pair left is at least this far
    ++out.node_pairs;
    const ProbabilisticBVH::Node& na = a.node (e.a);
    const ProbabilisticBVH::Node& nb = b.node (e.b);
    if (na.isLeaf () && nb.isLeaf ())
    {
      // Each of B's points against A's leaf: skipped when A's box is no nearer than the best.
      const BoxFrame& box_a = frameA (e.a);
      for (const int j : b.indices (nb))
      {
        const std::size_t sj = static_cast<std::size_t> (j);
        if (scratch.mapped[sj] != stamp)
        {
          scratch.points_b[sj] = T_a_b * b.means ()[sj];
          scratch.mapped[sj] = stamp;
        }
        const Eigen::Vector3d& q = scratch.points_b[sj];
        const Eigen::Vector3d outside =
            ((box_a.axes.transpose () * (q - box_a.center)).cwiseAbs () - box_a.half).cwiseMax (0.0);
        if (outside.squaredNorm () >= best2)
          continue;
        for (const int i : a.indices (na))
        {
          const double d2 = (a.means ()[static_cast<std::size_t> (i)] - q).squaredNorm ();
          if (d2 < best2)
          {
            best2 = d2;
            out.index_a = i;
            out.index_b = j;
            leaf_a = e.a;
            leaf_b = e.b;
          }
        }
      }
      continue;
    }
    // Open the larger node (or the one that is not a leaf).
    const bool open_a = !na.isLeaf () && (nb.isLeaf () || na.box.halfDiagonalSquared () >= nb.box.halfDiagonalSquared ());
    if (open_a)
      for (int c = 0; c < na.num_children; ++c)
        push (na.first_child + c, e.b);
    else
      for (int c = 0; c < nb.num_children; ++c)
        push (e.a, nb.first_child + c);
  }
  if (out.index_a >= 0)
  {
    // The spacing about a sample: its nearest distinct neighbour among its leaf's points.
    auto spacing = [] (const ProbabilisticBVH& bvh, std::int32_t leaf, int index) {
      const Eigen::Vector3d& p = bvh.means ()[static_cast<std::size_t> (index)];
      double nearest2 = std::numeric_limits<double>::infinity ();
      for (const int k : bvh.indices (bvh.node (leaf)))
      {
        const double d2 = (bvh.means ()[static_cast<std::size_t> (k)] - p).squaredNorm ();
        if (d2 > 0.0)
          nearest2 = std::min (nearest2, d2);
      }
      return std::isfinite (nearest2) ? std::sqrt (nearest2) : 0.0;
    };
    out.spacing_a = spacing (a, leaf_a, out.index_a);
    out.spacing_b = spacing (b, leaf_b, out.index_b);
    out.point_a = a.means ()[static_cast<std::size_t> (out.index_a)];
    out.point_b = T_a_b * b.means ()[static_cast<std::size_t> (out.index_b)];
  }
  return out;
}

NearestSample
nearestSample (const ProbabilisticBVH& bvh, const Eigen::Vector3d& x)
{
  NearestSample out;
  if (bvh.empty ())
    return out;
  const auto& means = bvh.means ();
  // The distance from x to a node's box, less a slack for its rounding (the box's frame is
  // rebuilt from two stored axes, its coordinates rounded): the box is passed over only when
  // it lies farther than the best by more than the slack.
  struct Entry
  {
    double bound;
    std::int32_t id;
    bool operator> (const Entry& o) const { return bound > o.bound || (bound == o.bound && id > o.id); }
  };
  const auto lowerBound = [&] (const OrientedBox& box) {
    const double slack = 1e-9 * ((x - box.center).norm () + box.halfExtents ().norm ()) + std::numeric_limits<double>::min ();
    return box.distanceTo (x) - slack;
  };
  thread_local std::vector<Entry> heap;
  heap.clear ();
  double best2 = std::numeric_limits<double>::infinity (), best = best2;
  const auto push = [&] (std::int32_t id) {
    const double bound = lowerBound (bvh.node (id).box);
    if (bound > best)
      return;
    heap.push_back ({bound, id});
    std::push_heap (heap.begin (), heap.end (), std::greater<Entry> ());
  };
  push (ProbabilisticBVH::rootId ());
  while (!heap.empty ())
  {
    std::pop_heap (heap.begin (), heap.end (), std::greater<Entry> ());
    const Entry e = heap.back ();
    heap.pop_back ();
    if (e.bound > best)
      break;  // every box left lies farther than the best by more than its rounding
    const ProbabilisticBVH::Node& node = bvh.node (e.id);
    if (!node.isLeaf ())
    {
      for (int c = 0; c < node.num_children; ++c)
        push (node.first_child + c);
      continue;
    }
    for (const int i : bvh.indices (node))
    {
      const double d2 = (means[static_cast<std::size_t> (i)] - x).squaredNorm ();
      if (d2 < best2 || (d2 == best2 && i < out.index))
      {
        best2 = d2;
        best = std::sqrt (d2);
        out.index = i;
      }
    }
  }
  out.distance = best;
  return out;
}
} // namespace detail
} // namespace pcl_probcollision
