// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Geometry>

#include <string>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Largest coordinate or translation magnitude accepted, in the data's units. Beyond it
  * float arithmetic overflows: FLANN's middle split computes (min + max) / 2 = inf, and mapped
  * boxes become inf - inf = NaN, which never prune (both found by fuzz/fuzz_collide). */
constexpr double kMaxCoordinate = 1e15;

/** \brief The one rigid-pose check of the library: empty when T is finite, a rotation
  * (orthonormal within 1e-6, determinant +1) plus a translation within +-kMaxCoordinate;
  * otherwise why not, naming the pose `name`. */
inline std::string
poseError (const Eigen::Isometry3d& T, const std::string& name)
{
  if (!T.matrix ().allFinite ())
    return "pose " + name + " is not finite";
  const Eigen::Matrix3d R = T.linear ();
  if (!(R.transpose () * R).isIdentity (1e-6) || R.determinant () < 0.0)
    return "pose " + name + " is not a rotation plus translation";
  if (!(T.translation ().cwiseAbs ().maxCoeff () <= kMaxCoordinate))
    return "pose " + name + " translation is beyond the supported range of +-1e15";
  return std::string ();
}
} // namespace detail
} // namespace pcl_probcollision
