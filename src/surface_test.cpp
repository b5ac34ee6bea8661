// SPDX-License-Identifier: BSD-3-Clause
#include "surface_test.h"

#include "nearest_samples.h"

#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/detail/bvh_traversal.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <tuple>
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
/** \brief Holes are bridged up to this many sample spacings from the nearest sample (holes up
  * to twice as wide: an occlusion shadow) when samples lie on the far rim; farther, or with no
  * far rim, the surface has ended and the point is outside by its distance to an edge half a
  * spacing past that sample. */
constexpr double kBridgeSpacings = 6.0;
/** \brief Robust reweighting rounds of the implicit surface (RIMLS, Oeztireli et al. 2009):
  * samples across a crease, whose plane disagrees with the local surface, lose their weight. */
constexpr int kRobustRounds = 3;
/** \brief Faces among the nearest samples: a box corner has three. */
constexpr int kMaxFaces = 3;
/** \brief A sample belongs to a face when its normal is within 45 degrees of the face's first
  * sample's (noisy normals of one flat face stay well within it). */
constexpr double kSameFaceCosine = 0.7071;
/** \brief Two faces are concave (an inner corner, a gap) only when each lies in front of the
  * other by more than this many noise deviations in sum; otherwise convex (a slab, a sheet). */
constexpr double kConcaveNoiseSigmas = 6.0;
/** \brief A face other than the nearest sample's needs this many samples to count: a single
  * stray normal must not turn a point inside out. */
constexpr int kMinFaceSamples = 2;
/** \brief ... or one among the nearest, corroborated by another sample of the pool within this
  * many gaps of the point, on that sample's plane (within the sheet's thickness) with a normal
  * along it. Beside a convex edge the nearest samples can hold one sample of the face the point
  * stands in front of and many of the side face, behind whose plane it lies: without the second
  * face it read inside (a cube held 3 sigma_eff above a slab, its true normals given, read
  * P = 0.48 at 2.5 mm noise, scripts/probe-face-contact.py's geometry). */
constexpr double kCorroborationGaps = 3.0;
/** \brief Behind the local plane by more than this many of its deviations, a point is inside
  * only if the winding number agrees. */
constexpr double kDeepSigmas = 2.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();
/** \brief A deep point is behind an open surface (a scan, a sheet) when its winding number
  * exceeds this: about 1/2 behind an open sheet (space behind a sheet is occupied), 0 beside or
  * in front of it. Behind a closed surface (closedSurface) it is inside above kInsideWinding:
  * with 1/4 there too, points in front of a thin wall of the sparse room whose near face was
  * missing locally read 100 mm deep. */
constexpr double kBehindWinding = 0.25;
/** \brief A surface is closed when its area-weighted normals sum to less than this share of
  * its area. */
constexpr double kClosedFlux = 0.15;
/** \brief Two points of one object are taken as joined by its surface (for the crossing test)
  * up to this many of their sample spacings apart: a gap narrower than two spacings is below the
  * sampling's resolution. */
constexpr double kCrossingSpacings = 3.0;
/** \brief ... when their normals agree (kSameFaceCosine) and the segment between them lies
  * within 45 degrees of the tangent plane at both ends (|n . u| below this): the two faces of a
  * slab, a fork's facing prongs or the two sides of a corner are not one sheet. */
constexpr double kCrossingTangentCosine = 0.7071;
/** \brief A crossing's end is extended along the query's surface (farthestJoined) to a joined
  * point in front of the same face: its own distance within this many of its deviations of its
  * offset from the end's face plane (not another face with the same normal). */
constexpr double kCrossingPlaneSigmas = 2.0;
/** \brief ... only where the sheet's samples resolve its edges: their noise deviation, times
  * this, under their spacing. Otherwise the test that the sheet reaches the crossing (surrounded)
  * is blurred by the noise, and a crossing made certain by far points of a large query surface
  * reads P = 1 for a free pose (at 1 % noise, the room's surface beside a thin part of the piano
  * 12 mm clear of it: the part looked as reaching through, the room's points 100 mm either side
  * made the pair sure). */
constexpr double kCrossingResolvedSigmas = 3.0;
/** \brief A crossing's two faces are a slab's (parallel, their planes meeting far away) when
  * their normals are within 20 degrees of opposite; further apart they are a wedge (a box's
  * corner seen edge on, a tapered part), whose planes meet near the pair: the pair may pass
  * beyond the wedge's tip. */
constexpr double kSlabFacesCosine = 0.94;
/** \brief ... and by more than this many of their normals' combined spreads
  * (Evaluation::normal_spread): less is within the noise of a slab. */
constexpr double kWedgeNormalSpreads = 2.0;
/** \brief A winding number above this is inside (about 1 inside a closed surface, 0 outside). */
constexpr double kInsideWinding = 0.5;

/** \brief One sample of the other surface, in A's local frame. */
struct Sample
{
  Eigen::Vector3d position;
  Eigen::Vector3d normal;
  double spacing;
  double variance;  ///< the sample's variance along its own normal
  /** \brief The gap over which the surface may run unsampled here: the larger of the sample's
    * spacing and its surface's (SurfaceModel::surfaceSpacing). A sample in a cluster (a
    * triangle soup's repeated vertex, a scan's dense patch) has a spacing far below the gaps of
    * the surface around it; an empty disc no wider than those gaps says nothing about an edge. */
  double gap;
  /** \brief SurfaceModel::openings, the bisector in A's frame (zero: an inner sample). */
  Eigen::Vector3d open = Eigen::Vector3d::Zero ();
  double open_cos = 1.0;
};

/** \brief How far off a sample's plane another sample still lies on the same sheet: half its
  * spacing and 3 noise deviations. */
double
sheetThickness (const Sample& s)
{
  return 0.5 * std::max (s.spacing, 1e-12) + 3.0 * std::sqrt (std::max (s.variance, 0.0));
}

/** \brief The samples of the surface leaves paired with one query leaf, ordered by their
  * distance from the leaf's centre (the key), so that a search about a point x can stop early:
  * |p - x| >= |key(p) - key(x)|. Sorted lazily, as far as the searches have asked: a prefix in
  * (key, sample) order holding every entry whose key is at most the largest limit asked of
  * sortThrough() so far. Where the noise is wide
  * against the spacing (leaf boxes grown by 3 deviations) a pool holds thousands of samples
  * while a point's search ends within a few spacings: sorting every pool whole took a third of
  * the query of a scan against itself. The prefix is always the whole sort's, so every search
  * visits the samples in the same order as over a sorted pool. */
class SortedPool
{
public:
  void
  clear ()
  {
    entries_.clear ();
    sorted_ = 0;
    limit_ = -std::numeric_limits<double>::infinity ();
  }
  void
  add (double key, int sample)
  {
    entries_.emplace_back (key, sample);
  }
  bool
  empty () const
  {
    return entries_.empty ();
  }
  /** \brief The sorted prefix's length: entries [0, sorted()) are in order. */
  std::size_t
  sorted () const
  {
    return sorted_;
  }
  double
  key (std::size_t k) const
  {
    return entries_[k].first;
  }
  int
  sample (std::size_t k) const
  {
    return entries_[k].second;
  }
  /** \brief Sorts every entry with key <= limit into the prefix. */
  void
  sortThrough (double limit)
  {
    if (limit <= limit_ || sorted_ == entries_.size ())
      return;
    const auto rest = entries_.begin () + static_cast<std::ptrdiff_t> (sorted_);
    const auto end = std::partition (rest, entries_.end (), [limit] (const std::pair<double, int>& e) { return e.first <= limit; });
    std::sort (rest, end);
    sorted_ = static_cast<std::size_t> (end - entries_.begin ());
    limit_ = limit;
  }
  /** \brief Sorts at least one more entry into the prefix (unless all are), the limit at
    * least doubled, so that a search that needs many costs a few partitions. */
  void
  grow ()
  {
    if (sorted_ == entries_.size ())
      return;
    double smallest = std::numeric_limits<double>::infinity ();
    for (std::size_t k = sorted_; k < entries_.size (); ++k)
      smallest = std::min (smallest, entries_[k].first);
    sortThrough (std::max (smallest, 2.0 * std::max (limit_, 0.0)));
  }
  /** \brief The prefix's entries with keys in [low, high]: [begin, end) indices. */
  std::pair<std::size_t, std::size_t>
  window (double low, double high)
  {
    sortThrough (high);
    const auto first = entries_.begin ();
    const auto last = first + static_cast<std::ptrdiff_t> (sorted_);
    auto begin = std::lower_bound (first, last, low, [] (const std::pair<double, int>& e, double v) { return e.first < v; });
    auto end = std::upper_bound (begin, last, high, [] (double v, const std::pair<double, int>& e) { return v < e.first; });
    return {static_cast<std::size_t> (begin - first), static_cast<std::size_t> (end - first)};
  }

private:
  std::vector<std::pair<double, int>> entries_;
  std::size_t sorted_ = 0;
  double limit_ = -std::numeric_limits<double>::infinity ();
};

/** \brief Per-thread buffers: a query allocates nothing once they have grown. */
struct Scratch
{
  std::vector<std::uint32_t> pooled, cached;  ///< stamps per point of the surface's model
  std::vector<Sample> cache;                  ///< the surface's samples mapped into A's frame
  SortedPool pool;
  std::vector<int> wide;              ///< one leaf's samples within the bridging reach (farRimAnywhere)
  std::vector<std::int32_t> stack;    ///< its hierarchy walk
  std::uint32_t stamp = 0;
  /** \brief The side's surface is two-sided: its orientation does not say where its inside is (SurfaceModel::insideKnown). */
  bool two_sided = false;
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs, grouped;
  std::vector<std::size_t> group_start;  ///< groupByFirst's counts, then offsets
  /** \brief The capped enumeration's (enumerateUpToCap): A's parents and leaves, and the batch marked. */
  std::vector<std::int32_t> parent, leaves;
  std::vector<char> marked;
  /** \brief The current query leaf's points found outside the other surface, for crossings. */
  struct Outside
  {
    int index;
    Eigen::Vector3d x, normal, own_normal;  ///< the other's face normal; the point's own normal
    double distance, sigma, spacing;
    double normal_spread;  ///< Evaluation::normal_spread of the other's face
  };
  std::vector<Outside> outside;
  /** \brief The points found outside in the side's earlier leaves, and per leaf their range in
    * it, bounding sphere and largest spacing: partners for crossings across leaves. */
  std::vector<Outside> earlier;
  struct OutsideLeaf
  {
    Eigen::Vector3d center = Eigen::Vector3d::Zero ();
    double radius = 0.0, spacing = 0.0;
    std::size_t begin = 0, end = 0;
  };
  std::vector<OutsideLeaf> earlier_leaves;
  /** \brief farthestJoined's candidates for a point, kept for one crossings() call (outside
    * and earlier do not change within it): the points joined to it that face the same way and
    * lie in front of its face. They depend on the point alone, not on the sheet's thickness, and
    * one point ends many pairs. Per point slot (its index in outside, then in earlier after
    * those): seen_stamp holds the call's stamp once the point was asked (a plain scan, nothing
    * kept), joined_stamp once its candidates are kept, at [joined_begin, joined_end). */
  struct Joined
  {
    const Outside* point;
    double offset;  ///< from the asking point's face plane
  };
  std::vector<Joined> joined;
  std::vector<std::uint32_t> seen_stamp, joined_stamp;
  std::vector<std::size_t> joined_begin, joined_end;
  std::uint32_t joined_call = 0;

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
  double nearest = 0.0;  ///< distance to the nearest sample
  double spacing = 0.0;  ///< that sample's spacing
  /** \brief The surface spans a hole in the samples here (far rim found beyond a spacing). */
  bool bridged = false;
  int first = -1;          ///< the nearest sample (index into the samples)
  double tangential = 0.0; ///< x's distance from it across its normal
  /** \brief How far the chosen face's sample normals scatter (radians, about their RMS angle
    * from its normal): its normal is no surer than that. */
  double normal_spread = 0.0;
  bool past_edge = false;  ///< past the surface's edge: normal is the direction from the last sample
  /** \brief The face's plane alone (with the discretisation term): what a point clearly behind
    * it is judged by (with the winding number), where distance and sigma may also weigh in the
    * surface's ending at an edge (evaluate). */
  double plane_distance = 0.0, plane_sigma = 0.0;
  /** \brief Read as beside an edge (the mixture in evaluate), on the paired leaves' samples. */
  bool beside_edge = false;
};

