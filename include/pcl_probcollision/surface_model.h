// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model_params.h>
#include <pcl_probcollision/probabilistic_bvh.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

namespace pcl_probcollision
{
/** \brief The oriented surface of one cloud (METHOD.md 10a): a unit outward normal and a local
  * sample spacing per point, and one dipole per hierarchy node for the winding number.
  *
  * Part of a CloudModel, built with it in its local frame over its hierarchy's points (index i
  * = point i of the hierarchy). The query (CollisionRequest::surface) reads it to tell on which
  * side of the other object's surface each point lies: near contact from a local implicit
  * surface of the nearest samples' oriented planes, far from it from the winding number.
  *
  * Spacing: s_i = r_i sqrt(pi / k), r_i the distance to the k-th neighbour, is the side of the
  * square each sample stands for on a uniformly sampled surface (k samples in pi r_i^2), at most
  * the square root of the neighbours' spread's area over k + 1 (a strip narrower than the
  * neighbourhood). It sets the surface layer's reaches (bridged holes, edges, joined points).
  * Area: a_i, the sample's Voronoi cell in its tangent plane (areas()), weighs the winding
  * number. On a lattice a_i is about s_i^2; on uniformly random samples s_i^2 reads about 0.76
  * of a_i (the spread of a few random neighbours), which is why the two are kept apart: the
  * winding number needs the true area, the reaches were chosen with s_i.
  */
class SurfaceModel
{
public:
  /** \brief What build() takes, index-aligned with the hierarchy's points. */
  struct Inputs
  {
    /** \brief Unit normals: unoriented from the neighbours' plane, or the point type's own
      * (given[i] set); zero where undetermined. */
    std::vector<Eigen::Vector3f> normals;
    /** \brief Per point: the normal is the caller's (PointNormal types), already outward. */
    std::vector<std::uint8_t> given;
    /** \brief Distance of each point to its k-th neighbour. */
    std::vector<float> radii;
    /** \brief k neighbours per point (row-major, point indices, -1 where fewer). */
    std::vector<int> neighbours;
    /** \brief Neighbours per point in radii and neighbours (>= 1). */
    int k = 0;
    /** \brief The sensor origin in the local frame, when the cloud has one. */
    std::optional<Eigen::Vector3d> viewpoint;
    /** \brief CloudModelParams::closed_objects: a propagated orientation is checked (closedShare()). */
    bool closed_objects = false;
    /** \brief Threads of the per-point passes (CloudModelParams::threads: 0 = every core);
      * the model is the same for any count. */
    int threads = 1;
  };

  /** \brief One node's dipole, stored in single precision (summed in double; 28 bytes instead
    * of 64, for issue #17's memory target): the area-weighted centre of its
    * oriented samples, the sum of their area-weighted normals, and the largest distance of such
    * a sample from the stored centre, rounded up so that it still bounds them. A node without
    * an oriented sample has radius -1 (empty()). */
  struct Dipole
  {
    /** \brief Area-weighted centre of the node's oriented samples (local frame). */
    Eigen::Vector3f center = Eigen::Vector3f::Zero ();
    /** \brief Sum of those samples' area-weighted unit normals. */
    Eigen::Vector3f moment = Eigen::Vector3f::Zero ();
    /** \brief Bound on those samples' distance from center; -1 for a node without one. */
    float radius = -1.0f;

    /** \brief True when the node holds no oriented sample (it adds nothing to the winding
      * number). */
    bool empty () const { return radius < 0.0f; }
  };

  SurfaceModel () = default;

  /** \brief Orients the normals (mode; Auto resolved as NormalOrientation documents) and sums
    * the dipoles over bvh's nodes. bvh must hold the points the inputs describe.
    * \throws pcl::BadArgumentException when the inputs' sizes disagree with bvh. */
  void build (const ProbabilisticBVH& bvh, Inputs&& inputs, NormalOrientation mode);

