// SPDX-License-Identifier: BSD-3-Clause
// The per-point passes of a hierarchy node's build, declared in detail/node_kernels.h, and the
// tabulated normal tail they use. GCC vectorises them (gathering the points' means and
// covariances by index, and the tails' table entries) when: the projections run in blocks of
// kLanes points with a lane each for the running minima and maxima (exact in any order); the
// arrays written are __restrict parameters of the exported function, whose loops are its own
// (restrict on locals or on inlined helpers does not rule out the aliasing of a gather); and no
// loop holds another. This file is compiled without FMA contraction (CMakeLists.txt), and every
// sum keeps the order of the scalar code before it, so each clone (simd_clones.h) computes the
// same bits: a hierarchy is the same on any x86-64 machine.
#include <pcl_probcollision/detail/node_kernels.h>

#include "simd_clones.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
constexpr std::size_t kLanes = 8;

// The table of normalTailTabulated: Phi(-z_i) and the step times its derivative at z_i = i /
// 128 on [0, kNegligibleTailZ], one zero entry past the end; built at load time, so the lookup
// needs no guard.
constexpr int kTailSteps = 128 * static_cast<int> (kNegligibleTailZ);
constexpr double kTailStep = kNegligibleTailZ / kTailSteps;
struct TailTable
{
  double f[kTailSteps + 2];
  double df[kTailSteps + 2];
  TailTable ()
  {
    for (int i = 0; i <= kTailSteps; ++i)
    {
      const double zi = i * kTailStep;
      f[i] = normalCdf (-zi);
      df[i] = -kTailStep * 0.39894228040143267794 * std::exp (-0.5 * zi * zi);
    }
    f[kTailSteps + 1] = df[kTailSteps + 1] = 0.0;
  }
};
const TailTable kTailTable;

/** \brief normalTailTabulated for z >= 0 (not NaN; +inf reads the last node) on the table f,
  * df (kTailTable's, as restrict pointers so that loops vectorise the lookups): cubic Hermite,
  * without a branch (z beyond the table reads its last node, Phi(-10) = 7.6e-24). */
PCL_PROBCOLLISION_ALWAYS_INLINE double
tail (double z, const double* __restrict f, const double* __restrict df)
{
  const double x = std::min (z * (1.0 / kTailStep), static_cast<double> (kTailSteps));
  const int i = static_cast<int> (x);
  const double t = x - i, t2 = t * t, t3 = t2 * t;
  return (2.0 * t3 - 3.0 * t2 + 1.0) * f[i] + (t3 - 2.0 * t2 + t) * df[i] + (3.0 * t2 - 2.0 * t3) * f[i + 1] +
         (t3 - t2) * df[i + 1];
}

/** \brief Per-lane running extremes of nodeProjections(). */
struct Extremes
{
  double lo[3][kLanes], hi[3][kLanes], s_max[3][kLanes], q_min[3][kLanes], q_max[3][kLanes];
};

/** \brief Axis k of point i of nodeProjections(), into lane j. The sums are those of the scalar
  * code before it, term by term and in its order: Eigen 3.4's 3 x 3 product axes^T (x - mean)
  * (rows 0 and 1 as packet multiply-adds, row 2 as a tree reduction) and
  * PackedCovariance::quadratic(). Unrolled by hand (k a template argument): GCC vectorises no
  * loop that holds another. */
template <int k>
PCL_PROBCOLLISION_ALWAYS_INLINE void
projectAxis (std::size_t i, double d0, double d1, double d2, const PackedCovariance& cov, const double (*a)[3],
             const double (*c)[6], double k_sigma, double* q_out, double* s_out, Extremes& e, std::size_t j)
{
  const double q = k < 2 ? (a[k][0] * d0 + a[k][1] * d1) + a[k][2] * d2 : a[k][0] * d0 + (a[k][1] * d1 + a[k][2] * d2);
  const double var = c[k][0] * double (cov.xx) + c[k][1] * double (cov.yy) + c[k][2] * double (cov.zz) +
                     2.0 * (c[k][3] * double (cov.xy) + c[k][4] * double (cov.xz) + c[k][5] * double (cov.yz));
  const double sd = std::sqrt (std::max (0.0, var));
  q_out[i] = q;
  s_out[i] = sd;
  e.lo[k][j] = std::min (e.lo[k][j], q - k_sigma * sd);
  e.hi[k][j] = std::max (e.hi[k][j], q + k_sigma * sd);
  e.s_max[k][j] = std::max (e.s_max[k][j], sd);
  e.q_min[k][j] = std::min (e.q_min[k][j], q);
  e.q_max[k][j] = std::max (e.q_max[k][j], q);
}

