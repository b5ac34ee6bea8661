// SPDX-License-Identifier: BSD-3-Clause
// One rung of the classifier's ladder fitted to a normalised problem (METHOD.md 5.2-5.5): the
// Standard solve, the gamma cap and the Robust re-solve, for the plane (damped Newton) or for
// random Fourier features (L-BFGS). Defined in src/detail/separator_fit.cpp.
// Internal: not API.
#pragma once

#include <pcl_probcollision/detail/separator_problem.h>
#include <pcl_probcollision/robust_classifier.h>

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief One fitted rung with its evaluation at the training points and its assessment
  * (assessFit(), detail/point_probabilities.h). */
struct RungFit
{
  Rung rung = Rung::None;
  Eigen::VectorXd theta;  ///< (w, b)
  double gamma_effective = 0.0;
  int iterations = 0;
  bool converged = false;
  double objective = std::numeric_limits<double>::quiet_NaN ();
  Eigen::ArrayXd f;           ///< f(x_i)
  Eigen::ArrayXd gx, gy, gz;  ///< grad f(x_i) in the unit-cube frame; empty for a plane
  Eigen::Vector3d plane_gradient = Eigen::Vector3d::Zero ();  ///< w, for a plane
  /** \brief z_i with P_i = normalCdf (z_i) (+-inf and 0 for the cases without spread or
    * gradient): the normal tails are taken only where they are needed. */
  Eigen::ArrayXd z;
  std::size_t misclassified = 0;
  /** \brief max_i sigma_i, the standard deviation along the gradient (collapsed points aside). */
  double largest_spread = 0.0;
  bool degenerate = false;

  bool isPlane () const { return gx.size () == 0; }
  Eigen::Vector3d
  gradient (Eigen::Index i) const
  {
    return isPlane () ? plane_gradient : Eigen::Vector3d (gx (i), gy (i), gz (i));
  }
};

class LinearSeparatorSolver;

/** \brief The plane: Standard solve, then for Robust training the re-solve with the capped
  * gamma (METHOD.md 5.2, 5.3); assessed at the end.
  * \param[in] gamma Phi^-1(confidence), the uncapped gamma
  * \param[in] solver the plane's solver on p with its loss (detail/linear_separator.h), built
  *            once a problem
  * \param[in] start the Newton start, solver.start () when null (given when the caller has it
  *            already: the solve then reuses the solver's evaluation there) */
RungFit fitLinear (const SeparatorProblem& p, const ClassifierParams& params, double gamma,
                   LinearSeparatorSolver& solver, const Eigen::Vector4d* start = nullptr);

/** \brief max_i P_i of the plane start (LinearSeparatorSolver::start()), with assessFit()'s P_i, over the points
  * marked in uncertain (every point when it is null); NaN when start is theta = 0. No solve. */
double meansPlaneMaximum (const SeparatorProblem& p, const Eigen::Vector4d& start, const std::vector<bool>* uncertain);

/** \brief As fitLinear() with the first features rows of the random Fourier feature draw
  * (omega, beta) (METHOD.md 5.5); rung names the result (RFF or RFFLarge). */
RungFit fitRff (const SeparatorProblem& p, const ClassifierParams& params, const MarginLoss& loss,
                double gamma, const Eigen::MatrixXd& omega, const Eigen::VectorXd& beta,
                int features, Rung rung);
} // namespace detail
} // namespace pcl_probcollision
