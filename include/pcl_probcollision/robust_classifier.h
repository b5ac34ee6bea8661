// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/classifier_params.h>
#include <pcl_probcollision/normal_distribution.h>
#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace pcl_probcollision
{
/** \brief The model actually fitted for one problem. */
enum class Rung
{
  None,    ///< nothing fitted (error)
  Linear,  ///< a plane
  RFF,     ///< random Fourier features with rff_features
  RFFLarge ///< random Fourier features with rff_features_large
};

/** \brief The separating function fitted by one classification, in a form that
  * RobustClassifier::evaluate() can evaluate anywhere.
  *
  * With x' = scale * (x - centroid) + (0.5, 0.5, 0.5) the unit-cube coordinates of an input
  * point x (Uniform scaling, METHOD.md 4: uniformUnitCubeTransform (centroid, scale) of
  * normalization.h), the function is f(x') = w^T x' + b (Linear) or
  * f(x') = w^T phi(frame^T (x' - o)) + b with o = (0.5, 0.5, 0.5) and phi the random Fourier
  * feature map of D = weights.size () features (RFF, RFFLarge). f > 0 on A's side. */
struct SeparatorModel
{
  /** \brief Which model f is (None: nothing fitted, the model is empty). */
  Rung rung = Rung::None;
  /** \brief The centre the unit-cube map subtracts (input frame; the centroid of both point
    * sets). */
  Eigen::Vector3d centroid = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  double scale = std::numeric_limits<double>::quiet_NaN ();  ///< 1 / (2 r_c), 1 when r_c = 0
  /** \brief The axes (columns, a rotation) the random features are drawn along (RFF, RFFLarge):
    * the principal axes of both point sets, so that the fit turns with the points. */
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity ();
  Eigen::VectorXd weights;  ///< w: 3 entries (Linear) or D entries (RFF)
  double bias = std::numeric_limits<double>::quiet_NaN ();  ///< b
};

/** \brief What one classification produced. Probabilities are per point, index-aligned with
  * the inputs; NaN marks anything not computed. */
struct ClassifierResult
{
  bool ok = false;                 ///< false: inputs unusable, see message
  /** \brief No rung was fitted: the start plane's maximum was at most the caller's
    * skip_at_or_below (classify() with a kernel mode). */
  bool dominated = false;
  /** \brief Why the classification failed (ok false): an unusable input or a non-finite
    * separator; empty otherwise. */
  std::string message;
  /** \brief The rung kept (None when nothing was fitted: a failure, or dominated). */
  Rung rung = Rung::None;
  /** \brief Every solve of the kept rung met its tolerance: Newton |grad J| <= 1e-10
    * max(1, |J|) or an accepted step below 1e-12 (METHOD.md 5.3); L-BFGS |grad J| <= 1e-9
    * max(1, |J|). False after the iteration cap or a failed line search. */
  bool converged = false;
  int iterations = 0;              ///< solver iterations summed over the rungs tried
  double objective = std::numeric_limits<double>::quiet_NaN ();  ///< final J of the kept rung
  /** \brief No separating direction: |grad f| < 1e-8 at every point (METHOD.md 6.1); then
    * every P_i and probability are 0.5. */
  bool degenerate = false;
  /** \brief The gamma the kept rung was trained with: 0 for Standard training, and for
    * Robust training when the Standard fit penetrates (t_hat <= 0) or collapsed. */
  double gamma_effective = std::numeric_limits<double>::quiet_NaN ();

  /** \brief P_i for the points of A (label +1); empty when the caller asked for none
    * (classify()'s point_probabilities) or when no rung was fitted. */
  std::vector<double> probabilities_a;
  std::vector<double> probabilities_b;  ///< P_i for the points of B (label -1), likewise

  double probability = std::numeric_limits<double>::quiet_NaN ();  ///< max over both sides
  int witness_side = 0;            ///< +1: the maximum is a point of A; -1: of B
  std::size_t witness_index = 0;   ///< index of that point within its side
  /** \brief Unit gradient of f at the witness in the input frame (points toward A's side);
    * NaN when the gradient collapsed there. */
  Eigen::Vector3d witness_normal = Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ());
  /** \brief Signed distance of the witness to the surface, first order (c_i f_i / |g_i|),
    * input units; positive on its own side. NaN when the gradient collapsed there. */
  double witness_distance = std::numeric_limits<double>::quiet_NaN ();

  /** \brief Points of the fitted rung on the wrong side by more than ladder_depth_sigmas of
    * their own standard deviation along the gradient (any wrong-side point when that standard
    * deviation is zero), plus points where the gradient collapsed (|grad f| < 1e-8). */
  std::size_t misclassified = 0;
  /** \brief Points of both sides that were fitted (the ladder rule's n; the per-point arrays
    * are filled only when asked). */
  std::size_t points = 0;
  /** \brief Number of rungs fitted (1 unless the Ladder escalated). */
  int rungs_tried = 0;
  /** \brief The fitted function, for RobustClassifier::evaluate(). */
  SeparatorModel separator;
};