/** \brief The quarter of the plane (spanned by unit u and w) that v points into, as a bit:
  * about +u 1, -u 2, +w 4, -w 8. Samples in all four quarters (15) surround a point. */
int
quarterBit (const Eigen::Vector3d& v, const Eigen::Vector3d& u, const Eigen::Vector3d& w)
{
  const double cu = v.dot (u), cw = v.dot (w);
  return std::abs (cu) >= std::abs (cw) ? (cu > 0.0 ? 1 : 2) : (cw > 0.0 ? 4 : 8);
}

/** \brief Candidate samples for a search about a point: any (radius, test) is true when `test`
  * holds for a candidate; those within `radius` of the point are among the candidates. The
  * pool's, about a point at x_key from the query leaf's centre: only keys within radius of it. */
auto
inPool (SortedPool& pool, double x_key)
{
  return [&pool, x_key] (double radius, const auto& test) {
    const auto range = pool.window (x_key - radius, x_key + radius);
    for (std::size_t k = range.first; k < range.second; ++k)
      if (test (pool.sample (k)))
        return true;
    return false;
  };
}

/** \brief ... every sample of a list. */
auto
inList (const std::vector<int>& list)
{
  return [&list] (double, const auto& test) {
    for (const int j : list)
      if (test (j))
        return true;
    return false;
  };
}

/** \brief True when samples of the surface lie beyond x, seen from its nearest sample `first`
  * (offset along its normal `along`, `tangential` across it, > 0): in its plane (within half its
  * spacing and the noise), farther along the same direction (within 60 degrees), on the same
  * face, within `reach` of its gaps. x then lies over a hole, not past an edge. */
template <typename Candidates>
bool
farRim (const Eigen::Vector3d& x, const Sample& first, double along, double tangential, double reach,
        const Candidates& candidates, const std::vector<Sample>& samples)
{
  const Eigen::Vector3d offset = x - first.position;
  const Eigen::Vector3d u = (offset - along * first.normal) / tangential;
  const double reach2 = (reach * first.gap) * (reach * first.gap);
  const double thickness = sheetThickness (first);
  return candidates (reach * first.gap, [&] (int j) {
    const Sample& s = samples[static_cast<std::size_t> (j)];
    const Eigen::Vector3d v = s.position - x;
    const double height = first.normal.dot (v);
    // Across the gap: within 60 degrees of u in the plane (a sample off to the side, beside an
    // edge, is not a far rim), on the same face (not the far face of a thin sheet).
    return s.normal.dot (first.normal) > kSameFaceCosine &&
           v.dot (u) > 0.5 * std::sqrt (std::max (0.0, v.squaredNorm () - height * height)) &&
           std::abs (height + along) < thickness && v.squaredNorm () < reach2;
  });
}

/** \brief True when samples of the sheet `first` lies on (x's nearest sample, with normal n)
  * surround x within `reach` of its spacings: in each quarter of the plane around x (about
  * the directions +-u and +-n x u, u = across from first to x), one at least, within the sheet's
  * thickness of first's plane (half a spacing and 3 noise deviations). x then lies inside the
  * sheet, not at or past its edge. The samples' own normals are not asked: where the noise is
  * about the spacing (the evaluation's piano at 0.5 %), a plane fit's normals scatter by 30-90
  * degrees, and a test within 45 degrees of first's dropped half of the samples around a
  * crossing, which then read as passing beside the sheet's edge. */
template <typename Candidates>
bool
surrounded (const Eigen::Vector3d& x, const Sample& first, double reach, const Candidates& candidates,
            const std::vector<Sample>& samples)
{
  const double h = std::max (first.spacing, 1e-12);
  const Eigen::Vector3d& n = first.normal;
  const Eigen::Vector3d offset = x - first.position;
  Eigen::Vector3d u = offset - n.dot (offset) * n;
  u = u.norm () > 1e-9 * h ? Eigen::Vector3d (u.normalized ()) : n.unitOrthogonal ();
  const Eigen::Vector3d w = n.cross (u);
  const double reach2 = (reach * h) * (reach * h);
  const double thickness = sheetThickness (first);
  const double along = n.dot (offset);
  int quarters = 0;
  return candidates (reach * h, [&] (int j) {
    const Sample& s = samples[static_cast<std::size_t> (j)];
    const Eigen::Vector3d v = s.position - x;
    if (v.squaredNorm () >= reach2 || std::abs (n.dot (v) + along) >= thickness)
      return false;
    quarters |= quarterBit (v, u, w);
    return quarters == 15;
  });
}

/** \brief x against the pool: implicit surface f(x) = sum w_j n_j . (x - p_j) / sum w_j of the
  * nearest samples (Kolluri's IMLS), with robust weights; variance from the query point's own
  * covariance along the normal (variance_of), the fit's error and the discretisation. */
