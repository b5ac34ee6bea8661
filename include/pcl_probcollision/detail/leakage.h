// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/detail/obb.h>
#include <pcl_probcollision/normal_distribution.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace pcl_probcollision
{
namespace detail
{
/** \brief |z| beyond which a tail term Phi(-|z|) (< 7.7e-24) is taken as 0 to save an erfc. */
constexpr double kNegligibleTailZ = 10.0;

/** \brief Phi(-z), the upper normal tail, by cubic Hermite interpolation of a table of
  * Phi(-z) and its derivative -phi(z) on [0, kNegligibleTailZ] with step 1/128 (20 KB, built
  * when the library loads); 0 beyond kNegligibleTailZ and 1 - Phi(z) below 0. Absolute error below
  * 1e-11 (the Hermite bound h^4 / 384 max |d^4 Phi / dz^4| = 5e-12), a fraction of the time
  * of erfc: the hierarchy build evaluates it for the points of every node (METHOD.md 8.4). For
  * relative accuracy in the far tail use normalCdf. */
double normalTailTabulated (double z);

/** \brief Probability that a Gaussian scalar falls outside the slab [lo, hi] (METHOD.md 8.4):
  * Phi((lo - m) / s) + Phi(-(hi - m) / s), i.e. 1 - P_slab, computed from the two tails so that
  * small values keep their relative precision.
  * \param[in] lo lower face (metres)
  * \param[in] hi upper face (metres), hi >= lo
  * \param[in] m mean of the projection a^T mu (metres)
  * \param[in] s standard deviation sqrt(a^T Sigma a) (metres); 0 gives the indicator of
  *            m outside [lo, hi] */
inline double
slabOutsideProbability (double lo, double hi, double m, double s)
{
  if (!(s > 0.0))
    return (m >= lo && m <= hi) ? 0.0 : 1.0;
  const double z_lo = (lo - m) / s;  // below the lower face: Phi(z_lo)
  const double z_hi = (hi - m) / s;  // above the upper face: Phi(-z_hi)
  const double below = (z_lo < -kNegligibleTailZ) ? 0.0 : normalCdf (z_lo);
  const double above = (z_hi > kNegligibleTailZ) ? 0.0 : normalCdf (-z_hi);
  return std::min (1.0, below + above);
}

/** \brief How the three slab probabilities of a box combine into P_x (METHOD.md 8.4). */
enum class LeakageBound
{
  MinSlab,    ///< P_x = 1 - min_a P_slab(a): a lower bound on the outside probability (default)
  UnionBound  ///< P_x = min(1, sum_a (1 - P_slab(a))): an upper bound
};

/** \brief Combines the three per-axis outside probabilities 1 - P_slab(a) into P_x. */
inline double
combineSlabs (double out0, double out1, double out2, LeakageBound bound)
{
  if (bound == LeakageBound::UnionBound)
    return std::min (1.0, out0 + out1 + out2);
  return std::max (out0, std::max (out1, out2));
}

/** \brief Probability that a point x ~ N(mean, covariance) lies outside box (METHOD.md 8.4).
  * \param[in] box the box, in the same frame as the point
  * \param[in] mean point mean (metres)
  * \param[in] covariance point covariance (square metres)
  * \param[in] bound MinSlab (default, lower bound) or UnionBound (upper bound)
  * \return P_x in [0, 1] */
inline double
pointOutsideProbability (const OrientedBox& box, const Eigen::Vector3d& mean,
                         const Eigen::Matrix3d& covariance,
                         LeakageBound bound = LeakageBound::MinSlab)
{
  double out[3];
  const Eigen::Vector3d d = mean - box.center;
  const Eigen::Matrix3d axes = box.axes ();
  for (int k = 0; k < 3; ++k)
  {
    const Eigen::Vector3d a = axes.col (k);
    const double s = std::sqrt (std::max (0.0, a.dot (covariance * a)));
    const double h = static_cast<double> (box.half_extents (k));
    out[k] = slabOutsideProbability (-h, h, a.dot (d), s);
  }
  return combineSlabs (out[0], out[1], out[2], bound);
}
} // namespace detail
} // namespace pcl_probcollision
