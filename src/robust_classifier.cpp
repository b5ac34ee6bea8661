// SPDX-License-Identifier: BSD-3-Clause
// RobustClassifier: input checks, the unit-cube problem, the ladder of rungs and the output
// (METHOD.md 4, 5.7, 6.1-6.2). The rungs are fitted in src/detail/separator_fit.cpp, assessed in
// src/detail/point_probabilities.cpp, and their loops run in src/detail/kernels.cpp.
#include <pcl_probcollision/robust_classifier.h>

#include <pcl_probcollision/detail/linear_separator.h>
#include <pcl_probcollision/detail/point_probabilities.h>
#include <pcl_probcollision/detail/principal_axes.h>
#include <pcl_probcollision/detail/rff_features.h>
#include <pcl_probcollision/detail/separator_fit.h>
#include <pcl_probcollision/detail/separator_problem.h>
#include <pcl_probcollision/normalization.h>

#include <pcl/exceptions.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <utility>

namespace pcl_probcollision
{
namespace
{
/** \brief The ladder rule: whether a fit of n points, degenerate or with that many
  * misclassified points, sends the ladder to the next rung. */
bool
needsEscalation (bool degenerate, std::size_t misclassified, double ladder_fraction, std::size_t n)
{
  return degenerate || static_cast<double> (misclassified) > ladder_fraction * static_cast<double> (n);
}

/** \brief Whether a fit of a more complex rung replaces the best fit so far. */
bool
replaces (const detail::RungFit& candidate, const detail::RungFit& best)
{
  if (candidate.degenerate)
    return false;
  return best.degenerate || candidate.misclassified < best.misclassified;
}

/** \brief Checks one input side; fills result.message and returns false when unusable. */
bool
checkSide (const PointSetView& side, const char* name, ClassifierResult& result)
{
  char buffer[512];
  if (side.size == 0)
  {
    std::snprintf (buffer, sizeof (buffer),
                   "[pcl_probcollision::RobustClassifier::classify] cloud %s is empty", name);
    result.message = buffer;
    return false;
  }
  if (!side.means || !side.covariances)
  {
    std::snprintf (buffer, sizeof (buffer),
                   "[pcl_probcollision::RobustClassifier::classify] cloud %s has %zu points but no %s",
                   name, side.size, side.means ? "covariances" : "means");
    result.message = buffer;
    return false;
  }
  for (std::size_t i = 0; i < side.size; ++i)
  {
    const Eigen::Vector3d& m = side.means[i];
    const bool mean_ok = m.allFinite ();
    if (mean_ok && side.covariances[i].allFinite ())
      continue;
    if (!mean_ok)
      std::snprintf (buffer, sizeof (buffer),
                     "[pcl_probcollision::RobustClassifier::classify] cloud %s point %zu has a "
                     "non-finite mean (%.9g, %.9g, %.9g)",
                     name, i, m.x (), m.y (), m.z ());
    else
      std::snprintf (buffer, sizeof (buffer),
                     "[pcl_probcollision::RobustClassifier::classify] cloud %s point %zu at "
                     "(%.9g, %.9g, %.9g) has a non-finite covariance",
                     name, i, m.x (), m.y (), m.z ());
    result.message = buffer;
    return false;
  }
  return true;
}

/** \brief Doubles of the per-thread problem kept between classify() calls: 512 KB, the eleven
  * columns of about 5,900 points (leaf pairs hold tens). */
constexpr std::size_t kProblemKeep = std::size_t (1) << 16;

/** \brief The two-class problem of METHOD.md 5.1 in the unit cube: A's points (label +1) then
  * B's, mapped by to_cube, with class-balanced weights C_i = C n / (2 n_{c_i}).
  * \return false when some input mean or covariance entry is not finite (p is then unusable):
  *         the check costs nothing in this pass, a pass of its own would. */
bool
makeProblem (const PointSetView& a, const PointSetView& b, const UnitCubeTransform& transform,
             double C, detail::SeparatorProblem& p)
{
  // a local copy, which no store below can alias, so that its entries stay in registers
  const UnitCubeTransform to_cube = transform;
  // stays 0 unless an entry is inf or NaN (or a covariance's entries sum past the double range)
  double finite_check = 0.0;
  const std::size_t n = a.size + b.size;
  p.n_a = static_cast<Eigen::Index> (a.size);
  p.resize (static_cast<Eigen::Index> (n));
  Eigen::Index k = 0;
  for (const PointSetView* side : {&a, &b})
  {
    const double label = side == &a ? 1.0 : -1.0;
    // each cloud carries half of the total weight
    const double weight = C * static_cast<double> (n) / (2.0 * static_cast<double> (side->size));
    for (std::size_t i = 0; i < side->size; ++i, ++k)
    {
      const Eigen::Vector3d& m = side->means[i];
      const Eigen::Matrix3d& sigma = side->covariances[i];
      finite_check += (0.0 * m).sum () + 0.0 * sigma.sum ();
      const Eigen::Vector3d x = to_cube.apply (m);
      const Eigen::Matrix3d s = to_cube.applyToCovariance (sigma);
      p.x (k) = x.x ();
      p.y (k) = x.y ();
      p.z (k) = x.z ();
      p.sxx (k) = s (0, 0);
      p.syy (k) = s (1, 1);
      p.szz (k) = s (2, 2);
      p.sxy (k) = s (0, 1);
      p.sxz (k) = s (0, 2);
      p.syz (k) = s (1, 2);
      p.label (k) = label;
      p.weight (k) = weight;
    }
  }
  return finite_check == 0.0;
}
/** \brief A point whose standard deviation along the fitted gradient is under this fraction of
  * the pair's largest is left out of the maximum, as an exact point is
  * (ClassifierParams::exact_points_in_maximum). Why: the soft margin resolves a gap only down
  * to about sqrt(2 / C) of the pair's normalised extent; under that it prefers a tilted
  * separator with a slack, and a precise sample on its wrong side then reads P_i = 1 from the
  * regulariser, not from the data. A box sampled every 1 cm, 1 mm above a plate, with a sensor
  * noise of 1e-9 or 1e-6 read P = 1 that way, its plate samples 1e-7 to 1e-4 of a box edge's
  * spread along the tilted normal; now 0.63 and 0.57 (test Collide.NoiseFarUnderTheSpacing...).
  * At 1e-4 the deciding plate sample lies at 0.039 and still reads P = 1: a fraction of 0.05 or
  * 0.1 fixes that case too but moved 6 and 9 verdicts of the sparse room at 0.25 %
  * noise on seed 3 (0.1 made a collision 2 sigma deep read free), where 0.03 moved 2 answers
  * of 19,600 on seeds 2-8 (docs/RELIABILITY.md). */
constexpr double kPreciseFraction = 0.03;

/** \brief The frame a problem's random features are drawn in (rffDrawInFrame): its points'
  * principalFrame in the unit cube, which turns with the points, so a rigid motion of the whole
  * scene leaves a kernel rung's fit the same. (With the draw fixed in the unit cube's axes, each
  * frame fitted another draw: the real stereo mug scene's pose 95 read P 0.904-0.966 over 9
  * frames.) */
Eigen::Matrix3d
featureFrame (const detail::SeparatorProblem& p)
{
  Eigen::Vector3d mean, lambda;
  Eigen::Matrix3d axes;
  detail::principalFrame (
      static_cast<std::size_t> (p.n),
      [&p] (std::size_t i) {
        const auto k = static_cast<Eigen::Index> (i);
        return Eigen::Vector3d (p.x (k), p.y (k), p.z (k));
      },
      mean, lambda, axes);
  return axes;
}
} // namespace

void
ClassifierParams::validate () const
{
  const char* prefix = "[pcl_probcollision::ClassifierParams::validate] ";
  if (kernel != KernelMode::Linear && kernel != KernelMode::RFF && kernel != KernelMode::Ladder)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "kernel " << static_cast<int> (kernel) << " is not a KernelMode");
  if (training != TrainingMode::Standard && training != TrainingMode::Robust)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "training " << static_cast<int> (training) << " is not a TrainingMode");
  if (loss != Loss::SquaredHinge && loss != Loss::Huber)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "loss " << static_cast<int> (loss) << " is not a Loss");
  if (!(confidence > 0.5 && confidence < 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "confidence " << confidence << " outside (0.5, 1)");
  if (!(gamma_cap > 0.0 && gamma_cap < 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "gamma_cap " << gamma_cap << " outside (0, 1)");
  if (!(C > 0.0 && std::isfinite (C)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "C " << C << " must be finite and > 0");
  if (!(rbf_gamma > 0.0 && std::isfinite (rbf_gamma)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "rbf_gamma " << rbf_gamma << " must be finite and > 0");
  if (rff_features < 8)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "rff_features " << rff_features << " must be >= 8");
  if (rff_features_large < rff_features || rff_features_large > 65536)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "rff_features_large " << rff_features_large
                         << " outside [rff_features = " << rff_features << ", 65536]");
  if (!(ladder_depth_sigmas > 0.0 && std::isfinite (ladder_depth_sigmas)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "ladder_depth_sigmas " << ladder_depth_sigmas << " must be finite and > 0");
  if (!(ladder_fraction >= 0.0 && ladder_fraction < 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "ladder_fraction " << ladder_fraction << " outside [0, 1)");
  if (max_iterations < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, prefix << "max_iterations " << max_iterations << " must be >= 1");
}

bool
ClassifierParams::operator== (const ClassifierParams& o) const
{
  return kernel == o.kernel && training == o.training && confidence == o.confidence &&
         gamma_cap == o.gamma_cap && C == o.C && rbf_gamma == o.rbf_gamma &&
         rff_features == o.rff_features && rff_features_large == o.rff_features_large &&
         rff_seed == o.rff_seed && ladder_depth_sigmas == o.ladder_depth_sigmas &&
         ladder_fraction == o.ladder_fraction && max_iterations == o.max_iterations && loss == o.loss &&
         exact_points_in_maximum == o.exact_points_in_maximum;
}

RobustClassifier::RobustClassifier (const ClassifierParams& params) : params_ (params)
{
  params_.validate ();
  detail::drawRandomFourierFeatures (params_.rff_seed, params_.rff_features_large,
                                     params_.rbf_gamma, omega_, beta_);
}

bool
RobustClassifier::classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result) const
{
  return classify (a, b, result, params_.kernel);
}

bool
RobustClassifier::needsKernel (const ClassifierResult& plane) const
{
  return needsEscalation (plane.degenerate, plane.misclassified, params_.ladder_fraction, plane.points);
}

bool
RobustClassifier::classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result,
                            KernelMode kernel, double skip_at_or_below, bool point_probabilities) const
{
  result = ClassifierResult ();
  if (a.size == 0 || b.size == 0 || !a.means || !a.covariances || !b.means || !b.covariances)
  {
    if (checkSide (a, "A", result))
      checkSide (b, "B", result);
    return false;
  }

  // Uniform normalisation (METHOD.md 4); checkSide() names an offending point only when the
  // cheap checks fail
  const UnitCubeTransform to_cube = computeUnitCubeTransform ({a, b});
  // One problem per thread, reused from call to call: its buffer is kept, so most calls
  // allocate nothing for it (classify() is const and may run on several threads at once).
  // Above kProblemKeep doubles it is freed on return: big problems are rare.
  thread_local detail::SeparatorProblem p;
  struct Release
  {
    detail::SeparatorProblem& problem;
    ~Release () { problem.releaseAbove (kProblemKeep); }
  } release {p};
  if (!makeProblem (a, b, to_cube, params_.C, p) || !to_cube.isFinite ())
  {
    if (checkSide (a, "A", result) && checkSide (b, "B", result))
      result.message = "[pcl_probcollision::RobustClassifier::classify] the coordinates overflow "
                       "double precision (centroid or radius not finite)";
    return false;
  }
  const std::size_t na = a.size, n = static_cast<std::size_t> (p.n);
  const double scale = to_cube.scale.x ();

  detail::MarginLoss loss;
  loss.huber = params_.loss == Loss::Huber;
  const double gamma = normalQuantile (params_.confidence);

  // The points the maximum runs over: the uncertain ones (see
  // ClassifierParams::exact_points_in_maximum), or every point when none is uncertain.
  thread_local std::vector<bool> uncertain;
  uncertain.assign (n, false);
  bool some_uncertain = false;
  if (!params_.exact_points_in_maximum)
    for (std::size_t i = 0; i < n; ++i)
      some_uncertain |= (uncertain[i] = (i < na ? a.covariances[i] : b.covariances[i - na]).trace () > 0.0);
  const std::vector<bool>* in_maximum = some_uncertain ? &uncertain : nullptr;

  // A pair that cannot raise the caller's maximum (skip_at_or_below, see the declaration):
  // no solve when the plane Newton would start from already leaves every point there.
  // The start is computed once: the plane's fit below starts from it.
  Eigen::Vector4d start;
  std::optional<detail::LinearSeparatorSolver> plane;  // one for the start and the fit
  if (kernel != KernelMode::RFF)
    plane.emplace (p, loss);
  const bool have_start = skip_at_or_below >= 0.0 && kernel != KernelMode::RFF;
  if (have_start)
  {
    start = plane->start ();
    const double p0 = detail::meansPlaneMaximum (p, start, in_maximum);
    if (p0 < 0.5 && p0 <= skip_at_or_below)
    {
      result.ok = true;
      result.dominated = true;
      result.probability = p0;
      return true;
    }
  }

  // The ladder (see the class documentation)
  detail::RungFit best;
  int iterations = 0;
  // A kernel rung fits on the draw turned into the problem's frame, found at the first one
  std::optional<Eigen::Matrix3d> frame;
  thread_local Eigen::MatrixXd omega_frame;
  thread_local Eigen::VectorXd beta_frame;
  const auto fitKernel = [&] (int features, Rung rung) {
    if (!frame)
      frame = featureFrame (p);
    detail::rffDrawInFrame (omega_, beta_, features, *frame, omega_frame, beta_frame);
    return detail::fitRff (p, params_, loss, gamma, omega_frame, beta_frame, features, rung);
  };
  if (kernel == KernelMode::RFF)
  {
    best = fitKernel (params_.rff_features, Rung::RFF);
    iterations = best.iterations;
    result.rungs_tried = 1;
  }
  else
  {
    best = detail::fitLinear (p, params_, gamma, *plane, have_start ? &start : nullptr);
    iterations = best.iterations;
    result.rungs_tried = 1;
    if (kernel == KernelMode::Ladder)
    {
      const int sizes[2] = {params_.rff_features, params_.rff_features_large};
      const Rung rungs[2] = {Rung::RFF, Rung::RFFLarge};
      const std::size_t n_points = static_cast<std::size_t> (p.n);
      bool escalate = needsEscalation (best.degenerate, best.misclassified, params_.ladder_fraction, n_points);
      for (int k = 0; k < 2 && escalate; ++k)
      {
        if (k == 1 && sizes[1] == sizes[0])
          break;
        detail::RungFit fit = fitKernel (sizes[k], rungs[k]);
        iterations += fit.iterations;
        ++result.rungs_tried;
        escalate = needsEscalation (fit.degenerate, fit.misclassified, params_.ladder_fraction, n_points);
        if (replaces (fit, best))
          best = std::move (fit);
      }
    }
  }

  // Output (METHOD.md 6.1-6.2)
  if (!best.theta.allFinite () || best.z.isNaN ().any ())
  {
    // a numeric failure gives NaN and a status, never a plausible-looking number
    result.message = "[pcl_probcollision::RobustClassifier::classify] the solver produced a "
                     "non-finite separator";
    return false;
  }
  result.ok = true;
  result.rung = best.rung;
  result.converged = best.converged;
  result.iterations = iterations;
  result.objective = best.objective;
  result.degenerate = best.degenerate;
  result.gamma_effective = best.gamma_effective;
  result.misclassified = best.misclassified;
  result.points = n;
  if (point_probabilities)
  {
    result.probabilities_a.resize (na);
    result.probabilities_b.resize (n - na);
    for (std::size_t i = 0; i < n; ++i)
      (i < na ? result.probabilities_a[i] : result.probabilities_b[i - na]) = normalCdf (best.z (static_cast<Eigen::Index> (i)));
  }
  // The maximum and its witness, the first point that reaches it. P_i = Phi(z_i) rises with z_i,
  // so a point whose z_i is not above every z_j before it cannot raise the maximum: a normal
  // tail is taken only at a new largest z_i (a few per pair), not at every point. Points far
  // more precise along the fitted gradient than the pair's least precise one count as exact too
  // (kPreciseFraction), tested at those candidates only; the least precise point itself is
  // never left out, so some point always remains.
  const double precise_below = params_.exact_points_in_maximum ? 0.0 : kPreciseFraction * best.largest_spread;
  const auto precise = [&] (Eigen::Index i) {
    const double norm = best.isPlane () ? best.plane_gradient.norm () : detail::gradientNorm (best, i);
    return norm >= detail::kCollapse && std::sqrt (detail::quadraticForm (p, best, i)) / norm < precise_below;
  };
  Eigen::Index witness = -1;
  result.probability = -1.0;
  double largest = -std::numeric_limits<double>::infinity ();
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index> (n); ++i)
    if ((!in_maximum || uncertain[static_cast<std::size_t> (i)]) && (witness < 0 || best.z (i) > largest) &&
        !precise (i))
    {
      largest = best.z (i);
      const double p_i = normalCdf (largest);
      if (p_i > result.probability)
      {
        result.probability = p_i;
        witness = i;
      }
    }
  if (best.degenerate)
    result.probability = 0.5;
  result.witness_side = witness < p.n_a ? 1 : -1;
  result.witness_index = static_cast<std::size_t> (witness < p.n_a ? witness : witness - p.n_a);
  const Eigen::Vector3d g = best.gradient (witness);
  if (g.norm () >= detail::kCollapse)
  {
    // S is a uniform scale: the unit gradient is the same in the input frame, and the
    // first-order distance u = c f / |g| scales back by 1 / S
    result.witness_normal = g.normalized ();
    result.witness_distance = p.label (witness) * best.f (witness) / g.norm () / scale;
  }

  result.separator.rung = best.rung;
  result.separator.centroid = to_cube.shift;
  result.separator.scale = scale;
  if (!best.isPlane () && frame)
    result.separator.frame = *frame;
  result.separator.weights = best.theta.head (best.theta.size () - 1);
  result.separator.bias = best.theta (best.theta.size () - 1);
  return true;
}