template <typename VarianceOf>
bool
evaluate (const Eigen::Vector3d& x, SortedPool& pool, double x_key, const std::vector<Sample>& samples,
          const VarianceOf& variance_of, bool two_sided, Evaluation& out)
{
  std::array<int, kSurfaceNeighbours> nearest;
  std::array<double, kSurfaceNeighbours> d2;
  int found = 0;
  for (std::size_t k = 0;; ++k)
  {
    if (k == pool.sorted ())
    {
      // Sort on as far as the 8th nearest so far reaches (a hair farther, so that no entry
      // left out could pass the test below), or further while fewer are found.
      if (found == kSurfaceNeighbours)
        pool.sortThrough (x_key + std::sqrt (d2[kSurfaceNeighbours - 1]) * (1.0 + 1e-9) + 1e-300);
      else
        pool.grow ();
      if (k == pool.sorted ())
        break;
    }
    // |p - x| >= key(p) - key(x): past this, no sample is nearer than the current 8th.
    const double bound = pool.key (k) - x_key;
    if (found == kSurfaceNeighbours && bound > 0.0 && bound * bound >= d2[kSurfaceNeighbours - 1])
      break;
    const int j = pool.sample (k);
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
  const double g = std::max (first.gap, h);
  // Tangential distance to the nearest sample: how far the surface is extrapolated.
  const Eigen::Vector3d offset = x - first.position;
  out.nearest = std::sqrt (d2[0]);
  out.spacing = h;
  const double along = first.normal.dot (offset);
  const double tangential = std::sqrt (std::max (0.0, offset.squaredNorm () - along * along));
  // More than a gap along the surface from its nearest sample, the surface either spans a hole
  // (samples of the far rim lie beyond x, in the plane, within the bridging reach) or has ended
  // at an edge (every sample lies behind x). Only a hole is bridged. The gap, not the nearest
  // sample's own spacing: a cluster's spacing is not the surface's.
  out.first = nearest[0];
  out.tangential = tangential;
  const bool past_edge =
    tangential > kBridgeSpacings * g || (tangential > g && !farRim (x, first, along, tangential, kBridgeSpacings, inPool (pool, x_key), samples));
  out.bridged = !past_edge && tangential > g;
  if (past_edge)
  {
    // Past the surface's edge: outside. The edge lies anywhere within a spacing beyond the last
    // sample: half a spacing on average, uncertain by 0.29 spacing.
    const double beyond = std::max (0.0, tangential - 0.5 * h);
    out.distance = std::sqrt (beyond * beyond + along * along);
    out.normal = offset / std::max (offset.norm (), 1e-300);
    out.sigma = std::sqrt (variance_of (out.normal) + first.variance) + kDiscretisationPerDistance * h;
    // The direction from a sample as uncertain as sigma: within sigma / distance of its own.
    out.normal_spread = std::atan2 (out.sigma, out.distance);
    out.past_edge = true;
    out.plane_distance = out.distance;
    out.plane_sigma = out.sigma;
    return true;
  }
  // The samples split into faces by their normals (up to kMaxFaces: the faces of a box's edge
  // or corner, the two faces of a thin slab); each face is its own implicit plane.
  std::array<double, kSurfaceNeighbours> base, r;
  std::array<int, kSurfaceNeighbours> face;
  std::array<Eigen::Vector3d, kMaxFaces> face_seed;
  std::array<int, kMaxFaces> face_size{};
  std::array<int, kMaxFaces> face_first{};  ///< each face's nearest sample, an index into nearest
  int faces = 0;
  for (int j = 0; j < found; ++j)
  {
    const std::size_t sj = static_cast<std::size_t> (j);
    const Sample& s = samples[static_cast<std::size_t> (nearest[sj])];
    base[sj] = std::exp (-(d2[sj] - d2[0]) / (h * h));
    r[sj] = s.normal.dot (x - s.position);
    int best = -1;
    double best_cos = -2.0;
    for (int c = 0; c < faces; ++c)
    {
      const double cosine = s.normal.dot (face_seed[static_cast<std::size_t> (c)]);
      if (cosine > best_cos)
      {
        best_cos = cosine;
        best = c;
      }
    }
    if ((best < 0 || best_cos < kSameFaceCosine) && faces < kMaxFaces)
    {
      best = faces++;
      face_seed[static_cast<std::size_t> (best)] = s.normal;
      face_first[static_cast<std::size_t> (best)] = j;
    }
    face[sj] = best;
    ++face_size[static_cast<std::size_t> (best)];
  }
  // Residual scale of the robust weights: the sheet's thickness (half a spacing plus the
  // samples' noise).
  const double scale = sheetThickness (first);
  struct Fit
  {
    double f = 0.0, fit_var = 0.0, weight = 0.0, spread = 0.0;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero (), center = Eigen::Vector3d::Zero ();
  };
  auto fit = [&] (int c) {
    std::array<double, kSurfaceNeighbours> w;
    for (int j = 0; j < found; ++j)
      w[static_cast<std::size_t> (j)] = face[static_cast<std::size_t> (j)] == c ? base[static_cast<std::size_t> (j)] : 0.0;
    Fit out;
    for (int round = 0; round < kRobustRounds; ++round)
    {
      double num = 0.0, den = 0.0;
      for (int j = 0; j < found; ++j)
      {
        num += w[static_cast<std::size_t> (j)] * r[static_cast<std::size_t> (j)];
        den += w[static_cast<std::size_t> (j)];
      }
      out.f = num / std::max (den, 1e-300);
      bool first_of_face = true;
      for (int j = 0; j < found; ++j)
        if (face[static_cast<std::size_t> (j)] == c)
        {
          const double e = (r[static_cast<std::size_t> (j)] - out.f) / scale;
          // The face's nearest sample always counts.
          w[static_cast<std::size_t> (j)] =
            std::max (base[static_cast<std::size_t> (j)] * std::exp (-e * e), first_of_face ? 1e-12 : 0.0);
          first_of_face = false;
        }
    }
    for (int j = 0; j < found; ++j)
    {
      const Sample& s = samples[static_cast<std::size_t> (nearest[static_cast<std::size_t> (j)])];
      const double wj = w[static_cast<std::size_t> (j)];
      out.weight += wj;
      out.fit_var += wj * wj * s.variance;
      out.normal += wj * s.normal;
      out.center += wj * s.position;
    }
    out.fit_var /= out.weight * out.weight;
    out.center /= out.weight;
    const double norm = out.normal.norm ();
    // Mean resultant length R of the weighted unit normals: RMS angle about sqrt(2 (1 - R)).
    out.spread = std::sqrt (2.0 * std::max (0.0, 1.0 - norm / std::max (out.weight, 1e-300)));
    out.normal = norm > 0.0 ? Eigen::Vector3d (out.normal / norm) : first.normal;
    return out;
  };
  // The nearest sample's face, then each other face of enough samples: at a convex edge (each
  // face behind the other's plane; also the two faces of a slab) inside means behind both, the
  // larger distance; at a concave one (each in front of the other: an inner corner, a gap
  // between two solids) behind either, the smaller.
  // A face's lone sample among the nearest, and another sample of the pool on its plane within
  // kCorroborationGaps of x (kMinFaceSamples).
  auto corroborated = [&] (int c) {
    const int lone = nearest[static_cast<std::size_t> (face_first[static_cast<std::size_t> (c)])];
    const Sample& s = samples[static_cast<std::size_t> (lone)];
    const double thickness = sheetThickness (s);
    const double reach = kCorroborationGaps * g;
    const double reach2 = reach * reach;
    return inPool (pool, x_key) (reach, [&] (int j) {
      const Sample& o = samples[static_cast<std::size_t> (j)];
      return j != lone && o.normal.dot (s.normal) >= kSameFaceCosine && std::abs (s.normal.dot (o.position - s.position)) < thickness &&
             (o.position - x).squaredNorm () < reach2;
    });
  };
  const Fit nearest_face = fit (0);
  Fit chosen = nearest_face;
  for (int c = 1; c < faces; ++c)
  {
    if (face_size[static_cast<std::size_t> (c)] < kMinFaceSamples && !corroborated (c))
      continue;
    Fit other = fit (c);
    if (two_sided)
    {
      // A face's plane holds only about its samples: past the face's nearest sample by more
      // than a gap across it, x is at least that far beyond the face's end (on a 2 mm plate
      // with 1 mm noise, three scattered normals made a face whose plane, extended 19 mm past
      // them, put a point 6 sigma clear on the surface). Only for a two-sided surface, whose
      // faces' signs say nothing.
      const Sample& p = samples[static_cast<std::size_t> (nearest[static_cast<std::size_t> (face_first[static_cast<std::size_t> (c)])])];
      const double across = std::sqrt (std::max (0.0, (x - p.position).squaredNorm () - other.f * other.f));
      const double beyond = std::max (0.0, across - std::max (p.gap, p.spacing));
      other.f = std::copysign (std::hypot (other.f, beyond), other.f);
    }
    const double facing = nearest_face.normal.dot (other.center - nearest_face.center) +
                          other.normal.dot (nearest_face.center - other.center);
    // Noise blurs the two faces of a slab as thin as it into one sheet whose faces' order is
    // random: only a clear lead is concave (a sheet has no inside, the larger distance).
    const bool concave = facing > kConcaveNoiseSigmas * std::sqrt (std::max (first.variance, 0.0));
    if (concave == (other.f < chosen.f))
      chosen = other;
  }
  // A two-sided surface (an orientation that is not trusted) has no inside: x is as far from it
  // behind as in front, and faces it from its own side (crossings then find a part through it).
  if (two_sided && chosen.f < 0.0)
  {
    chosen.f = -chosen.f;
    chosen.normal = -chosen.normal;
  }
  // Where the surface runs between samples is uncertain within one gap of the last one (an
  // edge may lie there); a bridged hole continues the fitted plane. Inside a face, its
  // samples among the nearest on all four sides of x (quarters about u = across from the
  // nearest sample to x, and n x u), no edge lies between them: the plane holds there.
  bool inside_face = false;
  if (tangential > 0.0)
  {
    const Eigen::Vector3d u = (offset - along * first.normal) / tangential;
    const Eigen::Vector3d w = first.normal.cross (u);
    int quarters = 0;
    for (int j = 0; j < found; ++j)
    {
      if (face[static_cast<std::size_t> (j)] != 0)
        continue;
      quarters |= quarterBit (samples[static_cast<std::size_t> (nearest[static_cast<std::size_t> (j)])].position - x, u, w);
    }
    inside_face = quarters == 15;
  }
  const double disc = inside_face ? 0.0 : kDiscretisationPerDistance * std::min (tangential, g);
  out.distance = chosen.f;
  out.normal = chosen.normal;
  out.normal_spread = chosen.spread;
  const double own_var = variance_of (out.normal);
  out.sigma = std::sqrt (own_var + chosen.fit_var + disc * disc);
  out.plane_distance = out.distance;
  out.plane_sigma = out.sigma;
  // At the surface's edge (the nearest sample's neighbours leave the surface open toward x within
  // their reach, SurfaceModel::openings, and no sample of the face lies beyond x: farRim here
  // on the pool, then testSide on the whole surface) the face may end anywhere within a gap past
  // the last sample, uniformly: it reaches x's foot with chance w = 1 - t / g. Otherwise x is
  // beside the edge, as past it (above). P is the mixture's; its deviation the mixture's, and
  // the distance the one that gives P with it. The plane with a symmetric discretisation term
  // read points beside a furniture edge 20-35 mm clear as on the extended face (d about 0, P
  // about 0.5): the one place the truth cannot be farther than.
  const double open_reach = first.open.norm ();
  const bool toward_open = tangential > 0.0 && open_reach > 0.0 && tangential <= open_reach &&
                           first.open.dot (offset - along * first.normal) > first.open_cos * tangential * open_reach;
  if (!inside_face && toward_open && !farRim (x, first, along, tangential, kBridgeSpacings, inPool (pool, x_key), samples))
  {
    const double sigma_plane = std::sqrt (own_var + chosen.fit_var);
    const double p_plane = normalCdf (-chosen.f / std::max (sigma_plane, 1e-300));
    const double beyond = std::max (0.0, tangential - 0.5 * h);
    const double d_edge = std::sqrt (beyond * beyond + along * along);
    const Eigen::Vector3d direction = offset / std::max (offset.norm (), 1e-300);
    const double sigma_edge = std::sqrt (variance_of (direction) + first.variance) + kDiscretisationPerDistance * h;
    const double p_edge = normalCdf (-d_edge / std::max (sigma_edge, 1e-300));
    const double w = std::max (0.0, 1.0 - tangential / g);
    const double p = std::min (std::max (w * p_plane + (1.0 - w) * p_edge, 1e-15), 1.0 - 1e-15);
    const double mean = w * chosen.f + (1.0 - w) * d_edge;
    const double second = w * (sigma_plane * sigma_plane + chosen.f * chosen.f) +
                          (1.0 - w) * (sigma_edge * sigma_edge + d_edge * d_edge);
    out.sigma = std::sqrt (std::max (second - mean * mean, 1e-300));
    out.distance = out.sigma * normalQuantile (1.0 - p);
    out.beside_edge = true;
  }
  return true;
}

/** \brief Whether p and q (v = q - p, length = |v|) are joined by their object's own surface,
  * as the crossing test takes it: within kCrossingSpacings of their spacings, their own normals
  * within kSameFaceCosine, and the segment along the surface at both ends (kCrossingTangentCosine). */
bool
joinedBySurface (const Scratch::Outside& p, const Scratch::Outside& q, const Eigen::Vector3d& v, double length)
{
  return length > 0.0 && length <= kCrossingSpacings * std::max (p.spacing, q.spacing) &&
         p.own_normal.dot (q.own_normal) >= kSameFaceCosine &&
         std::abs (p.own_normal.dot (v)) <= kCrossingTangentCosine * length &&
         std::abs (q.own_normal.dot (v)) <= kCrossingTangentCosine * length;
}

/** \brief Of the points found outside (this leaf's and the side's earlier leaves' within
  * reach), the one farthest in front of p's face plane in its own deviations ((offset + t) /
  * sigma, t the sheet's thickness), among p and the points joined to p (joinedBySurface) that
  * face the same way (normals within kSameFaceCosine) and lie in front of that same face: their
  * own distance within kCrossingPlaneSigmas of their offset from p's face plane (not another
  * face with the same normal). Returns that point and its offset. A point asked again within
  * one crossings() call reads its candidates back (Scratch::joined): only the choice among them
  * depends on t. */
std::pair<const Scratch::Outside*, double>
farthestJoined (Scratch& scratch, const Scratch::Outside& p, double t)
{
  const Scratch::Outside* const begin = scratch.outside.data ();
  const std::size_t slot = std::less_equal<const Scratch::Outside*> () (begin, &p) &&
                                   std::less<const Scratch::Outside*> () (&p, begin + scratch.outside.size ())
                               ? static_cast<std::size_t> (&p - begin)
                               : scratch.outside.size () + static_cast<std::size_t> (&p - scratch.earlier.data ());
  // Calls f (q, offset) for every joined point q in front of p's face, in a fixed order.
  auto forEachJoined = [&] (auto&& f) {
    auto consider = [&] (const Scratch::Outside& q) {
      if (&q == &p)
        return;
      const Eigen::Vector3d v = q.x - p.x;
      const double offset = p.distance + p.normal.dot (v);
      if (f.skip (q, offset) || q.normal.dot (p.normal) < kSameFaceCosine ||
          std::abs (q.distance - offset) > kCrossingPlaneSigmas * q.sigma || !joinedBySurface (p, q, v, v.norm ()))
        return;
      f.take (q, offset);
    };
    for (const Scratch::Outside& q : scratch.outside)
      consider (q);
    for (const Scratch::OutsideLeaf& leaf : scratch.earlier_leaves)
    {
      if ((leaf.center - p.x).norm () > leaf.radius + kCrossingSpacings * std::max (leaf.spacing, p.spacing))
        continue;
      for (std::size_t k = leaf.begin; k < leaf.end; ++k)
        consider (scratch.earlier[k]);
    }
  };
  const Scratch::Outside* best = &p;
  double best_offset = p.distance;
  double best_score = (p.distance + t) / p.sigma;
  // The largest score wins, the first of equals.
  struct Choose
  {
    const Scratch::Outside*& best;
    double &best_offset, &best_score, t;
    bool skip (const Scratch::Outside& q, double offset) const { return (offset + t) / q.sigma <= best_score; }
    void take (const Scratch::Outside& q, double offset) { best = &q; best_offset = offset; best_score = (offset + t) / q.sigma; }
  };
  Choose choose {best, best_offset, best_score, t};
  if (scratch.seen_stamp[slot] != scratch.joined_call)
  {
    // First asked in this call: one scan that skips every point no farther than the best so far.
    scratch.seen_stamp[slot] = scratch.joined_call;
    forEachJoined (choose);
    return {best, best_offset};
  }
  if (scratch.joined_stamp[slot] != scratch.joined_call)
  {
    // Asked again: every candidate kept, whatever t.
    struct Keep
    {
      std::vector<Scratch::Joined>& joined;
      bool skip (const Scratch::Outside&, double) const { return false; }
      void take (const Scratch::Outside& q, double offset) { joined.push_back ({&q, offset}); }
    };
    scratch.joined_stamp[slot] = scratch.joined_call;
    scratch.joined_begin[slot] = scratch.joined.size ();
    Keep keep {scratch.joined};
    forEachJoined (keep);
    scratch.joined_end[slot] = scratch.joined.size ();
  }
  for (std::size_t k = scratch.joined_begin[slot]; k < scratch.joined_end[slot]; ++k)
  {
    const Scratch::Joined& j = scratch.joined[k];
    if (!choose.skip (*j.point, j.offset))
      choose.take (*j.point, j.offset);
  }
  return {best, best_offset};
}

/** \brief A crossing's first test (the pair's faces opposite), made by crossPair's callers
  * before the call: most pairs of points found outside face the same way, and the call itself
  * (a large frame) cost more than the test (15 % of pcd_collision's samples, build included, on
  * seed 2's dumped W1 scans at 0.5 %; docs/PERFORMANCE.md). */
inline bool
mayCross (const Scratch::Outside& a, const Scratch::Outside& b)
{
  return &a != &b && a.normal.dot (b.normal) <= -kSameFaceCosine;
}

/** \brief A crossing: two points of the query outside the other surface, joined by their own
  * surface (kCrossingSpacings, kCrossingTangentCosine), in front of the two opposite faces of one
  * sheet of it (face normals more than 135 degrees apart, the second point behind the first's
  * face plane): a wall about as thin as the noise, crossed, where no sample need lie deep inside
  * anything. The pair misses the sheet only if both lie in front of the first face, or both
  * beyond the second:
  * P_free = Phi(d_a / s_a) Phi(g_b / s_b) + Phi(-(d_a + t) / s_a) Phi(d_b / s_b), g_b the second's
  * offset from the first's face plane (negative), t = max(0, -g_b - d_b) the sheet's thickness.
  * The pair may pass beside the sheet: past its edge (unless samples of that face surround the
  * point where the pair meets its plane), beyond a wedge's tip, or in front of a third face. P
  * is scaled by the chance of each. The distance is z sigma (z the crossing's Phi^-1, sigma the
  * larger of the pair's deviations), at most the depth a crossing implies: the sheet's thickness
  * and the smaller of the two clearances; there the deviation is at least half that bound. */
void
crossPair (Scratch& scratch, const Scratch::Outside& a, const Scratch::Outside& b, const Eigen::Vector3d& center,
           int side, std::vector<float>* per_point, SurfaceAnswer& answer, double& best_z)
{
  // The callers have tested mayCross (a, b).
  const Eigen::Vector3d v = b.x - a.x;
  const double length = v.norm ();
  const double g = a.distance + a.normal.dot (v);  // b's offset from a's face plane
  // One sheet of the query, b behind a's face plane.
  if (g >= 0.0 || !joinedBySurface (a, b, v, length))
    return;
  const double t = std::max (0.0, -g - b.distance);
  // The pair alone, and (where the sheet's samples resolve its edges, below) the pair's ends
  // extended along the query's surface: a point joined to a that lies farther in front of a's
  // face (or to b, beyond the sheet) makes a crossing surer and deeper than the pair alone
  // shows (a part pushed 50 mm through a 10 mm wall reads as a crossing by the pairs nearest
  // the wall, each alone a few deviations from either face). The step only lowers P_free, and
  // its search is made only where it can change the answer.
  double free = normalCdf (a.distance / a.sigma) * normalCdf (g / b.sigma) +
                normalCdf (-(a.distance + t) / a.sigma) * normalCdf (b.distance / b.sigma);
  const Scratch::Outside* a_end = &a;
  const Scratch::Outside* b_end = &b;
  double a_reach = a.distance;
  double b_reach = b.distance;
  double stepped_free = -1.0;  // not yet searched
  auto step = [&] () {
    if (stepped_free >= 0.0)
      return;
    std::tie (a_end, a_reach) = farthestJoined (scratch, a, t);
    std::tie (b_end, b_reach) = farthestJoined (scratch, b, t);
    const double in_front = std::min (normalCdf (g / b.sigma), normalCdf (-(b_reach + t) / b_end->sigma));
    const double beyond = std::min (normalCdf (-(a.distance + t) / a.sigma), normalCdf (-(a_reach + t) / a_end->sigma));
    stepped_free = normalCdf (a.distance / a.sigma) * in_front + beyond * normalCdf (b.distance / b.sigma);
  };
  auto zOf = [] (double p_free) { return normalQuantile (std::clamp (p_free, 1e-300, 1.0 - 1e-16)); };
  // A wedge rather than a slab: the region behind both face planes ends at the line where
  // they meet, and the pair's segment may pass beyond it. Along the segment its offsets
  // from the two planes vary linearly; where they are equal it lies deepest behind both,
  // by `depth` (negative: beyond the tip). That depth, against the deviation the pair's
  // points give it there, says how likely the segment passes through rather than beside
  // the tip. Before this term a piano's corner 3 mm clear of the room (faces 137 degrees
  // apart; the room's points 68 and 40 mm in front of each face, the tip blurred by the
  // noise so that samples surrounded it) read P = 1; its segment lies 9 mm inside.
  // Computed before the edge term's search, so that a pair it rules out costs no search.
  // Noisy normals make a slab's faces look like a wedge's: only a lead over two of their
  // combined spreads is a wedge. (At 4 % noise slabs' faces read 20-40 degrees apart with
  // spreads of 10-35 each, and the term read collisions 3-7 sigma deep as contact.)
  const double apart = std::acos (std::clamp (-a.normal.dot (b.normal), -1.0, 1.0));
  const bool wedge = apart > std::max (std::acos (kSlabFacesCosine),
                                       kWedgeNormalSpreads * std::hypot (a.normal_spread, b.normal_spread));
  double through_tip = 1.0;
  if (wedge)
  {
    const double a_offset = b.distance + b.normal.dot (a.x - b.x);  // from b's face plane
    const double slope = (g - a.distance) - (b.distance - a_offset);
    const double s = std::clamp (slope != 0.0 ? (a_offset - a.distance) / slope : 0.5, 0.0, 1.0);
    const double depth = std::min (-(a.distance + s * (g - a.distance)), -(a_offset + s * (b.distance - a_offset)));
    through_tip = normalCdf (depth / std::hypot ((1.0 - s) * a.sigma, s * b.sigma));
  }
  // The edge term below only raises P_free: a pair already no better than the best is done.
  auto withTip = [&] (double p_free) { return wedge ? 1.0 - (1.0 - p_free) * through_tip : p_free; };
  if (!per_point && zOf (withTip (free)) >= best_z)
  {
    step ();
    if (zOf (withTip (stepped_free)) >= best_z)
      return;
  }
  // Does the sheet reach where the pair meets a's face plane, or does the pair pass beside
  // or past its edge? Surrounded by samples of that face, it does. Otherwise the point may
  // lie past an edge: the edge lies anywhere within a spacing past the last sample (half a
  // spacing on average, 0.29 spacing deviation: kDiscretisationPerDistance's model), and
  // the point itself is as uncertain as the pair.
  const Eigen::Vector3d x = a.x + (a.distance / (a.distance - g)) * v;
  Evaluation at;
  const double x_key = (x - center).norm ();
  if (!evaluate (x, scratch.pool, x_key, scratch.cache, [] (const Eigen::Vector3d&) { return 0.0; }, scratch.two_sided, at))
    return;
  const Sample& first = scratch.cache[static_cast<std::size_t> (at.first)];
  // Where the noise blurs the sheet's edges, the pair's own ends (kCrossingResolvedSigmas).
  if (kCrossingResolvedSigmas * std::sqrt (std::max (first.variance, 0.0)) < first.spacing)
  {
    step ();
    free = stepped_free;
  }
  else if (!per_point && zOf (withTip (free)) >= best_z)
    return;  // only the step passed the check above
  else
  {
    a_end = &a;
    a_reach = a.distance;
    b_end = &b;
    b_reach = b.distance;
  }
  // Where evaluate found the face ended short of x (past_edge: no sample of it beyond x within
  // the bridging reach), no sample band around x says the sheet reaches it: samples of a side
  // face near the edge, within the band of a's face plane tilted by a corner's blended normal,
  // surrounded x under a gripper's fingertip, and a sparse table passing 2.5-3 mm under it read
  // as crossing the finger, P = 1 (an approach-sweep probe, 2026-12-07).
  if (at.past_edge || !surrounded (x, first, kCrossingSpacings, inPool (scratch.pool, x_key), scratch.cache))
  {
    const double h = std::max (first.spacing, 1e-12);
    const double spread = std::hypot (kDiscretisationPerDistance * h, std::max (a.sigma, b.sigma));
    free = 1.0 - (1.0 - free) * normalCdf (-(at.tangential - 0.5 * h) / spread);
  }
  if (wedge)
    free = 1.0 - (1.0 - free) * through_tip;
  // Beside the sheet: where the pair meets a's face plane, another face of the other surface
  // (neither pair's) has x in front of it, as past a box's edge. Samples of that face,
  // within the sheet's band of the plane near the edge, make x look surrounded. The sheet
  // reaches x only if x lies behind that face. (Before this term a room's wall 11 mm from a
  // piano's underside read P = 1: its points 369 mm apart straddled the piano's sides.)
  if (!at.past_edge && at.distance > 0.0 && at.normal.dot (a.normal) < kSameFaceCosine &&
      at.normal.dot (b.normal) < kSameFaceCosine)
    free = 1.0 - (1.0 - free) * normalCdf (-at.distance / std::hypot (at.sigma, std::max (a.sigma, b.sigma)));
  const double z = zOf (free);
  if (per_point)
  {
    const float p = static_cast<float> (1.0 - free);
    for (const int i : {a.index, b.index})
    {
      float& slot = (*per_point)[static_cast<std::size_t> (i)];
      if (std::isnan (slot) || p > slot)
        slot = p;
    }
  }
  if (z < best_z)
  {
    best_z = z;
    answer.reached = true;
    // In the pair's deviation, so that P = Phi(-d / sigma) holds as for a point; at most
    // the depth a crossing implies (the sheet's thickness and the smaller clearance). At that
    // bound the depth is not known: a part through a thin wall may stick out anywhere from 0
    // to it: the deviation adds half the bound to the pair's own in quadrature (independent:
    // where in the range, and where the ends really lie), so the +-2 interval reaches past 0
    // by the noise. Short of the bound, z sigma says how sure the crossing is, not how deep: the
    // same half bound, weighted by the crossing's probability. P keeps the crossing's z
    // (docs/SURFACE.md, "A crossing's depth is its bound").
    const double sigma = std::max (a_end->sigma, b_end->sigma);
    const double bound = t + std::min (a_reach, b_reach);
    const bool at_bound = z * sigma < -bound;
    answer.signed_distance = at_bound ? -bound : z * sigma;
    answer.signed_distance_std = std::hypot (sigma, 0.5 * bound * (at_bound ? 1.0 : 1.0 - free));
    answer.unobserved = false;
    answer.witness_side = side;
    answer.witness_index = a.index;
    answer.witness_point = x;
    answer.witness_normal = side > 0 ? a.normal : Eigen::Vector3d (-a.normal);
  }
}

/** \brief The crossings of one query leaf's points found outside (scratch.outside): among
  * themselves, and with the points of the side's earlier leaves within reach (a pair straddling
  * a wall as thick as a leaf is wide lies in two leaves). Then adds them to those. A pair across
  * leaves is judged against this leaf's pool of samples. */
void
crossings (Scratch& scratch, const Eigen::Vector3d& center, int side, std::vector<float>* per_point,
           SurfaceAnswer& answer, double& best_z)
{
  const auto& outside = scratch.outside;
  if (outside.empty ())
    return;
  // farthestJoined's candidates are found anew for this call's points.
  scratch.joined.clear ();
  const std::size_t slots = outside.size () + scratch.earlier.size ();
  if (scratch.joined_stamp.size () < slots)
  {
    scratch.seen_stamp.resize (slots, 0);
    scratch.joined_stamp.resize (slots, 0);
    scratch.joined_begin.resize (slots);
    scratch.joined_end.resize (slots);
  }
  if (++scratch.joined_call == 0)
  {
    std::fill (scratch.seen_stamp.begin (), scratch.seen_stamp.end (), 0);
    std::fill (scratch.joined_stamp.begin (), scratch.joined_stamp.end (), 0);
    scratch.joined_call = 1;
  }
  for (const Scratch::Outside& a : outside)
    for (const Scratch::Outside& b : outside)
      if (mayCross (a, b))
        crossPair (scratch, a, b, center, side, per_point, answer, best_z);
  // This leaf's bounding sphere and widest reach.
  Scratch::OutsideLeaf leaf;
  leaf.begin = scratch.earlier.size ();
  for (const Scratch::Outside& a : outside)
  {
    leaf.center += a.x;
    leaf.spacing = std::max (leaf.spacing, a.spacing);
  }
  leaf.center /= static_cast<double> (outside.size ());
  for (const Scratch::Outside& a : outside)
    leaf.radius = std::max (leaf.radius, (a.x - leaf.center).norm ());
  for (const Scratch::OutsideLeaf& other : scratch.earlier_leaves)
  {
    const double reach = kCrossingSpacings * std::max (leaf.spacing, other.spacing);
    if ((other.center - leaf.center).norm () > leaf.radius + other.radius + reach)
      continue;
    for (const Scratch::Outside& a : outside)
    {
      if ((a.x - other.center).norm () > other.radius + reach)
        continue;
      for (std::size_t k = other.begin; k < other.end; ++k)
        if (mayCross (a, scratch.earlier[k]))
        {
          crossPair (scratch, a, scratch.earlier[k], center, side, per_point, answer, best_z);
          crossPair (scratch, scratch.earlier[k], a, center, side, per_point, answer, best_z);
        }
    }
  }
  scratch.earlier.insert (scratch.earlier.end (), outside.begin (), outside.end ());
  leaf.end = scratch.earlier.size ();
  scratch.earlier_leaves.push_back (leaf);
}

/** \brief True when the surface's area-weighted normals cancel to within kClosedFlux of its
  * area: a closed surface (exactly 0 by the divergence theorem; the evaluation's rooms sum to
  * under 1 %, its piano, with noisy normals on thin parts, to 6 %), not an open sheet (100 % when
  * flat) or a scan's partial view. */
bool
closedSurface (const SurfaceModel& s)
{
  if (s.dipoles ().empty ())
    return false;
  const SurfaceModel::Dipole& root = s.dipoles ()[static_cast<std::size_t> (ProbabilisticBVH::rootId ())];
  return s.area () > 0.0 && root.moment.cast<double> ().norm () < kClosedFlux * s.area ();
}

/** \brief The winding number above which a point behind `s` lies in its solid, near the surface
  * as deep inside it: kBehindWinding behind a scan from one viewpoint or any open surface (the
  * space behind a sheet is occupied), kInsideWinding in a closed one. */
double
behindThreshold (const SurfaceModel& s)
{
  return s.orientation () == NormalOrientation::Viewpoint || !closedSurface (s) ? kBehindWinding : kInsideWinding;
}

/** \brief The winding number by which x (in `s`'s local frame) lies behind `s`, for
  * behindThreshold: windingNumber less SurfaceModel::viewWinding() (not 0 only for a viewpoint
  * within the cloud's box: a room seen from within, whose walls cancel behind its floor). The one
  * reading of both behind tests, near the surface (testSide) and beyond its reach (insideOf). */
double
behindWinding (const SurfaceModel& s, const ProbabilisticBVH& bvh, const Eigen::Vector3d& x)
{
  return s.windingNumber (bvh, x) - s.viewWinding ();
}

/** \brief How far x (in `surface`'s local frame) lies behind what `surface`'s viewpoint saw
  * along its line of sight (SurfaceModel::behindView), where that is more than margin and x lies
  * within the scan's bounding box or at most SurfaceModel::hiddenShell() beyond: space the
  * sensor never observed, which the scan's object may or may not fill. NaN elsewhere, and for a
  * surface not seen from one viewpoint. */
double
shadowDepth (const CloudModel& surface, const Eigen::Vector3d& x, double margin)
{
  const SurfaceModel& s = surface.surface ();
  if (!s.seenFromViewpoint ())
    return kNaN;
  double beyond = kNaN;
  const double behind = s.behindView (surface.hierarchy (), x, &beyond);
  if (!(behind > margin))
    return kNaN;
  const OrientedBox& bound = surface.hierarchy ().node (ProbabilisticBVH::rootId ()).box;
  return beyond <= s.hiddenShell () || bound.contains (x) ? behind : kNaN;
}

/** \brief The points of `query` (mapped by T_q into A's frame) against `surface` (mapped by
  * T_s), leaf by leaf: groups[i] = (query leaf, surface leaf) sorted by query leaf. Before each
  * leaf it stops at a sure point (best_z < stop_z), then at the cap (max_pairs); more_leaves says
  * that leaves not in groups follow (enumerateUpToCap stopped at the cap), so the checks run once
  * more after the last group. */
void
testSide (const CloudModel& query, const Eigen::Isometry3d& T_q, const CloudModel& surface, const Eigen::Isometry3d& T_s,
          const std::vector<std::pair<std::int32_t, std::int32_t>>& groups, Scratch& scratch, int side,
          std::vector<float>* per_point, double stop_z, std::size_t max_pairs, bool more_leaves, SurfaceAnswer& answer,
          double& best_z)
{
  const ProbabilisticBVH& q_bvh = query.hierarchy ();
  const ProbabilisticBVH& s_bvh = surface.hierarchy ();
  const SurfaceModel& s_model = surface.surface ();
  const SurfaceModel& q_model = query.surface ();
  const bool behind_unseen = s_model.seenFromViewpoint ();
  scratch.two_sided = !s_model.insideKnown ();
  // A deep point inside by the winding number is inside a solid (inside_confirmed) only where
  // the surface has a known inside and is no scan's view (behind a sheet is `unobserved`).
  const bool inside_known = !scratch.two_sided && !behind_unseen;
  // Behind a scan from one viewpoint or any open surface (winding about 1/2 behind a sheet) the
  // space is occupied; inside a closed surface means a winding number above 1/2.
  const double behind_threshold = behindThreshold (s_model);
  const Eigen::Matrix3d R_q = T_q.linear ();
  const Eigen::Matrix3d R_s = T_s.linear ();
  const Eigen::Isometry3d T_s_inverse = T_s.inverse ();
  scratch.prepare (s_bvh.size ());
  scratch.earlier.clear ();
  scratch.earlier_leaves.clear ();
  const std::uint32_t cache_stamp = scratch.next ();
  // A sample of the surface mapped into A's frame, once per side.
  auto cacheSample = [&] (std::size_t sj) {
    if (scratch.cached[sj] == cache_stamp)
      return;
    scratch.cached[sj] = cache_stamp;
    const Eigen::Vector3d n = s_model.normals ()[sj].cast<double> ();
    const Eigen::Vector4f open = s_model.opening (sj);
    scratch.cache[sj] = {T_s * s_bvh.means ()[sj], R_s * n, s_model.spacing ()[sj],
                         std::max (0.0, s_bvh.covariances ()[sj].quadratic (n)),
                         std::max<double> (s_model.spacing ()[sj], s_model.surfaceSpacing ()),
                         R_s * open.head<3> ().cast<double> (), static_cast<double> (open.w ())};
  };
  // evaluate's far-rim test sees the pool alone: before a point is read as beside an edge
  // (Evaluation::beside_edge), the whole surface within the bridging reach is searched, leaf by
  // leaf, stopping at the first far-rim sample.
  auto farRimAnywhere = [&] (const Eigen::Vector3d& x, const Evaluation& e) {
    const Sample& first = scratch.cache[static_cast<std::size_t> (e.first)];
    const double reach = kBridgeSpacings * first.gap;
    const double along = first.normal.dot (x - first.position);
    const Eigen::Vector3d x_s = T_s_inverse * x;
    scratch.stack.assign (1, ProbabilisticBVH::rootId ());
    while (!scratch.stack.empty ())
    {
      const ProbabilisticBVH::Node& node = s_bvh.node (scratch.stack.back ());
      scratch.stack.pop_back ();
      const OrientedBox& b = node.box;
      if (b.distanceTo (x_s) > reach)
        continue;
      if (!node.isLeaf ())
      {
        for (int c = 0; c < node.num_children; ++c)
          scratch.stack.push_back (node.first_child + c);
        continue;
      }
      scratch.wide.clear ();
      for (const int j : s_bvh.indices (node))
      {
        const std::size_t sj = static_cast<std::size_t> (j);
        if (s_model.normals ()[sj].isZero ())
          continue;
        cacheSample (sj);
        scratch.wide.push_back (j);
      }
      if (farRim (x, first, along, e.tangential, kBridgeSpacings, inList (scratch.wide), scratch.cache))
        return true;
    }
    return false;
  };
  for (std::size_t g = 0; g < groups.size () || more_leaves;)
  {
    if (best_z < stop_z)
    {
      answer.stopped_early = true;
      return;
    }
    if (max_pairs > 0 && answer.pairs_tested >= max_pairs)
    {
      answer.budget_exhausted = true;
      return;
    }
    if (g == groups.size ())
      return;  // (not reached: enumerateUpToCap leaves leaves out only past the cap)
    const std::int32_t q_leaf = groups[g].first;
    // The pool: every sample of the surface leaves paired with this query leaf, once.
    const std::uint32_t pool_stamp = scratch.next ();
    // Keyed by distance from the query leaf's centre (sorted as the searches need).
    const Eigen::Vector3d center = T_q * q_bvh.node (q_leaf).box.center;
    scratch.pool.clear ();
    for (; g < groups.size () && groups[g].first == q_leaf; ++g, ++answer.pairs_tested)
      for (const int j : s_bvh.indices (s_bvh.node (groups[g].second)))
      {
        const std::size_t sj = static_cast<std::size_t> (j);
        if (scratch.pooled[sj] == pool_stamp || s_model.normals ()[sj].isZero ())
          continue;
        scratch.pooled[sj] = pool_stamp;
        cacheSample (sj);
        scratch.pool.add ((scratch.cache[sj].position - center).norm (), j);
      }
    if (scratch.pool.empty ())
    {
      answer.unjudged = true;
      continue;
    }
    scratch.outside.clear ();
    for (const int i : q_bvh.indices (q_bvh.node (q_leaf)))
    {
      const std::size_t qi = static_cast<std::size_t> (i);
      const Eigen::Vector3d x = T_q * q_bvh.means ()[qi];
      const PackedCovariance& cov = q_bvh.covariances ()[qi];
      Evaluation e;
      if (!evaluate (x, scratch.pool, (x - center).norm (), scratch.cache,
                     [&] (const Eigen::Vector3d& n) { return std::max (0.0, cov.quadratic (R_q.transpose () * n)); },
                     scratch.two_sided, e))
        continue;
      ++answer.points_tested;
      // Clearly behind the local plane, or behind it farther than a spacing from its nearest
      // sample: the plane may be extrapolated there (past a face's edge whose other face was not
      // sampled). The winding number of the whole surface decides: outside, the point is at
      // least its distance to the nearest sample away. Points within the noise of the plane keep
      // the local answer: there the winding number is about 1/2 on either side.
      // Only a point that matters is checked: one that would set the pair's minimum, or any
      // with per-point values. A deep point is judged by the plane (the edge's mixture in
      // evaluate is for points within the noise of it; the winding number decides here).
      const bool deep = e.plane_distance < 0.0 && (e.nearest > e.spacing || e.plane_distance < -kDeepSigmas * e.plane_sigma);
      // Deep, or beside an edge only for want of the samples beyond it among the paired leaves:
      // the plane's answer. Every such point is searched, not only one that could set the
      // minimum: its answer also decides whether it is found outside, a crossing's end, so a
      // gate on the minimum so far made the pair's answer depend on the visiting order and on
      // per_point (found in review: 2 of 400 exhaustive poses of a plate against a table).
      if (deep || (e.beside_edge && farRimAnywhere (x, e)))
      {
        e.distance = e.plane_distance;
        e.sigma = e.plane_sigma;
      }
      const bool matters = per_point || e.distance / std::max (e.sigma, 1e-300) < best_z;
      bool confirmed = false;
      // How far x lies behind what the surface's viewpoint saw, where the scan cannot tell
      // whether its object reaches x (shadowDepth); NaN elsewhere.
      double shadow = kNaN;
      if (matters && deep)
      {
        const Eigen::Vector3d x_s = T_s_inverse * x;
        const double winding = behindWinding (s_model, s_bvh, x_s);
        // Behind one scanned view, the sheets it saw may cancel: a box's top seen from straight
        // above and the table around it put 1-2 cm under the top at a winding number near 0.1,
        // and a 1 cm cube there read free (d = +5 mm).
        if (winding < behind_threshold && behind_unseen)
          shadow = shadowDepth (surface, x_s, std::min (kDeepSigmas * e.plane_sigma, SurfaceModel::kHiddenSpacings * s_model.medianSpacing ()));
        if (winding < behind_threshold && std::isnan (shadow))
        {
          e.distance = e.nearest;
          e.normal = Eigen::Vector3d::Zero ();
        }
        else if (winding >= behind_threshold)
          confirmed = inside_known && winding > kInsideWinding;
      }
      // Outside the surface near x, yet behind what the sensor saw along its line of sight: past
      // the edge of the table a box seen from above hides, a cube 1 cm into the box's unseen
      // side read free. The shadow rule's answer, as out of reach. A hidden point reads z = 0,
      // so it matters wherever the least z so far is above 0, however clear its local answer:
      // gated on that answer, whether a hidden point was found followed the visiting order (the
      // query's hierarchy, which a rigid motion of the scene changes), and a mug scan's pose
      // read 0.164 in 6 of 9 frames and unknown 0.5 in 3.
      else if (behind_unseen && e.distance > 0.0 && (matters || best_z > 0.0))
        shadow = shadowDepth (surface, T_s_inverse * x, SurfaceModel::kHiddenSpacings * s_model.medianSpacing ());
      const bool hidden = !std::isnan (shadow);
      // Over a bridged hole, clearly behind a surface seen from one viewpoint (whose far side no
      // sample shows), or hidden from it, the answer rests on surface the samples do not show.
      const bool unobserved = e.bridged || hidden || (behind_unseen && deep && e.distance < 0.0);
      // The crossing test reads the local answer; a hidden point is unknown (P = 1/2) to the
      // pair, its way out toward the sensor.
      if (e.distance > 0.0 && !e.normal.isZero ())
        scratch.outside.push_back ({i, x, e.normal, R_q * q_model.normals ()[qi].cast<double> (), e.distance,
                                    std::max (e.sigma, 1e-300), static_cast<double> (q_model.spacing ()[qi]), e.normal_spread});
      if (hidden)
      {
        e.distance = 0.0;
        e.sigma = shadow;
        e.normal = R_s * (s_model.viewpoint () - T_s_inverse * x).normalized ();
        confirmed = false;
      }
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
        answer.unobserved = unobserved;
        answer.inside_confirmed = confirmed && !unobserved;
      }
    }
    crossings (scratch, center, side, per_point, answer, best_z);
  }
}

