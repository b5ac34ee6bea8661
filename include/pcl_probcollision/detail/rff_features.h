// SPDX-License-Identifier: BSD-3-Clause
// Random Fourier features of the RBF kernel (METHOD.md 5.5): the draw of (Omega, beta), and the
// feature map phi(x) = sqrt(2/D) cos(Omega x + beta) with its Jacobian at one point.
// Internal: not API.
#pragma once

#include <pcl_probcollision/detail/kernels.h>
#include <pcl_probcollision/normal_distribution.h>

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Draws the random Fourier feature map of K(x, y) = exp(-gamma_k |x - y|^2):
  * rows omega_k ~ N(0, 2 gamma_k I_3) of omega (features x 3) and phases beta_k ~ U[0, 2 pi).
  *
  * Portable: uniforms are the top 53 bits of std::mt19937_64 (whose output sequence the C++
  * standard fixes) and normals come from Marsaglia's polar method written here, not from
  * std::normal_distribution (whose algorithm is implementation-defined). Only the last ulp of
  * std::log may differ between C libraries. Feature k consumes three normals and then one
  * uniform, so the first D rows do not depend on how many features are drawn. */
inline void
drawRandomFourierFeatures (std::uint64_t seed, int features, double rbf_gamma,
                           Eigen::MatrixXd& omega, Eigen::VectorXd& beta)
{
  std::mt19937_64 engine (seed);
  const auto uniform = [&engine] () { return uniformUnit (engine); };
  bool have_spare = false;
  double spare = 0.0;
  const auto normal = [&] () {
    if (have_spare)
    {
      have_spare = false;
      return spare;
    }
    double u, v, s;
    do
    {
      u = 2.0 * uniform () - 1.0;
      v = 2.0 * uniform () - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double factor = std::sqrt (-2.0 * std::log (s) / s);
    spare = v * factor;
    have_spare = true;
    return u * factor;
  };
  const double omega_sigma = std::sqrt (2.0 * rbf_gamma);
  constexpr double two_pi = 6.28318530717958647692;
  omega.resize (features, 3);
  beta.resize (features);
  for (int k = 0; k < features; ++k)
  {
    for (int d = 0; d < 3; ++d)
      omega (k, d) = omega_sigma * normal ();
    beta (k) = two_pi * uniform ();
  }
}

/** \brief The first D rows of a draw turned into a frame: omega_out = Omega_D R^T and
  * beta_out = beta_D - omega_out o with o = (1/2, 1/2, 1/2), so that
  * omega_out x' + beta_out = Omega_D R^T (x' - o) + beta_D: the features of a unit-cube point x'
  * taken in the frame R (columns: its axes) centred on the cube's centre. Omega's law,
  * N(0, 2 gamma I_3), is the same in every frame; fixing the draw in a frame that turns with the
  * points makes the features, and a fit on them, turn with the points too.
  * \param[in] omega, beta the draw of drawRandomFourierFeatures(), at least D rows */
inline void
rffDrawInFrame (const Eigen::MatrixXd& omega, const Eigen::VectorXd& beta, int features,
                const Eigen::Matrix3d& frame, Eigen::MatrixXd& omega_out, Eigen::VectorXd& beta_out)
{
  omega_out.noalias () = omega.topRows (features) * frame.transpose ();
  beta_out.noalias () = beta.head (features) - omega_out * Eigen::Vector3d::Constant (0.5);
}

/** \brief phi(x) = sqrt(2/D) cos(Omega_D x + beta_D) with the first D rows of omega and beta,
  * and optionally the Jacobian J(x) = -sqrt(2/D) diag(sin(Omega_D x + beta_D)) Omega_D (D x 3).
  * \param[in] omega, beta the draw of drawRandomFourierFeatures(), at least D rows */
inline void
rffFeatures (const Eigen::MatrixXd& omega, const Eigen::VectorXd& beta, int features,
             const Eigen::Vector3d& x, Eigen::VectorXd& phi, Eigen::MatrixXd* jacobian = nullptr)
{
  const Eigen::VectorXd arg = omega.topRows (features) * x + beta.head (features);
  Eigen::VectorXd sin_arg (features);
  phi.resize (features);
  sinCos (arg.data (), sin_arg.data (), phi.data (), static_cast<std::size_t> (features));
  const double norm = std::sqrt (2.0 / features);
  phi *= norm;
  if (jacobian)
    *jacobian = (-norm * sin_arg).asDiagonal () * omega.topRows (features);
}
} // namespace detail
} // namespace pcl_probcollision
