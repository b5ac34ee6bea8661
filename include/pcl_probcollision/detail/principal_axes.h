// SPDX-License-Identifier: BSD-3-Clause
// Principal axes that turn with the points: the one rule for the signs of a hierarchy node's
// box axes and of the frame a classification's random features are drawn in. Internal: not API.
#pragma once

#include <Eigen/Core>

#include <cstddef>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Gives principal axes the signs a rigid motion of the points carries along.
  *
  * An eigen solver picks the sign of each eigenvector arbitrarily. Each of the first two columns
  * of axes is turned to where the points' third moment about mean along it is positive, and the
  * third column is set to their cross product, so axes is a rotation. (A third moment of exactly
  * 0, a symmetric set, keeps the solver's sign.)
  * \param[in,out] axes orthonormal columns, the first two the ones to orient
  * \param[in] mean the points' mean
  * \param[in] n the number of points
  * \param[in] point point (i) gives point i, for i < n */
template <typename PointAt>
void
orientByThirdMoment (Eigen::Matrix3d& axes, const Eigen::Vector3d& mean, std::size_t n, const PointAt& point)
{
  Eigen::Vector2d third = Eigen::Vector2d::Zero ();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector2d d = axes.leftCols<2> ().transpose () * (point (i) - mean);
    third += d.cwiseProduct (d).cwiseProduct (d);
  }
  for (int k = 0; k < 2; ++k)
    if (third (k) < 0.0)
      axes.col (k) = -axes.col (k);
  axes.col (2) = axes.col (0).cross (axes.col (1));
}
} // namespace detail
} // namespace pcl_probcollision
