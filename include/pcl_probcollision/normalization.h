// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Core>

#include <initializer_list>
#include <vector>

namespace pcl_probcollision
{
/** \brief How a classification problem is mapped into the unit cube (METHOD.md 4). */
enum class Scaling
{
  Uniform,  ///< x' = (x - c) / (2 r_c) + 1/2: a similarity, invariant under rigid motion (default)
  PerAxis   ///< x' = diag(1/e) (x - min corner): the thesis' choice; changes angles
};

/** \brief The affine map x' = S (x - m) + o into the unit cube, with covariances mapped as
  * S Sigma S^T. S is diagonal (uniform or per axis). RobustClassifier maps every problem with
  * it (Uniform scaling). */
struct UnitCubeTransform
{
  Eigen::Vector3d scale = Eigen::Vector3d::Ones ();   ///< diagonal of S
  Eigen::Vector3d shift = Eigen::Vector3d::Zero ();   ///< m
  Eigen::Vector3d offset = Eigen::Vector3d::Zero ();  ///< o

  /** \brief Maps a point into the unit cube: S (x - m) + o. */
  Eigen::Vector3d apply (const Eigen::Vector3d& x) const
  {
    return scale.cwiseProduct (x - shift) + offset;
  }
  /** \brief Maps a unit-cube point back: S^-1 (y - o) + m. */
  Eigen::Vector3d applyInverse (const Eigen::Vector3d& y) const
  {
    return (y - offset).cwiseQuotient (scale) + shift;
  }
  /** \brief S Sigma S^T of the symmetric part of Sigma: s_i^2 Sigma_ii on the diagonal,
    * (s_i s_j / 2) (Sigma_ij + Sigma_ji) off it, evaluated in that order (the classifier's
    * results depend on it to the last bit). Exactly symmetric, as products such as
    * R Sigma R^T are only up to rounding. */
  Eigen::Matrix3d applyToCovariance (const Eigen::Matrix3d& sigma) const
  {
    const double sx = scale.x (), sy = scale.y (), sz = scale.z ();
    const double xy = sx * sy * 0.5 * (sigma (0, 1) + sigma (1, 0));
    const double xz = sx * sz * 0.5 * (sigma (0, 2) + sigma (2, 0));
    const double yz = sy * sz * 0.5 * (sigma (1, 2) + sigma (2, 1));
    Eigen::Matrix3d m;
    m << sx * sx * sigma (0, 0), xy, xz,
         xy, sy * sy * sigma (1, 1), yz,
         xz, yz, sz * sz * sigma (2, 2);
    return m;
  }
  /** \brief Maps a unit-cube covariance back: S^-1 Sigma S^-1 (not symmetrised). */
  Eigen::Matrix3d applyInverseToCovariance (const Eigen::Matrix3d& sigma) const
  {
    const Eigen::Vector3d inv = scale.cwiseInverse ();
    return inv.asDiagonal () * sigma * inv.asDiagonal ();
  }
  /** \brief False when the coordinates overflowed double precision while the map was computed
    * (see computeUnitCubeTransform()). */
  bool isFinite () const { return scale.allFinite () && shift.allFinite () && offset.allFinite (); }
};

/** \brief The Uniform map with centre c and scale s > 0: x' = s (x - c) + (1/2, 1/2, 1/2). */
inline UnitCubeTransform
uniformUnitCubeTransform (const Eigen::Vector3d& centre, double scale)
{
  UnitCubeTransform t;
  t.scale = Eigen::Vector3d::Constant (scale);
  t.shift = centre;
  t.offset = Eigen::Vector3d::Constant (0.5);
  return t;
}

/** \brief The unit-cube map of the union of the given point sets (finite means only; an empty
  * union gives the identity).
  * \note Uniform: c is the centroid and r_c the largest distance to it, S = 1 / (2 r_c); S = I
  *       when r_c = 0 or so small that 1 / (2 r_c) overflows. PerAxis: m is the minimum corner
  *       and e the extents; extents below 1e-9 max(e) are raised to that value, all-zero
  *       extents give S = I.
  * \note Means so large that their centroid or r_c overflows double precision give a map that
  *       is not finite (UnitCubeTransform::isFinite() is false), never a plausible one. */
UnitCubeTransform computeUnitCubeTransform (const std::vector<const UncertainCloud*>& sets,
                                            Scaling scaling = Scaling::Uniform);

/** \brief As above, for the means of point set views (covariances are not read). */
UnitCubeTransform computeUnitCubeTransform (std::initializer_list<PointSetView> sets,
                                            Scaling scaling = Scaling::Uniform);

/** \brief Applies the map to every mean and covariance of a cloud, in place. */
void applyUnitCubeTransform (const UnitCubeTransform& transform, UncertainCloud& cloud);
} // namespace pcl_probcollision
