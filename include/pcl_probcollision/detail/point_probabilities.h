// SPDX-License-Identifier: BSD-3-Clause
// The per-point collision probability of a fitted rung (METHOD.md 6.1) and the quantities it
// shares with the gamma cap of training (METHOD.md 5.2): |g_i| and g_i^T Sigma_i g_i.
// Defined in src/detail/point_probabilities.cpp. Internal: not API.
#pragma once

#include <pcl_probcollision/detail/separator_fit.h>
#include <pcl_probcollision/detail/separator_problem.h>

#include <Eigen/Core>

namespace pcl_probcollision
{
namespace detail
{
/** \brief |grad f| below this (unit-cube units) is a collapsed classifier (METHOD.md 6.1). */
constexpr double kCollapse = 1e-8;
/** \brief Standard deviation along the gradient below this counts as none (METHOD.md 6.1). */
constexpr double kNoSpread = 1e-12;

/** \brief g_i^T Sigma_i g_i (clamped at 0) for per-point gradients, or for one gradient w. */
Eigen::ArrayXd quadraticForms (const SeparatorProblem& p, const RungFit& fit);

/** \brief |g_i| for each of the n points. */
Eigen::ArrayXd gradientNorms (const RungFit& fit, Eigen::Index n);

/** \brief METHOD.md 6.1 for every point, and the ladder's misclassification count: fills
  * fit.probability, fit.misclassified and fit.degenerate. With u_i = c_i f_i / |g_i| and
  * sigma_i = sqrt(g_i^T Sigma_i g_i) / |g_i|: |g_i| < kCollapse gives 0.5 (collapsed, counted
  * as misclassified); sigma_i < kNoSpread gives 1, 0.5 or 0 by the sign of u_i (tolerance
  * kNoSpread); otherwise Phi(-u_i / sigma_i), misclassified when u_i < -depth_sigmas sigma_i. */
void assessFit (const SeparatorProblem& p, double depth_sigmas, RungFit& fit);
} // namespace detail
} // namespace pcl_probcollision
