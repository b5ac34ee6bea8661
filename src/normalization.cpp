// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/normalization.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_probcollision
{
namespace
{
/** \brief The means of one point set. */
struct Means
{
  const Eigen::Vector3d* data;
  std::size_t size;
};

/** \brief Calls visit (x) for the means x of all sets, in order; the finite ones only when
  * finite_only (a template argument: -O2 does not unswitch loops). */
template <bool finite_only, typename Sets, typename MeansOf, typename Visit>
void
forEachMean (const Sets& sets, MeansOf means_of, Visit visit)
{
  for (const auto& set : sets)
  {
    const Means means = means_of (set);
    for (std::size_t i = 0; i < means.size; ++i)
      if (!finite_only || means.data[i].allFinite ())
        visit (means.data[i]);
  }
}

/** \brief computeUnitCubeTransform() over any list of sets; means_of (set) gives its Means. */
template <typename Sets, typename MeansOf>
UnitCubeTransform
unitCubeTransform (const Sets& sets, MeansOf means_of, Scaling scaling)
{
  // The plain sum of all means is finite exactly when every mean is finite and nothing
  // overflows: the means are tested one by one only when it is not (the classifier's inputs
  // are finite, and this runs once per leaf pair).
  std::size_t n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero ();
  forEachMean<false> (sets, means_of, [&] (const Eigen::Vector3d& x) {
    ++n;
    sum += x;
  });
  const bool all_finite = sum.allFinite ();
  if (!all_finite)
  {
    n = 0;
    sum.setZero ();
    forEachMean<true> (sets, means_of, [&] (const Eigen::Vector3d& x) {
      ++n;
      sum += x;
    });
  }
  UnitCubeTransform t;
  if (n == 0)
    return t;

  if (scaling == Scaling::PerAxis)
  {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ());
    Eigen::Vector3d hi = -lo;
    forEachMean<true> (sets, means_of, [&] (const Eigen::Vector3d& x) {
      lo = lo.cwiseMin (x);
      hi = hi.cwiseMax (x);
    });
    Eigen::Vector3d extent = hi - lo;
    const double largest = extent.maxCoeff ();
    if (largest > 0.0)
    {
      extent = extent.cwiseMax (1e-9 * largest);
      t.scale = extent.cwiseInverse ();
    }
    t.shift = lo;
    return t;
  }

  // Uniform: centre on the centroid; the radius and centroid do not change under rigid motion,
  // unlike a bounding box. The largest squared distance has one square root (sqrt is monotonic,
  // so this is the largest distance to the last bit).
  const Eigen::Vector3d centroid = sum / static_cast<double> (n);
  double r2 = 0.0;
  const auto farthest = [&] (const Eigen::Vector3d& x) {
    r2 = std::max (r2, (x - centroid).squaredNorm ());
  };
  if (centroid.allFinite ())  // else the sum overflowed: the map is not finite in any case
  {
    if (all_finite)
      forEachMean<false> (sets, means_of, farthest);
    else
      forEachMean<true> (sets, means_of, farthest);
  }
  const double radius = std::sqrt (r2);
  double scale = 1.0;
  if (!std::isfinite (radius))
    scale = std::numeric_limits<double>::quiet_NaN ();  // the distances overflow
  else if (radius > 0.0 && std::isfinite (0.5 / radius))
    scale = 0.5 / radius;
  return uniformUnitCubeTransform (centroid, scale);
}
} // namespace

UnitCubeTransform
computeUnitCubeTransform (const std::vector<const UncertainCloud*>& sets, Scaling scaling)
{
  return unitCubeTransform (
      sets, [] (const UncertainCloud* c) { return Means{c->means.data (), c->means.size ()}; }, scaling);
}

UnitCubeTransform
computeUnitCubeTransform (std::initializer_list<PointSetView> sets, Scaling scaling)
{
  return unitCubeTransform (
      sets, [] (const PointSetView& v) { return Means{v.means, v.means ? v.size : 0}; }, scaling);
}

void
applyUnitCubeTransform (const UnitCubeTransform& transform, UncertainCloud& cloud)
{
  for (Eigen::Vector3d& x : cloud.means)
    x = transform.apply (x);
  for (Eigen::Matrix3d& c : cloud.covariances)
    c = transform.applyToCovariance (c);
}
} // namespace pcl_probcollision
