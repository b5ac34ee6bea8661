// SPDX-License-Identifier: BSD-3-Clause
// Robust separating-surface classifier and per-point collision probabilities
// (METHOD.md 4, 5.1-5.3, 5.5, 5.7, 6.1-6.2).
#include <pcl_probcollision/robust_classifier.h>

#include <pcl_probcollision/detail/kernels.h>
#include <pcl_probcollision/detail/linear_separator.h>
#include <pcl_probcollision/detail/rff_features.h>
#include <pcl_probcollision/detail/rff_separator.h>
#include <pcl_probcollision/detail/separator_problem.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();
constexpr double kInf = std::numeric_limits<double>::infinity ();
/** \brief |grad f| below this (unit-cube units) is a collapsed classifier (METHOD.md 6.1). */
constexpr double kCollapse = 1e-8;
/** \brief Standard deviation along the gradient below this counts as none (METHOD.md 6.1). */
constexpr double kNoSpread = 1e-12;
/** \brief Gradient tolerance of L-BFGS, relative to max(1, |J|) (Newton uses 1e-10, METHOD.md
  * 5.3). J is 1-strongly convex in w and |phi_i| <= 1, so an error e in grad J moves w, and f
  * through it, by about e; at 1e-9 |J| that is far below the per-point standard deviations
  * along g that scale P_i. */
constexpr double kRffTolerance = 1e-9;
/** \brief RFF feature storage (doubles) kept per thread between calls: 4 MB. */
constexpr std::size_t kWorkspaceKeep = std::size_t (1) << 19;
/** \brief L-BFGS iterations allowed per unit of ClassifierParams::max_iterations. */
constexpr int kRffIterationFactor = 10;

/** \brief One fitted rung with its evaluation at the training points. */
struct RungFit
{
  Rung rung = Rung::None;
  Eigen::VectorXd theta;  // (w, b)
  double gamma_effective = 0.0;
  int iterations = 0;
  bool converged = false;
  double objective = kNaN;
  Eigen::ArrayXd f;           // f(x_i)
  Eigen::ArrayXd gx, gy, gz;  // grad f(x_i) in the unit-cube frame; empty for a plane
  Eigen::Vector3d plane_gradient = Eigen::Vector3d::Zero ();  // w, for a plane
  Eigen::ArrayXd probability;
  std::size_t misclassified = 0;
  bool degenerate = false;

  bool isPlane () const { return gx.size () == 0; }
  Eigen::Vector3d
  gradient (Eigen::Index i) const
  {
    return isPlane () ? plane_gradient : Eigen::Vector3d (gx (i), gy (i), gz (i));
  }
};

/** \brief g_i^T Sigma_i g_i (clamped at 0) for per-point gradients, or for one gradient w. */
Eigen::ArrayXd
quadraticForms (const detail::SeparatorProblem& p, const RungFit& fit)
{
  if (fit.isPlane ())
  {
    const Eigen::Vector3d& w = fit.plane_gradient;
    return (w (0) * w (0) * p.sxx + w (1) * w (1) * p.syy + w (2) * w (2) * p.szz +
            2.0 * (w (0) * w (1) * p.sxy + w (0) * w (2) * p.sxz + w (1) * w (2) * p.syz))
        .max (0.0);
  }
  return (fit.gx * fit.gx * p.sxx + fit.gy * fit.gy * p.syy + fit.gz * fit.gz * p.szz +
          2.0 * (fit.gx * fit.gy * p.sxy + fit.gx * fit.gz * p.sxz + fit.gy * fit.gz * p.syz))
      .max (0.0);
}

/** \brief |g_i|. */
Eigen::ArrayXd
gradientNorms (const RungFit& fit, Eigen::Index n)
{
  if (fit.isPlane ())
    return Eigen::ArrayXd::Constant (n, fit.plane_gradient.norm ());
  return (fit.gx.square () + fit.gy.square () + fit.gz.square ()).sqrt ();
}

/** \brief METHOD.md 6.1 for every point, and the ladder's misclassification count. With
  * u_i = c_i f_i / |g_i| and sigma_i = sqrt(g_i^T Sigma_i g_i) / |g_i|: |g_i| < 1e-8 gives 0.5
  * (collapsed); sigma_i < 1e-12 gives 1, 0.5 or 0 by the sign of u_i (tolerance 1e-12);
  * otherwise Phi(-u_i / sigma_i). */
void
assessFit (const detail::SeparatorProblem& p, double depth_sigmas, RungFit& fit)
{
  const Eigen::Index n = p.n;
  const Eigen::ArrayXd norm = gradientNorms (fit, n);
  const Eigen::ArrayXd u = p.label * fit.f / norm;
  const Eigen::ArrayXd sigma = quadraticForms (p, fit).sqrt () / norm;
  fit.probability.resize (n);
  fit.misclassified = 0;
  Eigen::Index collapsed = 0;
  for (Eigen::Index i = 0; i < n; ++i)
  {
    if (!(norm (i) >= kCollapse))
    {
      fit.probability (i) = 0.5;
      ++fit.misclassified;
      ++collapsed;
    }
    else if (sigma (i) < kNoSpread)
    {
      fit.probability (i) = u (i) < -kNoSpread ? 1.0 : (u (i) <= kNoSpread ? 0.5 : 0.0);
      fit.misclassified += u (i) < -kNoSpread;
    }
    else
    {
      fit.probability (i) = normalCdf (-u (i) / sigma (i));
      fit.misclassified += u (i) < -depth_sigmas * sigma (i);
    }
  }
  fit.degenerate = collapsed == n;
}

/** \brief gamma_eff of METHOD.md 5.2 from the Standard fit: min(gamma, eta max(0, t_hat)),
  * t_hat = min c_i f_i / s_i over the points with s_i > 0 and a gradient that has not
  * collapsed; 0 when every gradient collapsed (no separator to make robust). */