/** \brief Sorts the leaf pairs by their first leaf (ids below `nodes`), keeping the order
  * within a leaf: a counting sort, linear where std::sort cost 5 % of a query. testSide needs
  * them grouped, in ascending order (which leaf comes first decides where decision mode stops);
  * the order within a group does not matter (the pool is ordered by distance). */
void
groupByFirst (std::vector<std::pair<std::int32_t, std::int32_t>>& pairs, std::size_t nodes, Scratch& scratch)
{
  auto& start = scratch.group_start;
  start.assign (nodes + 1, 0);
  for (const auto& p : pairs)
    ++start[static_cast<std::size_t> (p.first) + 1];
  for (std::size_t i = 0; i < nodes; ++i)
    start[i + 1] += start[i];
  scratch.grouped.resize (pairs.size ());
  for (const auto& p : pairs)
    scratch.grouped[start[static_cast<std::size_t> (p.first)]++] = p;
  pairs.swap (scratch.grouped);
}

/** \brief A point of one object found inside the other, away from its surface. */
struct DeepPoint
{
  bool found = false;
  int side = 1;
  int index = -1;         ///< hierarchy index in its own model
  Eigen::Vector3d point = Eigen::Vector3d::Zero ();  ///< in A's local frame
  double depth = 0.0;     ///< distance to the other's nearest sample
  /** \brief That sample's outward normal, in A's local frame (zero where it has none): the way
    * out of the other object from there. */
  Eigen::Vector3d normal = Eigen::Vector3d::Zero ();
  /** \brief A point in the space behind the other's scan, clear of its surface
    * (SurfaceModel::behindView), which the sensor never observed: read where no point was found
    * inside. */
  struct Shadowed
  {
    bool found = false;
    int side = 1;
    int index = -1;  ///< hierarchy index in its own model
    Eigen::Vector3d point = Eigen::Vector3d::Zero ();   ///< in A's local frame
    Eigen::Vector3d normal = Eigen::Vector3d::Zero ();  ///< toward that sensor, in A's local frame
    double depth = 0.0;  ///< how far behind what the scan saw
  } shadowed;
};

