// SPDX-License-Identifier: BSD-3-Clause
// detail/rff_features.h: the random Fourier feature map of the kernel rung (METHOD.md 5.5): its
// Jacobian against central differences, its inner products against the RBF kernel, and the
// draw (reproducible, the small rung a prefix of the large one, the right moments).
#include <pcl_probcollision/detail/rff_features.h>

#include <gtest/gtest.h>

#include "seeded_draws.h"

#include <Eigen/Core>

#include <cmath>
#include <random>

using namespace pcl_probcollision;
using pcl_probcollision_test::draw3;

namespace
{
const double kPi = 3.14159265358979323846;
} // namespace

TEST (RffFeatures, RffJacobianMatchesCentralDifferences)
{
  Eigen::MatrixXd omega;
  Eigen::VectorXd beta;
  const int features = 256;
  detail::drawRandomFourierFeatures (12345, features, 1.0, omega, beta);
  std::mt19937_64 rng (5);
  std::uniform_real_distribution<double> u (0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial)
  {
    const Eigen::Vector3d x = draw3 (u, rng);
    Eigen::VectorXd phi0;
    Eigen::MatrixXd jacobian;
    detail::rffFeatures (omega, beta, features, x, phi0, &jacobian);
    Eigen::MatrixXd numeric (features, 3);
    const double step = 1e-6;
    for (int k = 0; k < 3; ++k)
    {
      Eigen::VectorXd plus, minus;
      detail::rffFeatures (omega, beta, features, x + step * Eigen::Vector3d::Unit (k), plus);
      detail::rffFeatures (omega, beta, features, x - step * Eigen::Vector3d::Unit (k), minus);
      numeric.col (k) = (plus - minus) / (2.0 * step);
    }
    EXPECT_LT ((numeric - jacobian).norm () / jacobian.norm (), 1e-6);
  }
}

TEST (RffFeatures, RffApproximatesTheRbfKernel)
{
  std::mt19937_64 rng (8);
  std::uniform_real_distribution<double> u (0.0, 1.0);
  for (int features : {256, 4096})
    for (double gamma_k : {1.0, 10.0})
    {
      Eigen::MatrixXd omega;
      Eigen::VectorXd beta;
      detail::drawRandomFourierFeatures (12345, features, gamma_k, omega, beta);
      double error = 0.0;
      const int pairs = 2000;
      for (int k = 0; k < pairs; ++k)
      {
        const Eigen::Vector3d x = draw3 (u, rng);
        const Eigen::Vector3d y = draw3 (u, rng);
        Eigen::VectorXd px, py;
        detail::rffFeatures (omega, beta, features, x, px);
        detail::rffFeatures (omega, beta, features, y, py);
        error += std::abs (px.dot (py) - std::exp (-gamma_k * (x - y).squaredNorm ()));
      }
      EXPECT_LE (error / pairs, 3.0 / std::sqrt (static_cast<double> (features)))
          << "D " << features << " gamma_k " << gamma_k;
    }
}

TEST (RffFeatures, RffDrawIsReproducibleAndHasTheRightMoments)
{
  Eigen::MatrixXd o1, o2, o3;
  Eigen::VectorXd b1, b2, b3;
  detail::drawRandomFourierFeatures (12345, 4096, 2.5, o1, b1);
  detail::drawRandomFourierFeatures (12345, 4096, 2.5, o2, b2);
  detail::drawRandomFourierFeatures (12345, 256, 2.5, o3, b3);
  EXPECT_EQ (o1, o2);
  EXPECT_EQ (b1, b2);
  EXPECT_EQ (o1.topRows (256), o3);  // the small rung is a prefix of the large one
  EXPECT_EQ (b1.head (256), b3);
  // omega_k ~ N(0, 2 gamma_k I): 12288 draws, variance 5; 5 standard errors
  const double n = static_cast<double> (o1.size ());
  const double mean = o1.mean (), var = (o1.array () - mean).square ().sum () / (n - 1.0);
  EXPECT_NEAR (mean, 0.0, 5.0 * std::sqrt (5.0 / n));
  EXPECT_NEAR (var, 5.0, 5.0 * 5.0 * std::sqrt (2.0 / n));
  // beta ~ U[0, 2 pi)
  EXPECT_GE (b1.minCoeff (), 0.0);
  EXPECT_LT (b1.maxCoeff (), 2.0 * kPi);
  EXPECT_NEAR (b1.mean (), kPi, 5.0 * 2.0 * kPi / std::sqrt (12.0 * 4096.0));
}
