// SPDX-License-Identifier: BSD-3-Clause
// The start plane of a leaf pair (METHOD.md 5.3), assessed from the two hierarchies' own arrays
// without gathering the points: collide()'s leaf test orders and passes over pairs by it before
// any fit (src/leaf_pair_test.cpp). Defined in src/detail/start_plane.cpp. Internal: not API.
#pragma once

#include <pcl_probcollision/probabilistic_bvh.h>

#include <Eigen/Geometry>

#include <limits>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Rounding room of startPlane()'s tests against RobustClassifier::classify()'s own:
  * relative, far above the differences of the two computations (about 1e-14), so that the
  * tests lean to fitting. */
constexpr double kStartSlack = 1e-7;

/** \brief A leaf pair's start plane: the plane RobustClassifier::classify() starts the plane
  * Newton from (f = 1 and -1 at the class means, the bisector of the means). */
struct StartPlane
{
  /** \brief The largest z_i = -u_i / sigma_i over both leaves' points, P_i = Phi(z_i) (u_i the
    * signed distance to the plane, positive on the point's own side; sigma_i its standard
    * deviation along the normal); +inf when the means coincide. */
  double z = std::numeric_limits<double>::infinity ();
  /** \brief classify() would start from this plane too (its Standard objective lies below that
    * of theta = 0, by more than rounding) and every point has a spread well above classify()'s
    * kNoSpread. Otherwise only classify() can say whether the pair is passed over. */
  bool usable = false;
};

/** \brief The start plane of leaf_a (of a) and leaf_b (of b, mapped into A's frame by T_a_b), for
  * a classifier with penalty C and the squared hinge: one pass over the two leaves' points in
  * their own frames, nothing copied. The plane is the same in any frame, so z needs no unit-cube
  * map; only the usable test computes the map's scale. */
StartPlane startPlane (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
                       const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C);

/** \brief True only when classify() with this skip_at_or_below would surely pass the pair over
  * (its start plane separates every point, maximum P under 0.5 and at most the threshold):
  * z is raised by kStartSlack first. */
bool passesOver (const StartPlane& start, double skip_at_or_below);
} // namespace detail
} // namespace pcl_probcollision