/** \brief The depth of x (in `surface`'s local frame, mapped into A's by T_s) below `surface`:
  * the distance to its nearest sample, and that sample's outward normal in A's frame. */
void
setDepth (const CloudModel& surface, const Eigen::Isometry3d& T_s, const Eigen::Vector3d& x, DeepPoint& deep)
{
  const NearestSample sample = nearestSample (surface.hierarchy (), x);
  const int nearest = sample.index;
  deep.depth = sample.distance;
  deep.normal = nearest >= 0 ? Eigen::Vector3d (T_s.linear () * surface.surface ().normals ()[static_cast<std::size_t> (nearest)].cast<double> ())
                             : Eigen::Vector3d::Zero ();
}

/** \brief Whether x (in `surface`'s local frame) lies inside it by its winding number, above
  * behindThreshold as near the surface: behind one scanned view of a box, 2-8 cm under its seen
  * top, the winding number is 0.33-0.47, and under 1/2 such a part read free (a probe,
  * 2026-12-04). Outside its bounding box a point is outside it (behind an open sheet's box edge
  * the winding number is small too): no winding number needed. (Behind a scan, the unobserved
  * space reaches past the box by a shell: shadowDepth.) */
bool
insideOf (const CloudModel& surface, const Eigen::Vector3d& x)
{
  const ProbabilisticBVH& bvh = surface.hierarchy ();
  const OrientedBox& bound = bvh.node (ProbabilisticBVH::rootId ()).box;
  return bound.contains (x) && behindWinding (surface.surface (), bvh, x) > behindThreshold (surface.surface ());
}

