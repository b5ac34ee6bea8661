// SPDX-License-Identifier: BSD-3-Clause
// The rungs of the classifier's ladder: Standard solve, gamma cap, Robust re-solve
// (METHOD.md 5.2, 5.3, 5.5).
#include <pcl_probcollision/detail/separator_fit.h>

#include <pcl_probcollision/detail/linear_separator.h>
#include <pcl_probcollision/detail/point_probabilities.h>
#include <pcl_probcollision/detail/rff_separator.h>
#include <pcl_probcollision/normal_distribution.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
/** \brief Gradient tolerance of L-BFGS, relative to max(1, |J|) (Newton uses 1e-10, METHOD.md
  * 5.3). J is 1-strongly convex in w and |phi_i| <= 1, so an error e in grad J moves w, and f
  * through it, by about e; at 1e-9 |J| that is far below the per-point standard deviations
  * along g that scale P_i. */
constexpr double kRffTolerance = 1e-9;
/** \brief RFF feature storage (doubles) kept per thread between calls: 4 MB. */
constexpr std::size_t kWorkspaceKeep = std::size_t (1) << 19;
/** \brief L-BFGS iterations allowed per unit of ClassifierParams::max_iterations. */
constexpr int kRffIterationFactor = 10;

/** \brief gamma_eff of METHOD.md 5.2 from the Standard fit: min(gamma, eta max(0, t_hat)),
  * t_hat = min c_i f_i / s_i over the points with s_i > 0 and a gradient that has not
  * collapsed; 0 when every gradient collapsed (no separator to make robust). */
double
effectiveGamma (const SeparatorProblem& p, const RungFit& fit, double gamma, double eta)
{
  // Point by point, without temporary arrays (this runs for every leaf pair's fit).
  const double plane_norm = fit.isPlane () ? fit.plane_gradient.norm () : 0.0;
  double t_hat = std::numeric_limits<double>::infinity ();
  bool any_direction = false;
  for (Eigen::Index i = 0; i < p.n; ++i)
  {
    if (!((fit.isPlane () ? plane_norm : gradientNorm (fit, i)) >= kCollapse))
      continue;
    any_direction = true;
    const double s = std::sqrt (quadraticForm (p, fit, i));
    if (s > 0.0)
      t_hat = std::min (t_hat, p.label (i) * fit.f (i) / s);
  }
  if (!any_direction)
    return 0.0;
  return std::min (gamma, eta * std::max (0.0, t_hat));
}

/** \brief The training procedure of METHOD.md 5.2 for one rung: the Standard solve; for
  * Robust training gamma_eff from it and, when positive, the re-solve from the Standard
  * solution; then assessFit(). solve (gamma) runs the rung's solver on its theta, evaluate ()
  * writes f and grad f at the training points into fit. */
template <typename Solve, typename Evaluate>
void
train (const SeparatorProblem& p, const ClassifierParams& params, double gamma, Solve solve,
       Evaluate evaluate, RungFit& fit)
{
  SolverReport report = solve (0.0);
  fit.iterations = report.iterations;
  evaluate ();
  if (params.training == TrainingMode::Robust)
  {
    fit.gamma_effective = effectiveGamma (p, fit, gamma, params.gamma_cap);
    if (fit.gamma_effective > 0.0)
    {
      const SolverReport robust = solve (fit.gamma_effective);
      fit.iterations += robust.iterations;
      report.converged = report.converged && robust.converged;
      report.objective = robust.objective;
      evaluate ();
    }
  }
  fit.converged = report.converged;
  fit.objective = report.objective;
  assessFit (p, params.ladder_depth_sigmas, fit);
}
} // namespace

RungFit
fitLinear (const SeparatorProblem& p, const ClassifierParams& params, double gamma, LinearSeparatorSolver& solver,
           const Eigen::Vector4d* start)
{
  RungFit fit;
  fit.rung = Rung::Linear;
  Eigen::Vector4d theta = start ? *start : solver.start ();
  train (
      p, params, gamma, [&] (double g) { return solver.solve (theta, g, params.max_iterations); },
      [&] {
        fit.f = theta (0) * p.x + theta (1) * p.y + theta (2) * p.z + theta (3);
        fit.plane_gradient = theta.head<3> ();
      },
      fit);
  fit.theta = theta;
  return fit;
}

double
meansPlaneMaximum (const SeparatorProblem& p, const Eigen::Vector4d& theta, const std::vector<bool>* uncertain)
{
  const Eigen::Vector3d w = theta.head<3> ();
  const double norm = w.norm ();
  if (!(norm >= kCollapse) || !std::isfinite (norm))
    return std::numeric_limits<double>::quiet_NaN ();
  RungFit plane;
  plane.plane_gradient = w;
  // assessFit's P_i = Phi(z_i) rises with z_i, so the maximum needs one normal tail, at the
  // largest z_i.
  double largest = -std::numeric_limits<double>::infinity ();
  for (Eigen::Index i = 0; i < p.n; ++i)
    if (!uncertain || (*uncertain)[static_cast<std::size_t> (i)])
    {
      const double f = theta (0) * p.x (i) + theta (1) * p.y (i) + theta (2) * p.z (i) + theta (3);
      const double u = p.label (i) * f / norm;
      largest = std::max (largest, pointZ (u, std::sqrt (quadraticForm (p, plane, i)) / norm));
    }
  return normalCdf (largest);  // 1 and 0 at +-inf
}

RungFit
fitRff (const SeparatorProblem& p, const ClassifierParams& params,
        const MarginLoss& loss, double gamma, const Eigen::MatrixXd& omega,
        const Eigen::VectorXd& beta, int features, Rung rung)
{
  RungFit fit;
  fit.rung = rung;
  // Per-thread storage for the n x D feature matrices, kept between calls so that leaf after
  // leaf reuses it (classify() stays const and reentrant). Above kWorkspaceKeep doubles it is
  // released after the fit: big problems are rare and pay their own allocation.
  thread_local std::vector<double> workspace;
  struct Release
  {
    std::vector<double>& w;
    ~Release ()
    {
      if (w.capacity () > kWorkspaceKeep)
        std::vector<double> ().swap (w);
    }
  } release{workspace};
  RffSeparatorSolver solver (p, loss, omega, beta, features, workspace);
  const int max_iterations = kRffIterationFactor * params.max_iterations;
  Eigen::VectorXd theta = Eigen::VectorXd::Zero (features + 1);
  train (
      p, params, gamma,
      [&] (double g) { return solver.solve (theta, g, max_iterations, kRffTolerance); },
      [&] { solver.evaluate (theta, fit.f, fit.gx, fit.gy, fit.gz); }, fit);
  fit.theta = std::move (theta);
  return fit;
}
} // namespace detail
} // namespace pcl_probcollision
