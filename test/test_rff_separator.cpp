// SPDX-License-Identifier: BSD-3-Clause
// detail/rff_separator.h: the kernel rung's solver. A problem of at most kExactPoints points is
// preconditioned by the exact Standard Hessian, a larger one by the polynomial subspace; both
// must reach the same minimiser. The reference is the same objective written differently: every
// point doubled at half its weight, solved on the subspace path.
#include <pcl_probcollision/detail/rff_features.h>
#include <pcl_probcollision/detail/rff_separator.h>

#include <gtest/gtest.h>

#include "seeded_draws.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <vector>

using namespace pcl_probcollision;
using pcl_probcollision::detail::RffSeparatorSolver;
using pcl_probcollision::detail::SeparatorProblem;
using pcl_probcollision_test::draw3;

namespace
{
/** \brief n points in the unit cube on either side of a wavy sheet, a few on the wrong side
  * (so that the active set is not empty at the optimum), each with an anisotropic covariance;
  * every point repeated `copies` times at 1 / copies of its weight. */
SeparatorProblem
wavySheet (int n, int copies, double c)
{
  std::mt19937_64 rng (7);
  std::uniform_real_distribution<double> unit (0.0, 1.0);
  std::vector<Eigen::Vector3d> x (static_cast<std::size_t> (n));
  std::vector<double> label (static_cast<std::size_t> (n));
  int n_a = 0;
  for (int i = 0; i < n; ++i)
  {
    const Eigen::Vector3d u = draw3 (unit, rng);
    const double sheet = 0.5 + 0.15 * std::sin (6.0 * u.x ()) * std::cos (5.0 * u.y ());
    const bool above = i % 2 == 0;
    const bool wrong = i % 9 == 4;  // a few points across the sheet
    const double offset = (above != wrong ? 1.0 : -1.0) * (0.05 + 0.3 * u.z ());
    x[static_cast<std::size_t> (i)] = Eigen::Vector3d (u.x (), u.y (), sheet + offset);
    label[static_cast<std::size_t> (i)] = above ? 1.0 : -1.0;
    n_a += above;
  }
  SeparatorProblem p;
  p.resize (static_cast<Eigen::Index> (n) * copies);
  p.n_a = static_cast<Eigen::Index> (n_a) * copies;
  Eigen::Index k = 0;
  for (const double side : {1.0, -1.0})  // points of A first
    for (int i = 0; i < n; ++i)
      for (int copy = 0; copy < copies; ++copy)
      {
        const std::size_t j = static_cast<std::size_t> (i);
        if (label[j] != side)
          continue;
        p.x (k) = x[j].x ();
        p.y (k) = x[j].y ();
        p.z (k) = x[j].z ();
        p.sxx (k) = 4e-4;
        p.syy (k) = 1e-4;
        p.szz (k) = 2.5e-5 * (1.0 + j % 3);
        p.sxy (k) = 5e-5;
        p.sxz (k) = p.syz (k) = 0.0;
        p.label (k) = side;
        const double n_side = side > 0.0 ? n_a : n - n_a;
        p.weight (k) = c * n / (2.0 * n_side) / copies;
        ++k;
      }
  return p;
}

struct Solved
{
  Eigen::VectorXd theta;
  int standard_iterations = 0;
  double standard_objective = 0.0;
  bool converged = false;
};

Solved
solve (const SeparatorProblem& p, double gamma, Eigen::Index exact_points = RffSeparatorSolver::kExactPoints)
{
  Eigen::MatrixXd omega;
  Eigen::VectorXd beta;
  constexpr int kFeatures = 256;
  detail::drawRandomFourierFeatures (11, kFeatures, 4.0, omega, beta);
  std::vector<double> workspace;
  RffSeparatorSolver solver (p, detail::MarginLoss (), omega, beta, kFeatures, workspace, exact_points);
  Solved s;
  s.theta = Eigen::VectorXd::Zero (kFeatures + 1);
  const detail::SolverReport standard = solver.solve (s.theta, 0.0, 10000, 1e-9);
  s.standard_iterations = standard.iterations;
  s.standard_objective = standard.objective;
  const detail::SolverReport robust = solver.solve (s.theta, gamma, 10000, 1e-9);
  s.converged = standard.converged && robust.converged;
  return s;
}
} // namespace

