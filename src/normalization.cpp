// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/normalization.h>

#include <algorithm>
#include <limits>

namespace pcl_probcollision
{
UnitCubeTransform
computeUnitCubeTransform (const std::vector<const UncertainCloud*>& sets, Scaling scaling)
{
  UnitCubeTransform t;
  std::size_t n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero ();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ());
  Eigen::Vector3d hi = -lo;
  for (const UncertainCloud* set : sets)
    for (const Eigen::Vector3d& x : set->means)
      if (x.allFinite ())
      {
        ++n;
        sum += x;
        lo = lo.cwiseMin (x);
        hi = hi.cwiseMax (x);
      }
  if (n == 0)
    return t;

  if (scaling == Scaling::PerAxis)
  {
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
  // unlike a bounding box.
  const Eigen::Vector3d centroid = sum / static_cast<double> (n);
  double radius = 0.0;
  for (const UncertainCloud* set : sets)
    for (const Eigen::Vector3d& x : set->means)
      if (x.allFinite ())
        radius = std::max (radius, (x - centroid).norm ());
  t.shift = centroid;
  t.offset = Eigen::Vector3d::Constant (0.5);
  if (radius > 0.0)
    t.scale = Eigen::Vector3d::Constant (1.0 / (2.0 * radius));
  return t;
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
