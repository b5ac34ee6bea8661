// SPDX-License-Identifier: BSD-3-Clause
// The linear rung (METHOD.md 5.3): damped Newton on theta = (w, b) in R^4 for
//   J = |w|^2 / 2 + eta_b b^2 / 2 + sum_i C_i l(v_i),
//   v_i = 1 - c_i (w^T x_i + b) + gamma sqrt(w^T Sigma_i w + eps_s^2).
// Internal: not API.
#pragma once

#include <pcl_probcollision/detail/kernels.h>
#include <pcl_probcollision/detail/separator_problem.h>

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Damped Newton for the 4 unknowns of the plane. Keeps its work arrays between calls,
  * so one instance solves the Standard and the Robust problem without reallocating. */
class LinearSeparatorSolver
{
public:
  LinearSeparatorSolver (const SeparatorProblem& problem, const MarginLoss& loss)
    : p_ (problem), loss_ (loss), v_ (problem.n), s_ (problem.n), v_trial_ (problem.n),
      s_trial_ (problem.n)
  {
    points_ = LinearPoints{static_cast<std::size_t> (p_.n), p_.x.data (), p_.y.data (), p_.z.data (),
                           p_.sxx.data (), p_.sxy.data (), p_.sxz.data (), p_.syy.data (), p_.syz.data (),
                           p_.szz.data (), p_.label.data (), p_.weight.data ()};
  }

  /** \brief The start of METHOD.md 5.3: f(m_+) = 1, f(m_-) = -1 with m_+- the class means;
    * theta = 0 when the means coincide or when that start is worse than theta = 0 (means
    * that nearly coincide would give an enormous w). The Standard solve from it reuses its
    * evaluation there. */
  Eigen::Vector4d
  start ()
  {
    evaluated_ = false;
    const Eigen::Index n = p_.n, na = p_.n_a, nb = n - na;
    const Eigen::Vector3d mp (p_.x.head (na).mean (), p_.y.head (na).mean (), p_.z.head (na).mean ());
    const Eigen::Vector3d mm (p_.x.tail (nb).mean (), p_.y.tail (nb).mean (), p_.z.tail (nb).mean ());
    const Eigen::Vector3d d = mp - mm;
    Eigen::Vector4d zero = Eigen::Vector4d::Zero ();
    if (d.squaredNorm () == 0.0)
      return zero;
    Eigen::Vector4d theta;
    theta.head<3> () = 2.0 * d / d.squaredNorm ();
    theta (3) = -theta.head<3> ().dot (0.5 * (mp + mm));
    if (!theta.allFinite ())
      return zero;
    // theta = 0 first, so that the work arrays end with theta's evaluation
    const double at_zero = objective (zero, 0.0, v_, s_);
    const double at_theta = objective (theta, 0.0, v_, s_);
    if (at_theta > at_zero)
      return zero;
    evaluated_ = true;
    evaluated_theta_ = theta;
    evaluated_value_ = at_theta;
    return theta;
  }

  /** \brief J at theta; fills v and s (s_i = sqrt(w^T Sigma_i w + eps_s^2), only when gamma > 0). */
  double
  objective (const Eigen::Vector4d& theta, double gamma, Eigen::ArrayXd& v, Eigen::ArrayXd& s) const
  {
    const double data = linearLoss (points_, theta.data (), gamma, loss_.huber ? loss_.width : 0.0,
                                    kSigmaFloor, v.data (), s.data ());
    return 0.5 * theta.head<3> ().squaredNorm () + 0.5 * kBiasRidge * theta (3) * theta (3) + data;
  }

