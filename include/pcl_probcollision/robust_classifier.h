// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

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

/** \brief The model actually fitted for one problem. */
enum class Rung
{
  None,    ///< nothing fitted (error)
  Linear,  ///< a plane
  RFF,     ///< random Fourier features with rff_features
  RFFLarge ///< random Fourier features with rff_features_large
};

/** \brief Classifier parameters with their defaults (METHOD.md 5.7). All lengths are in the
  * unit-cube frame of the problem (Uniform scaling, METHOD.md 4), so they do not depend on units.
  */
struct ClassifierParams
{
  KernelMode kernel = KernelMode::Ladder;
  TrainingMode training = TrainingMode::Robust;
  /** \brief kappa, the per-point chance-constraint level in (0.5, 1); gamma = Phi^-1(kappa)
    * (1.2816 for 0.9). */
  double confidence = 0.9;
  /** \brief eta: the robust gamma is capped at eta * t_hat of the Standard solution, (0, 1). */
  double gamma_cap = 0.9;
  /** \brief Soft-margin weight C > 0, class-balanced (each cloud carries half the weight). */
  double C = 10.0;
  /** \brief RBF width gamma_k > 0 in unit-cube units: K(x, y) = exp(-gamma_k |x - y|^2). */
  double rbf_gamma = 1.0;
  /** \brief Number of random Fourier features D of the first kernel rung (>= 8). */
  int rff_features = 256;
  /** \brief D of the last ladder rung (>= rff_features). */
  int rff_features_large = 1024;
  /** \brief Seed of the random Fourier feature draw (Omega, beta), drawn once per classifier. */
  std::uint64_t rff_seed = 12345;
  /** \brief Ladder: a point counts as misclassified when it lies on the wrong side of the
    * surface by more than this many of its own standard deviations along the gradient (> 0). */
  double ladder_depth_sigmas = 3.0;
  /** \brief Ladder: escalate when the fraction of misclassified points exceeds this, [0, 1). */
  double ladder_fraction = 0.0;
  /** \brief Newton / L-BFGS iteration cap (>= 1). */
  int max_iterations = 100;

  /** \brief Throws pcl::BadArgumentException naming the first parameter out of range. */
  void validate () const;
};

/** \brief What one classification produced. Probabilities are per point, index-aligned with
  * the inputs; NaN marks anything not computed. */
struct ClassifierResult
{
  bool ok = false;                 ///< false: inputs unusable, see message
  std::string message;
  Rung rung = Rung::None;
  bool converged = false;          ///< the solver met its gradient tolerance
  int iterations = 0;              ///< solver iterations summed over the rungs tried
  double objective = std::numeric_limits<double>::quiet_NaN ();
  bool degenerate = false;         ///< no separating direction (|grad f| < 1e-8 everywhere)
  double gamma_effective = std::numeric_limits<double>::quiet_NaN ();

  std::vector<double> probabilities_a;  ///< P_i for the points of A (label +1)
  std::vector<double> probabilities_b;  ///< P_i for the points of B (label -1)

  double probability = std::numeric_limits<double>::quiet_NaN ();  ///< max over both sides
  int witness_side = 0;            ///< +1: the maximum is a point of A; -1: of B
  std::size_t witness_index = 0;   ///< index of that point within its side
  /** \brief Unit gradient of f at the witness in the input frame (points toward A's side). */
  Eigen::Vector3d witness_normal = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief Signed distance of the witness to the surface, first order, input units; positive
    * on its own side. */
  double witness_distance = std::numeric_limits<double>::quiet_NaN ();
};

/** \brief Chance-constrained (robust) SVM between two uncertain point sets and the per-point
  * collision probability P_i = Phi(-c_i f(x_i) / sqrt(g_i^T Sigma_i g_i)) (METHOD.md 5, 6).
  *
  * Points of A carry label +1, points of B label -1; f > 0 on A's side. The problem is
  * normalised into the unit cube with Uniform scaling first, so results are invariant under a
  * common rigid motion and change of units.
  *
  * \note Thread safety: classify() is const and may run concurrently on one instance.
  */
class RobustClassifier
{
public:
  /** \brief Validates the parameters (throws pcl::BadArgumentException) and draws the RFF map. */
  explicit RobustClassifier (const ClassifierParams& params = ClassifierParams ());

  const ClassifierParams& getParams () const { return params_; }

  /** \brief Fits the separator and fills per-point probabilities.
    * \param[in] a points of object A (label +1), at least one
    * \param[in] b points of object B (label -1), at least one, in the same frame as a
    * \param[out] result everything computed; result.ok == false with a message when the
    *             inputs are unusable (empty side, non-finite mean or covariance)
    * \return result.ok */
  bool classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result) const;

private:
  ClassifierParams params_;
  // Random Fourier feature draws in unit-cube coordinates, rows of Omega and phases beta,
  // for the large rung; the first rung uses the first rff_features rows.
  Eigen::MatrixXd omega_;
  Eigen::VectorXd beta_;
};

/** \brief Standard normal CDF, Phi(z) = erfc(-z / sqrt 2) / 2, accurate in both tails. */
double normalCdf (double z);
/** \brief Inverse of normalCdf for p in (0, 1). */
double normalQuantile (double p);
} // namespace pcl_probcollision
