// SPDX-License-Identifier: BSD-3-Clause
// detail/separator_fit.h: the rung fits (METHOD.md 5.2, 5.3) checked from their definition,
// through RobustClassifier with the Linear rung: the plane returned minimises the objective
// J(w, b), written out here independently of the library, and Robust training's gamma follows
// the Standard solution as the gamma cap says.
#include <pcl_probcollision/robust_classifier.h>

#include <gtest/gtest.h>

#include "result_checks.h"
#include "scenes.h"
#include "seeded_draws.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using Cloud = pcl_probcollision_test::ClassifierCloud;
using pcl_probcollision_test::classify;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::genericPatches;
using pcl_probcollision_test::oracle;

namespace
{
/** \brief J(w, b) of METHOD.md 5.3 (squared hinge), written out independently of the library:
  * Uniform normalisation, class-balanced C_i, eps_s = 1e-12, eta_b = 1e-10. */
struct LinearObjective
{
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Matrix3d> sigma;
  std::vector<double> label, weight;
  double gamma = 0.0;

  LinearObjective (const Cloud& a, const Cloud& b, double c, double gamma_)
    : gamma (gamma_)
  {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero ();
    for (const Cloud* side : {&a, &b})
      for (const Eigen::Vector3d& m : side->means)
        centroid += m;
    const double n = static_cast<double> (a.size () + b.size ());
    centroid /= n;
    double r = 0.0;
    for (const Cloud* side : {&a, &b})
      for (const Eigen::Vector3d& m : side->means)
        r = std::max (r, (m - centroid).norm ());
    const double scale = 0.5 / r;
    for (const Cloud* side : {&a, &b})
      for (std::size_t i = 0; i < side->size (); ++i)
      {
        x.push_back (scale * (side->means[i] - centroid) + Eigen::Vector3d::Constant (0.5));
        sigma.push_back (scale * scale * side->covariances[i]);
        label.push_back (side == &a ? 1.0 : -1.0);
        weight.push_back (c * n / (2.0 * static_cast<double> (side->size ())));
      }
  }

  double operator() (const Eigen::Vector4d& theta) const
  {
    const Eigen::Vector3d w = theta.head<3> ();
    double j = 0.5 * w.squaredNorm () + 0.5 * 1e-10 * theta (3) * theta (3);
    for (std::size_t i = 0; i < x.size (); ++i)
    {
      const double v = 1.0 - label[i] * (w.dot (x[i]) + theta (3)) + gamma * std::sqrt (w.dot (sigma[i] * w) + 1e-24);
      j += weight[i] * 0.5 * std::max (v, 0.0) * std::max (v, 0.0);
    }
    return j;
  }
};

Eigen::Vector4d
theta (const ClassifierResult& r)
{
  Eigen::Vector4d t;
  t << r.separator.weights, r.separator.bias;
  return t;
}
} // namespace

TEST (SeparatorFit, LinearSolutionMinimisesTheObjective)
{
  // The returned (w, b) must be the minimiser of J: J is convex, so a point where no
  // direction decreases J (beyond rounding, ~1e-13 |J|) and the central-difference slope
  // vanishes (the solver stops at |grad J| <= 1e-10 max(1, |J|)) is the global minimum.
  Cloud a, b;
  genericPatches (a, b);
  std::mt19937_64 rng (17);
  std::normal_distribution<double> z (0.0, 1.0);
  for (TrainingMode mode : {TrainingMode::Standard, TrainingMode::Robust})
  {
    ClassifierParams p = oracle (mode);
    p.C = 10.0;
    const ClassifierResult r = classify (p, a, b);
    ASSERT_TRUE (r.converged);
    const LinearObjective objective (a, b, p.C, r.gamma_effective);
    const Eigen::Vector4d t = theta (r);
    const double j0 = objective (t);
    EXPECT_NEAR (j0, r.objective, 1e-12 * j0);
    for (int k = 0; k < 100; ++k)
    {
      const double d0 = z (rng);
      const Eigen::Vector3d d123 = draw3 (z, rng);
      const Eigen::Vector4d dir = Eigen::Vector4d (d0, d123 (0), d123 (1), d123 (2)).normalized ();
      const double h = 1e-4 * t.norm ();
      EXPECT_GE (objective (t + h * dir) - j0, -1e-13 * j0);
      // J is piecewise quadratic, so the central difference has no truncation error away from
      // the hinges; its rounding error is at most n eps |J| / step (n summed terms)
      const double step = 1e-5;
      const double slope = (objective (t + step * dir) - objective (t - step * dir)) / (2.0 * step);
      const double rounding = static_cast<double> (objective.x.size ()) * 1.1e-16 * j0 / step;
      EXPECT_LT (std::abs (slope), 1e-10 * std::max (1.0, j0) + rounding);
    }
  }
}

TEST (SeparatorFit, RobustGammaFollowsTheStandardSolution)
{
  // METHOD.md 5.2: t_hat = min c_i f_i / s_i over s_i > 0 on the Standard solution,
  // gamma_eff = min(gamma, 0.9 max(0, t_hat)).
  Cloud a, b;
  genericPatches (a, b);
  for (double scale : {0.5, 2.0, 8.0})
  {
    Cloud na = a, nb = b;
    for (Eigen::Matrix3d& c : na.covariances)
      c *= scale * scale;
    for (Eigen::Matrix3d& c : nb.covariances)
      c *= scale * scale;
    ClassifierParams p = oracle (TrainingMode::Standard);
    p.C = 10.0;
    const ClassifierResult standard = classify (p, na, nb);
    const LinearObjective o (na, nb, p.C, 0.0);
    const Eigen::Vector4d t = theta (standard);
    double t_hat = std::numeric_limits<double>::infinity ();
    for (std::size_t i = 0; i < o.x.size (); ++i)
    {
      const double s = std::sqrt (t.head<3> ().dot (o.sigma[i] * t.head<3> ()));
      if (s > 0.0)
        t_hat = std::min (t_hat, o.label[i] * (t.head<3> ().dot (o.x[i]) + t (3)) / s);
    }
    p.training = TrainingMode::Robust;
    const ClassifierResult robust = classify (p, na, nb);
    const double expected = std::min (normalQuantile (0.9), 0.9 * std::max (0.0, t_hat));
    std::cout << "[ robust gamma ] noise x" << scale << ": t_hat " << t_hat << ", gamma_eff "
              << robust.gamma_effective << "\n";
    EXPECT_NEAR (robust.gamma_effective, expected, 1e-12 * std::max (1.0, expected));
  }
}