TEST (RffSeparatorSolver, ExactAndSubspacePreconditionersReachTheSameMinimiser)
{
  const int n = 40;
  ASSERT_LE (n, RffSeparatorSolver::kExactPoints);
  const double gamma = 1.2815515655446004;  // Phi^-1(0.9)
  // C = 10: both paths converge
  const Solved exact = solve (wavySheet (n, 1, 10.0), gamma);
  const Solved subspace = solve (wavySheet (n, 2, 10.0), gamma, 0);
  ASSERT_TRUE (exact.converged);
  ASSERT_TRUE (subspace.converged);
  const double scale = subspace.theta.cwiseAbs ().maxCoeff ();
  const double difference = (exact.theta - subspace.theta).cwiseAbs ().maxCoeff ();
  std::cout << "[ C = 10 ] Standard solve " << exact.standard_iterations << " (exact) vs "
            << subspace.standard_iterations << " (subspace) iterations; max |theta difference| "
            << difference << " of max |theta| " << scale << "\n";
  EXPECT_GT (scale, 1.0);  // a separator that does something
  EXPECT_LT (difference, 1e-6 * scale);
  // The Standard objective is piecewise quadratic: with its exact Hessian each step is
  // Newton's, which ends once the active set settles.
  EXPECT_LE (exact.standard_iterations, 10);
  EXPECT_LT (exact.standard_iterations, subspace.standard_iterations);

  // The library's C = 1000: the subspace path does not reach the tolerance in 10,000
  // iterations on this problem (not run here); the exact one does in a few.
  const Solved stiff = solve (wavySheet (n, 1, 1000.0), gamma);
  std::cout << "[ C = 1000 ] Standard solve " << stiff.standard_iterations << " iterations (exact)\n";
  EXPECT_TRUE (stiff.converged);
  EXPECT_LE (stiff.standard_iterations, 10);
}

TEST (RffSeparatorSolver, AStiffNewtonSolveStopsAtRounding)
{
  // At C = 1e9 the tolerance on |grad J| is out of reach of rounding; full Newton steps that
  // leave J equal were accepted until the iteration cap (10,000 here). The solve must stop
  // near the optimum instead: this problem is separable, so J(C) rises to the hard-margin
  // value as C grows, and J at 1e9 lies just above J at 1e6.
  const double gamma = 0.0;  // the Standard solve only (the second one starts at its end)
  const Solved soft = solve (wavySheet (40, 1, 1e6), gamma);
  const Solved stiff = solve (wavySheet (40, 1, 1e9), gamma);
  std::cout << "[ C = 1e6 / 1e9 ] Standard solve " << soft.standard_iterations << " / "
            << stiff.standard_iterations << " iterations, J " << soft.standard_objective << " / "
            << stiff.standard_objective << "\n";
  EXPECT_LE (stiff.standard_iterations, 30);
  EXPECT_GE (stiff.standard_objective, soft.standard_objective * (1.0 - 1e-9));
  EXPECT_LE (stiff.standard_objective, soft.standard_objective * 1.001);
}

// The leaf problem's columns (what every rung reads): n values each, aligned as an
// Eigen::ArrayXd, apart from each other, the buffer kept when a problem shrinks (classify()
// reuses one per thread) and freed by releaseAbove(); a copy owns its own values.
TEST (SeparatorProblem, ColumnsFollowResizeWithoutReallocatingWhenSmaller)
{
  SeparatorProblem p;
  const auto columns = [] (SeparatorProblem& q) {
    return std::vector<SeparatorProblem::Column*> {&q.x, &q.y, &q.z, &q.sxx, &q.sxy, &q.sxz,
                                                   &q.syy, &q.syz, &q.szz, &q.label, &q.weight};
  };
  const auto check = [&] (SeparatorProblem& q, Eigen::Index n) {
    for (SeparatorProblem::Column* c : columns (q))
    {
      EXPECT_EQ (c->size (), n);
      EXPECT_EQ (reinterpret_cast<std::uintptr_t> (c->data ()) % EIGEN_MAX_ALIGN_BYTES, 0u);
    }
    // Every column written with its own value, then read back: no two overlap.
    double v = 1.0;
    for (SeparatorProblem::Column* c : columns (q))
      c->setConstant (v++);
    v = 1.0;
    for (SeparatorProblem::Column* c : columns (q))
      EXPECT_TRUE ((*c == v++).all ());
  };
  p.resize (37);
  check (p, 37);
  const double* before = p.x.data ();
  p.resize (5);
  check (p, 5);
  EXPECT_EQ (p.x.data (), before);  // the buffer was kept
  const SeparatorProblem copy = p;
  p.x.setConstant (-1.0);
  EXPECT_EQ (copy.x.size (), 5);
  EXPECT_TRUE ((copy.x == 1.0).all ());
  EXPECT_NE (copy.x.data (), p.x.data ());
  p.resize (40);
  check (p, 40);
  p.releaseAbove (1);
  EXPECT_EQ (p.n, 0);
  EXPECT_EQ (p.x.size (), 0);
  p.resize (3);
  check (p, 3);
}
