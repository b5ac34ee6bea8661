// SPDX-License-Identifier: BSD-3-Clause
// The start plane of a leaf pair, assessed from the hierarchies' own arrays (detail/start_plane.h).
#include <pcl_probcollision/detail/start_plane.h>

#include <pcl_probcollision/detail/separator_problem.h>
#include <pcl_probcollision/normal_distribution.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
namespace
{
/** \brief classify()'s start (METHOD.md 5.3), f = 1 and -1 at the class means, is the bisector of
  * the means, f(x) = 2 d . (x - mid) / |d|^2 with d = m_a - m_b, in any frame. B's points stay in
  * B's frame: d and mid are mapped there instead, and nothing is copied. */
struct Bisector
{
  ProbabilisticBVH::IndexSpan span_a, span_b;
  double na = 0.0, nb = 0.0;
  Eigen::Vector3d d, mid, centroid;  ///< in A's frame
  Eigen::Vector3d d_b;               ///< d in B's frame
  double offset_b = 0.0;             ///< d . (T x - mid) = d_b . x + offset_b for x in B's frame
  double dd = 0.0;                   ///< |d|^2; not positive (or not finite) when the means coincide

  Bisector (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
            const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b)
    : span_a (a.indices (leaf_a)), span_b (b.indices (leaf_b))
  {
    Eigen::Vector3d sum_a = Eigen::Vector3d::Zero (), sum_b = Eigen::Vector3d::Zero ();
    for (std::size_t i = 0; i < span_a.size; ++i)
      sum_a += a.means ()[span_a[i]];
    for (std::size_t j = 0; j < span_b.size; ++j)
      sum_b += b.means ()[span_b[j]];
    na = static_cast<double> (span_a.size);
    nb = static_cast<double> (span_b.size);
    const Eigen::Vector3d mean_a = sum_a / na;
    const Eigen::Vector3d mean_b = T_a_b * (sum_b / nb);
    d = mean_a - mean_b;
    dd = d.squaredNorm ();
    mid = 0.5 * (mean_a + mean_b);
    centroid = (na * mean_a + nb * mean_b) / (na + nb);
    d_b = T_a_b.linear ().transpose () * d;
    offset_b = d.dot (T_a_b.translation () - mid);
  }
  bool usable () const { return dd > 0.0 && std::isfinite (dd); }
};
} // namespace

double
startPlaneZ (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
             const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b)
{
  const Bisector p (a, leaf_a, b, leaf_b, T_a_b);
  if (!p.usable ())
    return std::numeric_limits<double>::infinity ();
  // z_i = -c_i d . (x_i - mid) / sqrt(d^T Sigma_i d): no unit-cube map needed. A point without
  // spread counts only through startPlaneUsable().
  double largest = -std::numeric_limits<double>::infinity ();
  const auto take = [&] (double u, double q) {
    if (q > 0.0)
      largest = std::max (largest, -u / std::sqrt (q));
  };
  for (std::size_t i = 0; i < p.span_a.size; ++i)
    take (p.d.dot (a.means ()[p.span_a[i]] - p.mid), a.covariances ()[p.span_a[i]].quadratic (p.d));
  for (std::size_t j = 0; j < p.span_b.size; ++j)
    take (-(p.d_b.dot (b.means ()[p.span_b[j]]) + p.offset_b), b.covariances ()[p.span_b[j]].quadratic (p.d_b));
  return largest;
}

bool
startPlaneUsable (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
                  const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C)
{
  const Bisector p (a, leaf_a, b, leaf_b, T_a_b);
  if (!p.usable ())
    return false;
  // The unit-cube map's scale (0.5 / the largest distance to the centroid), the hinge losses of
  // the Standard objective at the plane (makeProblem()'s weights: C n / 2 a side) and the
  // smallest spread along the plane's normal.
  const Eigen::Vector3d centroid_b = T_a_b.linear ().transpose () * (p.centroid - T_a_b.translation ());
  const double weight_a = C * (p.na + p.nb) / (2.0 * p.na), weight_b = C * (p.na + p.nb) / (2.0 * p.nb);
  const double inv_dd = 1.0 / p.dd;
  double r2 = 0.0, loss = 0.0, least_q = std::numeric_limits<double>::infinity ();
  const auto point = [&] (double u, double q, double distance2, double weight) {
    r2 = std::max (r2, distance2);
    const double v = std::max (0.0, 1.0 - 2.0 * u * inv_dd);
    loss += weight * 0.5 * v * v;
    least_q = std::min (least_q, q);
  };
  for (std::size_t i = 0; i < p.span_a.size; ++i)
  {
    const Eigen::Vector3d& x = a.means ()[p.span_a[i]];
    point (p.d.dot (x - p.mid), a.covariances ()[p.span_a[i]].quadratic (p.d), (x - p.centroid).squaredNorm (), weight_a);
  }
  for (std::size_t j = 0; j < p.span_b.size; ++j)
  {
    const Eigen::Vector3d& x = b.means ()[p.span_b[j]];
    point (-(p.d_b.dot (x) + p.offset_b), b.covariances ()[p.span_b[j]].quadratic (p.d_b), (x - centroid_b).squaredNorm (),
           weight_b);
  }
  // In unit-cube coordinates (scale s) the plane's |w|^2 is 4 / (s^2 |d|^2) and its bias
  // -(2 / |d|^2) d . (mid - centroid) - d . (1, 1, 1) / (s |d|^2); classify() starts from theta = 0
  // instead when the Standard objective there (C n / 2) is lower. A point without spread (sigma_i
  // under 1e-9 in unit-cube units) or a plane near collapse: classify() decides.
  const double r = std::sqrt (r2);
  const double s = r > 0.0 && std::isfinite (0.5 / r) ? 0.5 / r : 1.0;
  const double w2 = 4.0 * inv_dd / (s * s);
  const double bias = -2.0 * inv_dd * p.d.dot (p.mid - p.centroid) - p.d.sum () * inv_dd / s;
  const double objective = 0.5 * w2 + 0.5 * kBiasRidge * bias * bias + loss;
  const double objective_zero = 0.5 * C * (p.na + p.nb);
  return std::isfinite (objective) && objective < objective_zero * (1.0 - kStartSlack) && w2 > 1e-12 &&
         s * std::sqrt (least_q * inv_dd) > 1e-9;
}

bool
mayPassOver (double z, double skip_at_or_below)
{
  if (!(skip_at_or_below >= 0.0) || std::isnan (z))
    return false;
  const double p0 = normalCdf (z + kStartSlack * std::max (1.0, std::abs (z)));
  return p0 < 0.5 && p0 <= skip_at_or_below;
}

bool
passesOver (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
            const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C, double z,
            double skip_at_or_below)
{
  return mayPassOver (z, skip_at_or_below) && startPlaneUsable (a, leaf_a, b, leaf_b, T_a_b, C);
}
} // namespace detail
} // namespace pcl_probcollision
