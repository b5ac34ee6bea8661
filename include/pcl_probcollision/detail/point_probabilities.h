// SPDX-License-Identifier: BSD-3-Clause
// The per-point collision probability of a fitted rung (METHOD.md 6.1) and the quantities it
// shares with the gamma cap of training (METHOD.md 5.2): |g_i| and g_i^T Sigma_i g_i.
// Defined in src/detail/point_probabilities.cpp. Internal: not API.
#pragma once

#include <pcl_probcollision/detail/separator_fit.h>
#include <pcl_probcollision/detail/separator_problem.h>

#include <Eigen/Core>

#include <cmath>
#include <limits>

namespace pcl_probcollision
{
namespace detail
{
/** \brief |grad f| below this (unit-cube units) is a collapsed classifier (METHOD.md 6.1). */
constexpr double kCollapse = 1e-8;
/** \brief Standard deviation along the gradient below this counts as none (METHOD.md 6.1). */
constexpr double kNoSpread = 1e-12;

/** \brief g_i^T Sigma_i g_i (clamped at 0) of point i: its own gradient, or a plane's w. */
inline double
quadraticForm (const SeparatorProblem& p, const RungFit& fit, Eigen::Index i)
{
  const bool plane = fit.isPlane ();
  const double gx = plane ? fit.plane_gradient (0) : fit.gx (i);
  const double gy = plane ? fit.plane_gradient (1) : fit.gy (i);
  const double gz = plane ? fit.plane_gradient (2) : fit.gz (i);
  const double q = gx * gx * p.sxx (i) + gy * gy * p.syy (i) + gz * gz * p.szz (i) +
                   2.0 * (gx * gy * p.sxy (i) + gx * gz * p.sxz (i) + gy * gz * p.syz (i));
  return q > 0.0 ? q : 0.0;
}

/** \brief |g_i| of point i for per-point gradients (a plane's is plane_gradient.norm(), the
  * same for every point). */
inline double
gradientNorm (const RungFit& fit, Eigen::Index i)
{
  return std::sqrt (fit.gx (i) * fit.gx (i) + fit.gy (i) * fit.gy (i) + fit.gz (i) * fit.gz (i));
}

/** \brief z of a point at signed distance u from the surface (positive on its own side) with
  * standard deviation sigma along the normal, P = Phi(z): -u / sigma, or for sigma < kNoSpread
  * +inf, 0 or -inf by the sign of u (tolerance kNoSpread), i.e. P = 1, 0.5 or 0. */
inline double
pointZ (double u, double sigma)
{
  constexpr double inf = std::numeric_limits<double>::infinity ();
  if (sigma < kNoSpread)
    return u < -kNoSpread ? inf : (u <= kNoSpread ? 0.0 : -inf);
  return -u / sigma;
}

/** \brief METHOD.md 6.1 for every point, and the ladder's misclassification count: fills
  * fit.z (P_i = Phi(z_i)), fit.misclassified, fit.largest_spread and fit.degenerate. With u_i = c_i f_i / |g_i| and
  * sigma_i = sqrt(g_i^T Sigma_i g_i) / |g_i|: |g_i| < kCollapse gives P_i = 0.5 (collapsed,
  * counted as misclassified); sigma_i < kNoSpread gives 1, 0.5 or 0 by the sign of u_i
  * (tolerance kNoSpread); otherwise Phi(-u_i / sigma_i), misclassified when
  * u_i < -depth_sigmas sigma_i. */
void assessFit (const SeparatorProblem& p, double depth_sigmas, RungFit& fit);
} // namespace detail
} // namespace pcl_probcollision
