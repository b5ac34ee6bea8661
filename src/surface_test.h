// SPDX-License-Identifier: BSD-3-Clause
// The surface layer of collide() (METHOD.md 10a): each object's points against the other's
// oriented surface. Private to the library (src/), used by src/collide.cpp.
#pragma once

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision_request.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief The spread of where a surface ends (or bends) between samples, per unit of distance
  * from the nearest sample, up to one spacing: an edge anywhere within one spacing, uniformly,
  * has a standard deviation of 1 / sqrt(12) = 0.29 spacing. Derived, not fitted. The surface
  * layer's discretisation term, and that of the nearest samples' distance (collide.cpp). */
constexpr double kDiscretisationPerDistance = 0.288675;

/** \brief What the surface test found for one pose. Frames: A's local frame. */
struct SurfaceAnswer
{
  /** \brief Some point came within reach of the other surface, or one object lies inside the
    * other; false: the surfaces never came near (P = 0, no distance). */
  bool reached = false;
  /** \brief One object entirely inside the other (winding number), found without contact. */
  bool contained = false;
  double probability = 0.0;
  double signed_distance = std::numeric_limits<double>::quiet_NaN ();
  double signed_distance_std = std::numeric_limits<double>::quiet_NaN ();
  /** \brief The deciding point: side +1 = A, -1 = B, 0 = none; its hierarchy index. */
  int witness_side = 0;
  int witness_index = -1;
  /** \brief Its position, and the other surface's normal there pointing toward A's side (for a
    * point deep inside the other object, the outward normal of the other's sample nearest it,
    * so turned: the way out; NaN where that sample has none). */
  Eigen::Vector3d witness_point = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  Eigen::Vector3d witness_normal = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief The deciding point lies over a bridged hole, or clearly behind a surface oriented
    * by its viewpoint (CollisionResult::unobserved). */
  bool unobserved = false;
  /** \brief Stopped at the first point with P_in > collision_above (decision mode): P and the
    * distance are then bounds (the deepest point may lie elsewhere). */
  bool stopped_early = false;
  /** \brief The deciding point lies inside the other's surface by its winding number (above
    * 1/2), a surface with a known inside that is no scan's view (not behind a sheet): a deep point
    * or an object wholly inside. Two surfaces need not cross there, so the separators cannot see
    * it, and a pool (CollisionRequest::surface_pooled, the ladder's after a free fit) lets the
    * surface layer's answer stand. */
  bool inside_confirmed = false;
  /** \brief A query leaf within reach met only samples without a normal (a cloud of coincident,
    * collinear or too few points has no surface there): its points were not judged, so a P of
    * 0 with reached false does not mean "far". */
  bool unjudged = false;
  /** \brief Stopped at CollisionRequest::max_surface_pairs with query leaves left untested: P
    * and the distance are bounds, and nothing beyond reach was judged. */
  bool budget_exhausted = false;
  std::size_t leaf_pairs = 0;    ///< leaf pairs within reach (their boxes; collide() counts them where a point was reached); with budget_exhausted, the pairs tested
  std::size_t pairs_tested = 0;  ///< leaf pairs tested, both sides (what max_surface_pairs counts)
  std::size_t points_tested = 0; ///< point-against-surface evaluations, both sides
  std::size_t bv_tests = 0;      ///< node pairs tested by its traversal
};

/** \brief Whether any leaf pair of a and b (B mapped into A by T_a_b) lies within the surface
  * layer's reach: their boxes grown to kReachSigmas point deviations and by `spacing` (the
  * larger median sample spacing of the two) meet. The one rule of "within reach", for the
  * surface layer's enumeration and for a distance asked beyond it (CollisionRequest::distance).
  * Stops at the first such pair. */
bool
withinReach (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b, double spacing);

/** \brief Every point of A and B within reach of the other's surface gets a local signed
  * distance d_i (an implicit surface of the nearest oriented samples, robust to creases) with a
  * standard deviation sigma_i (both clouds' noise along the normal, the fitted surface's own
  * error and the discretisation between samples); P_in,i = Phi(-d_i / sigma_i). The pair's P
  * and distance are those of the point with the smallest d_i / sigma_i. When no point is within
  * reach, the winding number tells whether one object lies entirely inside the other.
  *
  * \param[in] a, b models with surfaces (CloudModel::surface() not empty)
  * \param[in] T_a_b B's local frame to A's local frame
  * \param[in] request the query (its thresholds are not used here)
  * \param[out] per_point_a, per_point_b when not null, P_in per hierarchy point (kept maximum;
  *             NaN stays for points out of reach); sized by the caller */
SurfaceAnswer
surfaceTest (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
             std::vector<float>* per_point_a, std::vector<float>* per_point_b);
/** \brief Where no leaf pair comes within reach (the ladder, when the separators reached none):
  * whether one object lies inside the other, wholly or in part, by the winding number of each
  * surface that says where its inside is (SurfaceModel::insideKnown), as surfaceTest judges
  * points out of reach: every node of one object clear of the other's surface (within `margin`,
  * a sample spacing) by one of its points, from the root down. Found: P = 1 and the depth to the
  * other's nearest sample, as surfaceTest's deep points (in decision mode the first node found,
  * stopped_early: a bound), and P_in = 1 for the points of every node found inside (per_point_a,
  * per_point_b: as surfaceTest's; the search is then exhaustive); otherwise nothing reached. */
SurfaceAnswer
containmentTest (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b, const CollisionRequest& request,
                 std::vector<float>* per_point_a, std::vector<float>* per_point_b);
} // namespace detail
} // namespace pcl_probcollision
