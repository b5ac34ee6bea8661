// SPDX-License-Identifier: BSD-3-Clause
// Per-point collision probabilities of a fitted rung (METHOD.md 6.1).
#include <pcl_probcollision/detail/point_probabilities.h>

#include <pcl_probcollision/normal_distribution.h>

namespace pcl_probcollision
{
namespace detail
{
Eigen::ArrayXd
quadraticForms (const SeparatorProblem& p, const RungFit& fit)
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

Eigen::ArrayXd
gradientNorms (const RungFit& fit, Eigen::Index n)
{
  if (fit.isPlane ())
    return Eigen::ArrayXd::Constant (n, fit.plane_gradient.norm ());
  return (fit.gx.square () + fit.gy.square () + fit.gz.square ()).sqrt ();
}

void
assessFit (const SeparatorProblem& p, double depth_sigmas, RungFit& fit)
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
} // namespace detail
} // namespace pcl_probcollision
