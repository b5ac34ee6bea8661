// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace pcl_probcollision
{
/** \brief Standard normal CDF, Phi(z) = erfc(-z / sqrt 2) / 2, accurate in both tails. */
inline double
normalCdf (double z)
{
  return 0.5 * std::erfc (-z * 0.70710678118654752440);
}

/** \brief Inverse of normalCdf for p in (0, 1): Acklam's rational approximation refined by one
  * Halley step on erfc (relative error ~1e-15). Returns -inf at 0, +inf at 1, NaN outside. */
double normalQuantile (double p);

namespace detail
{
/** \brief Uniform double in [0, 1) from the top 53 bits of a 64-bit draw: the same sequence
  * with every standard library (std::uniform_real_distribution is implementation-defined). */
inline double
uniformUnit (std::mt19937_64& rng)
{
  return static_cast<double> (rng () >> 11) * 0x1.0p-53;
}

/** \brief Standard normal draw by Box-Muller on two uniformUnit draws (the cosine branch):
  * portable for the same reason. */
inline double
standardNormal (std::mt19937_64& rng)
{
  const double u1 = 1.0 - uniformUnit (rng);  // (0, 1]: the logarithm is finite
  const double u2 = uniformUnit (rng);
  return std::sqrt (-2.0 * std::log (u1)) * std::cos (6.283185307179586476925 * u2);
}
} // namespace detail
} // namespace pcl_probcollision