double
RobustClassifier::evaluate (const SeparatorModel& model, const Eigen::Vector3d& x,
                            Eigen::Vector3d* gradient) const
{
  const Eigen::Index size = model.weights.size ();
  const bool linear = model.rung == Rung::Linear && size == 3;
  const bool rff = (model.rung == Rung::RFF || model.rung == Rung::RFFLarge) && size >= 1 &&
                   size <= omega_.rows ();
  if (!linear && !rff)
  {
    if (gradient)
      gradient->setConstant (std::numeric_limits<double>::quiet_NaN ());
    return std::numeric_limits<double>::quiet_NaN ();
  }
  const Eigen::Vector3d xn = uniformUnitCubeTransform (model.centroid, model.scale).apply (x);
  if (linear)
  {
    if (gradient)
      *gradient = model.scale * model.weights;
    return model.weights.dot (xn) + model.bias;
  }
  Eigen::MatrixXd omega_frame;
  Eigen::VectorXd beta_frame, phi;
  Eigen::MatrixXd jacobian;
  detail::rffDrawInFrame (omega_, beta_, static_cast<int> (size), model.frame, omega_frame, beta_frame);
  detail::rffFeatures (omega_frame, beta_frame, static_cast<int> (size), xn, phi, gradient ? &jacobian : nullptr);
  if (gradient)
    *gradient = model.scale * (jacobian.transpose () * model.weights);
  return model.weights.dot (phi) + model.bias;
}
} // namespace pcl_probcollision
