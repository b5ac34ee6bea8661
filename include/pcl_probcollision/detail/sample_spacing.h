// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief How many finite points the median nearest-neighbour spacing looks at, at most. */
constexpr std::size_t kSpacingQueries = 20000;

/** \brief The median nearest-neighbour spacing of a cloud: the rule io::medianSpacing() and
  * CloudModel::medianNeighbourSpacing() share, so that both give the same number.
  *
  * Over the finite points in cloud order, every stride-th (stride = ceil(finite / max_queries),
  * so at most max_queries of them), the median of each one's distance to the nearest other
  * point at a positive distance (coincident points are no spacing).
  * \param[in] finite number of finite points
  * \param[in] max_queries at most this many points are looked at (>= 1)
  * \param[in] nearest nearest(i) for the i-th finite point: that distance; 0 when the point has
  *            none (it is then left out); NaN when it is not known (the result is then NaN)
  * \return the median; 0 with fewer than two finite points or none with a positive distance;
  *         NaN when nearest() did not know one. */
template <typename Nearest>
double
medianNearestSpacing (std::size_t finite, std::size_t max_queries, Nearest&& nearest)
{
  if (finite < 2)
    return 0.0;
  const std::size_t stride = std::max<std::size_t> (1, (finite + max_queries - 1) / std::max<std::size_t> (max_queries, 1));
  std::vector<double> d;
  d.reserve (finite / stride + 1);
  for (std::size_t i = 0; i < finite; i += stride)
  {
    const double v = nearest (i);
    if (std::isnan (v))
      return std::numeric_limits<double>::quiet_NaN ();
    if (v > 0.0)
      d.push_back (v);
  }
  if (d.empty ())
    return 0.0;
  std::nth_element (d.begin (), d.begin () + static_cast<std::ptrdiff_t> (d.size () / 2), d.end ());
  return d[d.size () / 2];
}
} // namespace detail
} // namespace pcl_probcollision
