// SPDX-License-Identifier: BSD-3-Clause
// Per-point collision probabilities of a fitted rung (METHOD.md 6.1).
#include <pcl_probcollision/detail/point_probabilities.h>

#include <algorithm>

namespace pcl_probcollision
{
namespace detail
{
void
assessFit (const SeparatorProblem& p, double depth_sigmas, RungFit& fit)
{
  const Eigen::Index n = p.n;
  fit.z.resize (n);
  fit.misclassified = 0;
  fit.largest_spread = 0.0;
  Eigen::Index collapsed = 0;
  // Point by point: no temporary arrays (this runs for every leaf pair's fit).
  const double plane_norm = fit.isPlane () ? fit.plane_gradient.norm () : 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
  {
    const double norm = fit.isPlane () ? plane_norm : gradientNorm (fit, i);
    const double u = p.label (i) * fit.f (i) / norm;
    const double sigma = std::sqrt (quadraticForm (p, fit, i)) / norm;
    if (!(norm >= kCollapse))
    {
      fit.z (i) = 0.0;  // P_i = 0.5
      ++fit.misclassified;
      ++collapsed;
    }
    else
    {
      fit.z (i) = pointZ (u, sigma);
      fit.largest_spread = std::max (fit.largest_spread, sigma);
      fit.misclassified += sigma < kNoSpread ? u < -kNoSpread : u < -depth_sigmas * sigma;
    }
  }
  fit.degenerate = collapsed == n;
}
} // namespace detail
} // namespace pcl_probcollision
