// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
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

/** \brief How far R^T R of a pose's rotation may depart from the identity, entry by entry, to be
  * used as given (rigidPose()): a rotation written with 7 significant digits passes. */
constexpr double kRotationTolerance = 1e-6;

/** \brief How far R^T R may depart from the identity, entry by entry, for a pose to be accepted
  * at all (poseError()); beyond kRotationTolerance it is taken to the nearest rotation
  * (rigidPose()). Rotations whose digits were rounded depart by up to 6e-6 when their quaternion
  * is printed with 6 decimals (52 % of random rotations depart by more than 1e-6, and were refused
  * before), 6e-4 with 4 and 6e-3 with 3 (as tf_echo prints them); a scale of 1.01 (2e-2) is
  * refused. */
constexpr double kRoundedRotationTolerance = 1e-2;

/** \brief R^T R - I's largest entry in magnitude: how far a pose's linear part is from a rotation. */
inline double
rotationDeparture (const Eigen::Isometry3d& T)
{
  const Eigen::Matrix3d R = T.linear ();
  return (R.transpose () * R - Eigen::Matrix3d::Identity ()).cwiseAbs ().maxCoeff ();
}

/** \brief The pose a query uses for T, which poseError() accepted: T itself when its rotation
  * departs by at most kRotationTolerance (bit for bit what was given), otherwise the nearest
  * rotation to its linear part (U V^T of its SVD, in the Frobenius norm) with T's translation.
  * Every inverse and covariance mapping of a query assumes R^T = R^-1; a rounded rotation would
  * scale them. */
inline Eigen::Isometry3d
rigidPose (const Eigen::Isometry3d& T)
{
  if (rotationDeparture (T) <= kRotationTolerance)
    return T;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd (T.linear (), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d rigid = T;
  rigid.linear () = svd.matrixU () * svd.matrixV ().transpose ();
  return rigid;
}

/** \brief The one check of a pose's last row: empty when it is (0, 0, 0, 1) exactly, otherwise
  * "the last row must be (0, 0, 0, 1), got (...)". Eigen's Isometry3d and Affine3d keep the row
  * but read only the top three (a projective matrix, or one written in by hand, was answered as
  * if the row were right: a probe, 2026-12-04); poseError() and the Python bindings call it. */
inline std::string
lastRowError (const Eigen::Matrix4d& m)
{
  if (m (3, 0) == 0.0 && m (3, 1) == 0.0 && m (3, 2) == 0.0 && m (3, 3) == 1.0)
    return std::string ();
  char why[200];
  std::snprintf (why, sizeof why, "the last row must be (0, 0, 0, 1), got (%.9g, %.9g, %.9g, %.9g)", m (3, 0), m (3, 1),
                 m (3, 2), m (3, 3));
  return why;
}

/** \brief The one rigid-pose check of the library: empty when T is finite, a rotation
  * (orthonormal within kRoundedRotationTolerance, determinant +1; queries use rigidPose (T)) plus a translation within
  * +-kMaxCoordinate, its last row (0, 0, 0, 1) (lastRowError()); otherwise why not (by how much,
  * for a rotation), naming the pose `name`. */
inline std::string
poseError (const Eigen::Isometry3d& T, const std::string& name)
{
  if (!T.matrix ().allFinite ())
    return "pose " + name + " is not finite";
  if (const std::string row = lastRowError (T.matrix ()); !row.empty ())
    return "pose " + name + ": " + row;
  const Eigen::Matrix3d R = T.linear ();
  const double departure = rotationDeparture (T);
  if (!(departure <= kRoundedRotationTolerance) || R.determinant () < 0.0)
  {
    // Say by how much: a rotation rounded to a few digits in a poses file fails the same way as
    // a scale, and the reader needs to know which.
    char why[160];
    if (R.determinant () < 0.0)
      std::snprintf (why, sizeof why, " (a reflection: det R = %.6g)", R.determinant ());
    else
      std::snprintf (why, sizeof why, " (R^T R departs from the identity by %.3g, more than the tolerance %g)", departure,
                     kRoundedRotationTolerance);
    return "pose " + name + " is not a rotation plus translation" + why;
  }
  if (!(T.translation ().cwiseAbs ().maxCoeff () <= kMaxCoordinate))
    return "pose " + name + " translation is beyond the supported range of +-1e15";
  return std::string ();
}
/** \brief The one check that a given covariance is a covariance: empty when the symmetric matrix
  * with these entries is positive semi-definite within rounding, otherwise "is not positive
  * semi-definite (xx .., yy .., zz .., xy .., xz .., yz ..)" with the entries at full precision.
  * Principal minors in double against the matrix's own scale (1e-6 of its largest entry), so
  * singular covariances (a flat disc, zero) pass. Finite entries expected: a non-finite one is
  * the caller's case (buildCloudModel takes it for a missing value, the CloudModel constructor
  * refuses it). buildCloudModel (and so ProbabilisticCollision::setInputCovariances) and the
  * CloudModel constructor both call it (found in review: -1e-6 I read as a sure collision; a
  * probe of 2026-12-04: the constructor took -4e-6 I everywhere and answered Ok). */
inline std::string
covarianceError (double xx, double xy, double xz, double yy, double yz, double zz)
{
  const double scale = std::max ({std::abs (xx), std::abs (yy), std::abs (zz), std::abs (xy), std::abs (xz), std::abs (yz)});
  const double tol = 1e-6 * scale;
  const double minor_xy = xx * yy - xy * xy, minor_xz = xx * zz - xz * xz, minor_yz = yy * zz - yz * yz;
  const double det = xx * minor_yz - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
  if (xx < -tol || yy < -tol || zz < -tol || minor_xy < -tol * scale || minor_xz < -tol * scale ||
      minor_yz < -tol * scale || det < -tol * scale * scale)
  {
    char why[256];
    std::snprintf (why, sizeof why, "is not positive semi-definite (xx %.9g, yy %.9g, zz %.9g, xy %.9g, xz %.9g, yz %.9g)",
                   xx, yy, zz, xy, xz, yz);
    return why;
  }
  return std::string ();
}

/** \brief covarianceError() of the symmetric part (S + S^T) / 2 of s, the part a model keeps
  * (PackedCovariance). */
inline std::string
covarianceError (const Eigen::Matrix3d& s)
{
  return covarianceError (s (0, 0), 0.5 * (s (0, 1) + s (1, 0)), 0.5 * (s (0, 2) + s (2, 0)), s (1, 1),
                          0.5 * (s (1, 2) + s (2, 1)), s (2, 2));
}
} // namespace detail
} // namespace pcl_probcollision