/** \brief Point i of nodeProjections() into lane j. */
PCL_PROBCOLLISION_ALWAYS_INLINE void
projectPoint (std::size_t i, const int* __restrict points, const double* __restrict means,
              const PackedCovariance* __restrict covariances, const double* mean, const double (*a)[3],
              const double (*c)[6], double k_sigma, double* q0, double* q1, double* q2, double* s0, double* s1,
              double* s2, Extremes& e, std::size_t j)
{
  const std::size_t p = static_cast<std::size_t> (points[i]);
  const PackedCovariance& cov = covariances[p];
  const double d0 = means[3 * p] - mean[0], d1 = means[3 * p + 1] - mean[1], d2 = means[3 * p + 2] - mean[2];
  projectAxis<0> (i, d0, d1, d2, cov, a, c, k_sigma, q0, s0, e, j);
  projectAxis<1> (i, d0, d1, d2, cov, a, c, k_sigma, q1, s1, e, j);
  projectAxis<2> (i, d0, d1, d2, cov, a, c, k_sigma, q2, s2, e, j);
}

/** \brief The distances of a point with projection q and deviation s to the faces lo and hi of
  * its axis in its deviations (+inf for s = 0: outside probability 0 on that axis). */
PCL_PROBCOLLISION_ALWAYS_INLINE void
faceDistances (double q, double s, double lo, double hi, double& z_lo, double& z_hi)
{
  constexpr double inf = std::numeric_limits<double>::infinity ();
  const double inv = 1.0 / s;
  const double below = std::max (0.0, q - lo) * inv, above = std::max (0.0, hi - q) * inv;
  z_lo = s > 0.0 ? below : inf;
  z_hi = s > 0.0 ? above : inf;
}

/** \brief An axis's outside probability, or 0 where the bound leaves it out (nodeOutside()):
  * MinSlab an axis that cannot attain the maximum, UnionBound one without deviation (d = +inf;
  * d is never NaN, faceDistances() sees to that). */
template <bool min_slab>
PCL_PROBCOLLISION_ALWAYS_INLINE double
axisOutside (double z_lo, double z_hi, double d_min, const double* __restrict f, const double* __restrict df)
{
  const double d = std::min (z_lo, z_hi);
  const double both = std::min (1.0, tail (z_lo, f, df) + tail (z_hi, f, df));
  if (min_slab)
    return d >= d_min + 1.0 ? 0.0 : both;
  return d <= std::numeric_limits<double>::max () ? both : 0.0;
}

/** \brief P_x of a point from its projections and deviations on the three axes (nodeOutside()). */
template <bool min_slab>
PCL_PROBCOLLISION_ALWAYS_INLINE double
pointOutside (double q0, double q1, double q2, double s0, double s1, double s2, const double* lo, const double* hi,
              const double* __restrict f, const double* __restrict df)
{
  double l0, h0, l1, h1, l2, h2;
  faceDistances (q0, s0, lo[0], hi[0], l0, h0);
  faceDistances (q1, s1, lo[1], hi[1], l1, h1);
  faceDistances (q2, s2, lo[2], hi[2], l2, h2);
  const double d_min =
      std::min (std::min (std::min (std::numeric_limits<double>::infinity (), std::min (l0, h0)), std::min (l1, h1)),
                std::min (l2, h2));
  const double o0 = axisOutside<min_slab> (l0, h0, d_min, f, df);
  const double o1 = axisOutside<min_slab> (l1, h1, d_min, f, df);
  const double o2 = axisOutside<min_slab> (l2, h2, d_min, f, df);
  return combineSlabs (o0, o1, o2, min_slab ? LeakageBound::MinSlab : LeakageBound::UnionBound);
}
} // namespace