/** \brief Chance-constrained (robust) SVM between two uncertain point sets and the per-point
  * collision probability P_i = Phi(-c_i f(x_i) / sqrt(g_i^T Sigma_i g_i)) (METHOD.md 5, 6).
  *
  * Points of A carry label +1, points of B label -1; f > 0 on A's side. The problem is
  * normalised into the unit cube with Uniform scaling first, so results are invariant under a
  * common rigid motion and change of units (the random features are drawn in the points'
  * principal frame, so RFF too, up to rounding and to sets whose principal axes are not unique).
  *
  * Training (METHOD.md 5.2-5.5): the Standard problem is solved first (damped Newton on (w, b)
  * for the plane, L-BFGS with memory 10 on the D + 1 unknowns for RFF); for Robust training
  * t_hat = min c_i f_i / s_i over the points with s_i > 0, gamma_eff = min(gamma, gamma_cap *
  * max(0, t_hat)), and the problem is re-solved from the Standard solution when gamma_eff > 0.
  * A collapsed Standard solution (|w| < 1e-8) has no t_hat: gamma_eff = 0.
  *
  * Ladder rule (METHOD.md 5.7): the plane is fitted first. A point is misclassified when
  * c_i f(x_i) < -ladder_depth_sigmas * sqrt(g_i^T Sigma_i g_i) (with zero standard deviation
  * along g_i: when it is on the wrong side at all, u_i < -1e-12), or when |g_i| < 1e-8. The
  * ladder escalates to RFF with rff_features, then to rff_features_large, while the fit is
  * degenerate (every gradient collapsed) or misclassifies more than ladder_fraction of all
  * points. Of the rungs fitted it keeps the non-degenerate one with the fewest misclassified
  * points; ties go to the simpler rung, and when every rung is degenerate the plane is kept.
  *
  * Numbers: L-BFGS stops at |grad J| <= 1e-9 max(1, |J|) and may take 10 * max_iterations
  * steps (each costs O(n D), against O(n) per Newton step). The RFF loops are compiled for
  * several x86-64 instruction sets and chosen at load time (detail/kernels.h), so RFF results
  * may differ between machines at the level of rounding.
  *
  * \note Thread safety: classify() is const and may run concurrently on one instance. Each
  * thread keeps a buffer for the RFF feature matrices (16 n D bytes) between calls; buffers
  * above 4 MB are released after use.
  * \note classify() prints nothing: callers report result.message as they see fit.
  */
class RobustClassifier
{
public:
  /** \brief Validates the parameters (throws pcl::BadArgumentException) and draws the RFF map. */
  explicit RobustClassifier (const ClassifierParams& params = ClassifierParams ());

  /** \brief The parameters this classifier was built with. */
  const ClassifierParams& getParams () const { return params_; }

  /** \brief Fits the separator and fills per-point probabilities.
    * \param[in] a points of object A (label +1), at least one
    * \param[in] b points of object B (label -1), at least one, in the same frame as a
    * \param[out] result everything computed; result.ok == false with a message when the
    *             inputs are unusable (empty side, non-finite mean or covariance)
    * \return result.ok */
  bool classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result) const;

  /** \brief As classify(), with another kernel mode than the parameters' for this call (the
    * random features stay this instance's). collide() fits the plane of every leaf pair
    * first and the kernel rungs only for the pairs that needsKernel() names and that can
    * still raise the maximum.
    *
    * With skip_at_or_below >= 0 (kernel Linear or Ladder), the plane Newton starts from (f = 1
    * and -1 at the class means, METHOD.md 5.3) is assessed first. When it leaves every point
    * on its side (its maximum P_i under 0.5) and its maximum is at most skip_at_or_below,
    * nothing is fitted: result.dominated is set, result.probability is that plane's maximum,
    * the rung None and the per-point arrays empty. collide() passes a bound one standard
    * normal quantile under its maximum so far (over the pair's reach weight): a fit as a rule
    * lowers a separable pair's maximum, and has not raised it by that much in any pair
    * measured (docs/PERFORMANCE.md), so such a pair is not fitted.
    *
    * With point_probabilities false the per-point arrays stay empty and only the maximum and
    * its witness are computed (the same values): a normal tail a new largest point instead of
    * one a point. collide() asks for them only with CollisionRequest::per_point. */
  bool classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result,
                 KernelMode kernel, double skip_at_or_below = -1.0, bool point_probabilities = true) const;

  /** \brief Whether the Ladder goes on to a kernel rung after this plane fit (a Linear
    * classify() result): the fit is degenerate or misclassifies more than ladder_fraction of
    * the points (the ladder rule of the class documentation). */
  bool needsKernel (const ClassifierResult& plane) const;

  /** \brief Evaluates a fitted separator at an input-frame point.
    * \param[in] model result.separator of a classify() call on this instance (RFF models use
    *            this instance's random features)
    * \param[in] x a point in the frame of the inputs
    * \param[out] gradient if not null, the gradient of the returned value with respect to x
    *            (input units; its direction is that of the unit-cube gradient)
    * \return f at x, in the unit-cube scale of the problem (positive on A's side); NaN when
    *         the model is empty or does not belong to this instance */
  double evaluate (const SeparatorModel& model, const Eigen::Vector3d& x,
                   Eigen::Vector3d* gradient = nullptr) const;

private:
  ClassifierParams params_;
  // Random Fourier feature draws in unit-cube coordinates, rows of Omega and phases beta,
  // for the large rung; the first rung uses the first rff_features rows.
  Eigen::MatrixXd omega_;
  Eigen::VectorXd beta_;
};

} // namespace pcl_probcollision