  /** \brief Minimises J from theta (in/out).
    * Stops when |grad J| <= 1e-10 max(1, |J|) (converged), when an accepted step is shorter
    * than 1e-12 or the Newton step is within rounding (withinRounding(); converged: no
    * representable progress left), when the line search cannot
    * decrease J (not converged unless the gradient test holds) or after max_iterations. */
  SolverReport
  solve (Eigen::Vector4d& theta, double gamma, int max_iterations)
  {
    SolverReport report;
    // The Standard solve from start()'s theta has its evaluation already (v_, s_ and J).
    double value = evaluated_ && gamma == 0.0 && theta == evaluated_theta_ ? evaluated_value_
                                                                          : objective (theta, gamma, v_, s_);
    evaluated_ = false;
    for (;;)
    {
      Eigen::Vector4d gradient;
      Eigen::Matrix4d hessian;
      derivatives (theta, gamma, gradient, hessian);
      if (gradient.norm () <= 1e-10 * std::max (1.0, std::abs (value)))
      {
        report.converged = true;
        break;
      }
      if (report.iterations >= max_iterations)
        break;
      // L D L^T of H, with lambda I (1e-10, x10) when H is not positive definite
      Eigen::Vector4d step;
      bool factored = ldltSolve (hessian, -gradient, step);
      for (double lambda = 1e-10; !factored && lambda < 1e10; lambda *= 10.0)
        factored = ldltSolve (hessian + lambda * Eigen::Matrix4d::Identity (), -gradient, step);
      if (!factored)
        break;
      const double slope = gradient.dot (step);
      if (!(slope < 0.0))
        break;
      if (withinRounding (theta, step, slope, value))
      {
        report.converged = true;
        break;
      }
      // Armijo backtracking, c = 1e-4, halving (at most 60 times: t >= 2^-60)
      double t = 1.0, trial_value = 0.0;
      bool accepted = false;
      for (int halvings = 0; halvings <= 60; ++halvings)
      {
        trial_value = objective (theta + t * step, gamma, v_trial_, s_trial_);
        if (trial_value <= value + 1e-4 * t * slope)
        {
          accepted = true;
          break;
        }
        t *= 0.5;
      }
      if (!accepted)
        break;
      theta += t * step;
      value = trial_value;
      v_.swap (v_trial_);
      s_.swap (s_trial_);
      ++report.iterations;
      if (t * step.norm () < 1e-12)
      {
        report.converged = true;
        break;
      }
    }
    report.objective = value;
    return report;
  }

private:
  /** \brief x = H^-1 rhs for the symmetric 4 x 4 H by its factorisation L D L^T (L unit lower
    * triangular), written out: the pivots' reciprocals are its only divisions and it takes no
    * square root (Eigen's LLT and its triangular solves, a chain of divisions and roots on every
    * Newton step, were about 4 % of a query). False when H is not positive definite (a pivot
    * <= 0 or not finite). */
  static bool
  ldltSolve (const Eigen::Matrix4d& H, const Eigen::Vector4d& rhs, Eigen::Vector4d& x)
  {
    double L[4][4], d[4], inv[4];
    for (int j = 0; j < 4; ++j)
    {
      double dj = H (j, j);
      for (int k = 0; k < j; ++k)
        dj -= L[j][k] * L[j][k] * d[k];
      if (!(dj > 0.0) || !std::isfinite (dj))
        return false;
      d[j] = dj;
      inv[j] = 1.0 / dj;
      for (int i = j + 1; i < 4; ++i)
      {
        double v = H (i, j);
        for (int k = 0; k < j; ++k)
          v -= L[i][k] * L[j][k] * d[k];
        L[i][j] = v * inv[j];
      }
    }
    double y[4];
    for (int i = 0; i < 4; ++i)
    {
      double v = rhs (i);
      for (int k = 0; k < i; ++k)
        v -= L[i][k] * y[k];
      y[i] = v;
    }
    for (int i = 3; i >= 0; --i)
    {
      double v = y[i] * inv[i];
      for (int k = i + 1; k < 4; ++k)
        v -= L[k][i] * x (k);
      x (i) = v;
    }
    return x.allFinite ();
  }
  /** \brief Predicted decreases of J below this share of max(1, |J|) are within J's rounding:
    * its n terms are summed with a relative error of about n 1e-16. */
  static constexpr double kRoundingDecrease = 1e-14;
  /** \brief Newton steps shorter than this share of max(1, |theta|) move theta by rounding. */
  static constexpr double kRoundingStep = 1e-7;
  /** \brief Whether the Newton step from theta can make no representable progress: the
    * quadratic model's decrease, -slope / 2, is within the rounding of J and the step a
    * rounding-level move. Armijo's test then passes or fails by the rounding of J, and halving
    * until it passes (seen down to t = 2^-31 on the Robust re-solves) would only move theta by
    * about 1e-16, the step rule of METHOD.md 5.3 reached after dozens of evaluations. */
  static bool
  withinRounding (const Eigen::Vector4d& theta, const Eigen::Vector4d& step, double slope, double value)
  {
    return -slope <= kRoundingDecrease * std::max (1.0, std::abs (value)) &&
           step.norm () <= kRoundingStep * std::max (1.0, theta.norm ());
  }
  /** \brief Gradient and generalised Hessian at theta, from the v_ and s_ of theta. */
  void
  derivatives (const Eigen::Vector4d& theta, double gamma, Eigen::Vector4d& gradient,
               Eigen::Matrix4d& hessian) const
  {
    double t[20];
    linearDerivatives (points_, theta.data (), gamma, loss_.huber ? loss_.width : 0.0, v_.data (),
                       s_.data (), t);
    const double* g = t;
    const double* h = t + 4;
    const double* r = t + 14;
    gradient << theta (0) + g[0], theta (1) + g[1], theta (2) + g[2], kBiasRidge * theta (3) + g[3];
    hessian << 1.0 + h[0] + r[0], h[1] + r[1], h[2] + r[2], h[3],
               0.0, 1.0 + h[4] + r[3], h[5] + r[4], h[6],
               0.0, 0.0, 1.0 + h[7] + r[5], h[8],
               0.0, 0.0, 0.0, kBiasRidge + h[9];
    hessian.triangularView<Eigen::StrictlyLower> () = hessian.triangularView<Eigen::StrictlyUpper> ().transpose ();
  }

  const SeparatorProblem& p_;
  MarginLoss loss_;
  LinearPoints points_;
  Eigen::ArrayXd v_, s_, v_trial_, s_trial_;
  /** \brief v_ and s_ hold the Standard evaluation at evaluated_theta_, whose J is evaluated_value_. */
  bool evaluated_ = false;
  Eigen::Vector4d evaluated_theta_ = Eigen::Vector4d::Zero ();
  double evaluated_value_ = 0.0;
};
} // namespace detail
} // namespace pcl_probcollision
