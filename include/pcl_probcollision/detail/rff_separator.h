// SPDX-License-Identifier: BSD-3-Clause
// The random Fourier feature rung (METHOD.md 5.5): the objective of 5.3 with x_i replaced by
// phi(x_i) and the robust term gamma sqrt(g_i^T Sigma_i g_i + eps_s^2), g_i = J_i^T w the
// gradient of f at x_i, minimised over (w, b) in R^(D+1) by preconditioned L-BFGS.
// Internal: not API.
#pragma once

#include <pcl_probcollision/detail/kernels.h>
#include <pcl_probcollision/detail/separator_problem.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <new>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief L-BFGS (memory 10) on the RFF problem.
  *
  * Precomputed per point: phi_i (row i of Phi) and -sqrt(2/D) sin(Omega x_i + beta) (row i of
  * Sm), so that the gradients of f at all points are G = Sm diag(w) Omega; A_i w = J_i^T w is
  * never formed point by point, and the robust term uses g_i^T Sigma_i g_i, which equals
  * |L_i^T A_i w|^2 without the Cholesky factor L_i.
  *
  * Preconditioning. The Hessian I + Phi_a^T C_a Phi_a (+ the bias) is badly conditioned in a
  * few directions only: the RBF kernel on the unit cube is smooth, so the spectrum of
  * Phi^T Phi is dominated by the images of low-degree polynomials (the constant mode alone is
  * about n C and couples to b). Plain L-BFGS needed ~240 iterations on a 200-point curved
  * case and then stalled at |grad J| ~ 1e-6; with H0 = M^-1, where M is the exact Standard
  * Hessian on span(Phi^T Q) + the bias (Q: the 10 monomials of degree <= 2 of the centred
  * coordinates) and the identity (the regulariser's curvature) elsewhere, it converges to
  * 1e-10 relative in ~20. M follows the active set: built in O(n m^2) (m = 10) when a solve
  * starts, then updated by rank one per point that enters or leaves it.
  *
  * Problems of at most kExactPoints points (every leaf pair of a collision query) use the
  * exact Standard Hessian instead, H = diag(I, rho) + Psi^T diag(h) Psi with Psi = [Phi 1],
  * inverted through the n x n Gram matrix K = Phi Phi^T (Woodbury, below): the first step of
  * a solve whose active set does not change is then the Newton step. Its cost is one K
  * (n^2 D / 2) per rung instead of the basis' QR, a Cholesky factor of the active block when
  * the active set changes, and two n x D products per application.
  *
  * Robust evaluations skip g_i, exactly, for points that are certainly inactive (see
  * valueAndGradient()). */
class RffSeparatorSolver
{
public:
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  static constexpr int kMemory = 10;
  /** \brief Default largest n whose preconditioner is the exact Standard Hessian. Leaf pairs
    * hold 10-40 points; on bench_robust_classifier's bowls (200 to 2,000 points) the exact
    * path is 1.2 to 14 times faster with the same P, and K is 8 MB at this size. */
  static constexpr Eigen::Index kExactPoints = 1024;
  /** \brief When the descent has ended at rounding. A solve whose J has stalled short of the
    * gradient tolerance (seen on near noise-free points pushed through each other: |grad J|
    * stuck at 1e-8 to 6e-8 of |J|, J equal to 17 digits for hundreds of iterations) has its
    * steps accepted by the approximate Armijo condition only after 40 to 57 halvings, each a
    * function evaluation, and goes on so until max_iterations (0.1-0.6 s for one leaf pair).
    * It stops at an accepted step shorter than kShortestStep of the quasi-Newton step, or
    * shorter than kShortStep without lowering J. A normal descent accepts steps of 1/2 to
    * 1/8192 of it, and near its end full steps that may leave J equal while the gradient
    * still falls. */
  static constexpr double kShortestStep = 0x1p-40;
  /** \brief See kShortestStep. */
  static constexpr double kShortStep = 0x1p-20;

  /** \param[in] omega, beta the draw of drawRandomFourierFeatures(), at least features rows
    * \param[in,out] workspace storage for phi_i and sm_i (2 n D doubles), grown when needed; the
    *            caller keeps it between calls (a buffer of this size would otherwise come from
    *            mmap each time, and its page faults cost as much as the solve)
    * \param[in] exact_points the largest n preconditioned by the exact Hessian (tests compare
    *            the two paths) */
  RffSeparatorSolver (const SeparatorProblem& problem, const MarginLoss& loss,
                      const Eigen::MatrixXd& omega, const Eigen::VectorXd& beta, int features,
                      std::vector<double>& workspace, Eigen::Index exact_points = kExactPoints)
    : p_ (problem), loss_ (loss), d_ (features), phi_ (nullptr, 0, 0), sin_ (nullptr, 0, 0)
  {
    const Eigen::Index n = p_.n;
    ox_ = omega.col (0).head (d_);
    oy_ = omega.col (1).head (d_);
    oz_ = omega.col (2).head (d_);
    const std::size_t size = static_cast<std::size_t> (n) * static_cast<std::size_t> (d_);
    if (workspace.size () < 2 * size)
      workspace.resize (2 * size);
    new (&phi_) Eigen::Map<RowMatrix> (workspace.data (), n, d_);
    new (&sin_) Eigen::Map<RowMatrix> (workspace.data () + size, n, d_);
    rffFeatureRows (static_cast<std::size_t> (n), static_cast<std::size_t> (d_), p_.x.data (),
                    p_.y.data (), p_.z.data (), ox_.data (), oy_.data (), oz_.data (),
                    beta.data (), phi_.data (), sin_.data ());
    for (Eigen::ArrayXd* a : {&f_, &v_, &gx_, &gy_, &gz_, &s_bound_, &s_bound_trial_, &curvature_})
      a->setZero (n);
    // |s_i(w') - s_i(w)| <= |L_i^T A_i (w' - w)| <= sqrt(trace Sigma_i) |A_i|_F |w' - w|, with
    // |A_i|_F^2 = sum_k sm_ik^2 |omega_k|^2
    const Eigen::VectorXd omega_norm2 = (ox_.array ().square () + oy_.array ().square () + oz_.array ().square ()).matrix ();
    lipschitz_.resize (n);
    lipschitz_.matrix ().noalias () = sin_.cwiseAbs2 () * omega_norm2;
    lipschitz_ = (lipschitz_ * (p_.sxx + p_.syy + p_.szz).max (0.0)).sqrt ();
    rows_ = RffRows{static_cast<std::size_t> (n), static_cast<std::size_t> (d_), phi_.data (), sin_.data (),
                    ox_.data (), oy_.data (), oz_.data (), p_.label.data (), p_.weight.data (),
                    p_.sxx.data (), p_.sxy.data (), p_.sxz.data (), p_.syy.data (), p_.syz.data (),
                    p_.szz.data (), lipschitz_.data ()};
    for (Eigen::VectorXd* a : {&wx_, &wy_, &wz_})
      a->resize (d_);
    exact_ = n <= exact_points;
    if (exact_)
    {
      // the lower triangle by a symmetric rank-D update (half a product's work), then mirrored
      gram_.setZero (n, n);
      gram_.selfadjointView<Eigen::Lower> ().rankUpdate (phi_);
      gram_.triangularView<Eigen::StrictlyUpper> () = gram_.transpose ();
    }
    else
      buildPreconditionerBasis ();
    const Eigen::Index dim = d_ + 1;
    s_mem_.resize (dim, kMemory);
    y_mem_.resize (dim, kMemory);
    rho_.resize (kMemory);
    alpha_.resize (kMemory);
    gradient_.resize (dim);
    trial_gradient_.resize (dim);
    direction_.resize (dim);
    trial_.resize (dim);
  }

  int features () const { return d_; }
  /** \brief Objective and gradient evaluations so far (line-search trials included). */
  int evaluations () const { return evaluations_; }

  /** \brief Minimises J from theta (in/out, D + 1 entries, bias last).
    * Armijo backtracking (c = 1e-4, halving) from the unit step; once J stalls at rounding
    * the approximate Armijo condition of Hager and Zhang (2005) accepts a step that keeps J
    * within 1e-14 |J| and whose directional derivative has dropped below 0.8 |slope|.
    * Converged when |grad J| <= tolerance * max(1, |J|); it also stops after max_iterations,
    * when no step is accepted, or when rounding has ended the descent (kShortestStep, or a
    * Newton step that does not lower J). */
  SolverReport
  solve (Eigen::VectorXd& theta, double gamma, int max_iterations, double tolerance)
  {
    SolverReport report;
    double value = valueAndGradient (theta, gamma, gradient_, kFreshEvaluation);
    s_bound_.swap (s_bound_trial_);
    refresh_curvature_ = true;
    int stored = 0, next = 0;
    // With the exact Hessian of a piecewise quadratic J (the Standard squared hinge) as H0, a
    // step is Newton's; curvature pairs from an earlier active set would only bend it (21
    // iterations instead of 5 on the benchmark's leaf pairs).
    const bool newton = exact_ && gamma == 0.0 && !loss_.huber;
    while (true)
    {
      if (gradient_.norm () <= tolerance * std::max (1.0, std::abs (value)))
      {
        report.converged = true;
        break;
      }
      if (report.iterations >= max_iterations)
        break;
      updatePreconditioner ();
      // two-loop recursion with H0 = M^-1
      direction_ = -gradient_;
      for (int k = 0; k < stored; ++k)
      {
        const int j = (next - 1 - k + kMemory) % kMemory;
        alpha_ (j) = rho_ (j) * s_mem_.col (j).dot (direction_);
        direction_ -= alpha_ (j) * y_mem_.col (j);
      }
      applyPreconditioner (direction_);
      for (int k = stored - 1; k >= 0; --k)
      {
        const int j = (next - 1 - k + kMemory) % kMemory;
        const double b = rho_ (j) * y_mem_.col (j).dot (direction_);
        direction_ += (alpha_ (j) - b) * s_mem_.col (j);
      }
      double slope = gradient_.dot (direction_);
      if (!(slope < 0.0))
      {
        // lost descent (rounding; J is convex): drop the memory
        stored = 0;
        direction_ = -gradient_;
        applyPreconditioner (direction_);
        slope = gradient_.dot (direction_);
        if (!(slope < 0.0))
          break;
      }
      double t = 1.0, trial_value = 0.0, step = 0.0;
      bool accepted = false;
      for (int halvings = 0; halvings <= 60 && !accepted; ++halvings, t *= 0.5)
      {
        trial_ = theta + t * direction_;
        trial_value = valueAndGradient (trial_, gamma, trial_gradient_, t * direction_.head (d_).norm ());
        accepted = trial_value <= value + 1e-4 * t * slope ||
                   (trial_value <= value + 1e-14 * std::abs (value) &&
                    trial_gradient_.dot (direction_) <= -0.8 * slope);
        step = t;
      }
      // A Newton step of a convex piecewise quadratic that does not lower J is at rounding
      // (seen at C = 1e9: full steps accepted by the approximate Armijo condition, J equal,
      // until the iteration cap).
      if (!accepted || step < kShortestStep || ((newton || step < kShortStep) && !(trial_value < value)))
        break;
      // curvature pair; s^T y >= |s_w|^2 > 0 for this strictly convex J, but guard rounding
      s_mem_.col (next) = trial_ - theta;
      y_mem_.col (next) = trial_gradient_ - gradient_;
      const double sy = s_mem_.col (next).dot (y_mem_.col (next));
      if (!newton && sy > 1e-14 * s_mem_.col (next).norm () * y_mem_.col (next).norm () && sy > 0.0)
      {
        rho_ (next) = 1.0 / sy;
        next = (next + 1) % kMemory;
        stored = std::min (stored + 1, static_cast<int> (kMemory));
      }
      theta.swap (trial_);
      gradient_.swap (trial_gradient_);
      s_bound_.swap (s_bound_trial_);
      value = trial_value;
      ++report.iterations;
    }
    report.objective = value;
    return report;
  }

  /** \brief f and grad f (unit-cube frame) at the training points. */
  void
  evaluate (const Eigen::VectorXd& theta, Eigen::ArrayXd& f, Eigen::ArrayXd& gx, Eigen::ArrayXd& gy,
            Eigen::ArrayXd& gz)
  {
    setWeightedOmega (theta);
    rffForward (static_cast<std::size_t> (p_.n), static_cast<std::size_t> (d_), phi_.data (),
                sin_.data (), theta.data (), wx_.data (), wy_.data (), wz_.data (), f_.data (),
                gx_.data (), gy_.data (), gz_.data ());
    ++evaluations_;
    f = f_ + theta (d_);
    gx = gx_;
    gy = gy_;
    gz = gz_;
  }

  /** \brief Displacement argument of valueAndGradient() that evaluates every point. */
  static constexpr double kFreshEvaluation = -1.0;

  /** \brief J and its gradient at theta.
    * \param[in] displacement |w - w_c| from the accepted point w_c whose bounds s_bound_
    *            hold, or kFreshEvaluation. With gamma > 0, a point whose margin violation is
    *            certainly <= 0 under the bound s_i <= s_bound_i + K_i |w - w_c| contributes
    *            nothing to J or its gradient, so its g_i is not computed (this is exact). */
  double
  valueAndGradient (const Eigen::VectorXd& theta, double gamma, Eigen::VectorXd& gradient,
                    double displacement)
  {
    ++evaluations_;
    const bool robust = gamma > 0.0;
    if (robust)
      setWeightedOmega (theta);
    const double b = theta (d_);
    gradient.head (d_) = theta.head (d_);
    double gradient_b = kBiasRidge * b;
    const double data = rffObjective (rows_, theta.data (), b, wx_.data (), wy_.data (), wz_.data (),
                                      gamma, loss_.huber ? loss_.width : 0.0, kSigmaFloor,
                                      s_bound_.data (), displacement, s_bound_trial_.data (),
                                      v_.data (), gradient.data (), &gradient_b);
    gradient (d_) = gradient_b;
    return 0.5 * theta.head (d_).squaredNorm () + 0.5 * kBiasRidge * b * b + data;
  }

private:
  void
  setWeightedOmega (const Eigen::VectorXd& theta)
  {
    wx_ = theta.head (d_).cwiseProduct (ox_);
    wy_ = theta.head (d_).cwiseProduct (oy_);
    wz_ = theta.head (d_).cwiseProduct (oz_);
  }

  /** \brief basis_ (D x m): orthonormal basis of Phi^T Q; projected_ = Phi basis_ (n x m). */
  void
  buildPreconditionerBasis ()
  {
    const Eigen::Index n = p_.n, m = static_cast<Eigen::Index> (kProjection);
    Eigen::MatrixXd q (n, m);
    const Eigen::ArrayXd dx = p_.x - 0.5, dy = p_.y - 0.5, dz = p_.z - 0.5;
    q.col (0).setOnes ();
    q.col (1) = dx.matrix ();
    q.col (2) = dy.matrix ();
    q.col (3) = dz.matrix ();
    q.col (4) = (dx * dx).matrix ();
    q.col (5) = (dy * dy).matrix ();
    q.col (6) = (dz * dz).matrix ();
    q.col (7) = (dx * dy).matrix ();
    q.col (8) = (dx * dz).matrix ();
    q.col (9) = (dy * dz).matrix ();
    Eigen::MatrixXd u (d_, m);
    rffProjectColumns (static_cast<std::size_t> (n), static_cast<std::size_t> (d_), phi_.data (),
                       q.data (), u.data ());
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr (u);
    // m orthonormal columns; with D < m the last m - D are zero (harmless: M is the identity
    // on them)
    const Eigen::Index k = m;
    basis_ = Eigen::MatrixXd::Zero (d_, m);
    const Eigen::Index rank = std::min<Eigen::Index> (m, d_);
    basis_.leftCols (rank) = qr.householderQ () * Eigen::MatrixXd::Identity (d_, rank);
    projected_.resize (n, k);
    rffProjectRows (static_cast<std::size_t> (n), static_cast<std::size_t> (d_), phi_.data (),
                    basis_.data (), projected_.data ());
    weighted_projected_.resize (n, k);
    small_.resize (k + 1, k + 1);
    regularised_.resize (k + 1, k + 1);
    coefficients_.resize (k + 1);
  }

  /** \brief h_i = C_i l''(v_i) at the last evaluation (v_): point i's weight in the Standard
    * Hessian, for both preconditioners. */
  double curvatureWeight (Eigen::Index i) const { return p_.weight (i) * loss_.second (v_ (i)); }

  /** \brief The subspace block of M from the curvature weights h_i = C_i l''(v_i) at the
    * current iterate (v_ holds the last evaluation, which is the accepted point). Rebuilt at
    * the start of a solve, then updated by rank one for the points whose h_i changed (with
    * the squared hinge: the points that entered or left the active set). */
  void
  updatePreconditioner ()
  {
    if (exact_)
    {
      updateExactPreconditioner ();
      return;
    }
    const Eigen::Index m = basis_.cols ();
    if (refresh_curvature_)
    {
      refresh_curvature_ = false;
      for (Eigen::Index i = 0; i < p_.n; ++i)
        curvature_ (i) = curvatureWeight (i);
      weighted_projected_ = projected_.array ().colwise () * curvature_;
      small_.setZero ();
      small_.topLeftCorner (m, m).noalias () = projected_.transpose ().lazyProduct (weighted_projected_);
      small_.block (m, 0, 1, m) = weighted_projected_.colwise ().sum ();
      small_.block (0, m, m, 1) = small_.block (m, 0, 1, m).transpose ();
      small_ (m, m) = curvature_.sum ();
    }
    else
    {
      for (Eigen::Index i = 0; i < p_.n; ++i)
      {
        const double h = curvatureWeight (i);
        const double delta = h - curvature_ (i);
        if (delta == 0.0)
          continue;
        curvature_ (i) = h;
        for (Eigen::Index r = 0; r < m; ++r)
        {
          const double pr = delta * projected_ (i, r);
          for (Eigen::Index c = 0; c < m; ++c)
            small_ (r, c) += pr * projected_ (i, c);
          small_ (r, m) += pr;
          small_ (m, r) += pr;
        }
        small_ (m, m) += delta;
      }
    }
    regularised_ = small_;
    regularised_.topLeftCorner (m, m).diagonal ().array () += 1.0;
    regularised_ (m, m) += kBiasRidge;
    small_llt_.compute (regularised_);
  }

  /** \brief The exact preconditioner's factors at the current curvature weights h_i (see
    * applyPreconditioner()): S = K_aa + diag(1 / h_a) over the points a with h_i > 0, its
    * Cholesky factor and z = S^-1 1. Refactored only when some h_i changed. */
  void
  updateExactPreconditioner ()
  {
    bool changed = refresh_curvature_;
    refresh_curvature_ = false;
    for (Eigen::Index i = 0; i < p_.n; ++i)
    {
      const double h = curvatureWeight (i);
      changed = changed || h != curvature_ (i);
      curvature_ (i) = h;
    }
    if (!changed)
      return;
    active_.clear ();
    for (Eigen::Index i = 0; i < p_.n; ++i)
      if (curvature_ (i) > 0.0)
        active_.push_back (i);
    const Eigen::Index na = static_cast<Eigen::Index> (active_.size ());
    regularised_.resize (na, na);
    for (Eigen::Index r = 0; r < na; ++r)
    {
      for (Eigen::Index c = 0; c < na; ++c)
        regularised_ (r, c) = gram_ (active_[r], active_[c]);
      regularised_ (r, r) += 1.0 / curvature_ (active_[r]);
    }
    small_llt_.compute (regularised_);
    ones_solved_ = Eigen::VectorXd::Ones (na);
    small_llt_.solveInPlace (ones_solved_);
    projection_.resize (p_.n);
    coefficients_.resize (na);
  }

  /** \brief v <- H^-1 v for the exact Standard Hessian H = [[A, u], [u^T, c]], A = I +
    * Phi_a^T diag(h_a) Phi_a, u = Phi_a^T h_a, c = rho + sum h_a. By Woodbury A^-1 r = r -
    * Phi_a^T S^-1 Phi_a r, and since S^-1 K_aa h_a = h_a - S^-1 1 every term reduces to q =
    * S^-1 Phi_a r and z = S^-1 1: u^T A^-1 r = sum q, the Schur complement c - u^T A^-1 u =
    * rho + sum z, the bias y = (s - sum q) / (rho + sum z) and x = r - Phi_a^T (q + y z). */
  void
  applyExactPreconditioner (Eigen::VectorXd& v)
  {
    const Eigen::Index na = static_cast<Eigen::Index> (active_.size ());
    projection_.noalias () = phi_ * v.head (d_);
    for (Eigen::Index r = 0; r < na; ++r)
      coefficients_ (r) = projection_ (active_[r]);
    small_llt_.solveInPlace (coefficients_);
    const double y = (v (d_) - coefficients_.sum ()) / (kBiasRidge + ones_solved_.sum ());
    projection_.setZero ();
    for (Eigen::Index r = 0; r < na; ++r)
      projection_ (active_[r]) = coefficients_ (r) + y * ones_solved_ (r);
    v.head (d_).noalias () -= phi_.transpose () * projection_;
    v (d_) = y;
  }

  /** \brief v <- M^-1 v: the inverse of M on span(basis_) + bias, identity elsewhere. */
  void
  applyPreconditioner (Eigen::VectorXd& v)
  {
    if (exact_)
    {
      applyExactPreconditioner (v);
      return;
    }
    const Eigen::Index m = basis_.cols ();
    coefficients_.head (m).noalias () = basis_.transpose () * v.head (d_);
    coefficients_ (m) = v (d_);
    v.head (d_).noalias () -= basis_ * coefficients_.head (m);
    small_llt_.solveInPlace (coefficients_);
    v.head (d_).noalias () += basis_ * coefficients_.head (m);
    v (d_) = coefficients_ (m);
  }

  const SeparatorProblem& p_;
  MarginLoss loss_;
  int d_;
  int evaluations_ = 0;
  Eigen::VectorXd ox_, oy_, oz_;  // columns of Omega (first D rows)
  Eigen::Map<RowMatrix> phi_, sin_;  // n x D: phi_i and -sqrt(2/D) sin(Omega x_i + beta)
  Eigen::ArrayXd f_, v_, gx_, gy_, gz_;
  Eigen::ArrayXd s_bound_, s_bound_trial_, lipschitz_, curvature_;
  RffRows rows_;
  Eigen::VectorXd wx_, wy_, wz_;
  Eigen::MatrixXd basis_, projected_, weighted_projected_, small_, regularised_;
  bool refresh_curvature_ = true;
  bool exact_ = false;               // the exact Standard Hessian (n <= exact_points)
  Eigen::MatrixXd gram_;             // K = Phi Phi^T (exact_ only)
  std::vector<Eigen::Index> active_; // points with h_i > 0
  Eigen::VectorXd ones_solved_, projection_;  // z = S^-1 1; scratch of n entries
  Eigen::VectorXd coefficients_;
  Eigen::LLT<Eigen::MatrixXd> small_llt_;
  Eigen::MatrixXd s_mem_, y_mem_;
  Eigen::VectorXd rho_, alpha_, gradient_, trial_gradient_, direction_, trial_;
};
} // namespace detail
} // namespace pcl_probcollision