  /** \brief True before build(). */
  bool empty () const { return normals_.empty (); }
  /** \brief Unit outward normal of each point, in the local frame; zero where undetermined. */
  const std::vector<Eigen::Vector3f>& normals () const { return normals_; }
  /** \brief Local sample spacing s_i of each point (data units). */
  const std::vector<float>& spacing () const { return spacing_; }
  /** \brief The surface area a_i each point stands for (data units squared): its Voronoi cell
    * among its neighbours in its tangent plane, within their spread; the winding number's
    * weights. Exact copies of a point share its cell; 0 for a point repeated past k times or
    * whose neighbours lie on a line; s_i^2 for a point with fewer than two neighbours. */
  const std::vector<float>& areas () const { return areas_; }
  /** \brief Where the neighbours of point i leave the surface open (the point lies on its
    * edge): xyz the bisector, in the tangent plane, of the widest angle between its neighbours
    * seen from it, of length the distance to its k-th neighbour (how far they show the surface
    * open); w the cosine of half that angle. Zero where that angle is at most 150 degrees (an
    * inner point) or the neighbours lie along a line (a row of mesh vertices). A direction d in
    * the plane points off the surface, within that length, when xyz . d > w |xyz| |d|.
    * Only the open points' values are stored, found through a bit per point and a count per 64
    * (31 % of the points of bench_performance's noisy room are open). Requires i < the
    * hierarchy's size(). */
  Eigen::Vector4f
  opening (std::size_t i) const
  {
    const OpenWord& word = open_words_[i / 64];
    if (!((word.bits >> (i % 64)) & 1u))
      return Eigen::Vector4f::Zero ();
    const std::uint64_t below = (std::uint64_t {1} << (i % 64)) - 1;
    return open_values_[word.rank + static_cast<std::size_t> (popcount (word.bits & below))];
  }
  /** \brief Number of points with a non-zero opening(). */
  std::size_t openPoints () const { return open_values_.size (); }
  /** \brief Median of spacing(): the cloud's typical sample spacing. */
  double medianSpacing () const { return median_spacing_; }
  /** \brief The spacing at a typical place of the surface (not of a typical sample): the median
    * of spacing() weighted by each sample's area s_i^2. Equal to medianSpacing() on a uniformly
    * sampled surface; far larger where most samples crowd into clusters (a triangle soup's
    * repeated vertices) and the surface between them is sampled sparsely. */
  double surfaceSpacing () const { return surface_spacing_; }
  /** \brief The orientation used (never Auto). */
  NormalOrientation orientation () const { return orientation_; }
  /** \brief Auto takes a viewpoint outside the cloud for a scan's only if at most this share of
    * the points lies hidden behind others as seen from it (hiddenFromViewpoint()). One scan holds
    * none (a sensor sees no point behind another; mixed pixels at depth edges, grazing surfaces a
    * few); a closed object sampled all round, seen from a point outside it, about half (its far
    * side): PCL's default sensor_origin_ (0, 0, 0) is no viewpoint for a mesh's samples. */
  static constexpr double kMaxHiddenShare = 0.1;
  /** \brief Auto takes a viewpoint for a scan's only if the cloud's nearest sample lies farther
    * from it than this many median spacings: a sensor's samples lie hundreds of spacings away,
    * and PCL's default origin beside a sampled solid is no sensor. */
  static constexpr double kMinViewSpacings = 10.0;
  /** \brief A point lies hidden behind others from a viewpoint (hiddenFromViewpoint()), or behind
    * the surface seen from it (behindView(), as the query asks), when it lies farther than the
    * nearest sample in its bin of directions, and off that sample's tangent plane, by more than
    * this many sample spacings. */
  static constexpr double kHiddenSpacings = 3.0;
  /** \brief A sample's k neighbours spread across a patch, not along a row, when their scatter's
    * middle eigenvalue is at least this share of its largest (a fifth as wide one way as the other):
    * the plane behindView() takes from them about their centroid where the sample's normal lies
    * more than 45 degrees off it (kStrayNormalCosine). */
  static constexpr double kPatchSpread = 0.05;
  /** \brief cos 45 degrees: a normal further off its neighbours' plane is a stray's (behindView()). */
  static constexpr float kStrayNormalCosine = 0.70710678f;
  /** \brief Where Auto weighed a viewpoint outside the cloud, or given normals faced the
    * viewpoint (outside the cloud, or within its bounding box for Auto): the share of points
    * hidden from it behind others (a scan from there hides none). Above kMaxHiddenShare the
    * viewpoint is not the cloud's (a mesh's samples with PCL's default sensor origin) and Auto
    * propagates instead. NaN where not weighed. */
  double hiddenFromViewpoint () const { return hidden_from_view_; }
  /** \brief Whether the samples are one scan's from the cloud's viewpoint, so that the space
    * behind the surface was never observed (CollisionResult::unobserved): oriented toward the
    * viewpoint (Viewpoint), or given normals that face a viewpoint outside the cloud as a scan's
    * do (PointNormals: a scan saved with PCL's normals). For the latter at least 1 % of the
    * normals lie within 78 degrees of the line of sight (toward the viewpoint or away), at most a
    * tenth of those away, and at most kMaxHiddenShare of the points hidden behind others. */
  bool seenFromViewpoint () const { return seen_from_view_; }
  /** \brief The winding number at the viewpoint where the surface is oriented by a viewpoint
    * within the cloud's bounding box (a room or a 360-degree scan seen from within), 0 otherwise:
    * the query measures how far a point lies behind the surface by its winding number less this
    * one (about -1 inside a room, whose walls cancel behind its floor). */
  double viewWinding () const { return view_winding_; }
  /** \brief Where seenFromViewpoint(): how far x (local frame) lies behind the surface the
    * viewpoint saw along x's line of sight: the least, over the 3 x 3 bins of directions about
    * x's (those of hiddenFromViewpoint(), two median spacings wide at the median depth), of x's
    * distance behind the tangent plane of the bin's nearest sample (its range beyond that
    * sample's where the sample has no normal). Negative in front of what the scan saw (a point
    * over a floor seen at a grazing angle lies farther than the floor's nearest sample in its
    * bin, but in front of its plane), over those of the nine that hold a sample; NaN where
    * more than two hold none (no surface was seen along that line, or x lies beside a
    * silhouette: a single view's bins hold one to three samples where it sees a surface at a
    * slant, and one may be empty), behind the viewpoint, or for a surface not seen from one
    * viewpoint. The space behind a scan was never observed: the
    * query reads a part there, clear of the surface, as unknown (docs/SURFACE.md, step 6).
    * \param[in] bvh the hierarchy this model was built over
    * \param[in] x the point, in the local frame
    * \param[out] beyond if not null, how far x lies beyond the nearest sample of its bin along
    *             its line of sight (its range less that sample's; the least over the nine bins
    *             where its own holds none); NaN where the result is NaN */
  double behindView (const ProbabilisticBVH& bvh, const Eigen::Vector3d& x, double* beyond = nullptr) const;
  /** \brief False when no point in the convex hull of `corners` (local frame) can lie more than
    * margin behind what the viewpoint saw (behindView() > margin): its farthest corner is nearer
    * the viewpoint than every sample in the bins its directions span, plus margin (a point
    * behind a sample's tangent plane along its line of sight is at least that much farther).
    * True where that cannot be told cheaply: more than max_bins bins spanned, a corner behind
    * the view's plane, or a viewpoint inside the cloud's bounding box. */
  bool mayLieBehindView (const std::array<Eigen::Vector3d, 8>& corners, double margin, std::int64_t max_bins) const;
  /** \brief Behind a scan, the space a query reads as unobserved (behindView() beyond
    * kHiddenSpacings spacings) is the part within the cloud's bounding box (the hierarchy's
    * root), and, within and beyond it, a shell this many median spacings deep along the line of
    * sight behind what the sensor saw (hiddenShell(); behindView()'s `beyond`). The box alone
    * followed its own tilt: on a rendered table scan from 45 degrees above, a principal-axes box
    * tilted about 5 degrees cut off the back of the table's slab, and 8 of 104 collisions of a
    * cube with its unseen faces read free. Deeper than the box and the shell the scan is taken to
    * end: a reach of the box's diagonal read the table behind a real stereo mug lifted 5 cm as
    * unknown (9-11 cm behind the mug's seen side), and so did a shell measured behind the
    * samples' tangent planes (2-4 cm there, under the mug's bottom rim). */
  static constexpr double kHiddenShellSpacings = 10.0;
  /** \brief kHiddenShellSpacings median spacings where seenFromViewpoint(), else 0. */
  double hiddenShell () const { return hidden_shell_; }
  /** \brief The viewpoint behindView() looks from (local frame); NaN where it has none. */
  const Eigen::Vector3d& viewpoint () const { return view_bins_.view; }
  /** \brief Whether Auto set the caller's normals aside because they all face the viewpoint, as
    * PCL's normal estimation turns them (at least half within 78 degrees of the line of sight, at
    * most a tenth of those away from it), while more than kMaxHiddenShare of the points lie hidden
    * from it (hiddenFromViewpoint()): turned toward a sensor that did not see the cloud as one
    * scan, they are not outward (a closed object's would face a viewpoint outside it on one side
    * only, and a viewpoint inside a non-convex object sees parts of it behind others). Their
    * directions are kept and their sides propagated (orientation() Propagate). From inside a
    * convex object nothing is hidden: its normals, turned inward, are kept (a room scanned from
    * within looks the same). */
  bool normalsTurnedToViewpoint () const { return normals_turned_to_view_; }
  /** \brief Whether nearly all the caller's normals face away from a viewpoint outside the
    * cloud (the mirror of a scan's, whose normals face its sensor): most likely turned the wrong
    * way. They are still taken as given; CloudModel::warning() says so. */
  bool givenNormalsFaceAwayFromViewpoint () const { return given_face_away_; }
  /** \brief Whether the caller's normals were not oriented: more than a tenth of those facing a
    * viewpoint outside the cloud (or away from it) face away, the viewpoint sees the cloud as one
    * scan (at most kMaxHiddenShare hidden), and their sides disagree between neighbours
    * (givenNormalSideDisagreement() above a tenth), as those of normals estimated without an
    * orientation do (Open3D's estimate_normals leaves each sign to its eigen solver). Auto then
    * keeps their directions and turns them toward the viewpoint (orientation() Viewpoint);
    * PointNormals takes them; CloudModel::warning() says so either way. Normals that agree
    * between neighbours are an orientation, and a viewpoint they face away from may be stale
    * (pcl::transformPointCloud leaves it behind): they are kept, with a warning
    * (givenNormalsFaceAwayFromViewpoint). Without a usable viewpoint, sides are not checked: a
    * thin part's two faces, blurred into one sheet by the noise, alternate between neighbours as
    * unoriented normals do. */
  bool givenNormalsMisoriented () const { return given_misoriented_; }
  /** \brief Where given normals were weighed against a viewpoint, the share of those facing it
    * or away that face away; NaN otherwise. */
  double givenNormalsAwayShare () const { return given_away_share_; }
  /** \brief Where given normals disagreed with a viewpoint that sees the cloud as one scan: the
    * share of them whose side disagrees with their part's majority once one side is carried
    * between neighbours within 26 degrees of each other (opposed neighbours lying across each
    * other's normal, a thin plate's two faces, are not carried). About 0 for an orientation, a
    * half for random signs. NaN where not checked. */
  double givenNormalSideDisagreement () const { return given_side_disagreement_; }
  /** \brief Above this givenNormalSpreadRatio(), orientation Auto sets the given normals aside
    * (normalsOffSurface()). Normals that belong read under 1 however noisy the points (the
    * spread along them is the noise's, across them the noise's and the surface's): 0.001-0.03 on
    * the scans of ../shared/data with normals estimated by Open3D, up to 0.87 on FCL's piano and
    * room sampled finer than 1 % noise. The same scans' points rotated 90 degrees, their normals
    * not, read 1.0-2.3: 1.2 sets aside six of eight such cases (a curved bunny rotated about its
    * up axis, 1.0, and a milk carton, 1.09, keep theirs). */
  static constexpr double kMaxNormalSpreadRatio = 1.2;
  /** \brief Where normals were given: the median, over probed samples (at most 1,024, evenly
    * spread), of the spread of a sample's k neighbours along its given normal over their mean
    * spread across it. About 0 for normals that belong to their points (the noise's share), 1
    * where the noise hides the surface, 2 for normals lying in the surface. NaN where none was
    * probed. */
  double givenNormalSpreadRatio () const { return normal_spread_ratio_; }
  /** \brief Whether Auto set the given normals aside because givenNormalSpreadRatio() exceeds
    * kMaxNormalSpreadRatio: most of them lie along the surface, so they do not belong to their
    * points (moved with pcl::transformPointCloud instead of transformPointCloudWithNormals, or
    * another cloud's). Each point takes its neighbours' plane instead, oriented as a cloud
    * without normals (its viewpoint, else propagation); PointNormals still takes them. */
  bool normalsOffSurface () const { return normals_off_surface_; }
  /** \brief Shares of the closed-objects check's probes that must read outside in front
    * (closedShare) and inside behind (solidShare) for a propagated orientation to be trusted
    * (insideKnown). In front, all but stray normals read outside on a closed surface oriented
    * outward; behind, the probes of samples at an edge (their normals between the two faces') or
    * on a part thinner than the offset come out of the solid (a noisy box sampled 6 mm apart: 89 %
    * inside), and on a plate all of them: then the orientation cannot be checked there. */
  static constexpr double kMinClosedShare = 0.9;
  /** \brief The solidShare() a propagated orientation needs (see kMinClosedShare). */
  static constexpr double kMinSolidShare = 0.5;
  /** \brief Where Inputs::closed_objects asked for it and the orientation was propagated: the
    * share of the probed samples (at most 1,024, evenly spread over the oriented ones) in front
    * of which the surface reads outside, |winding number| under 1/4 two spacings and three
    * noise deviations (along the normal) off the sample. An open sheet reads about -1/2 there,
    * a patch oriented inward about 1. NaN where not checked. */
  double closedShare () const { return closed_share_; }
  /** \brief With closedShare(): the share of the same probes behind which the surface reads
    * inside (winding number above 3/4). Samples at an edge and on parts thinner than the offset
    * come out of the solid (a plate: none inside), so this is lower than closedShare() even on
    * a well oriented solid. NaN where not checked. */
  double solidShare () const { return solid_share_; }
  /** \brief Whether the orientation says where the inside is: the caller's normals, a viewpoint,
    * or a propagated orientation checked closed (closedShare() at least kMinClosedShare and
    * solidShare() at least kMinSolidShare). Without it the surface is two-sided to the query: a point behind it is as far
    * from it as one in front, and no point is found deep inside it. */
  bool insideKnown () const;
  /** \brief Points without a normal (too few distinct neighbours): they bound nothing. */
  std::size_t unorientedPoints () const { return unoriented_; }
  /** \brief Points whose orientation came from propagation alone in Viewpoint mode (grazing
    * or out of the sensor's sight) or from a given normal's neighbours in PointNormals mode. */
  std::size_t propagatedPoints () const { return propagated_; }
  /** \brief Area of the oriented surface: the sum of areas() over the oriented samples (the
    * root dipole's, in double). */
  double area () const { return area_; }
  /** \brief Per hierarchy node, its dipole. */
  const std::vector<Dipole>& dipoles () const { return dipoles_; }