double
effectiveGamma (const detail::SeparatorProblem& p, const RungFit& fit, double gamma, double eta)
{
  const Eigen::ArrayXd norm = gradientNorms (fit, p.n);
  const Eigen::ArrayXd s = quadraticForms (p, fit).sqrt ();
  double t_hat = kInf;
  bool any_direction = false;
  for (Eigen::Index i = 0; i < p.n; ++i)
  {
    if (!(norm (i) >= kCollapse))
      continue;
    any_direction = true;
    if (s (i) > 0.0)
      t_hat = std::min (t_hat, p.label (i) * fit.f (i) / s (i));
  }
  if (!any_direction)
    return 0.0;
  return std::min (gamma, eta * std::max (0.0, t_hat));
}

RungFit
fitLinear (const detail::SeparatorProblem& p, const ClassifierParams& params,
           const detail::MarginLoss& loss, double gamma)
{
  RungFit fit;
  fit.rung = Rung::Linear;
  detail::LinearSeparatorSolver solver (p, loss);
  Eigen::Vector4d theta = solver.start ();
  const auto evaluateAt = [&p, &fit] (const Eigen::Vector4d& th) {
    fit.f = th (0) * p.x + th (1) * p.y + th (2) * p.z + th (3);
    fit.plane_gradient = th.head<3> ();
  };
  detail::SolverReport report = solver.solve (theta, 0.0, params.max_iterations);
  fit.iterations = report.iterations;
  evaluateAt (theta);
  if (params.training == TrainingMode::Robust)
  {
    fit.gamma_effective = effectiveGamma (p, fit, gamma, params.gamma_cap);
    if (fit.gamma_effective > 0.0)
    {
      const detail::SolverReport robust = solver.solve (theta, fit.gamma_effective, params.max_iterations);
      fit.iterations += robust.iterations;
      report.converged = report.converged && robust.converged;
      report.objective = robust.objective;
      evaluateAt (theta);
    }
  }
  fit.converged = report.converged;
  fit.objective = report.objective;
  fit.theta = theta;
  assessFit (p, params.ladder_depth_sigmas, fit);
  return fit;
}

RungFit
fitRff (const detail::SeparatorProblem& p, const ClassifierParams& params,
        const detail::MarginLoss& loss, double gamma, const Eigen::MatrixXd& omega,
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
  detail::RffSeparatorSolver solver (p, loss, omega, beta, features, workspace);
  const int max_iterations = kRffIterationFactor * params.max_iterations;
  Eigen::VectorXd theta = Eigen::VectorXd::Zero (features + 1);
  detail::SolverReport report = solver.solve (theta, 0.0, max_iterations, kRffTolerance);
  fit.iterations = report.iterations;
  solver.evaluate (theta, fit.f, fit.gx, fit.gy, fit.gz);
  if (params.training == TrainingMode::Robust)
  {
    fit.gamma_effective = effectiveGamma (p, fit, gamma, params.gamma_cap);
    if (fit.gamma_effective > 0.0)
    {
      const detail::SolverReport robust =
          solver.solve (theta, fit.gamma_effective, max_iterations, kRffTolerance);
      fit.iterations += robust.iterations;
      report.converged = report.converged && robust.converged;
      report.objective = robust.objective;
      solver.evaluate (theta, fit.f, fit.gx, fit.gy, fit.gz);
    }
  }
  fit.converged = report.converged;
  fit.objective = report.objective;
  fit.theta = theta;
  assessFit (p, params.ladder_depth_sigmas, fit);
  return fit;
}

/** \brief The ladder rule: whether a fit of n points, degenerate or with that many
  * misclassified points, sends the ladder to the next rung. */
bool
needsEscalation (bool degenerate, std::size_t misclassified, double ladder_fraction, std::size_t n)
{
  return degenerate || static_cast<double> (misclassified) > ladder_fraction * static_cast<double> (n);
}

/** \brief Whether a fit of a more complex rung replaces the best fit so far. */
bool
replaces (const RungFit& candidate, const RungFit& best)
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
} // namespace

