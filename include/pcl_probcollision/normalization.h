// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Core>

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
  * S Sigma S^T. S is diagonal (uniform or per axis). */
struct UnitCubeTransform
{
  Eigen::Vector3d scale = Eigen::Vector3d::Ones ();   ///< diagonal of S
  Eigen::Vector3d shift = Eigen::Vector3d::Zero ();   ///< m
  Eigen::Vector3d offset = Eigen::Vector3d::Zero ();  ///< o

  Eigen::Vector3d apply (const Eigen::Vector3d& x) const
  {
    return scale.cwiseProduct (x - shift) + offset;
  }
  Eigen::Vector3d applyInverse (const Eigen::Vector3d& y) const
  {
    return (y - offset).cwiseQuotient (scale) + shift;
  }
  /** \brief S Sigma S^T. */
  Eigen::Matrix3d applyToCovariance (const Eigen::Matrix3d& sigma) const
  {
    return scale.asDiagonal () * sigma * scale.asDiagonal ();
  }
  Eigen::Matrix3d applyInverseToCovariance (const Eigen::Matrix3d& sigma) const
  {
    const Eigen::Vector3d inv = scale.cwiseInverse ();
    return inv.asDiagonal () * sigma * inv.asDiagonal ();
  }
};

/** \brief The unit-cube map of the union of the given point sets (finite means only; an empty
  * union gives the identity).
  * \note Uniform: c is the centroid and r_c the largest distance to it; r_c = 0 gives S = I.
  *       PerAxis: m is the minimum corner and e the extents; extents below 1e-9 max(e) are
  *       raised to that value, all-zero extents give S = I. */
UnitCubeTransform computeUnitCubeTransform (const std::vector<const UncertainCloud*>& sets,
                                            Scaling scaling = Scaling::Uniform);

/** \brief Applies the map to every mean and covariance of a cloud, in place. */
void applyUnitCubeTransform (const UnitCubeTransform& transform, UncertainCloud& cloud);
} // namespace pcl_probcollision
