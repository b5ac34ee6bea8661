// SPDX-License-Identifier: BSD-3-Clause
// The hot loops of the classifier: O(n) per Newton step of the linear rung, O(n D) per L-BFGS
// step of the random Fourier feature rung. Defined in src/detail/kernels.cpp, where GCC on
// x86-64 compiles them for AVX-512, AVX2 + FMA and baseline SSE2 and picks one at load time
// (target_clones): the project builds with plain -O2, and these loops are nearly all of the
// cost. Clones differ only in rounding (FMA contraction), at the ulp level.
// Internal: not API.
#pragma once

#include <cstddef>

namespace pcl_probcollision
{
namespace detail
{
/** \brief The per-point data of the linear rung (unit-cube frame), structure of arrays. */
struct LinearPoints
{
  std::size_t n;
  const double *x, *y, *z;                    ///< means
  const double *sxx, *sxy, *sxz, *syy, *syz, *szz;  ///< covariances
  const double *label, *weight;               ///< c_i and C_i
};

/** \brief v_i = 1 - c_i (w . x_i + b) + gamma s_i with s_i = sqrt(max(0, w^T Sigma_i w) + eps^2)
  * (s_i written only when gamma > 0); returns sum_i C_i l(v_i), l the squared hinge
  * (huber_width = 0) or the Huberised hinge of that width. */
double linearLoss (const LinearPoints& p, const double* theta, double gamma, double huber_width,
                   double eps, double* v, double* s);

/** \brief Sums for the gradient and generalised Hessian of the linear objective at the v, s of
  * linearLoss(): out[0..3] = sum_i a_i d_i, out[4..13] = upper triangle (row-major) of
  * sum_i h_i d_i d_i^T, out[14..19] = upper triangle of sum_i a_i gamma (Sigma_i / s_i -
  * Sigma_i w w^T Sigma_i / s_i^3), with a_i = C_i l'(v_i), h_i = C_i l''(v_i) and
  * d_i = (-c_i x_i + gamma Sigma_i w / s_i, -c_i). */
void linearDerivatives (const LinearPoints& p, const double* theta, double gamma,
                        double huber_width, const double* v, const double* s, double* out);

/** \brief s_i = sin(z_i), c_i = cos(z_i): Cody-Waite reduction by pi/2 (three parts, exact
  * for |z| < 2^20 pi/2) and the fdlibm kernel polynomials on [-pi/4, pi/4], within ~2 ulp of
  * std::sin / std::cos. Blocks with an argument beyond 1e5 in magnitude or not finite take
  * std::sin / std::cos. glibc's scalar pair costs ~17 ns here; this loop ~1.5 ns. */
void sinCos (const double* z, double* s, double* c, std::size_t n);

/** \brief Rows i < n of phi = sqrt(2/D) cos(arg) and sm = -sqrt(2/D) sin(arg), where
  * arg_ik = ox_k x_i + oy_k y_i + oz_k z_i + beta_k. phi and sm are row-major n x D. */
void rffFeatureRows (std::size_t n, std::size_t features, const double* x, const double* y,
                     const double* z, const double* ox, const double* oy, const double* oz,
                     const double* beta, double* phi, double* sm);

/** \brief f_i = phi_i . w and g_i = (sm_i . wx, sm_i . wy, sm_i . wz) for every row (with
  * wx = w o Omega_x etc. g_i is grad f at x_i, since sm_i carries -sqrt(2/D)). */
void rffForward (std::size_t n, std::size_t features, const double* phi, const double* sm,
                 const double* w, const double* wx, const double* wy, const double* wz,
                 double* f, double* gx, double* gy, double* gz);

/** \brief The per-point data of the RFF rung. */
struct RffRows
{
  std::size_t n, features;
  const double *phi, *sm;                           ///< n x D row-major
  const double *ox, *oy, *oz;                       ///< columns of Omega
  const double *label, *weight;                     ///< c_i and C_i
  const double *sxx, *sxy, *sxz, *syy, *syz, *szz;  ///< unit-cube covariances
  const double* lipschitz;  ///< K_i: |s_i(w') - s_i(w)| <= K_i |w' - w|
};

/** \brief The RFF objective's data term and its gradient in one pass over the rows, each row
  * read once (the dot products and the gradient update of a row block share the cache).
  * With v_i = 1 - c_i (phi_i . w + b) + gamma s_i and s_i = sqrt(g_i^T Sigma_i g_i + eps^2),
  * g_i = (sm_i . wx, sm_i . wy, sm_i . wz): returns sum_i C_i l(v_i), writes v, adds
  * sum_i C_i l'(v_i) (-c_i phi_i + gamma sm_i o (Omega Sigma_i g_i) / s_i) to grad (D) and
  * sum_i -c_i C_i l'(v_i) to *grad_b. With gamma > 0, a row whose violation is certainly
  * <= 0 under s_i <= s_bound_i + K_i displacement (displacement < 0: no bound) skips g_i:
  * s_bound_out_i gets that bound, else the exact s_i. l is the squared hinge when
  * huber_width = 0, else the Huberised hinge. */
double rffObjective (const RffRows& rows, const double* w, double b, const double* wx,
                     const double* wy, const double* wz, double gamma, double huber_width,
                     double eps, const double* s_bound, double displacement, double* s_bound_out,
                     double* v, double* grad, double* grad_b);

/** \brief Number of columns of the preconditioner's projection (rff_separator.h). */
constexpr std::size_t kProjection = 10;

/** \brief u = phi^T q: q is n x kProjection, u is D x kProjection, both column-major. */
void rffProjectColumns (std::size_t n, std::size_t features, const double* phi, const double* q,
                        double* u);

/** \brief p = phi basis: basis is D x kProjection and p n x kProjection, column-major. */
void rffProjectRows (std::size_t n, std::size_t features, const double* phi, const double* basis,
                     double* p);
} // namespace detail
} // namespace pcl_probcollision
