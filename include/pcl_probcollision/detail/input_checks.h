// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Geometry>

#include <cstdio>
#include <string>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Largest coordinate or translation magnitude accepted, in the data's units. Beyond it
  * float arithmetic overflows: FLANN's middle split computes (min + max) / 2 = inf, and mapped
  * boxes become inf - inf = NaN, which never prune (both found by fuzz/fuzz_collide). */
constexpr double kMaxCoordinate = 1e15;

/** \brief How far R^T R of a pose's rotation may depart from the identity, entry by entry: a
  * rotation written with 7 significant digits passes, a scale of 1 + 1e-6 does not. */
constexpr double kRotationTolerance = 1e-6;

/** \brief The one rigid-pose check of the library: empty when T is finite, a rotation
  * (orthonormal within kRotationTolerance, determinant +1) plus a translation within
  * +-kMaxCoordinate; otherwise why not (by how much, for a rotation), naming the pose `name`. */
inline std::string
poseError (const Eigen::Isometry3d& T, const std::string& name)
{
  if (!T.matrix ().allFinite ())
    return "pose " + name + " is not finite";
  const Eigen::Matrix3d R = T.linear ();
  const double departure = (R.transpose () * R - Eigen::Matrix3d::Identity ()).cwiseAbs ().maxCoeff ();
  if (!(departure <= kRotationTolerance) || R.determinant () < 0.0)
  {
    // Say by how much: a rotation rounded to a few digits in a poses file fails the same way as
    // a scale, and the reader needs to know which.
    char why[160];
    if (R.determinant () < 0.0)
      std::snprintf (why, sizeof why, " (a reflection: det R = %.6g)", R.determinant ());
    else
      std::snprintf (why, sizeof why, " (R^T R departs from the identity by %.3g, more than the tolerance %g)", departure,
                     kRotationTolerance);
    return "pose " + name + " is not a rotation plus translation" + why;
  }
  if (!(T.translation ().cwiseAbs ().maxCoeff () <= kMaxCoordinate))
    return "pose " + name + " translation is beyond the supported range of +-1e15";
  return std::string ();
}
} // namespace detail
} // namespace pcl_probcollision
