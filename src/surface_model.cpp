// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/surface_model.h>
#include <pcl_probcollision/detail/parallel.h>
#include <pcl_probcollision/detail/resolution.h>

#include <pcl/exceptions.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <optional>
#include <limits>
#include <queue>
#include <tuple>
#include <utility>

namespace pcl_probcollision
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
/** \brief A point is on its surface's edge (SurfaceModel::openings) when the widest angle
  * between its neighbours, seen from it in its tangent plane, exceeds this. A point on a
  * straight edge has its neighbours in a half plane (180 degrees open); an inner point's k = 10
  * neighbours, uniformly around it, leave more than 150 degrees open about 8 % of the time
  * (k (1 - 150 / 360)^(k - 1)), more than 180 only 2 %. PCL's BoundaryEstimation uses 90
  * degrees and returns no direction. */
constexpr double kOpenGapDegrees = 150.0;
/** \brief ... unless its neighbours lie along a line: the smaller of their two spreads in the
  * tangent plane below this share of the larger (a half disc of neighbours, an edge's, gives
  * 0.28; a line of mesh vertices inside a flat face about 0, with 180 degrees open on either
  * side, which says nothing about where the face continues). */
constexpr double kOpenLineRatio = 0.1;
/** \brief A viewpoint orients a point only where the surface faces it at least this much
  * (|cos| of the angle between normal and line of sight): at grazing angles the fitted normal's
  * own error can flip the side. */
constexpr double kMinViewCosine = 0.2;

/** \brief Viewpoint orientation: above this share of the points it orients whose side disagrees
  * with their part's once one orientation is carried over the part (viewDisagreement), the
  * viewpoint sees the surface edge-on (a sheet in its plane: the points' noise tilts patches of
  * normals toward it and others away, about half each) and orients nothing. The scans of
  * ../shared/data disagree on 0-0.3 % of the points they seed (bunny.pcd 1.8 %, the demo's
  * data/table_mug.pcd 1.4 %); a sheet sampled every 1 cm with 2 mm noise, seen from its plane,
  * on 27-50 % (SurfaceModel.ASheetSeenEdgeOnThroughCoarseNoiseIsTwoSided). Until 2026-12-02
  * neighbour pairs pointing apart were counted instead (over a quarter): a patch's normals share
  * their neighbours and agree, so such a sheet passed in about half of its draws and the space
  * over it read occupied. A closed object's far side, which faces the viewpoint from behind,
  * disagrees too (SurfaceModel.AViewpointThatSeesAClosedObjectFromOutsideOrientsNothing). */
constexpr double kMaxViewDisagreement = 0.1;
/** \brief viewDisagreement carries an orientation only between neighbours whose normals are
  * within 26 degrees (|cos| at least this): breadth first, it takes the first edge that reaches
  * a point, and across a crease the side is a guess. With 0.5 (60 degrees) a stereo scan of a
  * mug (stereo_mug_object0_full.pcd) disagreed on 8.7 % of its points, with 0.9 on 0.3 %; an
  * edge-on sheet's patches are tilted by its noise, well within it (27-50 % either way). */
constexpr float kCarryCosine = 0.9f;
/** \brief viewDisagreement with points: opposed neighbours offset along the normal by more
  * than this share of their distance (30 degrees off the tangent plane) lie across the surface,
  * not beside each other on it. */
constexpr double kAcrossShare = 0.5;
/** \brief Viewpoint orientation: below this share of the points facing the viewpoint (|cos| at
  * least kMinViewCosine), it sees the surface edge-on too: a sheet in the viewpoint's plane
  * with 0.5 mm noise at 5 mm spacing has 1 of 1,600, tilted toward it or away at random; at 8
  * degrees above its plane, 89, every one toward it. */
constexpr double kMinViewSeeds = 0.01;

/** \brief behindView: at most this many of the nine bins about a point may hold no sample (a
  * single view's bins hold one to three samples where it sees a surface at a slant). */
constexpr int kMaxEmptyBins = 2;

/** \brief Samples probed by the given normals' check (SurfaceModel::givenNormalSpreadRatio),
  * evenly spread over those with a given normal. */
constexpr std::size_t kNormalProbes = 1024;

/** \brief Samples probed by the closed-objects check (SurfaceModel::closedShare), evenly spread:
  * 2,048 winding numbers, on one thread 7 ms for a 9,000-point sphere and 25-40 ms for a
  * 50,000-point room (docs/SURFACE.md, "Closed objects"). */
constexpr std::size_t kClosedProbes = 1024;
/** \brief The probes' offset from the sample, in its spacings (plus kClosedProbeSigmas noise
  * deviations along its normal): far enough that its own disc and noise do not decide the
  * winding number, near enough to stay inside parts a few spacings thick. */
constexpr double kClosedProbeSpacings = 2.0;
constexpr double kClosedProbeSigmas = 3.0;
/** \brief A probe in front reads outside below this |winding number|, one behind inside above
  * one minus it (an open sheet reads about -1/2 in front and 1/2 behind). */
constexpr double kClosedProbeWinding = 0.25;

/** \brief Symmetric neighbour graph in compressed rows: the k-nearest-neighbour relation is
  * not symmetric, and propagation must be able to cross an edge from either end. */
struct Graph
{
  std::vector<int> offsets, targets;
};

