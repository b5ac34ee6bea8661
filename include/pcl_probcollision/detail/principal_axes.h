// SPDX-License-Identifier: BSD-3-Clause
// Principal axes that turn with the points: the one rule for a hierarchy node's box axes and for
// the frame a classification's random features are drawn in. Internal: not API.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <cstddef>

namespace pcl_probcollision
{
namespace detail
{
/** \brief The mean of n points and the eigen-decomposition of their scatter (ascending
  * eigenvalues lambda, eigenvectors the columns of V; zero eigenvalues and identity axes when the
  * solver fails).
  * \param[in] point point (i) gives point i, for i < n (n > 0) */
template <typename PointAt>
void
meanAndScatter (std::size_t n, const PointAt& point, Eigen::Vector3d& mean, Eigen::Vector3d& lambda, Eigen::Matrix3d& V)
{
  mean.setZero ();
  for (std::size_t i = 0; i < n; ++i)
    mean += point (i);
  mean /= static_cast<double> (n);
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero ();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector3d d = point (i) - mean;
    C.noalias () += d * d.transpose ();
  }
  C /= static_cast<double> (n);

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es (C);
  lambda = es.eigenvalues ();
  V = es.eigenvectors ();
  if (es.info () != Eigen::Success || !V.allFinite ())
  {
    lambda.setZero ();
    V.setIdentity ();
  }
}

/** \brief The principal axes of n points (meanAndScatter), the largest spread first, with the
  * signs a rigid motion of the points carries along.
  *
  * An eigen solver picks the sign of each eigenvector arbitrarily. Each of the first two axes is
  * turned to where the points' third moment about their mean along it is positive, and the third
  * is their cross product, so axes is a rotation. (A third moment of exactly 0, a symmetric set,
  * keeps the solver's sign; points of equal spread along two axes leave those axes to the solver.)
  * \param[in] point point (i) gives point i, for i < n (n > 0)
  * \param[out] mean the points' mean
  * \param[out] lambda the scatter's eigenvalues, ascending
  * \param[out] axes the axes, columns */
template <typename PointAt>
void
principalFrame (std::size_t n, const PointAt& point, Eigen::Vector3d& mean, Eigen::Vector3d& lambda, Eigen::Matrix3d& axes)
{
  Eigen::Matrix3d V;
  meanAndScatter (n, point, mean, lambda, V);
  axes.col (0) = V.col (2);
  axes.col (1) = V.col (1);
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
