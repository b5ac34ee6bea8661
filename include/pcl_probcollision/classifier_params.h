// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <cstdint>

namespace pcl_probcollision
{
/** \brief Which separating surface to fit (METHOD.md 5.7). */
enum class KernelMode
{
  Linear,  ///< a plane only
  RFF,     ///< RBF kernel approximated by random Fourier features only
  Ladder   ///< plane first; RFF (then larger D) only when the plane misclassifies too much
};

/** \brief How the covariances enter training (METHOD.md 5.2). */
enum class TrainingMode
{
  Standard,  ///< plain soft-margin SVM; covariances used only for the probabilities
  Robust     ///< chance-constrained SVM with the gamma cap of METHOD.md 5.2
};

/** \brief Loss on the margin violation v of METHOD.md 5.3. */
enum class Loss
{
  SquaredHinge,  ///< l(v) = max(0, v)^2 / 2, the L2-loss SVM (default)
  Huber          ///< Huberised hinge of width h = 0.01: closer to the L1 hinge of (5.1)
};

/** \brief Classifier parameters with their defaults (METHOD.md 5.7). All lengths are in the
  * unit-cube frame of the problem (Uniform scaling, METHOD.md 4), so they do not depend on units.
  */
struct ClassifierParams
{
  /** \brief Which separating surface to fit (default Ladder). */
  KernelMode kernel = KernelMode::Ladder;
  /** \brief How the covariances enter training (default Robust). */
  TrainingMode training = TrainingMode::Robust;
  /** \brief kappa, the per-point chance-constraint level in (0.5, 1); gamma = Phi^-1(kappa)
    * (1.2816 for 0.9). */
  double confidence = 0.9;
  /** \brief eta: the robust gamma is capped at eta * t_hat of the Standard solution, (0, 1). */
  double gamma_cap = 0.9;
  /** \brief Soft-margin weight C > 0, class-balanced (each cloud carries half the weight).
    * Default 1000, not the reference code's 10 (METHOD.md 5.7): a leaf pair's points span far
    * more than the gap between them, and with C = 10 the soft margin preferred a separator
    * tilted between side-by-side patches that leaves a few points on the wrong side, so free
    * poses 4-7 sigma from contact read P = 1 (docs/RESULTS.md, the "C10" setting). */
  double C = 1000.0;
  /** \brief RBF width gamma_k > 0 in unit-cube units: K(x, y) = exp(-gamma_k |x - y|^2). */
  double rbf_gamma = 1.0;
  /** \brief Number of random Fourier features D of the first kernel rung (>= 8). */
  int rff_features = 256;
  /** \brief D of the last ladder rung (>= rff_features). */
  int rff_features_large = 1024;
  /** \brief Seed of the random Fourier feature draw (Omega, beta), drawn once per classifier and
    * laid, for each leaf pair, along the pair's principal axes, so that a fit turns with the
    * points. */
  std::uint64_t rff_seed = 12345;
  /** \brief Ladder: a point counts as misclassified when it lies on the wrong side of the
    * surface by more than this many of its own standard deviations along the gradient (> 0). */
  double ladder_depth_sigmas = 3.0;
  /** \brief Ladder: escalate when the fraction of misclassified points exceeds this, [0, 1). */
  double ladder_fraction = 0.0;
  /** \brief Whether exact points (zero covariance, e.g. mesh samples, METHOD.md 9) take part
    * in the maximum. Their P_i is 0, 0.5 or 1 by the side of the fitted surface they fall on
    * (METHOD.md 6.1): a property of the fit, not a probability, so one exact sample a hair over
    * a separator fitted to noisy data would make P = 1 for surfaces that merely touch. false
    * (default, METHOD.md 9: "only the cloud's points contribute graded probabilities"): the
    * maximum runs over the points with uncertainty, and over all points only when every point
    * is exact. Points nearly as sure count as exact too: a spread along the fitted surface's
    * gradient under 3 % of the pair's largest (a sensor noise far under the sample spacing,
    * docs/RELIABILITY.md). Per-point values are reported either way. */
  bool exact_points_in_maximum = false;
  /** \brief Newton iteration cap of the linear rung (>= 1). The RFF rung runs L-BFGS, whose
    * iterations are much cheaper and less effective; it gets 10 * max_iterations. */
  int max_iterations = 100;
  /** \brief Loss on the margin violation (METHOD.md 5.3). */
  Loss loss = Loss::SquaredHinge;

  /** \brief Throws pcl::BadArgumentException naming the first parameter out of range. */
  void validate () const;

  /** \brief Field-wise equality (every field, loss included). */
  bool operator== (const ClassifierParams& other) const;
  /** \brief The negation of operator==. */
  bool operator!= (const ClassifierParams& other) const { return !(*this == other); }
};

} // namespace pcl_probcollision