Graph
symmetricGraph (const std::vector<int>& neighbours, int k, std::size_t n)
{
  std::vector<int> degree (n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
    {
      const int t = neighbours[i * static_cast<std::size_t> (k) + static_cast<std::size_t> (j)];
      if (t < 0 || static_cast<std::size_t> (t) == i)
        continue;
      ++degree[i];
      ++degree[static_cast<std::size_t> (t)];
    }
  Graph g;
  g.offsets.assign (n + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    g.offsets[i + 1] = g.offsets[i] + degree[i];
  g.targets.resize (static_cast<std::size_t> (g.offsets[n]));
  std::vector<int> fill (g.offsets.begin (), g.offsets.end () - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
    {
      const int t = neighbours[i * static_cast<std::size_t> (k) + static_cast<std::size_t> (j)];
      if (t < 0 || static_cast<std::size_t> (t) == i)
        continue;
      g.targets[static_cast<std::size_t> (fill[i]++)] = t;
      g.targets[static_cast<std::size_t> (fill[static_cast<std::size_t> (t)]++)] = static_cast<int> (i);
    }
  return g;
}

/** \brief Orientation by propagation (Hoppe et al. 1992): from the oriented points, repeatedly
  * orient the unvisited neighbour whose normal is most nearly parallel to an oriented one's
  * (a maximum spanning tree on |n_i . n_j|), so that flips happen across flat regions, not
  * across creases. Marks every point it reaches with the component id. */
class Propagation
{
public:
  Propagation (const Graph& graph, std::vector<Eigen::Vector3f>& normals, std::vector<int>& component)
    : graph_ (graph), normals_ (normals), component_ (component),
      best_ (normals.size (), std::pair<float, int> (-1.0f, -1)) {}

  void
  seed (int i)
  {
    pushEdges (i);
  }

  void
  run ()
  {
    while (!queue_.empty ())
    {
      const auto [weight, from, to] = queue_.top ();
      queue_.pop ();
      (void) weight;
      if (component_[static_cast<std::size_t> (to)] >= 0)
        continue;
      Eigen::Vector3f& n = normals_[static_cast<std::size_t> (to)];
      if (n.dot (normals_[static_cast<std::size_t> (from)]) < 0.0f)
        n = -n;
      component_[static_cast<std::size_t> (to)] = component_[static_cast<std::size_t> (from)];
      pushEdges (to);
    }
  }

private:
  void
  pushEdges (int i)
  {
    const Eigen::Vector3f& n = normals_[static_cast<std::size_t> (i)];
    for (int e = graph_.offsets[static_cast<std::size_t> (i)]; e < graph_.offsets[static_cast<std::size_t> (i) + 1]; ++e)
    {
      const int t = graph_.targets[static_cast<std::size_t> (e)];
      if (component_[static_cast<std::size_t> (t)] >= 0 || normals_[static_cast<std::size_t> (t)].isZero ())
        continue;
      // An edge into t below one already queued for t would be popped after it, when t is
      // oriented already: it is not queued at all (the same orientation, a smaller queue).
      const std::pair<float, int> key (std::abs (n.dot (normals_[static_cast<std::size_t> (t)])), i);
      std::pair<float, int>& best = best_[static_cast<std::size_t> (t)];
      if (!(key > best))
        continue;
      best = key;
      queue_.emplace (key.first, i, t);
    }
  }

  const Graph& graph_;
  std::vector<Eigen::Vector3f>& normals_;
  std::vector<int>& component_;
  std::vector<std::pair<float, int>> best_;  ///< per point, the best (weight, from) queued into it
  std::priority_queue<std::tuple<float, int, int>> queue_;
};

/** \brief Viewpoint orientation: the share of the seeds (component 0) whose viewpoint side
  * disagrees with their part's majority once one orientation is carried over each part of the
  * graph from a seed. A scan's seeds agree but where the carrying jumps a crease; a sheet seen
  * edge-on has patches tilted toward the sensor and away, each consistent inside (its normals
  * share their neighbours), so neighbour pairs rarely disagree but the patches do. Breadth
  * first, over edges whose normals are within kCarryCosine (not Propagation's most-parallel-first
  * queue: on a 209,280-point stereo scan that added 12 % to the surface model's build, this 1-4 %,
  * measured with a 60-degree limit).
  * With points (the given normals' sides, SurfaceModel::givenNormalsMisoriented), opposed
  * neighbours that lie across each other's normal rather than beside it (offset more than
  * kAcrossShare of their distance along it) are not carried: a thin plate's two faces, or two
  * parts facing each other over a gap, are oriented apart and agree. */
double
viewDisagreement (const Graph& graph, const std::vector<Eigen::Vector3f>& normals, const std::vector<int>& component,
                  const std::vector<Eigen::Vector3d>* points = nullptr)
{
  const std::size_t n = normals.size ();
  std::vector<int> part (n, -1);
  std::vector<signed char> side (n, 0);  ///< +1: the normal as it is carries the part's orientation
  std::vector<std::array<std::size_t, 2>> votes;
  std::vector<int> queue;
  queue.reserve (n);
  for (std::size_t s = 0; s < n; ++s)
  {
    if (component[s] != 0 || part[s] >= 0)
      continue;
    const int id = static_cast<int> (votes.size ());
    votes.push_back ({0, 0});
    part[s] = id;
    side[s] = 1;
    queue.assign (1, static_cast<int> (s));
    for (std::size_t head = 0; head < queue.size (); ++head)
    {
      const std::size_t i = static_cast<std::size_t> (queue[head]);
      if (component[i] == 0)
        ++votes[static_cast<std::size_t> (id)][side[i] > 0 ? 0 : 1];
      for (int e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e)
      {
        const std::size_t t = static_cast<std::size_t> (graph.targets[static_cast<std::size_t> (e)]);
        const float cosine = normals[i].dot (normals[t]);
        if (part[t] >= 0 || std::abs (cosine) < kCarryCosine)
          continue;
        if (points && cosine < 0.0f)
        {
          const Eigen::Vector3d offset = (*points)[t] - (*points)[i];
          if (std::abs (offset.dot (normals[i].cast<double> ())) > kAcrossShare * offset.norm ())
            continue;
        }
        part[t] = id;
        side[t] = static_cast<signed char> (cosine < 0.0f ? -side[i] : side[i]);
        queue.push_back (static_cast<int> (t));
      }
    }
  }
  std::size_t seeded = 0, minority = 0;
  for (const auto& v : votes)
  {
    seeded += v[0] + v[1];
    minority += std::min (v[0], v[1]);
  }
  return seeded ? static_cast<double> (minority) / static_cast<double> (seeded) : 0.0;
}

/** \brief fn(i) for every point i < n, in chunks on `workers` threads; fn writes only slot i. */
template <typename Fn>
void
forEachPoint (std::size_t n, std::size_t workers, Fn&& fn)
{
  detail::parallelChunks (n, 4096, workers, [&] (std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      fn (i);
  });
}

/** \brief Stray normals: a plane fit 90 degrees off its flat patch (on a randomly sampled
  * noisy plane, a point lifted off it by its noise among neighbours that lie along a line:
  * about 5 % of the points 3 sigma apart) is a face of its own for the surface layer, and no
  * smoothing reaches it (no neighbour lies within kSmoothCosine). Where fewer than a quarter of
  * at least four neighbours agree with a normal within 45 degrees, the others agree among
  * themselves (their mean resultant length above 0.9) and the normal lies more than 45 degrees
  * off their mean but not opposite it (a thin slab's other face), it takes their mean. Corners,
  * edges and thin parts, whose neighbours do not agree, keep theirs. */
void
repairStrayNormals (const Graph& graph, std::vector<Eigen::Vector3f>& normals, std::size_t workers)
{
  constexpr float kAgreeCosine = 0.7071f;
  constexpr float kFlatResultant = 0.9f;
  std::vector<Eigen::Vector3f> next (normals);
  forEachPoint (normals.size (), workers, [&] (std::size_t i) {
    const Eigen::Vector3f& n = normals[i];
    if (n.isZero ())
      return;
    int agree = 0, others = 0;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero ();
    for (int e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e)
    {
      const Eigen::Vector3f& m = normals[static_cast<std::size_t> (graph.targets[static_cast<std::size_t> (e)])];
      if (m.isZero ())
        continue;
      if (m.dot (n) >= kAgreeCosine)
        ++agree;
      else
      {
        ++others;
        sum += m;
      }
    }
    const float length = sum.norm ();
    if (agree + others < 4 || 4 * agree >= agree + others || length <= kFlatResultant * static_cast<float> (others))
      return;
    const Eigen::Vector3f mean = sum / length;
    if (std::abs (mean.dot (n)) < kAgreeCosine)
      next[i] = mean;
  });
  normals.swap (next);
}

/** \brief Bilateral smoothing of oriented normals over the neighbour graph: each normal
  * becomes the mean of its own and its neighbours' that lie within kSmoothCosine of it (the
  * same face), kSmoothPasses times. A plane fitted to k noisy neighbours tilts by about
  * sigma / spacing; averaging the normals of one face cuts that without rounding its edges. */
void
smoothNormals (const Graph& graph, std::vector<Eigen::Vector3f>& normals, std::size_t workers)
{
  constexpr int kSmoothPasses = 2;
  constexpr float kSmoothCosine = 0.7071f;
  std::vector<Eigen::Vector3f> next (normals.size ());
  for (int pass = 0; pass < kSmoothPasses; ++pass)
  {
    forEachPoint (normals.size (), workers, [&] (std::size_t i) {
      const Eigen::Vector3f& n = normals[i];
      if (n.isZero ())
      {
        next[i] = n;
        return;
      }
      // Without a branch (whether a neighbour is on the same face is a coin toss near edges):
      // a neighbour off the face adds -0, which leaves every sum as it is.
      Eigen::Vector3f sum = n;
      for (int e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e)
      {
        const Eigen::Vector3f& m = normals[static_cast<std::size_t> (graph.targets[static_cast<std::size_t> (e)])];
        const bool same_face = (m.x () * n.x () + m.y () * n.y ()) + m.z () * n.z () > kSmoothCosine;
        sum.x () += same_face ? m.x () : -0.0f;
        sum.y () += same_face ? m.y () : -0.0f;
        sum.z () += same_face ? m.z () : -0.0f;
      }
      next[i] = sum.normalized ();
    });
    normals.swap (next);
  }
}
/** \brief A monotone stand-in for the angle of (x, y) in [0, 2 pi): in [0, 4), a division
  * where std::atan2 cost a tenth of the openings pass. */
double
pseudoAngle (double x, double y)
{
  if (y >= 0.0)
    return x >= 0.0 ? y / std::max (x + y, 1e-300) : 1.0 - x / (y - x);
  return x < 0.0 ? 2.0 - y / (-x - y) : 3.0 + x / std::max (x - y, 1e-300);
}

/** \brief The surface area sample i stands for (SurfaceModel::areas): its Voronoi cell among
  * its neighbours, in its tangent plane, cut by the ellipse of their spread there (two
  * deviations along each axis about their mean: the disc of radius r_k on a uniformly filled
  * disc, about the strip itself across a strip narrower than the neighbourhood). Barill et al.
  * (2018) weigh their dipoles by the same kind of tangent-plane Voronoi area. On uniformly random
  * samples (k = 10) these sum to 0.95 of a plane's area and 0.98 of a strip's, on a square
  * lattice to 1.00; the squared spacings to 0.76, 0.83 and 0.99 (a randomly sampled closed
  * sphere's winding number read 0.76 at its centre). Copies of the sample among its neighbours
  * (at exactly its position) share its cell. The normal is the one fitted to the neighbours (or
  * given), before the orientation's repair and smoothing, which turn about 1 % of a noisy
  * plane's normals and move the total area by under 2 %. Neighbours are input indices (-1: none). */
double
neighbourhoodArea (const std::vector<Eigen::Vector3d>& points, std::size_t i, const int* neighbours, std::size_t k,
                   const Eigen::Vector3f& normal)
{
  // The neighbourhood's mean and spread relative to the sample (differences, so that copies
  // of the sample add exact zeros), and the copies among the neighbours.
  const Eigen::Vector3d& p = points[i];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero ();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero ();
  double count = 1.0, copies = 0.0;
  for (std::size_t j = 0; j < k; ++j)
  {
    const int t = neighbours[j];
    if (t < 0 || static_cast<std::size_t> (t) >= points.size ())
      continue;
    const Eigen::Vector3d d = points[static_cast<std::size_t> (t)] - p;
    mean += d;
    second += d * d.transpose ();
    count += 1.0;
    copies += d.isZero (0.0) ? 1.0 : 0.0;
  }
  mean /= count;
  const Eigen::Matrix3d spread = second / count - mean * mean.transpose ();
  // The plane: the sample's normal's (a fit to the same neighbours, or a mesh face's), else
  // the neighbours' two larger spreads.
  Eigen::Vector3d e_u, e_v;
  if (!normal.isZero ())
  {
    const Eigen::Vector3d n = normal.cast<double> ();
    e_u = n.unitOrthogonal ();
    e_v = n.cross (e_u);
  }
  else
  {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect (spread, Eigen::ComputeEigenvectors);
    e_u = solver.eigenvectors ().col (2);
    e_v = solver.eigenvectors ().col (1);
  }
  // The spread in the plane and its axes (a symmetric 2 x 2 in closed form).
  const double suu = e_u.dot (spread * e_u), svv = e_v.dot (spread * e_v), suv = e_u.dot (spread * e_v);
  const double mid = 0.5 * (suu + svv), radius = std::hypot (0.5 * (suu - svv), suv);
  const double l_major = mid + radius, l_minor = mid - radius;
  if (!(l_minor > 1e-12 * l_major))
    return 0.0;  // collinear (up to rounding) or coincident neighbours: no area
  // The major axis's direction in (u, v): of the two forms of the eigenvector, the longer
  // (either can vanish); any direction when the spread is round.
  const Eigen::Vector2d form_a (l_major - svv, suv), form_b (suv, l_major - suu);
  Eigen::Vector2d major = form_a.squaredNorm () >= form_b.squaredNorm () ? form_a : form_b;
  major = major.squaredNorm () > 0.0 ? Eigen::Vector2d (major.normalized ()) : Eigen::Vector2d (1.0, 0.0);
  const Eigen::Vector2d minor (-major.y (), major.x ());
  // The ellipse as a polygon of kSides vertices with the ellipse's area.
  constexpr int kSides = 8;
  static const std::array<Eigen::Vector2d, kSides> unit = [] {
    std::array<Eigen::Vector2d, kSides> u;
    const double fit = std::sqrt (2.0 * kPi / (kSides * std::sin (2.0 * kPi / kSides)));
    for (int j = 0; j < kSides; ++j)
      u[static_cast<std::size_t> (j)] = fit * Eigen::Vector2d (std::cos (2.0 * kPi * j / kSides), std::sin (2.0 * kPi * j / kSides));
    return u;
  }();
  const Eigen::Vector2d centre (mean.dot (e_u), mean.dot (e_v));
  const double a = 2.0 * std::sqrt (l_major), b = 2.0 * std::sqrt (l_minor);
  // A convex polygon gains at most one vertex a cut: kSides + k vertices at most. Room for
  // twice that; should rounding make the polygon not quite convex, clipping stops before a cut
  // could overflow it (at most two vertices out for each in).
  constexpr std::size_t kOnStack = 128;
  const std::size_t capacity = std::max (kOnStack, 2 * (kSides + k));
  std::array<Eigen::Vector2d, kOnStack> stack_a, stack_b;
  std::vector<Eigen::Vector2d> heap_a, heap_b;
  Eigen::Vector2d *polygon = stack_a.data (), *cut = stack_b.data ();
  if (capacity > kOnStack)
  {
    heap_a.resize (capacity);
    heap_b.resize (capacity);
    polygon = heap_a.data ();
    cut = heap_b.data ();
  }
  std::size_t size = kSides;
  double reach2 = 0.0;  // the largest squared distance of a vertex from the sample
  for (std::size_t j = 0; j < size; ++j)
  {
    polygon[j] = centre + (a * unit[j].x ()) * major + (b * unit[j].y ()) * minor;
    reach2 = std::max (reach2, polygon[j].squaredNorm ());
  }
  for (std::size_t j = 0; j < k && size >= 3 && 2 * size <= capacity; ++j)
  {
    const int t = neighbours[j];
    if (t < 0 || static_cast<std::size_t> (t) >= points.size ())
      continue;
    const Eigen::Vector3d d = points[static_cast<std::size_t> (t)] - p;
    const Eigen::Vector2d v (d.dot (e_u), d.dot (e_v));
    const double half = 0.5 * v.squaredNorm ();
    // No bisector in the plane (a duplicate, or straight across it), or one farther from the
    // sample than every vertex (x . v <= |x| |v|): nothing to cut. Past the first few cuts most
    // neighbours are skipped on this test alone.
    if (!(half > 0.0) || half * half >= reach2 * v.squaredNorm ())
      continue;
    // Keep x . v <= |v|^2 / 2, the side of the bisector nearer to the sample.
    std::size_t kept = 0;
    for (std::size_t m = 0; m < size; ++m)
    {
      const Eigen::Vector2d& x = polygon[m];
      const Eigen::Vector2d& y = polygon[m + 1 < size ? m + 1 : 0];
      const double fx = x.dot (v) - half, fy = y.dot (v) - half;
      if (fx <= 0.0)
        cut[kept++] = x;
      if ((fx < 0.0 && fy > 0.0) || (fx > 0.0 && fy < 0.0))
        cut[kept++] = x + (fx / (fx - fy)) * (y - x);
    }
    std::swap (polygon, cut);
    size = kept;
    reach2 = 0.0;
    for (std::size_t m = 0; m < size; ++m)
      reach2 = std::max (reach2, polygon[m].squaredNorm ());
  }
  double twice = 0.0;
  for (std::size_t m = 0; m < size; ++m)
  {
    const Eigen::Vector2d& x = polygon[m];
    const Eigen::Vector2d& y = polygon[m + 1 < size ? m + 1 : 0];
    twice += x.x () * y.y () - x.y () * y.x ();
  }
  return size >= 3 ? 0.5 * std::abs (twice) / (1.0 + copies) : 0.0;
}

/** \brief SurfaceModel::openings for point i: the widest angle between its neighbours in the
  * plane of its (unoriented) normal; `reach` the distance to its k-th neighbour. */
Eigen::Vector4f
openingOf (const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3f& normal, std::size_t i, const int* neighbours,
           std::size_t k, float reach)
{
  if (normal.isZero ())
    return Eigen::Vector4f::Zero ();
  const Eigen::Vector3d n = normal.cast<double> ();
  const Eigen::Vector3d u = n.unitOrthogonal ();
  const Eigen::Vector3d v = n.cross (u);
  struct Direction
  {
    double key, a, b;  ///< pseudoAngle (a, b); coordinates along u and v
  };
  std::array<Direction, 64> dir;
  std::size_t count = 0;
  double sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
  for (std::size_t j = 0; j < k && count < dir.size (); ++j)
  {
    const int t = neighbours[j];
    if (t < 0 || static_cast<std::size_t> (t) >= points.size () || static_cast<std::size_t> (t) == i)
      continue;
    const Eigen::Vector3d d = points[static_cast<std::size_t> (t)] - points[i];
    const double a = d.dot (u), b = d.dot (v);
    const double r = std::sqrt (a * a + b * b);
    if (r <= 1e-12 * std::max (d.norm (), 1e-300))
      continue;  // straight above or below: no direction in the plane
    dir[count++] = {pseudoAngle (a, b), a / r, b / r};
    sa += a;
    sb += b;
    saa += a * a;
    sbb += b * b;
    sab += a * b;
  }
  if (count < 2)
    return Eigen::Vector4f::Zero ();
  // Neighbours along a line (their smaller spread in the plane under kOpenLineRatio of the
  // larger) show no side.
  const double m = static_cast<double> (count);
  const double caa = saa / m - (sa / m) * (sa / m), cbb = sbb / m - (sb / m) * (sb / m);
  const double cab = sab / m - (sa / m) * (sb / m);
  const double half_trace = 0.5 * (caa + cbb);
  const double root = std::sqrt (std::max (0.0, half_trace * half_trace - (caa * cbb - cab * cab)));
  if (half_trace - root < kOpenLineRatio * (half_trace + root))
    return Eigen::Vector4f::Zero ();
  std::sort (dir.begin (), dir.begin () + static_cast<std::ptrdiff_t> (count),
             [] (const Direction& x, const Direction& y) { return x.key < y.key; });
  // The angle from each direction to the next counterclockwise, compared by its own pseudo-angle.
  double widest = -1.0;
  std::size_t from = 0;
  for (std::size_t j = 0; j < count; ++j)
  {
    const Direction& p = dir[j];
    const Direction& q = dir[(j + 1) % count];
    const double gap = pseudoAngle (p.a * q.a + p.b * q.b, p.a * q.b - p.b * q.a);
    if (gap > widest)
    {
      widest = gap;
      from = j;
    }
  }
  static const double threshold =
    pseudoAngle (std::cos (kOpenGapDegrees * kPi / 180.0), std::sin (kOpenGapDegrees * kPi / 180.0));
  if (widest <= threshold)
    return Eigen::Vector4f::Zero ();
  const Direction& p = dir[from];
  const Direction& q = dir[(from + 1) % count];
  const double cosine = std::min (1.0, std::max (-1.0, p.a * q.a + p.b * q.b));
  // Half the angle from p to q, counterclockwise: past 180 degrees the bisector is minus the
  // sum's direction; at 180 exactly, p turned a quarter.
  double ba = p.a + q.a, bb = p.b + q.b;
  const double norm = std::sqrt (ba * ba + bb * bb);
  if (norm < 1e-9)
  {
    ba = -p.b;
    bb = p.a;
  }
  else
  {
    const double sign = p.a * q.b - p.b * q.a >= 0.0 && widest < 2.0 ? 1.0 : -1.0;
    ba *= sign / norm;
    bb *= sign / norm;
  }
  const Eigen::Vector3d bisector = static_cast<double> (reach) * (ba * u + bb * v);
  // cos(theta / 2) from cos(theta): the root's sign is the half angle's, negative past 180
  // degrees (a sheet's corner, open 270 degrees, has an open cone of +-135 degrees, not +-45).
  const double half_cosine = std::sqrt (0.5 * (1.0 + cosine));
  return {static_cast<float> (bisector.x ()), static_cast<float> (bisector.y ()), static_cast<float> (bisector.z ()),
          static_cast<float> (widest < 2.0 ? half_cosine : -half_cosine)};
}
} // namespace

double
SurfaceModel::ViewBins::depthOf (const Eigen::Vector3d& r, int& a, std::int64_t& face) const
{
  a = axis;
  double s = sign;
  face = 0;
  if (inside)
  {
    r.cwiseAbs ().maxCoeff (&a);
    s = r[a] < 0.0 ? -1.0 : 1.0;
    face = 2 * a + (s < 0.0 ? 1 : 0);
  }
  return s * r[a];
}

bool
SurfaceModel::ViewBins::keyOf (const Eigen::Vector3d& x, Key& key) const
{
  const Eigen::Vector3d r = relative (x);
  int a = 0;
  std::int64_t face = 0;
  const double t = depthOf (r, a, face);
  if (!(t > 0.0) || !(bin > 0.0))
    return false;
  const int u = (a + 1) % 3, v = (a + 2) % 3;
  const double cu = std::floor (r[u] / t / bin), cv = std::floor (r[v] / t / bin);
  // Far off the axis (a line of sight nearly parallel to the view's plane) no sample is binned.
  constexpr double kLimit = 1e15;
  if (!(std::abs (cu) < kLimit && std::abs (cv) < kLimit))
    return false;
  key = {face, static_cast<std::int64_t> (cu), static_cast<std::int64_t> (cv)};
  return true;
}

SurfaceModel::ViewBins
SurfaceModel::binView (const std::vector<Eigen::Vector3d>& points, const std::vector<float>& spacing,
                       const std::function<Eigen::Vector3f (std::size_t)>& plane_of, const Eigen::Vector3d& view,
                       const detail::OrientedBox& box, double* hidden)
{
  ViewBins bins;
  if (hidden)
    *hidden = 0.0;
  const std::size_t n = points.size ();
  if (n < 2)
    return bins;
  bins.view = view;
  bins.frame = box.axes ();
  // The axis along which view lies farthest outside the box: every point is in front of it.
  const Eigen::Vector3d at = box.boxCoordinates (view), h = box.halfExtents ();
  double best = -1.0;
  for (int d = 0; d < 3; ++d)
  {
    if (-h[d] - at[d] > best)
    {
      best = -h[d] - at[d];
      bins.axis = d;
      bins.sign = 1.0;
    }
    if (at[d] - h[d] > best)
    {
      best = at[d] - h[d];
      bins.axis = d;
      bins.sign = -1.0;
    }
  }
  // Inside the box (best <= 0), each point is binned on the cube face its direction crosses.
  bins.inside = !(best > 0.0);
  std::vector<double> depth (n), range (n), scratch;
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector3d r = bins.relative (points[i]);
    int a = 0;
    std::int64_t face = 0;
    depth[i] = bins.depthOf (r, a, face);
    range[i] = r.norm ();
  }
  auto median = [&scratch] (auto begin, auto end) {
    scratch.assign (begin, end);
    std::nth_element (scratch.begin (), scratch.begin () + static_cast<std::ptrdiff_t> (scratch.size () / 2), scratch.end ());
    return scratch[scratch.size () / 2];
  };
  const double s_median = median (spacing.begin (), spacing.end ());
  bins.bin = 2.0 * s_median / std::max (median (depth.begin (), depth.end ()), 1e-300);
  if (!(bins.bin > 0.0) || !std::isfinite (bins.bin))
  {
    bins.bin = 0.0;
    return bins;
  }
  std::vector<std::pair<ViewBins::Key, std::size_t>> cells;
  cells.reserve (n);
  for (std::size_t i = 0; i < n; ++i)
  {
    ViewBins::Key key;
    if (bins.keyOf (points[i], key))
      cells.emplace_back (key, i);
  }
  std::sort (cells.begin (), cells.end ());
  std::size_t count = 0;
  for (std::size_t b = 0; b < cells.size ();)
  {
    std::size_t e = b;
    double nearest = std::numeric_limits<double>::infinity ();
    std::size_t nearest_index = cells[b].second;
    for (; e < cells.size () && cells[e].first == cells[b].first; ++e)
      if (range[cells[e].second] < nearest)
      {
        nearest = range[cells[e].second];
        nearest_index = cells[e].second;
      }
    const Eigen::Vector3d plane = plane_of (nearest_index).cast<double> ();
    for (std::size_t j = b; j < e; ++j)
    {
      const std::size_t i = cells[j].second;
      const double margin = kHiddenSpacings * std::max<double> (spacing[i], s_median);
      count += range[i] > nearest + margin &&
                       (plane.isZero () || std::abs (plane.dot (points[i] - points[nearest_index])) > margin)
                   ? 1
                   : 0;
    }
    bins.keys.push_back (cells[b].first);
    bins.nearest.push_back ({static_cast<float> (nearest), static_cast<std::int32_t> (nearest_index)});
    b = e;
  }
  if (hidden)
    *hidden = static_cast<double> (count) / static_cast<double> (n);
  // A view outside: one face, the bins a grid (a scan's cover its field of view densely).
  if (!bins.inside && !bins.keys.empty ())
  {
    std::int64_t u1 = bins.keys.front ()[1], v1 = bins.keys.front ()[2];
    bins.u0 = u1;
    bins.v0 = v1;
    for (const ViewBins::Key& key : bins.keys)
    {
      bins.u0 = std::min (bins.u0, key[1]);
      u1 = std::max (u1, key[1]);
      bins.v0 = std::min (bins.v0, key[2]);
      v1 = std::max (v1, key[2]);
    }
    const double cells = (double (u1 - bins.u0) + 1.0) * (double (v1 - bins.v0) + 1.0);
    if (cells <= double (ViewBins::kDenseCells) * double (bins.keys.size ()))
    {
      bins.width = u1 - bins.u0 + 1;
      bins.height = v1 - bins.v0 + 1;
      bins.grid.assign (static_cast<std::size_t> (bins.width * bins.height), ViewBins::Nearest ());
      for (std::size_t j = 0; j < bins.keys.size (); ++j)
        bins.grid[static_cast<std::size_t> ((bins.keys[j][2] - bins.v0) * bins.width + (bins.keys[j][1] - bins.u0))] =
            bins.nearest[j];
      bins.keys = std::vector<ViewBins::Key> ();
      bins.nearest = std::vector<ViewBins::Nearest> ();
    }
  }
  return bins;
}

SurfaceModel::ViewBins::Nearest
SurfaceModel::ViewBins::nearestOf (const Key& key) const
{
  if (!grid.empty ())
  {
    const std::int64_t u = key[1] - u0, v = key[2] - v0;
    return u < 0 || v < 0 || u >= width || v >= height ? Nearest () : grid[static_cast<std::size_t> (v * width + u)];
  }
  const auto it = std::lower_bound (keys.begin (), keys.end (), key);
  return it == keys.end () || *it != key ? Nearest () : nearest[static_cast<std::size_t> (it - keys.begin ())];
}

bool
SurfaceModel::mayLieBehindView (const std::array<Eigen::Vector3d, 8>& corners, double margin, std::int64_t max_bins) const
{
  const ViewBins& b = view_bins_;
  if (b.grid.empty ())
    return !b.empty ();
  const int u = (b.axis + 1) % 3, v = (b.axis + 2) % 3;
  double u_lo = std::numeric_limits<double>::infinity (), u_hi = -u_lo, v_lo = u_lo, v_hi = -u_lo, farthest = 0.0;
  for (const Eigen::Vector3d& c : corners)
  {
    const Eigen::Vector3d r = b.relative (c);
    const double t = b.sign * r[b.axis];
    if (!(t > 0.0))
      return true;
    // A central projection maps the box to the hull of its corners' images; the distance to the
    // view is convex, so its largest value on the box is at a corner.
    u_lo = std::min (u_lo, r[u] / t / b.bin);
    u_hi = std::max (u_hi, r[u] / t / b.bin);
    v_lo = std::min (v_lo, r[v] / t / b.bin);
    v_hi = std::max (v_hi, r[v] / t / b.bin);
    farthest = std::max (farthest, r.norm ());
  }
  const double u0 = std::max (std::floor (u_lo), double (b.u0)), u1 = std::min (std::floor (u_hi), double (b.u0 + b.width - 1));
  const double v0 = std::max (std::floor (v_lo), double (b.v0)), v1 = std::min (std::floor (v_hi), double (b.v0 + b.height - 1));
  if (u0 > u1 || v0 > v1)
    return false;  // beside every bin the scan filled
  if ((u1 - u0 + 1.0) * (v1 - v0 + 1.0) > double (max_bins))
    return true;
  for (auto j = static_cast<std::int64_t> (v0); j <= static_cast<std::int64_t> (v1); ++j)
    for (auto i = static_cast<std::int64_t> (u0); i <= static_cast<std::int64_t> (u1); ++i)
    {
      const float nearest = b.grid[static_cast<std::size_t> ((j - b.v0) * b.width + (i - b.u0))].range;
      if (farthest - double (nearest) > margin)  // false for an empty (NaN) bin
        return true;
    }
  return false;
}

double
SurfaceModel::behindView (const ProbabilisticBVH& bvh, const Eigen::Vector3d& x, double* beyond) const
{
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();
  if (beyond)
    *beyond = kNaN;
  ViewBins::Key key;
  if (view_bins_.empty () || !view_bins_.keyOf (x, key) || bvh.size () != normals_.size ())
    return kNaN;
  const double range = (x - view_bins_.view).norm ();
  // Behind the bin's nearest sample: past its tangent plane (oriented toward the view), or,
  // without a normal, past its range.
  auto behind = [&] (const ViewBins::Nearest& nearest) {
    if (nearest.index < 0)
      return kNaN;
    const std::size_t j = static_cast<std::size_t> (nearest.index);
    const Eigen::Vector3d n = nearest.normal.cast<double> ();
    return n.isZero () ? range - double (nearest.range) : n.dot (bvh.means ()[j] - x);
  };
  // x's own bin first: most points a query asks about lie in front of what the scan saw.
  const ViewBins::Nearest own = view_bins_.nearestOf (key);
  double least = behind (own);
  if (!(least > 0.0) && !std::isnan (least))
  {
    if (beyond)
      *beyond = range - double (own.range);
    return least;
  }
  // A bin of a slanted scan holds a sample or two, and one may be empty inside a surface; beside
  // a silhouette, or where the scan saw nothing, a row of them is.
  int empty = 0;
  least = std::numeric_limits<double>::infinity ();
  double along = std::numeric_limits<double>::infinity ();
  for (std::int64_t du = -1; du <= 1; ++du)
    for (std::int64_t dv = -1; dv <= 1; ++dv)
    {
      const ViewBins::Nearest nearest = view_bins_.nearestOf ({key[0], key[1] + du, key[2] + dv});
      const double d = behind (nearest);
      if (std::isnan (d) && ++empty > kMaxEmptyBins)
        return kNaN;
      if (!std::isnan (d))
      {
        least = std::min (least, d);
        along = std::min (along, range - double (nearest.range));
      }
    }
  if (beyond)
    *beyond = own.index >= 0 ? range - double (own.range) : along;
  return least;
}

void
SurfaceModel::build (const ProbabilisticBVH& bvh, Inputs&& in, NormalOrientation mode)
{
  const std::size_t n = bvh.size ();
  if (in.normals.size () != n || in.radii.size () != n || in.k < 1 ||
      in.neighbours.size () != n * static_cast<std::size_t> (in.k) || (!in.given.empty () && in.given.size () != n))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::SurfaceModel::build] inputs of " << in.normals.size () << " normals, "
                                                                               << in.radii.size () << " radii and "
                                                                               << in.neighbours.size ()
                                                                               << " neighbours for " << n << " points");
  const std::vector<Eigen::Vector3d>& points = bvh.means ();
  normals_ = std::move (in.normals);
  for (Eigen::Vector3f& v : normals_)
  {
    const float norm = v.norm ();
    v = norm > 0.0f && std::isfinite (norm) ? Eigen::Vector3f (v / norm) : Eigen::Vector3f::Zero ();
  }
  spacing_.resize (n);
  areas_.resize (n);
  std::vector<Eigen::Vector4f> open (n, Eigen::Vector4f::Zero ());
  const double scale = std::sqrt (kPi / in.k);
  const std::size_t k = static_cast<std::size_t> (in.k);
  const std::size_t workers = detail::threadCount (in.threads);
  // The spread of point i and its k neighbours (their covariance), or nothing for fewer than
  // three.
  struct Spread
  {
    Eigen::Matrix3d covariance;
    double count;  ///< the point and its neighbours
  };
  auto neighbourSpread = [&] (std::size_t i) -> std::optional<Spread> {
    Eigen::Vector3d mean = points[i];
    Eigen::Matrix3d second = points[i] * points[i].transpose ();
    double count = 1.0;
    for (std::size_t j = 0; j < k; ++j)
    {
      const int t = in.neighbours[i * k + j];
      if (t < 0 || static_cast<std::size_t> (t) >= n)
        continue;
      const Eigen::Vector3d& p = points[static_cast<std::size_t> (t)];
      mean += p;
      second += p * p.transpose ();
      count += 1.0;
    }
    if (count < 3.0)
      return std::nullopt;
    mean /= count;
    return Spread {second / count - mean * mean.transpose (), count};
  };
  // Given normals that do not belong to their points (moved with pcl::transformPointCloud
  // rather than transformPointCloudWithNormals, or another cloud's) lie along the surface: the
  // neighbours spread more along such a normal than across it. The median, over probes, of the
  // spread along the normal over the mean spread across it: about 0 for normals that belong
  // (the noise's share), 1 where the noise hides the surface, 2 for normals lying in the surface.
  normal_spread_ratio_ = std::numeric_limits<double>::quiet_NaN ();
  normals_off_surface_ = false;
  {
    std::vector<std::size_t> given;
    for (std::size_t i = 0; i < in.given.size (); ++i)
      if (in.given[i] && !normals_[i].isZero () && std::isfinite (in.radii[i]))
        given.push_back (i);
    std::vector<double> ratios;
    const std::size_t probes = std::min (given.size (), kNormalProbes);
    for (std::size_t j = 0; j < probes; ++j)
    {
      const std::size_t i = given[j * given.size () / probes];
      const std::optional<Spread> spread = neighbourSpread (i);
      if (!spread)
        continue;
      const Eigen::Vector3d nd = normals_[i].cast<double> ();
      const double along = nd.dot (spread->covariance * nd), across = 0.5 * (spread->covariance.trace () - along);
      if (across > 0.0)
        ratios.push_back (along / across);
    }
    if (!ratios.empty ())
    {
      std::nth_element (ratios.begin (), ratios.begin () + static_cast<std::ptrdiff_t> (ratios.size () / 2), ratios.end ());
      normal_spread_ratio_ = ratios[ratios.size () / 2];
    }
    // Auto sets them aside: each point takes its neighbours' plane, unoriented, as without them.
    normals_off_surface_ = mode == NormalOrientation::Auto && normal_spread_ratio_ > kMaxNormalSpreadRatio;
    if (normals_off_surface_)
    {
      in.given.assign (n, 0);
      forEachPoint (n, workers, [&] (std::size_t i) {
        const std::optional<Spread> spread = std::isfinite (in.radii[i]) ? neighbourSpread (i) : std::nullopt;
        normals_[i] = Eigen::Vector3f::Zero ();
        if (spread)
        {
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
          solver.computeDirect (spread->covariance, Eigen::ComputeEigenvectors);
          normals_[i] = solver.eigenvectors ().col (0).cast<float> ();
        }
      });
    }
  }
  forEachPoint (n, workers, [&] (std::size_t i) {
    if (!std::isfinite (in.radii[i]))
    {
      spacing_[i] = 0.0f;
      areas_[i] = 0.0f;
      return;
    }
    double s = in.radii[i] * scale;
    // On a strip narrower than the neighbourhood (a board's edge, a leg, a thin rim) the k
    // neighbours do not fill the disc of radius r_k: the area they cover is that of the ellipse
    // of their spread in the plane, 4 pi sqrt(l1 l2) (l1, l2 the two larger eigenvalues; pi r^2
    // on a uniformly filled disc), so the spacing is at most sqrt(area / (k + 1)).
    const std::optional<Spread> spread = neighbourSpread (i);
    if (spread)
    {
      // Closed form (computeDirect): the iterative solver was a fifth of the surface model's build.
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
      const Eigen::Vector3d l = solver.computeDirect (spread->covariance, Eigen::EigenvaluesOnly).eigenvalues ();
      const double area = 4.0 * kPi * std::sqrt (std::max (0.0, l[1]) * std::max (0.0, l[2]));
      s = std::min (s, std::sqrt (area / spread->count));
    }
    // The area reads the same neighbours again, in differences from the sample: the spacing
    // above keeps its own sums, so that its values (which the query's reaches were chosen with)
    // stay those it had before the areas.
    areas_[i] = static_cast<float> (spread ? neighbourhoodArea (points, i, &in.neighbours[i * k], k, normals_[i]) : s * s);
    spacing_[i] = static_cast<float> (s);
    open[i] = openingOf (points, normals_[i], i, &in.neighbours[i * k], k, in.radii[i]);
  });
  packOpenings (open);
  open = std::vector<Eigen::Vector4f> ();
  // The spacing's statistics (a sort of every point's) need nothing of what follows until the
  // end: on a thread of their own when the build has several.
  auto spacingStatistics = [this] {
    std::vector<float> sorted (spacing_);
    // Weighted by area: half the surface's area lies on samples at most this far apart. The
    // spacings are finite and >= 0, so none is dropped and sorted is sorted in full.
    surface_spacing_ = detail::areaWeightedMedian (sorted);
    median_spacing_ = sorted.empty () ? 0.0 : sorted[sorted.size () / 2];
  };
  std::future<void> statistics;
  if (workers > 1)
    statistics = std::async (std::launch::async, spacingStatistics);
  else
    spacingStatistics ();

  const Graph graph = symmetricGraph (in.neighbours, in.k, n);

  // Resolve Auto: the caller's normals, else a viewpoint outside the cloud that sees it as one
  // scan does (binView's hidden share), else propagation.
  bool any_given = false;
  for (std::size_t i = 0; i < in.given.size () && !any_given; ++i)
    any_given = in.given[i] && !normals_[i].isZero ();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero ();
  for (const Eigen::Vector3d& p : points)
    centroid += p;
  centroid /= std::max<std::size_t> (n, 1);
  // The cloud's bounding box on its principal axes (the hierarchy's root): whether the viewpoint
  // lies inside it, and the view's bins, turn with the cloud (an axis-aligned box would not).
  const detail::OrientedBox box = bvh.empty () ? detail::OrientedBox () : bvh.node (ProbabilisticBVH::rootId ()).box;
  const bool view_outside = in.viewpoint && in.viewpoint->allFinite () && n > 0 && !box.contains (*in.viewpoint);
  // A sensor sees its samples from many spacings away (a depth camera at its 0.5 m minimum range,
  // hundreds); a viewpoint within a few spacings of the nearest sample is none's. PCL's default
  // origin 3 mm under a cylinder sampled all round "hid" 4 % of it, its bins too wide for the
  // samples near it, and Auto oriented the solid toward it (W2's cylinder on a plane, 4 and 6
  // sigma_eff clear, read contact).
  bool view_far = false;
  if (view_outside)
  {
    if (statistics.valid ())
      statistics.get ();
    double nearest = std::numeric_limits<double>::infinity ();
    for (const Eigen::Vector3d& p : points)
      nearest = std::min (nearest, (p - *in.viewpoint).squaredNorm ());
    view_far = std::sqrt (nearest) > kMinViewSpacings * median_spacing_;
  }
  hidden_from_view_ = std::numeric_limits<double>::quiet_NaN ();
  // The viewpoint's bins, built once: for the hidden share, and kept for behindView.
  std::optional<ViewBins> bins;
  // A bin's plane is its nearest sample's tangent plane, unless that sample's normal lies more
  // than 45 degrees off the plane of its neighbours about their centroid, where these spread
  // across a patch: a fitted normal is the plane about the sample itself, which the noise can lift
  // off its surface, and it then lies in the surface (8 % of a depth camera's samples at 1 m, 2.5
  // mm apart with 2 mm noise, after the stray normals' repair); a part 8 cm behind a box's top
  // seen from above read in front of it. The normal stays where it agrees: the model's are
  // smoothed, and a floor seen at a grazing angle, where a tilt of 10 degrees moves a point 10 cm
  // under it in front of its plane, needs that.
  auto planeOf = [&] (std::size_t i) -> Eigen::Vector3f {
    const Eigen::Vector3f& normal = normals_[i];
    const std::optional<Spread> spread = std::isfinite (in.radii[i]) ? neighbourSpread (i) : std::nullopt;
    if (!spread)
      return normal;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect (spread->covariance, Eigen::ComputeEigenvectors);
    const Eigen::Vector3d l = solver.eigenvalues ();
    const Eigen::Vector3f across = solver.eigenvectors ().col (0).cast<float> ();
    const bool patch = l[1] >= kPatchSpread * l[2];
    return patch && !(std::abs (normal.dot (across)) >= kStrayNormalCosine * normal.norm ()) ? across : normal;
  };
  auto hiddenShare = [&] {
    double share = 0.0;
    bins = binView (points, spacing_, planeOf, *in.viewpoint, box, &share);
    return share;
  };
  if (mode == NormalOrientation::Auto && !any_given && view_outside && view_far)
    hidden_from_view_ = hiddenShare ();
  // Given normals that face the viewpoint as a scan's do: enough of them facing it, few away
  // (PCL's normal estimation turns every normal toward its viewpoint). Outward normals of a
  // closed object face a viewpoint outside it on one side and away on the other. Read by Auto
  // (normals_turned_to_view_) and, for a viewpoint outside, by seen_from_view_.
  bool given_face_view = false, most_face_view = false;
  given_face_away_ = false;
  given_misoriented_ = false;
  given_away_share_ = given_side_disagreement_ = std::numeric_limits<double>::quiet_NaN ();
  if (any_given && in.viewpoint && in.viewpoint->allFinite () &&
      (mode == NormalOrientation::Auto || (mode == NormalOrientation::PointNormals && view_outside)))
  {
    std::size_t toward = 0, away = 0, given = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (!in.given[i] || normals_[i].isZero ())
        continue;
      ++given;
      const Eigen::Vector3d sight = *in.viewpoint - points[i];
      const double cosine = normals_[i].cast<double> ().dot (sight) / std::max (sight.norm (), 1e-300);
      toward += cosine >= kMinViewCosine ? 1 : 0;
      away += cosine <= -kMinViewCosine ? 1 : 0;
    }
    const double facing = static_cast<double> (toward + away);
    given_face_view = facing >= kMinViewSeeds * static_cast<double> (n) &&
                      static_cast<double> (away) <= kMaxViewDisagreement * facing;
    // Setting normals aside asks more: most of them facing it, not a few seen edge-on (a sheet
    // with PCL's default origin in its own plane).
    most_face_view = given_face_view && 2 * (toward + away) >= given;
    // The mirror image from outside: a sensor sees a surface's front, so normals facing away from
    // it nearly all were turned the wrong way (a probe: a table's normals given pointing down,
    // its sensor above, read a plate 12 mm over it as collision). Said (CloudModel::warning), not
    // changed: from inside an object (PCL's default origin in a mug) outward normals face away.
    given_face_away_ = view_outside && facing >= kMinViewSeeds * static_cast<double> (n) &&
                       static_cast<double> (toward) <= kMaxViewDisagreement * facing && 2 * away >= given;
    // Normals and a viewpoint outside the cloud that disagree: more than a tenth of those facing
    // it or away face away. Either may be wrong: a scan's normals estimated without an
    // orientation (Open3D's estimate_normals leaves each sign to its eigen solver: on the scenes'
    // objects 68-81 % face away, on their tables 7-8 %), or a VIEWPOINT left behind by
    // pcl::transformPointCloud (a table's normals up, its stale origin on the floor below). Their
    // sides between neighbours tell: an orientation's agree, unoriented ones disagree (the scenes'
    // objects, 19-32 %). Where they disagree and the viewpoint sees the cloud as one scan, Auto
    // turns their directions toward it. (That check alone cannot judge a cloud without a usable viewpoint: a thin part's two
    // faces, blurred into one sheet by the noise, alternate just as much; W1's room and piano,
    // with their meshes' normals, disagreed on 23-49 % of their points.)
    given_away_share_ = facing > 0.0 ? static_cast<double> (away) / facing : std::numeric_limits<double>::quiet_NaN ();
    const bool against_view = view_outside && view_far && facing >= kMinViewSeeds * static_cast<double> (n) &&
                              static_cast<double> (away) > kMaxViewDisagreement * facing;
    if ((given_face_view && (view_outside || (mode == NormalOrientation::Auto && most_face_view))) || against_view)
      hidden_from_view_ = hiddenShare ();
    if (against_view && hidden_from_view_ <= SurfaceModel::kMaxHiddenShare)
    {
      std::vector<int> seeds (n, -1);
      for (std::size_t i = 0; i < n; ++i)
        if (in.given[i] && !normals_[i].isZero ())
          seeds[i] = 0;
      given_side_disagreement_ = viewDisagreement (graph, normals_, seeds, &points);
    }
    given_misoriented_ = given_side_disagreement_ > kMaxViewDisagreement;
  }
  // Such normals on a cloud that viewpoint cannot see as one scan (a sphere sampled all round,
  // its normals turned toward PCL's default origin beside it: two thirds point in; a mug's,
  // turned toward the origin inside it: all point in) say nothing of the outside: Auto keeps
  // their directions and propagates their sides. From inside a convex object nothing is hidden,
  // and its normals turned inward cannot be told from a room's scanned from within: kept.
  normals_turned_to_view_ = mode == NormalOrientation::Auto && most_face_view &&
                            hidden_from_view_ > SurfaceModel::kMaxHiddenShare;
  if (mode == NormalOrientation::Auto)
    mode = any_given && !normals_turned_to_view_ && !given_misoriented_ ? NormalOrientation::PointNormals
           : view_outside && view_far && hidden_from_view_ <= SurfaceModel::kMaxHiddenShare ? NormalOrientation::Viewpoint
                                                                              : NormalOrientation::Propagate;
  if (mode == NormalOrientation::Viewpoint && !(in.viewpoint && in.viewpoint->allFinite ()))
    mode = NormalOrientation::Propagate;
  orientation_ = mode;

  std::vector<int> component (n, -1);
  Propagation propagation (graph, normals_, component);
  std::size_t seeded = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (normals_[i].isZero ())
      continue;
    bool seed = false;
    if (mode == NormalOrientation::PointNormals)
      seed = !in.given.empty () && in.given[i];
    else if (mode == NormalOrientation::Viewpoint)
    {
      const Eigen::Vector3d sight = *in.viewpoint - points[i];
      const double cosine = normals_[i].cast<double> ().dot (sight) / std::max (sight.norm (), 1e-300);
      if (std::abs (cosine) >= kMinViewCosine)
      {
        seed = true;
        if (cosine < 0.0)
          normals_[i] = -normals_[i];
      }
    }
    if (seed)
    {
      component[i] = 0;
      ++seeded;
    }
  }
  // A viewpoint that sees the cloud edge-on (kMinViewSeeds, kMaxViewDisagreement), or normals asked
  // for where none is given, say nothing of either side: the orientation is then propagation's,
  // with its rules (two-sided unless checked closed), rather than a side picked by the farthest
  // point below and trusted.
  if (mode == NormalOrientation::Viewpoint &&
      (static_cast<double> (seeded) < kMinViewSeeds * static_cast<double> (n) ||
       viewDisagreement (graph, normals_, component) > kMaxViewDisagreement))
  {
    std::fill (component.begin (), component.end (), -1);
    seeded = 0;
  }
  if (mode != NormalOrientation::Propagate && seeded == 0)
    orientation_ = mode = NormalOrientation::Propagate;
  // Seen from one viewpoint, the space behind the surface was never observed (the query's
  // `unobserved`). Given normals say so too when they face a viewpoint outside the cloud as a
  // scan's do and it hides nothing.
  seen_from_view_ = mode == NormalOrientation::Viewpoint ||
                    (mode == NormalOrientation::PointNormals && given_face_view && view_outside &&
                     hidden_from_view_ <= SurfaceModel::kMaxHiddenShare);
  // Where the scan looked, and how far it saw, for the query's parts behind it.
  view_bins_ = ViewBins ();
  if (seen_from_view_)
    view_bins_ = bins ? std::move (*bins) : binView (points, spacing_, planeOf, *in.viewpoint, box, nullptr);
  for (std::size_t i = 0; i < n; ++i)
    if (component[i] == 0)
      propagation.seed (static_cast<int> (i));
  propagation.run ();

  // Whatever no seed reached (every point in Propagate mode): one part at a time, from its
  // point farthest from the centroid, pointing away from it; then the part's enclosed volume
  // decides (a closed surface oriented outward encloses a positive one).
  // (The farthest-first order is sorted only when some point is left: a scan oriented from its
  // viewpoint or by its own normals usually leaves none.)
  std::vector<std::size_t> order;
  bool unreached = false;
  for (std::size_t i = 0; i < n && !unreached; ++i)
    unreached = component[i] < 0 && !normals_[i].isZero ();
  if (unreached)
  {
    std::vector<double> distance (n);
    order.resize (n);
    for (std::size_t i = 0; i < n; ++i)
    {
      distance[i] = (points[i] - centroid).squaredNorm ();
      order[i] = i;
    }
    std::sort (order.begin (), order.end (), [&] (std::size_t x, std::size_t y) {
      return distance[x] > distance[y] || (distance[x] == distance[y] && x < y);
    });
  }
  int next_component = 1;
  for (const std::size_t s : order)
  {
    if (component[s] >= 0 || normals_[s].isZero ())
      continue;
    const int id = next_component++;
    if (normals_[s].cast<double> ().dot (points[s] - centroid) < 0.0)
      normals_[s] = -normals_[s];
    component[s] = id;
    propagation.seed (static_cast<int> (s));
    propagation.run ();
  }
  if (next_component > 1)
  {
    const std::size_t parts = static_cast<std::size_t> (next_component);
    std::vector<Eigen::Vector3d> part_centroid (parts, Eigen::Vector3d::Zero ());
    std::vector<double> part_count (parts, 0.0), volume (parts, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      if (component[i] > 0)
      {
        part_centroid[static_cast<std::size_t> (component[i])] += points[i];
        part_count[static_cast<std::size_t> (component[i])] += 1.0;
      }
    for (std::size_t c = 1; c < parts; ++c)
      part_centroid[c] /= std::max (part_count[c], 1.0);
    for (std::size_t i = 0; i < n; ++i)
      if (component[i] > 0)
      {
        const std::size_t c = static_cast<std::size_t> (component[i]);
        volume[c] += static_cast<double> (areas_[i]) * normals_[i].cast<double> ().dot (points[i] - part_centroid[c]);
      }
    for (std::size_t i = 0; i < n; ++i)
      if (component[i] > 0 && volume[static_cast<std::size_t> (component[i])] < 0.0)
        normals_[i] = -normals_[i];
  }
  repairStrayNormals (graph, normals_, workers);
  smoothNormals (graph, normals_, workers);
  unoriented_ = 0;
  propagated_ = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    unoriented_ += normals_[i].isZero () ? 1 : 0;
    propagated_ += mode != NormalOrientation::Propagate && component[i] != 0 && !normals_[i].isZero () ? 1 : 0;
  }

  if (statistics.valid ())
    statistics.get ();
  hidden_shell_ = seen_from_view_ ? kHiddenShellSpacings * median_spacing_ : 0.0;

  // Dipoles: each point counts in the first leaf holding it (leaves overlap by epsilon).
  const auto& nodes = bvh.nodes ();
  const int* indices = bvh.pointIndices ().data ();
  // Positions [begin, end) of a node's range in pointIndices().
  auto begin_of = [] (const ProbabilisticBVH::Node& node) { return static_cast<std::size_t> (node.begin); };
  auto end_of = [] (const ProbabilisticBVH::Node& node) { return static_cast<std::size_t> (node.end); };
  owned_.assign ((bvh.pointIndices ().size () + 63) / 64, 0);
  {
    std::vector<std::uint8_t> counted (n, 0);
    for (const auto& node : nodes)
      if (node.isLeaf ())
        for (std::size_t j = begin_of (node); j < end_of (node); ++j)
          if (!counted[static_cast<std::size_t> (indices[j])])
          {
            counted[static_cast<std::size_t> (indices[j])] = 1;
            owned_[j / 64] |= std::uint64_t {1} << (j % 64);
          }
  }
  // The point at position j when the dipoles count it (its owner leaf, and oriented), else n.
  auto countedPoint = [&] (std::size_t j) {
    const std::size_t i = static_cast<std::size_t> (indices[j]);
    return owns (j) && !normals_[i].isZero () ? i : n;
  };
  dipoles_.assign (nodes.size (), Dipole ());
  area_ = 0.0;
  if (nodes.empty ())
    return;
  // Summed in double, stored in single precision (Dipole).
  struct Sum
  {
    Eigen::Vector3d center = Eigen::Vector3d::Zero ();
    Eigen::Vector3d moment = Eigen::Vector3d::Zero ();
    double area = 0.0;
    double radius = 0.0;
  };
  std::vector<Sum> sums (nodes.size ());
  // Stored in float: the centre moves by at most 2^-24 of each coordinate, so the radius (taken
  // from the centre in double) grows by 2^-23 of the centre's and its own magnitude before it is
  // rounded up, and still bounds the node's samples from the stored centre. (Not by measuring
  // from the centre rounded to float and back: GCC 12 at -O2 folded that round trip away in this
  // function.)
  auto store = [&] (std::size_t id) {
    const Sum& sum = sums[id];
    Dipole& d = dipoles_[id];
    d.center = sum.center.cast<float> ();
    d.moment = sum.moment.cast<float> ();
    const double moved = std::ldexp (sum.center.cwiseAbs ().sum () + sum.radius, -23);
    d.radius = sum.area > 0.0 ? std::nextafter (static_cast<float> (sum.radius + moved), std::numeric_limits<float>::infinity ()) : -1.0f;
  };
  // A leaf's dipole reads only its own points: the leaves on the workers, then the internal
  // nodes from their children, children first (a child's id is larger than its parent's).
  std::vector<std::int32_t> leaves;
  for (std::size_t id = 0; id < nodes.size (); ++id)
    if (nodes[id].isLeaf ())
      leaves.push_back (static_cast<std::int32_t> (id));
  detail::parallelChunks (leaves.size (), 1024, workers, [&] (std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t l = begin; l < end; ++l)
    {
      const std::size_t id = static_cast<std::size_t> (leaves[l]);
      const auto& node = nodes[id];
      Sum& d = sums[id];
      for (std::size_t j = begin_of (node); j < end_of (node); ++j)
        if (const std::size_t i = countedPoint (j); i < n)
        {
          const double a = areas_[i];
          d.area += a;
          d.center += a * points[i];
          d.moment += a * normals_[i].cast<double> ();
        }
      if (d.area > 0.0)
        d.center /= d.area;
      for (std::size_t j = begin_of (node); j < end_of (node); ++j)
        if (const std::size_t i = countedPoint (j); i < n)
          d.radius = std::max (d.radius, (points[i] - d.center).norm ());
      store (id);
    }
  });
  for (std::size_t id = nodes.size (); id-- > 0;)
  {
    const auto& node = nodes[id];
    if (node.isLeaf ())
      continue;
    Sum& d = sums[id];
    for (int c = 0; c < node.num_children; ++c)
    {
      const Sum& child = sums[static_cast<std::size_t> (node.first_child + c)];
      d.area += child.area;
      d.center += child.area * child.center;
      d.moment += child.moment;
    }
    if (d.area > 0.0)
      d.center /= d.area;
    for (int c = 0; c < node.num_children; ++c)
    {
      const std::size_t child = static_cast<std::size_t> (node.first_child + c);
      if (sums[child].area > 0.0)
        d.radius = std::max (d.radius, (sums[child].center - d.center).norm () + sums[child].radius);
    }
    store (id);
  }
  area_ = sums[static_cast<std::size_t> (ProbabilisticBVH::rootId ())].area;
  // A viewpoint within the cloud's bounding box (a room or a 360-degree scan seen from within,
  // oriented by Viewpoint as asked: Auto does not take such a viewpoint): the surfaces wind
  // around it, and behind them their winding numbers cancel (a room's floor and four walls put a
  // point 2 cm under the floor at about 0.1, and a cube there read free, d = +2 cm: a probe,
  // 2026-12-07). Behind is then measured from the viewpoint's own winding number.
  view_winding_ = 0.0;
  if (seen_from_view_ && orientation_ == NormalOrientation::Viewpoint && in.viewpoint && !view_outside)
    view_winding_ = windingNumber (bvh, *in.viewpoint);

  // Each bin's plane for behindView, from the normals as they now are (repaired, smoothed),
  // turned toward the view.
  for (std::vector<ViewBins::Nearest>* cells : {&view_bins_.grid, &view_bins_.nearest})
    for (ViewBins::Nearest& cell : *cells)
      if (cell.index >= 0)
      {
        const std::size_t i = static_cast<std::size_t> (cell.index);
        const Eigen::Vector3f plane = planeOf (i);
        cell.normal = plane.dot ((view_bins_.view - points[i]).cast<float> ()) < 0.0f ? Eigen::Vector3f (-plane) : plane;
      }

  // Closed objects: whether the propagated orientation reads as a closed surface oriented
  // outward, by the winding number just behind and in front of evenly spread samples.
  closed_share_ = std::numeric_limits<double>::quiet_NaN ();
  solid_share_ = std::numeric_limits<double>::quiet_NaN ();
  if (in.closed_objects && orientation_ == NormalOrientation::Propagate && area_ > 0.0)
  {
    std::vector<std::size_t> oriented;
    for (std::size_t i = 0; i < n; ++i)
      if (!normals_[i].isZero ())
        oriented.push_back (i);
    const std::size_t probes = std::min (oriented.size (), kClosedProbes);
    // Per probe: bit 0 outside in front, bit 1 inside behind.
    std::vector<std::uint8_t> reads (probes, 0);
    detail::parallelChunks (probes, 64, workers, [&] (std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t p = begin; p < end; ++p)
      {
        const std::size_t i = oriented[p * oriented.size () / probes];
        const Eigen::Vector3d normal = normals_[i].cast<double> ();
        const double sigma = std::sqrt (std::max (0.0, bvh.covariances ()[i].quadratic (normal)));
        const Eigen::Vector3d offset = (kClosedProbeSpacings * spacing_[i] + kClosedProbeSigmas * sigma) * normal;
        const bool outside = std::abs (windingNumber (bvh, points[i] + offset)) < kClosedProbeWinding;
        const bool inside = windingNumber (bvh, points[i] - offset) > 1.0 - kClosedProbeWinding;
        reads[p] = static_cast<std::uint8_t> ((outside ? 1 : 0) | (inside ? 2 : 0));
      }
    });
    std::size_t outside = 0, inside = 0;
    for (const std::uint8_t r : reads)
    {
      outside += r & 1;
      inside += (r >> 1) & 1;
    }
    const double total = static_cast<double> (std::max<std::size_t> (probes, 1));
    closed_share_ = static_cast<double> (outside) / total;
    solid_share_ = static_cast<double> (inside) / total;
  }
}