  /** \brief Generalised winding number of the oriented samples at q (local frame): about 1
    * inside a closed surface, 0 outside, +-1/2 on either side of an open sheet (Barill et al.
    * 2018, point version: each sample a disc of area a_i; nodes farther than twice their radius
    * are taken as one dipole).
    * \param[in] bvh the hierarchy this model was built over
    * \param[in] q the query point, in the local frame */
  double windingNumber (const ProbabilisticBVH& bvh, const Eigen::Vector3d& q) const;

  /** \brief Memory held in bytes. */
  std::size_t bytes () const;

private:
  /** \brief 64 points' open bits and the number of open points before them. */
  struct OpenWord
  {
    std::uint64_t bits = 0;
    std::uint32_t rank = 0;
  };
  static int
  popcount (std::uint64_t x)
  {
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_popcountll (x);
#else
    int count = 0;
    for (; x; x &= x - 1)
      ++count;
    return count;
#endif
  }
  /** \brief Directions from a viewpoint in bins, each with its nearest sample's range: where a
    * scan looked, and how far it saw. Bins are gnomonic across the axis that separates a view
    * outside the cloud's bounding box from it, or, for a view inside it, on the face of a cube
    * about the view that each direction crosses (its largest component). The box is the
    * hierarchy's root box, on the cloud's principal axes, and the bins lie on its axes: they turn
    * with the cloud, so a rigid motion of the whole scene bins the same samples together (on the
    * data frame's axes, a box scan turned by a rotation read another behindView() at thousands
    * of points). */
  struct ViewBins
  {
    using Key = std::array<std::int64_t, 3>;  ///< cube face (0 for a view outside), u, v
    Eigen::Vector3d view = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
    /** \brief The bins' axes as columns (the root box's), in the local frame. */
    Eigen::Matrix3d frame = Eigen::Matrix3d::Identity ();
    int axis = 0;
    double sign = 1.0;
    bool inside = false;
    double bin = 0.0;          ///< bin width in the gnomonic coordinates
    /** \brief A bin's nearest sample: its range from the view, its index (NaN and -1 where
      * the bin holds none) and the normal of the plane behindView() takes there, toward the view
      * (zero where the sample has none), set once the model's normals are final. */
    struct Nearest
    {
      /** \brief The sample's distance from the view (NaN where the bin holds none). */
      float range = std::numeric_limits<float>::quiet_NaN ();
      /** \brief The sample's point index (-1 where the bin holds none). */
      std::int32_t index = -1;
      /** \brief Unit normal of the plane behindView() takes there, toward the view (zero
        * where the sample has none). */
      Eigen::Vector3f normal = Eigen::Vector3f::Zero ();
    };
    std::vector<Key> keys;          ///< sorted
    std::vector<Nearest> nearest;   ///< per key
    /** \brief For a view outside: nearest as a dense grid over the keys' u, v, when that is at
      * most kDenseCells per key; empty otherwise (keys are searched). */
    std::vector<Nearest> grid;
    std::int64_t u0 = 0, v0 = 0, width = 0, height = 0;
    static constexpr std::int64_t kDenseCells = 8;
    /** \brief x (local frame) relative to the view, on the bins' axes. */
    Eigen::Vector3d relative (const Eigen::Vector3d& x) const { return frame.transpose () * (x - view); }
    /** \brief The depth of r (relative()) along the axis its bin is on, that axis and the cube
      * face (0 for a view outside). */
    double depthOf (const Eigen::Vector3d& r, int& a, std::int64_t& face) const;
    /** \brief x's bin; false where x lies behind the view's plane (a view outside) or on it. */
    bool keyOf (const Eigen::Vector3d& x, Key& key) const;
    /** \brief True when no bin holds a sample (fewer than two points, or no view). */
    bool empty () const { return keys.empty () && grid.empty (); }
    /** \brief The bin's nearest sample (empty where it holds none). */
    Nearest nearestOf (const Key& key) const;
  };
  /** \brief The bins of points seen from view, and (when hidden is not null) the share of the
    * points hidden from view behind others: farther than their bin's nearest point by more than
    * kHiddenSpacings spacings (the point's and the median), and as far off that point's tangent
    * plane (plane(i): sample i's tangent plane's normal as behindView() takes it, any sign;
    * a point without one: its range alone). A floor seen at a grazing angle spans many
    * spacings of range in one bin, all of it on one plane. Empty bins when there are fewer
    * than two points. box: the cloud's bounding box (the hierarchy's root), whose axes the bins
    * lie on. */
  static ViewBins binView (const std::vector<Eigen::Vector3d>& points, const std::vector<float>& spacing,
                           const std::function<Eigen::Vector3f (std::size_t)>& plane, const Eigen::Vector3d& view,
                           const detail::OrientedBox& box, double* hidden);
  /** \brief Stores the non-zero openings of open (one per point) and their bits. */
  void packOpenings (const std::vector<Eigen::Vector4f>& open);
  /** \brief Whether position j of bvh.pointIndices() is its point's owner: the first leaf
    * holding a point counts it (leaves overlap by epsilon), so each point counts once. */
  bool owns (std::size_t j) const { return (owned_[j / 64] >> (j % 64)) & 1u; }