/** \brief The points of `node` (of q_bvh, mapped into `surface`'s frame by T_s_q) that lie in the
  * space behind `surface`'s scan (shadowDepth: within its bounding box or hidden shell, and more
  * than SurfaceModel::kHiddenSpacings median spacings behind what the sensor saw along their line
  * of sight): the deepest of the first leaf holding any is recorded in deep.shadowed, and each
  * gets P = 1/2 in per_point when given (else that leaf ends the search). The node is clear of the
  * surface (out of reach) and outside it by the winding number: the scan cannot tell whether
  * the object it saw reaches there. */
void
shadowedPoints (const ProbabilisticBVH& q_bvh, const ProbabilisticBVH::Node& node, const Eigen::Isometry3d& T_s_q,
                const CloudModel& surface, const Eigen::Isometry3d& T_s, std::vector<float>* per_point, DeepPoint& deep)
{
  const SurfaceModel& s = surface.surface ();
  if (!s.seenFromViewpoint ())
    return;
  const double margin = SurfaceModel::kHiddenSpacings * s.medianSpacing ();
  // Whole nodes in front of what the sensor saw are passed over (a gripper above a scanned
  // table, most of a query's points): the points of a node are read only where its box may
  // reach behind the scan, from the node down to its leaves.
  constexpr std::int64_t kMaxBins = 64;
  thread_local std::vector<const ProbabilisticBVH::Node*> stack;
  stack.assign (1, &node);
  while (!stack.empty ())
  {
    const ProbabilisticBVH::Node& n = *stack.back ();
    stack.pop_back ();
    std::array<Eigen::Vector3d, 8> corners;
    const Eigen::Matrix3d axes = n.box.axes ();
    const Eigen::Vector3d h = n.box.halfExtents ();
    for (int c = 0; c < 8; ++c)
      corners[static_cast<std::size_t> (c)] =
          T_s_q * (n.box.center + axes * Eigen::Vector3d ((c & 1) ? h.x () : -h.x (), (c & 2) ? h.y () : -h.y (), (c & 4) ? h.z () : -h.z ()));
    if (!s.mayLieBehindView (corners, margin, kMaxBins))
      continue;
    if (!n.isLeaf ())
    {
      for (int c = 0; c < n.num_children; ++c)
        stack.push_back (&q_bvh.node (n.first_child + c));
      continue;
    }
    // The first leaf holding such points gives the deepest of them (a point the input's order
    // does not choose), with per-point values or without.
    const bool first_leaf = !deep.shadowed.found;
    for (const int i : q_bvh.indices (n))
    {
      const Eigen::Vector3d x = T_s_q * q_bvh.means ()[static_cast<std::size_t> (i)];
      const double behind = shadowDepth (surface, x, margin);
      if (std::isnan (behind))
        continue;
      if (first_leaf && (!deep.shadowed.found || behind > deep.shadowed.depth))
        deep.shadowed = {true, deep.shadowed.side, i, T_s * x, T_s.linear () * (s.viewpoint () - x).normalized (), behind};
      if (per_point)
      {
        float& p = (*per_point)[static_cast<std::size_t> (i)];
        if (!(p >= 0.5f))
          p = 0.5f;
      }
    }
    if (deep.shadowed.found && !per_point)
      return;
  }
}

