// SPDX-License-Identifier: BSD-3-Clause
// The start plane of a leaf pair (METHOD.md 5.3), assessed from the two hierarchies' own arrays
// without gathering the points: collide()'s leaf test orders and passes over pairs by it before
// any fit (src/leaf_pair_test.cpp). Defined in src/detail/start_plane.cpp. Internal: not API.
#pragma once

#include <pcl_probcollision/probabilistic_bvh.h>

#include <Eigen/Geometry>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Rounding room of mayPassOver() and startPlaneUsable() against RobustClassifier::classify()'s own:
  * relative, far above the differences of the two computations (about 1e-14), so that the
  * tests lean to fitting. */
constexpr double kStartSlack = 1e-7;

// A leaf pair's start plane is the plane RobustClassifier::classify() starts the plane Newton
// from (f = 1 and -1 at the class means: the bisector of the means).

/** \brief The start plane's largest z_i = -u_i / sigma_i over the points of leaf_a (of a) and
  * leaf_b (of b, mapped into A's frame by T_a_b), P_i = Phi(z_i): u_i the signed distance to the
  * plane, positive on the point's own side, sigma_i its standard deviation along the normal
  * (points without spread left out). +inf when the means coincide. One pass over the two
  * leaves' points in their own frames, nothing copied; the plane is the same in any frame, so
  * no unit-cube map is needed. */
double startPlaneZ (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
                    const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b);

/** \brief Whether classify() (penalty C, squared hinge) would start from that plane too: its
  * Standard objective lies below that of theta = 0 by more than rounding (which needs the
  * unit-cube map's scale), and every point has a spread well above classify()'s kNoSpread.
  * Otherwise only classify() can say whether the pair is passed over. One more pass. */
bool startPlaneUsable (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
                       const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C);

/** \brief The test of z alone: the start's maximum P, with z raised by kStartSlack, under 0.5
  * and at most skip_at_or_below (>= 0). */
bool mayPassOver (double z, double skip_at_or_below);

/** \brief True only when classify() with this skip_at_or_below would surely pass the pair over
  * (its start plane separates every point, maximum P under 0.5 and at most the threshold):
  * mayPassOver (z, ...), then startPlaneUsable(). z is startPlaneZ()'s for the same pair. */
bool passesOver (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
                 const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C, double z,
                 double skip_at_or_below);
} // namespace detail
} // namespace pcl_probcollision