bool
SurfaceModel::insideKnown () const
{
  if (orientation_ == NormalOrientation::Propagate)
    return closed_share_ >= kMinClosedShare && solid_share_ >= kMinSolidShare;  // false when NaN (not checked)
  return orientation_ != NormalOrientation::Auto;  // Auto: not built
}

void
SurfaceModel::packOpenings (const std::vector<Eigen::Vector4f>& open)
{
  open_words_.assign ((open.size () + 63) / 64, OpenWord ());
  open_values_.clear ();
  for (std::size_t i = 0; i < open.size (); ++i)
  {
    OpenWord& word = open_words_[i / 64];
    if (i % 64 == 0)
      word.rank = static_cast<std::uint32_t> (open_values_.size ());
    if (open[i].isZero ())
      continue;
    word.bits |= std::uint64_t {1} << (i % 64);
    open_values_.push_back (open[i]);
  }
  open_values_.shrink_to_fit ();
}

static_assert (sizeof (SurfaceModel::Dipole) == 28, "a dipole is 28 bytes");

double
SurfaceModel::windingNumber (const ProbabilisticBVH& bvh, const Eigen::Vector3d& q) const
{
  if (dipoles_.empty ())
    return 0.0;
  const std::vector<Eigen::Vector3d>& points = bvh.means ();
  const int* indices = bvh.pointIndices ().data ();
  // A node farther than this many radii is one dipole (Barill et al. use beta = 2).
  constexpr double kBeta = 2.0;
  double w = 0.0;
  thread_local std::vector<std::int32_t> stack;  // no allocation per call once grown
  stack.assign (1, ProbabilisticBVH::rootId ());
  while (!stack.empty ())
  {
    const std::int32_t id = stack.back ();
    stack.pop_back ();
    const Dipole& d = dipoles_[static_cast<std::size_t> (id)];
    if (d.empty ())
      continue;
    const Eigen::Vector3d v = d.center.cast<double> () - q;
    const double dist = v.norm ();
    if (dist > kBeta * d.radius && dist > 0.0)
    {
      w += d.moment.cast<double> ().dot (v) / (dist * dist * dist);
      continue;
    }
    const auto& node = bvh.node (id);
    if (!node.isLeaf ())
    {
      for (int c = 0; c < node.num_children; ++c)
        stack.push_back (node.first_child + c);
      continue;
    }
    for (std::size_t j = static_cast<std::size_t> (node.begin); j < static_cast<std::size_t> (node.end); ++j)
    {
      if (!owns (j))
        continue;
      const std::size_t s = static_cast<std::size_t> (indices[j]);
      if (normals_[s].isZero ())
        continue;
      const Eigen::Vector3d u = points[s] - q;
      // Each sample is a disc of area a_i: regularised at about its radius, so that a query on
      // a sample does not divide by zero.
      const double a = areas_[s];
      const double r2 = u.squaredNorm () + 0.25 * a;
      if (!(r2 > 0.0))
        continue;  // a sample of no area (repeated past k times) exactly at q: 0, not 0 / 0
      w += a * normals_[s].cast<double> ().dot (u) / (r2 * std::sqrt (r2));
    }
  }
  return w / (4.0 * kPi);
}

std::size_t
SurfaceModel::bytes () const
{
  return normals_.capacity () * sizeof (Eigen::Vector3f) + (spacing_.capacity () + areas_.capacity ()) * sizeof (float) +
         open_words_.capacity () * sizeof (OpenWord) + open_values_.capacity () * sizeof (Eigen::Vector4f) +
         owned_.capacity () * sizeof (std::uint64_t) + dipoles_.capacity () * sizeof (Dipole) +
         view_bins_.keys.capacity () * sizeof (ViewBins::Key) +
         (view_bins_.nearest.capacity () + view_bins_.grid.capacity ()) * sizeof (ViewBins::Nearest);
}
} // namespace pcl_probcollision