/** \brief True when some leaf box of `s_bvh` (mapped into the box's frame by T_box_s), grown by
  * margin as the box is, overlaps box: the surface may pass through it. */
bool
nearSurface (const ProbabilisticBVH& s_bvh, const OrientedBox& box, const Eigen::Isometry3d& T_box_s, double margin,
             std::vector<std::int32_t>& stack)
{
  stack.assign (1, ProbabilisticBVH::rootId ());
  while (!stack.empty ())
  {
    const ProbabilisticBVH::Node& node = s_bvh.node (stack.back ());
    stack.pop_back ();
    if (disjoint (box, node.box, T_box_s, margin))
      continue;
    if (node.isLeaf ())
      return true;
    for (int c = 0; c < node.num_children; ++c)
      stack.push_back (node.first_child + c);
  }
  return false;
}

/** \brief The point of `node` nearest its box's centre (the lowest index among equals): a point
  * that turns with the cloud and that its order does not choose. */
int
centralPoint (const ProbabilisticBVH& bvh, const ProbabilisticBVH::Node& node)
{
  const Eigen::Vector3d& center = node.box.center;
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity ();
  for (const int i : bvh.indices (node))
  {
    const double d2 = (bvh.means ()[static_cast<std::size_t> (i)] - center).squaredNorm ();
    if (d2 < best_d2 || (d2 == best_d2 && i < best))
    {
      best = i;
      best_d2 = d2;
    }
  }
  return best;
}

/** \brief The nodes of `query` whose boxes no leaf of `surface` comes near (the surface does not
  * pass through them, so all their points lie on one side of it), from the root down: the
  * winding number of one point per node says which side (centralPoint where exhaustive). In
  * decision mode (exhaustive false) returns the first node found inside, at that point;
  * otherwise the deepest point of all inside nodes, every inside node's points marked in
  * per_point. T_q and T_s map the two models into A's frame. */
DeepPoint
deepInside (const CloudModel& query, const Eigen::Isometry3d& T_q, const CloudModel& surface, const Eigen::Isometry3d& T_s,
            double margin, bool exhaustive, std::vector<float>* per_point)
{
  thread_local std::vector<std::int32_t> nodes, stack;
  const ProbabilisticBVH& q_bvh = query.hierarchy ();
  const ProbabilisticBVH& s_bvh = surface.hierarchy ();
  const Eigen::Isometry3d T_q_s = T_q.inverse () * T_s;  // surface frame -> query frame
  const Eigen::Isometry3d T_s_q = T_q_s.inverse ();
  const OrientedBox& bound = s_bvh.node (ProbabilisticBVH::rootId ()).box;
  // Behind a scan, the unobserved space reaches past its box by the hidden shell (shadowDepth):
  // at most that beyond a sample along the line of sight and a bin or so (two spacings at the
  // median depth) beside it, so within twice the shell of the box unless many times deeper than
  // the median sample.
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant (2.0 * surface.surface ().hiddenShell ());
  DeepPoint deep;
  nodes.assign (1, ProbabilisticBVH::rootId ());
  while (!nodes.empty ())
  {
    const std::int32_t id = nodes.back ();
    nodes.pop_back ();
    const ProbabilisticBVH::Node& node = q_bvh.node (id);
    // Clear of the surface's bounding box (grown for a scan's hidden shell): outside it, with
    // everything below.
    if (disjointInflated (node.box, Eigen::Vector3d::Zero (), bound, reach, T_q_s))
      continue;
    if (nearSurface (s_bvh, node.box, T_q_s, margin, stack))
    {
      for (int c = 0; c < node.num_children; ++c)
        nodes.push_back (node.first_child + c);
      continue;  // a leaf near the surface was tested point by point
    }
    // The node's points lie on one side of the surface: one of them says which. Where a distance
    // is asked for, the one nearest the box's centre, a point the input's order does not choose
    // (a node can straddle the threshold of a scan's winding number); in decision mode, which
    // stops at the first inside node and prints its depth as a bound, the node's first (the pass
    // over a node's points cost a planner's free poses half their time).
    const int central = exhaustive ? centralPoint (q_bvh, node) : *q_bvh.indices (node).begin ();
    const Eigen::Vector3d x = T_s_q * q_bvh.means ()[static_cast<std::size_t> (central)];
    if (!insideOf (surface, x))
    {
      if (!deep.found && (per_point || !deep.shadowed.found))
        shadowedPoints (q_bvh, node, T_s_q, surface, T_s, per_point, deep);
      continue;
    }
    // In decision mode the first inside node decides, at that point's depth (a bound);
    // otherwise the deepest point of every inside node sets the depth. (At one point a node,
    // the input's first, a permutation of a real stereo table moved the reported depth of a
    // mug pushed into it between 17 and 24 mm.)
    const auto consider = [&] (int i) {
      DeepPoint here;
      setDepth (surface, T_s, T_s_q * q_bvh.means ()[static_cast<std::size_t> (i)], here);
      if (!deep.found || here.depth > deep.depth)
      {
        deep = here;
        deep.found = true;
        deep.index = i;
        deep.point = T_q * q_bvh.means ()[static_cast<std::size_t> (i)];
      }
    };
    if (!exhaustive)
    {
      consider (central);
      return deep;
    }
    for (const int i : q_bvh.indices (node))
      consider (i);
    if (per_point)
      for (const int i : q_bvh.indices (node))
        (*per_point)[static_cast<std::size_t> (i)] = 1.0f;
  }
  return deep;
}

/** \brief deepInside both ways where a surface says where its inside is: A's nodes inside B, then
  * (unless decision mode found one) B's inside A; the deeper of the two. */
DeepPoint
insideEitherOutOfReach (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, double margin,
                        bool may_stop, std::vector<float>* per_point_a, std::vector<float>* per_point_b)
{
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
  DeepPoint deep;
  if (b.surface ().insideKnown ())
  {
    deep = deepInside (a, I, b, T_a_b, margin, !may_stop, per_point_a);
    deep.side = +1;
  }
  if ((!deep.found || !may_stop) && a.surface ().insideKnown ())
  {
    DeepPoint other = deepInside (b, T_a_b, a, I, margin, !may_stop, per_point_b);
    other.side = other.shadowed.side = -1;
    const DeepPoint::Shadowed shadowed = deep.shadowed.found ? deep.shadowed : other.shadowed;  // A's first
    if (other.found && (!deep.found || other.depth > deep.depth))
      deep = other;
    deep.shadowed = shadowed;
  }
  return deep;
}

/** \brief A point found inside the other surface, out of reach of it (deepInside, containment):
  * P = 1, the distance minus its depth to the other's nearest sample (about a spacing uncertain),
  * unless the answer already reads deeper. */
