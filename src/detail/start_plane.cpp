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
StartPlane
startPlane (const ProbabilisticBVH& a, const ProbabilisticBVH::Node& leaf_a, const ProbabilisticBVH& b,
            const ProbabilisticBVH::Node& leaf_b, const Eigen::Isometry3d& T_a_b, double C)
{
  // classify()'s start (METHOD.md 5.3), f = 1 and -1 at the class means, is the bisector of the
  // means, f(x) = 2 d . (x - mid) / |d|^2 with d = m_a - m_b, in any frame: z_i = -c_i d . (x_i -
  // mid) / sqrt(d^T Sigma_i d) needs no unit-cube map. B's points stay in B's frame (d and mid
  // are mapped there instead), and nothing is copied.
  StartPlane start;
  const auto span_a = a.indices (leaf_a);
  const auto span_b = b.indices (leaf_b);
  const std::vector<Eigen::Vector3d>& ma = a.means ();
  const std::vector<Eigen::Vector3d>& mb = b.means ();
  const std::vector<PackedCovariance>& ca = a.covariances ();
  const std::vector<PackedCovariance>& cb = b.covariances ();
  Eigen::Vector3d sum_a = Eigen::Vector3d::Zero (), sum_b = Eigen::Vector3d::Zero ();
  for (std::size_t i = 0; i < span_a.size; ++i)
    sum_a += ma[span_a[i]];
  for (std::size_t j = 0; j < span_b.size; ++j)
    sum_b += mb[span_b[j]];
  const double na = static_cast<double> (span_a.size), nb = static_cast<double> (span_b.size);
  const Eigen::Vector3d mean_a = sum_a / na;
  const Eigen::Vector3d mean_b = T_a_b * (sum_b / nb);
  const Eigen::Vector3d d = mean_a - mean_b;
  const double dd = d.squaredNorm ();
  if (!(dd > 0.0) || !std::isfinite (dd))
    return start;
  const Eigen::Vector3d mid = 0.5 * (mean_a + mean_b);
  const Eigen::Vector3d centroid = (na * mean_a + nb * mean_b) / (na + nb);
  const Eigen::Matrix3d R = T_a_b.linear ();
  const Eigen::Vector3d d_b = R.transpose () * d;
  const double offset_b = d.dot (T_a_b.translation () - mid);  // d . (T x - mid) = d_b . x + offset_b
  const Eigen::Vector3d centroid_b = R.transpose () * (centroid - T_a_b.translation ());

  // The unit-cube map's scale (0.5 / the largest distance to the centroid), the hinge losses of
  // the Standard objective at the plane (makeProblem()'s weights: C n / 2 a side) and the z_i.
  const double weight_a = C * (na + nb) / (2.0 * na), weight_b = C * (na + nb) / (2.0 * nb);
  double r2 = 0.0, loss = 0.0, largest = -std::numeric_limits<double>::infinity ();
  double least_q = std::numeric_limits<double>::infinity ();
  const double inv_dd = 1.0 / dd;
  auto point = [&] (double u, double q, double distance2, double weight) {
    r2 = std::max (r2, distance2);
    const double v = std::max (0.0, 1.0 - 2.0 * u * inv_dd);
    loss += weight * 0.5 * v * v;
    least_q = std::min (least_q, q);
    if (q > 0.0)
      largest = std::max (largest, -u / std::sqrt (q));
  };
  for (std::size_t i = 0; i < span_a.size; ++i)
  {
    const Eigen::Vector3d& x = ma[span_a[i]];
    point (d.dot (x - mid), ca[span_a[i]].quadratic (d), (x - centroid).squaredNorm (), weight_a);
  }
  for (std::size_t j = 0; j < span_b.size; ++j)
  {
    const Eigen::Vector3d& x = mb[span_b[j]];
    point (-(d_b.dot (x) + offset_b), cb[span_b[j]].quadratic (d_b), (x - centroid_b).squaredNorm (), weight_b);
  }
  start.z = largest;
  // In unit-cube coordinates (scale s) the plane's |w|^2 is 4 / (s^2 |d|^2) and its bias
  // -(2 / |d|^2) d . (mid - centroid) - d . (1, 1, 1) / (s |d|^2); classify() starts from theta = 0
  // instead when the Standard objective there (C n / 2) is lower. The smallest spread along the
  // plane's normal, sqrt(q) / |d| s, must also lie far above kNoSpread.
  const double r = std::sqrt (r2);
  const double s = r > 0.0 && std::isfinite (0.5 / r) ? 0.5 / r : 1.0;
  const double w2 = 4.0 * inv_dd / (s * s);
  const double bias = -2.0 * inv_dd * d.dot (mid - centroid) - d.sum () * inv_dd / s;
  const double objective = 0.5 * w2 + 0.5 * kBiasRidge * bias * bias + loss;
  const double objective_zero = 0.5 * C * (na + nb);
  // A point without spread (sigma_i under 1e-9 in unit-cube units), or a plane near collapse:
  // classify() decides.
  start.usable = std::isfinite (objective) && objective < objective_zero * (1.0 - kStartSlack) && w2 > 1e-12 &&
                 s * std::sqrt (least_q * inv_dd) > 1e-9;
  return start;
}

bool
passesOver (const StartPlane& start, double skip_at_or_below)
{
  if (!start.usable || !(skip_at_or_below >= 0.0))
    return false;
  const double p0 = normalCdf (start.z + kStartSlack * std::max (1.0, std::abs (start.z)));
  return p0 < 0.5 && p0 <= skip_at_or_below;
}
} // namespace detail
} // namespace pcl_probcollision