double
normalTailTabulated (double z)
{
  if (!(z >= 0.0))
    return z < 0.0 ? 1.0 - normalTailTabulated (-z) : z;  // NaN stays NaN
  return z < kNegligibleTailZ ? tail (z, kTailTable.f, kTailTable.df) : 0.0;
}

PCL_PROBCOLLISION_CLONES void
nodeProjections (std::size_t m, const int* __restrict points, const double* __restrict means,
                 const PackedCovariance* __restrict covariances, const Eigen::Vector3d& mean,
                 const Eigen::Matrix3d& axes, double k_sigma, double* __restrict q0, double* __restrict q1,
                 double* __restrict q2, double* __restrict s0, double* __restrict s1, double* __restrict s2,
                 NodeExtents& out)
{
  constexpr double inf = std::numeric_limits<double>::infinity ();
  // a[k] = row k of axes^T; c[k] the products of axis k's components in quadratic()'s order
  double a[3][3], c[3][6];
  for (int k = 0; k < 3; ++k)
  {
    const double x = axes (0, k), y = axes (1, k), z = axes (2, k);
    a[k][0] = x;
    a[k][1] = y;
    a[k][2] = z;
    c[k][0] = x * x;
    c[k][1] = y * y;
    c[k][2] = z * z;
    c[k][3] = x * y;
    c[k][4] = x * z;
    c[k][5] = y * z;
  }
  const double mu[3] = {mean.x (), mean.y (), mean.z ()};
  Extremes e;
  for (int k = 0; k < 3; ++k)
    for (std::size_t j = 0; j < kLanes; ++j)
    {
      e.lo[k][j] = e.q_min[k][j] = inf;
      e.hi[k][j] = e.q_max[k][j] = -inf;
      e.s_max[k][j] = 0.0;
    }
  std::size_t i = 0;
  for (; i + kLanes <= m; i += kLanes)
    for (std::size_t j = 0; j < kLanes; ++j)
      projectPoint (i + j, points, means, covariances, mu, a, c, k_sigma, q0, q1, q2, s0, s1, s2, e, j);
  for (; i < m; ++i)
    projectPoint (i, points, means, covariances, mu, a, c, k_sigma, q0, q1, q2, s0, s1, s2, e, 0);
  for (int k = 0; k < 3; ++k)
  {
    out.lo[k] = out.q_min[k] = inf;
    out.hi[k] = out.q_max[k] = -inf;
    out.s_max[k] = 0.0;
    for (std::size_t j = 0; j < kLanes; ++j)
    {
      out.lo[k] = std::min (out.lo[k], e.lo[k][j]);
      out.hi[k] = std::max (out.hi[k], e.hi[k][j]);
      out.s_max[k] = std::max (out.s_max[k], e.s_max[k][j]);
      out.q_min[k] = std::min (out.q_min[k], e.q_min[k][j]);
      out.q_max[k] = std::max (out.q_max[k], e.q_max[k][j]);
    }
  }
}

PCL_PROBCOLLISION_CLONES void
nodeOutside (std::size_t m, const double* __restrict q0, const double* __restrict q1, const double* __restrict q2,
             const double* __restrict s0, const double* __restrict s1, const double* __restrict s2, const double* lo,
             const double* hi, LeakageBound bound, double* __restrict out)
{
  const double* __restrict f = kTailTable.f;
  const double* __restrict df = kTailTable.df;
  const double l[3] = {lo[0], lo[1], lo[2]}, h[3] = {hi[0], hi[1], hi[2]};
  if (bound == LeakageBound::MinSlab)
    for (std::size_t i = 0; i < m; ++i)
      out[i] = pointOutside<true> (q0[i], q1[i], q2[i], s0[i], s1[i], s2[i], l, h, f, df);
  else
    for (std::size_t i = 0; i < m; ++i)
      out[i] = pointOutside<false> (q0[i], q1[i], q2[i], s0[i], s1[i], s2[i], l, h, f, df);
}
} // namespace detail
} // namespace pcl_probcollision
