// SPDX-License-Identifier: BSD-3-Clause
// The normalised two-class problem shared by the linear and the RFF rung (METHOD.md 4, 5.1,
// 5.3): points in the unit cube, covariances times S^2, labels, class-balanced weights, and
// the margin loss. Internal: not API.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <limits>

namespace pcl_probcollision
{
namespace detail
{
/** \brief eps_s of METHOD.md 5.3: s_i = sqrt(w^T Sigma_i w + eps_s^2). */
constexpr double kSigmaFloor = 1e-12;
/** \brief eta_b of METHOD.md 5.3: a ridge eta_b b^2 / 2 on the bias, so that H is never singular. */
constexpr double kBiasRidge = 1e-10;

/** \brief The loss l(v) of METHOD.md 5.3 and its first two derivatives. */
struct MarginLoss
{
  bool huber = false;   ///< false: squared hinge max(0, v)^2 / 2; true: Huberised hinge
  double width = 0.01;  ///< h of the Huberised hinge

  double value (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return 0.5 * v * v;
    return v <= width ? v * v / (2.0 * width) : v - 0.5 * width;
  }
  double first (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return v;
    return v <= width ? v / width : 1.0;
  }
  /** \brief The generalised second derivative ([v > 0] for the squared hinge). */
  double second (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return 1.0;
    return v <= width ? 1.0 / width : 0.0;
  }
  /** \brief sum_i weight_i l(v_i), vectorised. */
  template <typename Derived>
  double weightedSum (const Eigen::ArrayBase<Derived>& v, const Eigen::ArrayXd& weight) const
  {
    if (!huber)
      return 0.5 * (weight * v.max (0.0).square ()).sum ();
    // l = min(m, h)^2 / (2h) + (m - min(m, h)) with m = max(v, 0)
    const Eigen::ArrayXd m = v.max (0.0);
    return (weight * (m.min (width).square () / (2.0 * width) + (m - m.min (width)))).sum ();
  }
};

/** \brief The normalised problem, structure of arrays, points of A (label +1) first. */
struct SeparatorProblem
{
  Eigen::Index n = 0;    ///< number of points
  Eigen::Index n_a = 0;  ///< points 0 .. n_a - 1 belong to A
  Eigen::ArrayXd x, y, z;                       ///< unit-cube means
  Eigen::ArrayXd sxx, sxy, sxz, syy, syz, szz;  ///< unit-cube covariances S Sigma_i S^T
  Eigen::ArrayXd label;                         ///< c_i = +1 (A) or -1 (B)
  Eigen::ArrayXd weight;                        ///< C_i = C n / (2 n_{c_i})

  Eigen::Vector3d point (Eigen::Index i) const { return Eigen::Vector3d (x (i), y (i), z (i)); }
  Eigen::Matrix3d covariance (Eigen::Index i) const
  {
    Eigen::Matrix3d m;
    m << sxx (i), sxy (i), sxz (i), sxy (i), syy (i), syz (i), sxz (i), syz (i), szz (i);
    return m;
  }
  /** \brief g^T Sigma_i g, clamped at 0 (covariances are PSD up to rounding). */
  double quadratic (Eigen::Index i, const Eigen::Vector3d& g) const
  {
    const double q = g (0) * g (0) * sxx (i) + g (1) * g (1) * syy (i) + g (2) * g (2) * szz (i) +
                     2.0 * (g (0) * g (1) * sxy (i) + g (0) * g (2) * sxz (i) + g (1) * g (2) * syz (i));
    return std::max (q, 0.0);
  }
};

/** \brief How one solve went. */
struct SolverReport
{
  int iterations = 0;
  bool converged = false;
  double objective = std::numeric_limits<double>::quiet_NaN ();
};
} // namespace detail
} // namespace pcl_probcollision