  std::vector<Eigen::Vector3f> normals_;
  std::vector<float> spacing_;
  std::vector<float> areas_;
  std::vector<OpenWord> open_words_;
  std::vector<Eigen::Vector4f> open_values_;
  std::vector<std::uint64_t> owned_;
  std::vector<Dipole> dipoles_;
  double area_ = 0.0;
  double median_spacing_ = 0.0;
  double surface_spacing_ = 0.0;
  NormalOrientation orientation_ = NormalOrientation::Auto;
  std::size_t unoriented_ = 0;
  std::size_t propagated_ = 0;
  double hidden_from_view_ = std::numeric_limits<double>::quiet_NaN ();
  double view_winding_ = 0.0;
  bool seen_from_view_ = false;
  double hidden_shell_ = 0.0;
  /** \brief Where seen_from_view_: its viewpoint's bins (behindView). */
  ViewBins view_bins_;
  bool normals_turned_to_view_ = false;
  bool given_face_away_ = false;
  bool given_misoriented_ = false;
  double given_away_share_ = std::numeric_limits<double>::quiet_NaN ();
  double given_side_disagreement_ = std::numeric_limits<double>::quiet_NaN ();
  double normal_spread_ratio_ = std::numeric_limits<double>::quiet_NaN ();
  bool normals_off_surface_ = false;
  double closed_share_ = std::numeric_limits<double>::quiet_NaN ();
  double solid_share_ = std::numeric_limits<double>::quiet_NaN ();
};
} // namespace pcl_probcollision