void
answerDeep (const DeepPoint& deep, const CloudModel& a, const CloudModel& b, SurfaceAnswer& answer)
{
  const SurfaceModel& s = deep.side > 0 ? b.surface () : a.surface ();
  answer.contained = !answer.reached;
  answer.reached = true;
  if (!(answer.signed_distance <= -deep.depth))
  {
    answer.witness_side = deep.side;
    answer.witness_index = deep.index;
    answer.witness_point = deep.point;
    // Toward A's side, as a point near the surface gets it: the other surface's outward normal at
    // its nearest sample for a point of A (out of B), turned inward for a point of B (A's outward
    // normal points away from A). NaN where that sample has no normal (an unoriented point).
    answer.witness_normal = deep.normal.isZero () ? Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ())
                                                  : Eigen::Vector3d (deep.side > 0 ? deep.normal : -deep.normal);
    answer.signed_distance = -deep.depth;
    // The depth is measured to the nearest sample: uncertain by about one spacing.
    answer.signed_distance_std = s.medianSpacing ();
    // Inside a surface seen from one viewpoint: behind it, where no sample looked.
    answer.unobserved = s.seenFromViewpoint ();
  }
  // P = 1 rests on this point, inside a solid unless behind a scan's view.
  answer.inside_confirmed = answer.inside_confirmed || !s.seenFromViewpoint ();
  answer.probability = 1.0;
}
/** \brief A point in the space behind the other's scan (DeepPoint::Shadowed), where no point was
  * found inside: the scan cannot tell whether the object it saw reaches there. Unless the
  * answer already reads P >= 1/2: P = 1/2, unobserved, d = 0 with a standard deviation of its
  * depth behind what the sensor saw (the surface may lie anywhere between), the witness normal
  * toward that sensor (turned toward A's side): the way back to observed space. */
void
answerShadow (const DeepPoint::Shadowed& shadowed, SurfaceAnswer& answer)
{
  if (answer.probability >= 0.5)
    return;
  answer.reached = true;
  answer.probability = 0.5;
  answer.unobserved = true;
  answer.witness_side = shadowed.side;
  answer.witness_index = shadowed.index;
  answer.witness_point = shadowed.point;
  answer.witness_normal = shadowed.side > 0 ? shadowed.normal : Eigen::Vector3d (-shadowed.normal);
  answer.signed_distance = 0.0;
  answer.signed_distance_std = shadowed.depth;
}
} // namespace

SurfaceAnswer
containmentTest (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
                 std::vector<float>* per_point_a, std::vector<float>* per_point_b)
{
  SurfaceAnswer answer;
  // As surfaceTest out of reach: every node of one object clear of the other's surface is
  // judged by one winding number, from the root down (it was the first point alone, so an
  // object listed with a part outside first read free: a probe, 2026-12-04).
  const bool may_stop = !request.exhaustive && !request.distance && !per_point_a && !per_point_b;
  const DeepPoint deep = insideEitherOutOfReach (
      a, b, T_a_b, std::max (a.surface ().medianSpacing (), b.surface ().medianSpacing ()), may_stop, per_point_a, per_point_b);
  if (deep.found)
  {
    answerDeep (deep, a, b, answer);
    answer.stopped_early = may_stop;
  }
  else if (deep.shadowed.found)
    answerShadow (deep.shadowed, answer);
  return answer;
}

namespace
{
/** \brief The traversal of the leaf pairs within reach: boxes grown to kReachSigmas point
  * deviations and by one sample spacing, so that a point between two sparse samples still meets
  * their leaves. Every pair is enumerated (exhaustive, no cap, no order). */
TraversalParams
reachParams (double spacing)
{
  TraversalParams params ((CollisionRequest ()));
  params.mode = TraversalMode::ExpandedBV;
  params.expanded_k_sigma = kReachSigmas;
  params.exhaustive = true;
  params.skip_dominated = false;
  params.nearest_first = false;  // every pair is enumerated: the order is of no use here
  params.max_leaf_tests = 0;      // the separators' cap (max_leaf_fits) is not this layer's; testSide applies max_surface_pairs
  params.box_margin = std::isfinite (spacing) ? std::max (spacing, 0.0) : 0.0;
  return params;
}

/** \brief Appends the leaf pairs `params` reaches (node ids of A and B) to pairs, in the
  * traversal's order; returns its box tests. */
std::size_t
appendLeafPairs (const ProbabilisticBVH& bvh_a, const ProbabilisticBVH& bvh_b, const Eigen::Isometry3d& T_a_b,
                 const TraversalParams& params, std::vector<std::pair<std::int32_t, std::int32_t>>& pairs)
{
  const auto* nodes_a = bvh_a.nodes ().data ();
  const auto* nodes_b = bvh_b.nodes ().data ();
  return traverseHierarchies (bvh_a, bvh_b, T_a_b, params,
                              [&] (const ProbabilisticBVH::Node& la, const ProbabilisticBVH::Node& lb, double) {
                                pairs.emplace_back (static_cast<std::int32_t> (&la - nodes_a),
                                                    static_cast<std::int32_t> (&lb - nodes_b));
                                return 0.0;
                              })
      .node_pairs_tested;
}

/** \brief The leaf pairs within reach of A's first leaves (in node id order, the order testSide
  * takes them), until they hold at least max_pairs pairs or A's leaves run out: what testSide
  * reads of a capped side A, without the pairs it never reaches (at high noise a query's pairs
  * within reach number millions, and their enumeration alone took 0.7 s of a W2 query capped at
  * 256). Batches of leaves, doubling from 32, each with its ancestors marked for one traversal
  * (TraversalParams::only_a): the pairs and their order within a leaf are the whole
  * traversal's. Appends to pairs, adds the box tests to bv_tests; returns true when every leaf
  * of A was enumerated (pairs then holds every pair). */
bool
enumerateUpToCap (const ProbabilisticBVH& bvh_a, const ProbabilisticBVH& bvh_b, const Eigen::Isometry3d& T_a_b,
                  TraversalParams params, std::size_t max_pairs, Scratch& scratch, std::size_t& bv_tests)
{
  const auto& nodes = bvh_a.nodes ();
  scratch.parent.assign (nodes.size (), -1);
  scratch.leaves.clear ();
  for (std::size_t id = 0; id < nodes.size (); ++id)
  {
    if (nodes[id].isLeaf ())
      scratch.leaves.push_back (static_cast<std::int32_t> (id));
    else
      for (int c = 0; c < nodes[id].num_children; ++c)
        scratch.parent[static_cast<std::size_t> (nodes[id].first_child + c)] = static_cast<std::int32_t> (id);
  }
  scratch.marked.assign (nodes.size (), 0);
  params.only_a = &scratch.marked;
  auto& pairs = scratch.pairs;
  std::size_t next = 0, batch = 32;
  while (pairs.size () < max_pairs)
  {
    if (next >= scratch.leaves.size ())
      return true;
    const std::size_t end = std::min (scratch.leaves.size (), next + batch);
    std::fill (scratch.marked.begin (), scratch.marked.end (), 0);
    for (std::size_t k = next; k < end; ++k)
      for (std::int32_t id = scratch.leaves[k]; id >= 0 && !scratch.marked[static_cast<std::size_t> (id)];
           id = scratch.parent[static_cast<std::size_t> (id)])
        scratch.marked[static_cast<std::size_t> (id)] = 1;
    bv_tests += appendLeafPairs (bvh_a, bvh_b, T_a_b, params, pairs);
    next = end;
    batch *= 2;
  }
  return next >= scratch.leaves.size ();
}
} // namespace

bool
withinReach (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b, double spacing)
{
  TraversalParams params = reachParams (spacing);
  params.exhaustive = false;
  params.stop_probability = 0.0;  // the first pair found stops the descent
  return traverseHierarchies (a, b, T_a_b, params,
                              [] (const ProbabilisticBVH::Node&, const ProbabilisticBVH::Node&, double) { return 1.0; })
             .leaf_pairs_tested > 0;
}

SurfaceAnswer
surfaceTest (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
             std::vector<float>* per_point_a, std::vector<float>* per_point_b)
{
  thread_local Scratch scratch;
  SurfaceAnswer answer;
  const ProbabilisticBVH& bvh_a = a.hierarchy ();
  const ProbabilisticBVH& bvh_b = b.hierarchy ();
  const TraversalParams params = reachParams (std::max (a.surface ().medianSpacing (), b.surface ().medianSpacing ()));
  auto& pairs = scratch.pairs;
  pairs.clear ();
  // Capped, only the pairs side A's cap lets testSide reach are enumerated; the rest of the
  // traversal is the same.
  bool all_pairs = true;
  answer.bv_tests = 0;
  if (request.max_surface_pairs > 0)
    all_pairs = enumerateUpToCap (bvh_a, bvh_b, T_a_b, params, request.max_surface_pairs, scratch, answer.bv_tests);
  else
    answer.bv_tests = appendLeafPairs (bvh_a, bvh_b, T_a_b, params, pairs);
  answer.leaf_pairs = pairs.size ();
  double best_z = std::numeric_limits<double>::infinity ();
  // Decision mode: once a point's P_in exceeds collision_above the verdict is final (the
  // distance is then a bound: the deepest point may not have been reached). A requested
  // distance (CollisionRequest::distance) is an estimate, never such a bound.
  const bool may_stop = !request.exhaustive && !request.distance && !per_point_a && !per_point_b;
  const double stop_z = may_stop ? -normalQuantile (request.collision_above) : -std::numeric_limits<double>::infinity ();
  if (!pairs.empty ())
  {
    groupByFirst (pairs, bvh_a.nodes ().size (), scratch);
    testSide (a, Eigen::Isometry3d::Identity (), b, T_a_b, pairs, scratch, +1, per_point_a, stop_z, request.max_surface_pairs,
              !all_pairs, answer, best_z);
    if (!answer.stopped_early && !answer.budget_exhausted)
    {
      for (auto& p : pairs)
        std::swap (p.first, p.second);
      groupByFirst (pairs, bvh_b.nodes ().size (), scratch);
      testSide (b, T_a_b, a, Eigen::Isometry3d::Identity (), pairs, scratch, -1, per_point_b, stop_z,
                request.max_surface_pairs, false, answer, best_z);
    }
  }
  if (answer.stopped_early)
  {
    answer.probability = normalCdf (-best_z);
    return answer;
  }
  // Capped (CollisionRequest::max_surface_pairs): the largest P of the leaves tested, a lower
  // bound; what lies beyond reach is not judged either (its walks cost as much again).
  if (answer.budget_exhausted)
  {
    answer.leaf_pairs = answer.pairs_tested;
    answer.probability = answer.reached ? normalCdf (-best_z) : 0.0;
    return answer;
  }
  // Out of reach of each other's surface: parts of one object deep inside the other (a piano
  // pushed 30 cm through a wall: the wall's samples inside the piano are far from its surface),
  // or one object entirely inside the other. Only a trusted orientation (the points' own normals,
  // a viewpoint) may declare it: a propagated one can be inside out (a room seen from within).
  const DeepPoint deep = insideEitherOutOfReach (a, b, T_a_b, params.box_margin, may_stop, per_point_a, per_point_b);
  if (deep.found)
  {
    answerDeep (deep, a, b, answer);
    // In decision mode deepInside stops at the first node inside: its depth is a bound.
    answer.stopped_early = answer.stopped_early || may_stop;
    return answer;
  }
  answer.probability = answer.reached ? normalCdf (-best_z) : 0.0;
  if (deep.shadowed.found)
    answerShadow (deep.shadowed, answer);
  return answer;
}
} // namespace detail
} // namespace pcl_probcollision
