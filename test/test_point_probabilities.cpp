// SPDX-License-Identifier: BSD-3-Clause
// detail/point_probabilities.h: the per-point probability P_i of a fitted rung (METHOD.md 6.1)
// against Monte Carlo sampling of the point's Gaussian (METHOD.md 11.7): within 3 standard
// errors for a plane at any noise level, and within a second-order Taylor bound for a curved
// random-feature surface. Through RobustClassifier.
#include <pcl_probcollision/robust_classifier.h>

#include <gtest/gtest.h>

#include "scenes.h"
#include "seeded_draws.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using Cloud = pcl_probcollision_test::ClassifierCloud;
using pcl_probcollision_test::bowl;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::genericPatches;

namespace
{
const double kPi = 3.14159265358979323846;
} // namespace

TEST (PointProbabilities, MonteCarloLinear)
{
  // METHOD.md 11.7: the fraction of samples x ~ N(mean_i, Sigma_i) with c_i f(x) < 0 matches
  // P_i within 3 standard errors; for a linear f at any noise level.
  Cloud a, b;
  genericPatches (a, b);
  for (Eigen::Matrix3d& c : a.covariances)
    c *= 4.0;  // larger noise: P_i in a range where the comparison has power
  ClassifierParams p;
  p.kernel = KernelMode::Linear;
  const RobustClassifier classifier (p);
  ClassifierResult r;
  ASSERT_TRUE (classifier.classify (a.view (), b.view (), r));
  std::mt19937_64 rng (2024);
  std::normal_distribution<double> z (0.0, 1.0);
  const int samples = 100000;
  int tested = 0;
  for (int side = 0; side < 2; ++side)
  {
    const Cloud& cloud = side == 0 ? a : b;
    const std::vector<double>& probabilities = side == 0 ? r.probabilities_a : r.probabilities_b;
    const double c = side == 0 ? 1.0 : -1.0;
    for (std::size_t i = 0; i < cloud.size () && tested < 6; i += 7)
    {
      if (probabilities[i] < 0.01)
        continue;
      const Eigen::Matrix3d l = cloud.covariances[i].llt ().matrixL ();
      int crossed = 0;
      for (int s = 0; s < samples; ++s)
      {
        const Eigen::Vector3d x = cloud.means[i] + l * draw3 (z, rng);
        crossed += c * classifier.evaluate (r.separator, x) < 0.0;
      }
      const double pi = probabilities[i], se = std::sqrt (pi * (1.0 - pi) / samples);
      EXPECT_NEAR (static_cast<double> (crossed) / samples, pi, 3.0 * se) << "side " << side << " point " << i;
      ++tested;
    }
  }
  EXPECT_GE (tested, 4);
}

TEST (PointProbabilities, MonteCarloRff)
{
  // For a curved f the linearisation is first order. Second-order Taylor: f(x_i + e) = f_i +
  // g^T e + e^T H e / 2 + O(|e|^3), and e^T H e / 2 has mean tr(H Sigma) / 2 and standard
  // deviation sqrt(tr((H Sigma)^2) / 2). The documented error bound on P_i is the density
  // bound 1/sqrt(2 pi) times (|tr(H Sigma)| / 2 + sqrt(tr((H Sigma)^2) / 2)) / s_i, plus 3
  // standard errors, with H from central differences of the gradient.
  Cloud ball, cup;
  bowl (200, 0.02, ball, cup);
  ClassifierParams p;
  p.kernel = KernelMode::RFF;
  const RobustClassifier classifier (p);
  ClassifierResult r;
  ASSERT_TRUE (classifier.classify (ball.view (), cup.view (), r));
  std::mt19937_64 rng (99);
  std::normal_distribution<double> z (0.0, 1.0);
  const int samples = 100000;
  // the points with the largest P on each side
  for (int side = 0; side < 2; ++side)
  {
    const Cloud& cloud = side == 0 ? ball : cup;
    const std::vector<double>& probabilities = side == 0 ? r.probabilities_a : r.probabilities_b;
    const std::size_t i = static_cast<std::size_t> (
        std::max_element (probabilities.begin (), probabilities.end ()) - probabilities.begin ());
    const double c = side == 0 ? 1.0 : -1.0;
    const Eigen::Vector3d& x0 = cloud.means[i];
    const Eigen::Matrix3d& sigma = cloud.covariances[i];
    Eigen::Vector3d g;
    classifier.evaluate (r.separator, x0, &g);
    Eigen::Matrix3d h;
    const double step = 1e-5;
    for (int k = 0; k < 3; ++k)
    {
      Eigen::Vector3d gp, gm;
      classifier.evaluate (r.separator, x0 + step * Eigen::Vector3d::Unit (k), &gp);
      classifier.evaluate (r.separator, x0 - step * Eigen::Vector3d::Unit (k), &gm);
      h.col (k) = (gp - gm) / (2.0 * step);
    }
    const Eigen::Matrix3d hs = h * sigma;
    const double s = std::sqrt (g.dot (sigma * g));
    const double bias = (0.5 * std::abs (hs.trace ()) + std::sqrt (0.5 * (hs * hs).trace ())) / s / std::sqrt (2.0 * kPi);
    const Eigen::Matrix3d l = sigma.llt ().matrixL ();
    int crossed = 0;
    for (int k = 0; k < samples; ++k)
      crossed += c * classifier.evaluate (r.separator, x0 + l * draw3 (z, rng)) < 0.0;
    const double pi = probabilities[i], se = std::sqrt (std::max (pi * (1.0 - pi), 1.0 / samples) / samples);
    const double observed = static_cast<double> (crossed) / samples;
    std::cout << "[ RFF Monte Carlo ] side " << side << " point " << i << ": P_i " << pi
              << ", sampled " << observed << ", bound " << 3.0 * se + bias << "\n";
    EXPECT_NEAR (observed, pi, 3.0 * se + bias);
  }
}
