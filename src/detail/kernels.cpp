// SPDX-License-Identifier: BSD-3-Clause
// The hot loops of the classifier, declared in detail/kernels.h (METHOD.md 5.3, 5.5). Plain
// loops over fixed blocks of 8 or 16 so that GCC's -O2 vectoriser (very-cheap cost model: no
// epilogues) takes them, and separate accumulators per lane so that no reassociation is needed.
// Every exported kernel is compiled once per instruction set (simd_clones.h) and its helpers
// are always inlined into it, so each clone vectorises them for its own set: keep the helpers
// in this TU.
#include <pcl_probcollision/detail/kernels.h>

#include "simd_clones.h"

#include <Eigen/Core>

#include <cmath>
#include <cstddef>

namespace pcl_probcollision
{
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
} // namespace pcl_probcollision