// ---------------------------------------------------------------------------------------------
// Kernels (declared in detail/kernels.h). Plain loops over fixed blocks of
// 8 or 16 so that GCC's -O2 vectoriser (very-cheap cost model: no epilogues) takes them, and
// separate accumulators per lane so that no reassociation is needed.
// ---------------------------------------------------------------------------------------------
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12 && defined(__x86_64__) && defined(__linux__)
#define PCL_PROBCOLLISION_CLONES \
  __attribute__ ((target_clones ("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define PCL_PROBCOLLISION_CLONES
#endif
#if defined(__GNUC__)
#define PCL_PROBCOLLISION_ALWAYS_INLINE inline __attribute__ ((always_inline))
#define PCL_PROBCOLLISION_LAMBDA_INLINE __attribute__ ((always_inline))
#else
#define PCL_PROBCOLLISION_ALWAYS_INLINE inline
#define PCL_PROBCOLLISION_LAMBDA_INLINE
#endif

namespace detail
{
namespace
{
constexpr std::size_t kBlock = 16;
constexpr std::size_t kLanes = 8;

/** \brief Tree sum of 8 lanes, in a fixed order. */
PCL_PROBCOLLISION_ALWAYS_INLINE double
laneSum (const double* a)
{
  return ((a[0] + a[4]) + (a[2] + a[6])) + ((a[1] + a[5]) + (a[3] + a[7]));
}

/** \brief sin and cos of kBlock arguments (local arrays, no aliasing). */
PCL_PROBCOLLISION_ALWAYS_INLINE void
sinCosBlock (const double* __restrict z, double* __restrict s, double* __restrict c)
{
  constexpr double two_over_pi = 6.36619772367581382433e-01;
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52: (x + magic) - magic rounds x
  constexpr double p1 = 1.57079632673412561417e+00;  // pi/2 in three parts (fdlibm)
  constexpr double p2 = 6.07710050630396597660e-11;
  constexpr double p3 = 2.02226624879595063154e-21;
  constexpr double s1 = -1.66666666666666324348e-01, s2 = 8.33333333332248946124e-03,
                   s3 = -1.98412698298579493134e-04, s4 = 2.75573137070700676789e-06,
                   s5 = -2.50507602534068634195e-08, s6 = 1.58969099521155010221e-10;
  constexpr double c1 = 4.16666666666666019037e-02, c2 = -1.38888888888741095749e-03,
                   c3 = 2.48015872894767294178e-05, c4 = -2.75573143513906633035e-07,
                   c5 = 2.08757232129817482790e-09, c6 = -1.13596475577881948265e-11;
  constexpr double limit = 1e5;
  int bad = 0;
  for (std::size_t j = 0; j < kBlock; ++j)
    bad |= !(std::abs (z[j]) <= limit);
  if (bad)
  {
    for (std::size_t j = 0; j < kBlock; ++j)
    {
      const double x = z[j];
      s[j] = std::sin (x);
      c[j] = std::cos (x);
    }
    return;
  }
  for (std::size_t j = 0; j < kBlock; ++j)
  {
    const double x = z[j];
    const double k = (x * two_over_pi + magic) - magic;
    const double r = ((x - k * p1) - k * p2) - k * p3;
    const double r2 = r * r;
    const double sr = r + r * r2 * (s1 + r2 * (s2 + r2 * (s3 + r2 * (s4 + r2 * (s5 + r2 * s6)))));
    const double cr = 1.0 - 0.5 * r2 + r2 * r2 * (c1 + r2 * (c2 + r2 * (c3 + r2 * (c4 + r2 * (c5 + r2 * c6)))));
    // quadrant: k mod 4 = 2 hi + odd, x = r + (k mod 4) pi/2 (mod 2 pi)
    const double q = (k * 0.25 - 0.375 + magic) - magic;  // floor(k / 4)
    const double quadrant = k - 4.0 * q;                 // 0, 1, 2, 3
    const double hi = (quadrant * 0.5 - 0.25 + magic) - magic;
    const double odd = quadrant - 2.0 * hi;
    const double sign = 1.0 - 2.0 * hi;
    s[j] = sign * ((1.0 - odd) * sr + odd * cr);
    c[j] = sign * ((1.0 - odd) * cr - odd * sr);
  }
}
} // namespace

namespace
{
/** \brief w^T Sigma_k w with the products of w precomputed in q. */
PCL_PROBCOLLISION_ALWAYS_INLINE double
linearQuadratic (const LinearPoints& p, const double* q, std::size_t k)
{
  const double value = q[0] * p.sxx[k] + q[1] * p.syy[k] + q[2] * p.szz[k] + q[3] * p.sxy[k] +
                       q[4] * p.sxz[k] + q[5] * p.syz[k];
  return value > 0.0 ? value : 0.0;
}

/** \brief Adds the 20 terms of linearDerivatives() for point k to lane j of acc. */
template <bool robust, bool huber>
PCL_PROBCOLLISION_ALWAYS_INLINE void
linearPointDerivatives (const LinearPoints& p, const double* theta, double gamma, double h,
                        double inv_h, const double* v, const double* s, std::size_t k,
                        double (*acc)[kLanes], std::size_t j)
{
  const double w0 = theta[0], w1 = theta[1], w2 = theta[2];
  const double vk = v[k], c = p.label[k], weight = p.weight[k];
  const double m = 0.5 * (vk + std::abs (vk));
  double a, hh;
  // step(x) = [x > 0] as copysign(1/2, x) + 1/2 (1 at +0: the generalised second derivative
  // may take any value in [0, 1] at the kink); branch-free so that the loop vectorises
  const double positive = std::copysign (0.5, vk) + 0.5;
  if (huber)
  {
    const double mh = m * inv_h;
    a = weight * 0.5 * (mh + 1.0 - std::abs (mh - 1.0));  // min(m / h, 1)
    hh = weight * inv_h * positive * (std::copysign (0.5, h - vk) + 0.5);
  }
  else
  {
    a = weight * m;
    hh = weight * positive;
  }
  double d0 = -c * p.x[k], d1 = -c * p.y[k], d2 = -c * p.z[k];
  const double d3 = -c;
  if (robust)
  {
    const double sxx = p.sxx[k], sxy = p.sxy[k], sxz = p.sxz[k], syy = p.syy[k], syz = p.syz[k],
                 szz = p.szz[k];
    const double t0 = sxx * w0 + sxy * w1 + sxz * w2;
    const double t1 = sxy * w0 + syy * w1 + syz * w2;
    const double t2 = sxz * w0 + syz * w1 + szz * w2;
    const double inv_s = 1.0 / s[k];
    const double gs = gamma * inv_s;
    d0 += gs * t0;
    d1 += gs * t1;
    d2 += gs * t2;
    const double k1 = a * gs, k2 = k1 * inv_s * inv_s;
    acc[14][j] += k1 * sxx - k2 * t0 * t0;
    acc[15][j] += k1 * sxy - k2 * t0 * t1;
    acc[16][j] += k1 * sxz - k2 * t0 * t2;
    acc[17][j] += k1 * syy - k2 * t1 * t1;
    acc[18][j] += k1 * syz - k2 * t1 * t2;
    acc[19][j] += k1 * szz - k2 * t2 * t2;
  }
  acc[0][j] += a * d0;
  acc[1][j] += a * d1;
  acc[2][j] += a * d2;
  acc[3][j] += a * d3;
  const double e0 = hh * d0, e1 = hh * d1, e2 = hh * d2, e3 = hh * d3;
  acc[4][j] += e0 * d0;
  acc[5][j] += e0 * d1;
  acc[6][j] += e0 * d2;
  acc[7][j] += e0 * d3;
  acc[8][j] += e1 * d1;
  acc[9][j] += e1 * d2;
  acc[10][j] += e1 * d3;
  acc[11][j] += e2 * d2;
  acc[12][j] += e2 * d3;
  acc[13][j] += e3 * d3;
}

/** \brief The loops of linearLoss() and linearDerivatives(), one instance per mode so that the
  * loop bodies carry no loop-invariant branch (GCC's -O2 vectoriser does not unswitch loops).
  * Always inlined, so each target clone vectorises them for its own instruction set. */
template <bool robust, bool huber>
PCL_PROBCOLLISION_ALWAYS_INLINE double
linearLossLoop (const LinearPoints& p, const double* theta, double gamma, double h, double inv_2h,
                const double* __restrict s, double* __restrict v)
{
  // local restrict copies: GCC's -O2 vectoriser will not add runtime alias checks
  const double* __restrict x = p.x;
  const double* __restrict y = p.y;
  const double* __restrict z = p.z;
  const double* __restrict label = p.label;
  const double* __restrict weight = p.weight;
  const double w0 = theta[0], w1 = theta[1], w2 = theta[2], b = theta[3];
  const std::size_t n = p.n;
  const auto point = [&] (std::size_t k) PCL_PROBCOLLISION_LAMBDA_INLINE {
    double vk = 1.0 - label[k] * (w0 * x[k] + w1 * y[k] + w2 * z[k] + b);
    if (robust)
      vk += gamma * s[k];
    v[k] = vk;
    const double m = 0.5 * (vk + std::abs (vk));  // max(v, 0) without a branch
    double loss;
    if (huber)
    {
      const double mm = 0.5 * (m + h - std::abs (m - h));  // min(m, h)
      loss = mm * mm * inv_2h + (m - mm);
    }
    else
      loss = 0.5 * m * m;
    return weight[k] * loss;
  };
  double acc[kLanes] = {};
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (std::size_t j = 0; j < kLanes; ++j)
      acc[j] += point (i + j);
  double total = laneSum (acc);
  for (; i < n; ++i)
    total += point (i);
  return total;
}

template <bool robust, bool huber>
PCL_PROBCOLLISION_ALWAYS_INLINE void
linearDerivativeLoop (const LinearPoints& p, const double* theta, double gamma, double h,
                      double inv_h, const double* v, const double* s, double* out)
{
  constexpr std::size_t terms = 20;
  const std::size_t n = p.n;
  double acc[terms][kLanes] = {};
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (std::size_t j = 0; j < kLanes; ++j)
      linearPointDerivatives<robust, huber> (p, theta, gamma, h, inv_h, v, s, i + j, acc, j);
  // the remainder goes to lane 0
  for (; i < n; ++i)
    linearPointDerivatives<robust, huber> (p, theta, gamma, h, inv_h, v, s, i, acc, 0);
  for (std::size_t q = 0; q < terms; ++q)
    out[q] = laneSum (acc[q]);
}
} // namespace

PCL_PROBCOLLISION_CLONES double
linearLoss (const LinearPoints& p, const double* theta, double gamma, double huber_width,
            double eps, double* __restrict v, double* __restrict s)
{
  const std::size_t n = p.n;
  const bool robust = gamma > 0.0;
  if (robust)
  {
    const double w0 = theta[0], w1 = theta[1], w2 = theta[2];
    const double q[6] = {w0 * w0, w1 * w1, w2 * w2, 2.0 * w0 * w1, 2.0 * w0 * w2, 2.0 * w1 * w2};
    const double eps2 = eps * eps;
    for (std::size_t k = 0; k < n; ++k)
      s[k] = linearQuadratic (p, q, k) + eps2;
    // std::sqrt may set errno, which keeps GCC from vectorising it; Eigen's sqrt is the packet
    // instruction (the argument is >= eps^2 > 0 here)
    Eigen::Map<Eigen::ArrayXd> (s, static_cast<Eigen::Index> (n)) =
        Eigen::Map<Eigen::ArrayXd> (s, static_cast<Eigen::Index> (n)).sqrt ();
  }
  const double h = huber_width, inv_2h = huber_width > 0.0 ? 0.5 / huber_width : 0.0;
  if (robust)
    return h > 0.0 ? linearLossLoop<true, true> (p, theta, gamma, h, inv_2h, s, v)
                   : linearLossLoop<true, false> (p, theta, gamma, h, inv_2h, s, v);
  return h > 0.0 ? linearLossLoop<false, true> (p, theta, gamma, h, inv_2h, s, v)
                 : linearLossLoop<false, false> (p, theta, gamma, h, inv_2h, s, v);
}

PCL_PROBCOLLISION_CLONES void
linearDerivatives (const LinearPoints& p, const double* theta, double gamma, double huber_width,
                   const double* __restrict v, const double* __restrict s, double* out)
{
  const bool robust = gamma > 0.0;
  const double h = huber_width, inv_h = huber_width > 0.0 ? 1.0 / huber_width : 0.0;
  if (robust)
    h > 0.0 ? linearDerivativeLoop<true, true> (p, theta, gamma, h, inv_h, v, s, out)
            : linearDerivativeLoop<true, false> (p, theta, gamma, h, inv_h, v, s, out);
  else
    h > 0.0 ? linearDerivativeLoop<false, true> (p, theta, gamma, h, inv_h, v, s, out)
            : linearDerivativeLoop<false, false> (p, theta, gamma, h, inv_h, v, s, out);
}

PCL_PROBCOLLISION_CLONES void
sinCos (const double* z, double* s, double* c, std::size_t n)
{
  // blocks go through a local copy: z may alias c
  std::size_t i = 0;
  for (; i + kBlock <= n; i += kBlock)
  {
    double zz[kBlock], ss[kBlock], cc[kBlock];
    for (std::size_t j = 0; j < kBlock; ++j)
      zz[j] = z[i + j];
    sinCosBlock (zz, ss, cc);
    for (std::size_t j = 0; j < kBlock; ++j)
    {
      s[i + j] = ss[j];
      c[i + j] = cc[j];
    }
  }
  for (; i < n; ++i)
  {
    const double x = z[i];
    s[i] = std::sin (x);
    c[i] = std::cos (x);
  }
}

PCL_PROBCOLLISION_CLONES void
rffFeatureRows (std::size_t n, std::size_t features, const double* x, const double* y,
                const double* z, const double* __restrict ox, const double* __restrict oy,
                const double* __restrict oz, const double* __restrict beta,
                double* __restrict phi, double* __restrict sm)
{
  const double norm = std::sqrt (2.0 / static_cast<double> (features));
  for (std::size_t i = 0; i < n; ++i)
  {
    double* __restrict p = phi + i * features;
    double* __restrict s = sm + i * features;
    const double xi = x[i], yi = y[i], zi = z[i];
    std::size_t k = 0;
    for (; k + kBlock <= features; k += kBlock)
    {
      double arg[kBlock], ss[kBlock], cc[kBlock];
      for (std::size_t j = 0; j < kBlock; ++j)
        arg[j] = ox[k + j] * xi + oy[k + j] * yi + oz[k + j] * zi + beta[k + j];
      sinCosBlock (arg, ss, cc);
      for (std::size_t j = 0; j < kBlock; ++j)
      {
        p[k + j] = norm * cc[j];
        s[k + j] = -norm * ss[j];
      }
    }
    for (; k < features; ++k)
    {
      const double a = ox[k] * xi + oy[k] * yi + oz[k] * zi + beta[k];
      p[k] = norm * std::cos (a);
      s[k] = -norm * std::sin (a);
    }
  }
}

namespace
{
/** \brief C l(v) and C l'(v). */
PCL_PROBCOLLISION_ALWAYS_INLINE void
lossAndSlope (double v, double weight, double h, double* loss, double* slope)
{
  if (!(v > 0.0))
  {
    *loss = 0.0;
    *slope = 0.0;
    return;
  }
  if (h > 0.0)
  {
    *loss = weight * (v <= h ? v * v / (2.0 * h) : v - 0.5 * h);
    *slope = weight * (v <= h ? v / h : 1.0);
    return;
  }
  *loss = 0.5 * weight * v * v;
  *slope = weight * v;
}

/** \brief Dot products of four rows with one vector, 8 lanes each (4 accumulator chains). */
PCL_PROBCOLLISION_ALWAYS_INLINE void
rowDots4 (const double* __restrict p0, const double* __restrict p1, const double* __restrict p2,
          const double* __restrict p3, const double* __restrict x, std::size_t d, double* out)
{
  double a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {}, a3[kLanes] = {};
  std::size_t k = 0;
  for (; k + kLanes <= d; k += kLanes)
    for (std::size_t j = 0; j < kLanes; ++j)
    {
      const double xk = x[k + j];
      a0[j] += p0[k + j] * xk;
      a1[j] += p1[k + j] * xk;
      a2[j] += p2[k + j] * xk;
      a3[j] += p3[k + j] * xk;
    }
  double s0 = laneSum (a0), s1 = laneSum (a1), s2 = laneSum (a2), s3 = laneSum (a3);
  for (; k < d; ++k)
  {
    s0 += p0[k] * x[k];
    s1 += p1[k] * x[k];
    s2 += p2[k] * x[k];
    s3 += p3[k] * x[k];
  }
  out[0] = s0;
  out[1] = s1;
  out[2] = s2;
  out[3] = s3;
}
/** \brief The three dot products of four rows with wx, wy, wz in one loop (12 chains). */
PCL_PROBCOLLISION_ALWAYS_INLINE void
rowGradients4 (const double* __restrict q0, const double* __restrict q1, const double* __restrict q2,
               const double* __restrict q3, const double* __restrict wx, const double* __restrict wy,
               const double* __restrict wz, std::size_t d, double* gx, double* gy, double* gz)
{
  double x0[kLanes] = {}, x1[kLanes] = {}, x2[kLanes] = {}, x3[kLanes] = {};
  double y0[kLanes] = {}, y1[kLanes] = {}, y2[kLanes] = {}, y3[kLanes] = {};
  double z0[kLanes] = {}, z1[kLanes] = {}, z2[kLanes] = {}, z3[kLanes] = {};
  std::size_t k = 0;
  for (; k + kLanes <= d; k += kLanes)
    for (std::size_t j = 0; j < kLanes; ++j)
    {
      const double a = wx[k + j], b = wy[k + j], c = wz[k + j];
      const double s0 = q0[k + j], s1 = q1[k + j], s2 = q2[k + j], s3 = q3[k + j];
      x0[j] += s0 * a;
      x1[j] += s1 * a;
      x2[j] += s2 * a;
      x3[j] += s3 * a;
      y0[j] += s0 * b;
      y1[j] += s1 * b;
      y2[j] += s2 * b;
      y3[j] += s3 * b;
      z0[j] += s0 * c;
      z1[j] += s1 * c;
      z2[j] += s2 * c;
      z3[j] += s3 * c;
    }
  gx[0] = laneSum (x0);
  gx[1] = laneSum (x1);
  gx[2] = laneSum (x2);
  gx[3] = laneSum (x3);
  gy[0] = laneSum (y0);
  gy[1] = laneSum (y1);
  gy[2] = laneSum (y2);
  gy[3] = laneSum (y3);
  gz[0] = laneSum (z0);
  gz[1] = laneSum (z1);
  gz[2] = laneSum (z2);
  gz[3] = laneSum (z3);
  for (; k < d; ++k)
  {
    const double a = wx[k], b = wy[k], c = wz[k];
    gx[0] += q0[k] * a;
    gx[1] += q1[k] * a;
    gx[2] += q2[k] * a;
    gx[3] += q3[k] * a;
    gy[0] += q0[k] * b;
    gy[1] += q1[k] * b;
    gy[2] += q2[k] * b;
    gy[3] += q3[k] * b;
    gz[0] += q0[k] * c;
    gz[1] += q1[k] * c;
    gz[2] += q2[k] * c;
    gz[3] += q3[k] * c;
  }
}
} // namespace

PCL_PROBCOLLISION_CLONES double
rffObjective (const RffRows& q, const double* __restrict w, double b, const double* __restrict wx,
              const double* __restrict wy, const double* __restrict wz, double gamma,
              double huber_width, double eps, const double* __restrict s_bound,
              double displacement, double* __restrict s_bound_out, double* __restrict v,
              double* __restrict grad, double* __restrict grad_b)
{
  constexpr std::size_t block = 4;  // rows per block: 4 chains for f, 12 for g
  const std::size_t n = q.n, d = q.features;
  const bool robust = gamma > 0.0, fresh = !(displacement >= 0.0);
  const double eps2 = eps * eps;
  const double* __restrict ox = q.ox;
  const double* __restrict oy = q.oy;
  const double* __restrict oz = q.oz;
  double total = 0.0, gb = 0.0;
  for (std::size_t i0 = 0; i0 < n; i0 += block)
  {
    const std::size_t m = n - i0 < block ? n - i0 : block;
    const double* p[block];
    const double* sr[block];
    for (std::size_t r = 0; r < block; ++r)
    {
      const std::size_t i = i0 + (r < m ? r : 0);  // pad a short block with its first row
      p[r] = q.phi + i * d;
      sr[r] = q.sm + i * d;
    }
    const double* __restrict p0 = p[0];
    const double* __restrict p1 = p[1];
    const double* __restrict p2 = p[2];
    const double* __restrict p3 = p[3];
    const double* __restrict q0 = sr[0];
    const double* __restrict q1 = sr[1];
    const double* __restrict q2 = sr[2];
    const double* __restrict q3 = sr[3];
    double f[block];
    rowDots4 (p0, p1, p2, p3, w, d, f);
    double slope[block] = {}, t0[block] = {}, t1[block] = {}, t2[block] = {};
    bool any = false, any_candidate = false;
    double violation[block], bound[block];
    bool candidate[block];
    for (std::size_t r = 0; r < m; ++r)
    {
      const std::size_t i = i0 + r;
      violation[r] = 1.0 - q.label[i] * (f[r] + b);
      candidate[r] = false;
      if (robust)
      {
        bound[r] = fresh ? 0.0 : s_bound[i] + q.lipschitz[i] * displacement;
        candidate[r] = fresh || violation[r] + gamma * bound[r] > 0.0;
        any_candidate = any_candidate || candidate[r];
      }
    }
    double gx[block] = {}, gy[block] = {}, gz[block] = {};
    if (any_candidate)
    {
      rowGradients4 (q0, q1, q2, q3, wx, wy, wz, d, gx, gy, gz);
    }
    for (std::size_t r = 0; r < m; ++r)
    {
      const std::size_t i = i0 + r;
      double vi = violation[r];
      double si = 0.0;
      if (robust)
      {
        if (candidate[r])
        {
          const double x = gx[r], y = gy[r], z = gz[r];
          double quad = x * x * q.sxx[i] + y * y * q.syy[i] + z * z * q.szz[i] +
                        2.0 * (x * y * q.sxy[i] + x * z * q.sxz[i] + y * z * q.syz[i]);
          quad = quad > 0.0 ? quad : 0.0;
          si = std::sqrt (quad + eps2);
          s_bound_out[i] = si;
          vi += gamma * si;
        }
        else
        {
          s_bound_out[i] = bound[r];
          vi += gamma * bound[r];  // still <= 0: l, l' and l'' vanish as for the exact v_i
        }
      }
      v[i] = vi;
      double loss, a;
      lossAndSlope (vi, q.weight[i], huber_width, &loss, &a);
      total += loss;
      if (a != 0.0)
      {
        any = true;
        slope[r] = -q.label[i] * a;
        gb += slope[r];
        if (robust)
        {
          const double k = gamma * a / si, x = gx[r], y = gy[r], z = gz[r];
          t0[r] = k * (q.sxx[i] * x + q.sxy[i] * y + q.sxz[i] * z);
          t1[r] = k * (q.sxy[i] * x + q.syy[i] * y + q.syz[i] * z);
          t2[r] = k * (q.sxz[i] * x + q.syz[i] * y + q.szz[i] * z);
        }
      }
    }
    if (!any)
      continue;
    // grad += sum_r slope_r phi_r (+ sm_r o (Omega t_r)); padded rows have zero coefficients
    const double c0 = slope[0], c1 = slope[1], c2 = slope[2], c3 = slope[3];
    std::size_t k = 0;
    if (!robust)
    {
      for (; k + kLanes <= d; k += kLanes)
        for (std::size_t j = 0; j < kLanes; ++j)
          grad[k + j] += (c0 * p0[k + j] + c1 * p1[k + j]) + (c2 * p2[k + j] + c3 * p3[k + j]);
      for (; k < d; ++k)
        grad[k] += (c0 * p0[k] + c1 * p1[k]) + (c2 * p2[k] + c3 * p3[k]);
      continue;
    }
    const double u00 = t0[0], u01 = t1[0], u02 = t2[0], u10 = t0[1], u11 = t1[1], u12 = t2[1];
    const double u20 = t0[2], u21 = t1[2], u22 = t2[2], u30 = t0[3], u31 = t1[3], u32 = t2[3];
    for (; k + kLanes <= d; k += kLanes)
      for (std::size_t j = 0; j < kLanes; ++j)
      {
        const double x = ox[k + j], y = oy[k + j], z = oz[k + j];
        grad[k + j] += ((c0 * p0[k + j] + q0[k + j] * (x * u00 + y * u01 + z * u02)) +
                        (c1 * p1[k + j] + q1[k + j] * (x * u10 + y * u11 + z * u12))) +
                       ((c2 * p2[k + j] + q2[k + j] * (x * u20 + y * u21 + z * u22)) +
                        (c3 * p3[k + j] + q3[k + j] * (x * u30 + y * u31 + z * u32)));
      }
    for (; k < d; ++k)
    {
      const double x = ox[k], y = oy[k], z = oz[k];
      grad[k] += ((c0 * p0[k] + q0[k] * (x * u00 + y * u01 + z * u02)) +
                  (c1 * p1[k] + q1[k] * (x * u10 + y * u11 + z * u12))) +
                 ((c2 * p2[k] + q2[k] * (x * u20 + y * u21 + z * u22)) +
                  (c3 * p3[k] + q3[k] * (x * u30 + y * u31 + z * u32)));
    }
  }
  *grad_b += gb;
  return total;
}

PCL_PROBCOLLISION_CLONES void
rffForward (std::size_t n, std::size_t features, const double* __restrict phi,
            const double* __restrict sm, const double* __restrict w, const double* __restrict wx,
            const double* __restrict wy, const double* __restrict wz, double* __restrict f,
            double* __restrict gx, double* __restrict gy, double* __restrict gz)
{
  const std::size_t d = features;
  for (std::size_t i0 = 0; i0 < n; i0 += 4)
  {
    const std::size_t m = n - i0 < 4 ? n - i0 : 4;
    const std::size_t r1 = i0 + (m > 1 ? 1 : 0), r2 = i0 + (m > 2 ? 2 : 0), r3 = i0 + (m > 3 ? 3 : 0);
    double ff[4], x[4], y[4], z[4];
    rowDots4 (phi + i0 * d, phi + r1 * d, phi + r2 * d, phi + r3 * d, w, d, ff);
    rowGradients4 (sm + i0 * d, sm + r1 * d, sm + r2 * d, sm + r3 * d, wx, wy, wz, d, x, y, z);
    for (std::size_t r = 0; r < m; ++r)
    {
      f[i0 + r] = ff[r];
      gx[i0 + r] = x[r];
      gy[i0 + r] = y[r];
      gz[i0 + r] = z[r];
    }
  }
}

PCL_PROBCOLLISION_CLONES void
rffProjectColumns (std::size_t n, std::size_t features, const double* __restrict phi,
                   const double* __restrict q, double* __restrict u)
{
  // u[:, c] = sum_i q(i, c) phi_i: per block of 8 features, the 10 columns' accumulators stay
  // in registers while the rows stream by
  constexpr std::size_t m = kProjection;
  const std::size_t d = features;
  std::size_t k = 0;
  for (; k + kLanes <= d; k += kLanes)
  {
    double a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {}, a3[kLanes] = {}, a4[kLanes] = {};
    double a5[kLanes] = {}, a6[kLanes] = {}, a7[kLanes] = {}, a8[kLanes] = {}, a9[kLanes] = {};
    for (std::size_t i = 0; i < n; ++i)
    {
      const double* __restrict row = phi + i * d + k;
      const double c0 = q[i], c1 = q[n + i], c2 = q[2 * n + i], c3 = q[3 * n + i], c4 = q[4 * n + i];
      const double c5 = q[5 * n + i], c6 = q[6 * n + i], c7 = q[7 * n + i], c8 = q[8 * n + i],
                   c9 = q[9 * n + i];
      for (std::size_t j = 0; j < kLanes; ++j)
      {
        const double r = row[j];
        a0[j] += c0 * r;
        a1[j] += c1 * r;
        a2[j] += c2 * r;
        a3[j] += c3 * r;
        a4[j] += c4 * r;
        a5[j] += c5 * r;
        a6[j] += c6 * r;
        a7[j] += c7 * r;
        a8[j] += c8 * r;
        a9[j] += c9 * r;
      }
    }
    const double* acc[m] = {a0, a1, a2, a3, a4, a5, a6, a7, a8, a9};
    for (std::size_t c = 0; c < m; ++c)
      for (std::size_t j = 0; j < kLanes; ++j)
        u[c * d + k + j] = acc[c][j];
  }
  for (; k < d; ++k)
    for (std::size_t c = 0; c < m; ++c)
    {
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i)
        sum += q[c * n + i] * phi[i * d + k];
      u[c * d + k] = sum;
    }
}

PCL_PROBCOLLISION_CLONES void
rffProjectRows (std::size_t n, std::size_t features, const double* __restrict phi,
                const double* __restrict basis, double* __restrict p)
{
  // p(i, c) = phi_i . basis[:, c], 10 accumulator chains per row
  constexpr std::size_t m = kProjection;
  const std::size_t d = features;
  const double* __restrict b0 = basis;
  const double* __restrict b1 = basis + d;
  const double* __restrict b2 = basis + 2 * d;
  const double* __restrict b3 = basis + 3 * d;
  const double* __restrict b4 = basis + 4 * d;
  const double* __restrict b5 = basis + 5 * d;
  const double* __restrict b6 = basis + 6 * d;
  const double* __restrict b7 = basis + 7 * d;
  const double* __restrict b8 = basis + 8 * d;
  const double* __restrict b9 = basis + 9 * d;
  for (std::size_t i = 0; i < n; ++i)
  {
    const double* __restrict row = phi + i * d;
    double a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {}, a3[kLanes] = {}, a4[kLanes] = {};
    double a5[kLanes] = {}, a6[kLanes] = {}, a7[kLanes] = {}, a8[kLanes] = {}, a9[kLanes] = {};
    std::size_t k = 0;
    for (; k + kLanes <= d; k += kLanes)
      for (std::size_t j = 0; j < kLanes; ++j)
      {
        const double r = row[k + j];
        a0[j] += r * b0[k + j];
        a1[j] += r * b1[k + j];
        a2[j] += r * b2[k + j];
        a3[j] += r * b3[k + j];
        a4[j] += r * b4[k + j];
        a5[j] += r * b5[k + j];
        a6[j] += r * b6[k + j];
        a7[j] += r * b7[k + j];
        a8[j] += r * b8[k + j];
        a9[j] += r * b9[k + j];
      }
    const double* acc[m] = {a0, a1, a2, a3, a4, a5, a6, a7, a8, a9};
    for (std::size_t c = 0; c < m; ++c)
    {
      double sum = laneSum (acc[c]);
      for (std::size_t kk = k; kk < d; ++kk)
        sum += row[kk] * basis[c * d + kk];
      p[c * n + i] = sum;
    }
  }
}
} // namespace detail

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
  return needsEscalation (plane.degenerate, plane.misclassified, params_.ladder_fraction,
                          plane.probabilities_a.size () + plane.probabilities_b.size ());
}

bool
RobustClassifier::classify (const PointSetView& a, const PointSetView& b, ClassifierResult& result,
                            KernelMode kernel) const
{
  result = ClassifierResult ();
  if (a.size == 0 || b.size == 0 || !a.means || !a.covariances || !b.means || !b.covariances)
  {
    if (checkSide (a, "A", result))
      checkSide (b, "B", result);
    return false;
  }

  // Uniform normalisation (METHOD.md 4): x' = (x - c) / (2 r_c) + 1/2, Sigma' = Sigma / (2 r_c)^2
  const std::size_t na = a.size, nb = b.size, n = na + nb;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero ();
  double covariance_check = 0.0;  // stays 0 unless some covariance entry is inf or NaN
  for (const PointSetView* side : {&a, &b})
    for (std::size_t i = 0; i < side->size; ++i)
    {
      centroid += side->means[i];
      covariance_check += 0.0 * side->covariances[i].sum ();
    }
  centroid /= static_cast<double> (n);
  double r2 = 0.0;
  if (centroid.allFinite () && covariance_check == 0.0)
    for (const PointSetView* side : {&a, &b})
      for (std::size_t i = 0; i < side->size; ++i)
        r2 = std::max (r2, (side->means[i] - centroid).squaredNorm ());
  const double r_c = std::sqrt (r2);
  if (!centroid.allFinite () || covariance_check != 0.0 || !std::isfinite (r_c))
  {
    // find the offending point for the message (slow path)
    if (checkSide (a, "A", result) && checkSide (b, "B", result))
      result.message = "[pcl_probcollision::RobustClassifier::classify] the coordinates overflow "
                       "double precision (centroid or radius not finite)";
    return false;
  }
  double scale = 1.0;
  if (r_c > 0.0 && std::isfinite (0.5 / r_c))
    scale = 0.5 / r_c;

  detail::SeparatorProblem p;
  p.n = static_cast<Eigen::Index> (n);
  p.n_a = static_cast<Eigen::Index> (na);
  for (Eigen::ArrayXd* array : {&p.x, &p.y, &p.z, &p.sxx, &p.sxy, &p.sxz, &p.syy, &p.syz, &p.szz, &p.label, &p.weight})
    array->resize (p.n);
  const double scale2 = scale * scale;
  Eigen::Index k = 0;
  for (const PointSetView* side : {&a, &b})
  {
    const double label = side == &a ? 1.0 : -1.0;
    // C_i = C n / (2 n_c): each cloud carries half of the total weight
    const double weight = params_.C * static_cast<double> (n) / (2.0 * static_cast<double> (side->size));
    for (std::size_t i = 0; i < side->size; ++i, ++k)
    {
      const Eigen::Vector3d x = scale * (side->means[i] - centroid);
      const Eigen::Matrix3d& s = side->covariances[i];
      p.x (k) = x.x () + 0.5;
      p.y (k) = x.y () + 0.5;
      p.z (k) = x.z () + 0.5;
      p.sxx (k) = scale2 * s (0, 0);
      p.syy (k) = scale2 * s (1, 1);
      p.szz (k) = scale2 * s (2, 2);
      p.sxy (k) = scale2 * 0.5 * (s (0, 1) + s (1, 0));
      p.sxz (k) = scale2 * 0.5 * (s (0, 2) + s (2, 0));
      p.syz (k) = scale2 * 0.5 * (s (1, 2) + s (2, 1));
      p.label (k) = label;
      p.weight (k) = weight;
    }
  }

  detail::MarginLoss loss;
  loss.huber = params_.loss == Loss::Huber;
  const double gamma = normalQuantile (params_.confidence);

  // The ladder (see the class documentation)
  RungFit best;
  int iterations = 0;
  if (kernel == KernelMode::RFF)
  {
    best = fitRff (p, params_, loss, gamma, omega_, beta_, params_.rff_features, Rung::RFF);
    iterations = best.iterations;
    result.rungs_tried = 1;
  }
  else
  {
    best = fitLinear (p, params_, loss, gamma);
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
        RungFit fit = fitRff (p, params_, loss, gamma, omega_, beta_, sizes[k], rungs[k]);
        iterations += fit.iterations;
        ++result.rungs_tried;
        escalate = needsEscalation (fit.degenerate, fit.misclassified, params_.ladder_fraction, n_points);
        if (replaces (fit, best))
          best = std::move (fit);
      }
    }
  }

  // Output (METHOD.md 6.1-6.2)
  if (!best.theta.allFinite () || !best.probability.allFinite ())
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
  result.probabilities_a.assign (best.probability.data (), best.probability.data () + na);
  result.probabilities_b.assign (best.probability.data () + na, best.probability.data () + n);
  Eigen::Index witness = -1;
  result.probability = -1.0;
  if (!params_.exact_points_in_maximum)
  {
    // The maximum over the uncertain points (see ClassifierParams::exact_points_in_maximum).
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index> (n); ++i)
    {
      const Eigen::Matrix3d& c = i < p.n_a ? a.covariances[i] : b.covariances[i - p.n_a];
      if (c.trace () > 0.0 && best.probability (i) > result.probability)
      {
        result.probability = best.probability (i);
        witness = i;
      }
    }
  }
  if (witness < 0)
    result.probability = best.probability.maxCoeff (&witness);
  if (best.degenerate)
    result.probability = 0.5;
  result.witness_side = witness < p.n_a ? 1 : -1;
  result.witness_index = static_cast<std::size_t> (witness < p.n_a ? witness : witness - p.n_a);
  const Eigen::Vector3d g = best.gradient (witness);
  if (g.norm () >= kCollapse)
  {
    // S is a uniform scale: the unit gradient is the same in the input frame, and the
    // first-order distance u = c f / |g| scales back by 1 / S
    result.witness_normal = g.normalized ();
    result.witness_distance = p.label (witness) * best.f (witness) / g.norm () / scale;
  }

  result.separator.rung = best.rung;
  result.separator.centroid = centroid;
  result.separator.scale = scale;
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
      gradient->setConstant (kNaN);
    return kNaN;
  }
  const Eigen::Vector3d xn = model.scale * (x - model.centroid) + Eigen::Vector3d::Constant (0.5);
  if (linear)
  {
    if (gradient)
      *gradient = model.scale * model.weights;
    return model.weights.dot (xn) + model.bias;
  }
  Eigen::VectorXd phi;
  Eigen::MatrixXd jacobian;
  detail::rffFeatures (omega_, beta_, static_cast<int> (size), xn, phi, gradient ? &jacobian : nullptr);
  if (gradient)
    *gradient = model.scale * (jacobian.transpose () * model.weights);
  return model.weights.dot (phi) + model.bias;
}

double
normalQuantile (double p)
{
  if (!(p >= 0.0 && p <= 1.0))
    return kNaN;
  if (p == 0.0)
    return -kInf;
  if (p == 1.0)
    return kInf;
  if (p > 0.5)
    return -normalQuantile (1.0 - p);  // 1 - p is exact for p in [0.5, 1]
  // Acklam's rational approximation (relative error 1.15e-9), lower half
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425)
  {
    const double q = std::sqrt (-2.0 * std::log (p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  else
  {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  // One Halley step on Phi(x) - p, with Phi from erfc so the lower tail keeps its precision
  const double e = normalCdf (x) - p;
  const double u = e * 2.50662827463100050242 * std::exp (0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}
} // namespace pcl_probcollision
