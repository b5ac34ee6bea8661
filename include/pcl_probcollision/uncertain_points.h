// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace pcl_probcollision
{
/** \brief Points with uncertainty: one Gaussian per point (mean = the measured position,
  * covariance = discretisation + sensor noise), the currency of the classifier and the hierarchy.
  *
  * Structure of arrays, index-aligned. Units are the data's (metres for PCL scans); covariances
  * are in units squared. Means and covariances are double: the classifier and the leakage sums
  * accumulate many small terms. See METHOD.md section 3.
  */
struct UncertainCloud
{
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> covariances;
  /** \brief Surface area each point stands for, up to a common factor: r_k^2 with r_k the
    * distance to the k-th neighbour (METHOD.md 8.4). Empty means equal weights. */
  std::vector<double> area_weights;
  /** \brief Index of each point in the caller's input cloud (finite points only are kept). */
  std::vector<int> source_indices;

  std::size_t size () const { return means.size (); }
  bool empty () const { return means.empty (); }
};

/** \brief A non-owning view of n points with covariances, as the classifier consumes them. */
struct PointSetView
{
  const Eigen::Vector3d* means = nullptr;
  const Eigen::Matrix3d* covariances = nullptr;
  std::size_t size = 0;

  PointSetView () = default;
  PointSetView (const Eigen::Vector3d* m, const Eigen::Matrix3d* c, std::size_t n)
    : means (m), covariances (c), size (n) {}
  PointSetView (const std::vector<Eigen::Vector3d>& m, const std::vector<Eigen::Matrix3d>& c)
    : means (m.data ()), covariances (c.data ()), size (m.size () < c.size () ? m.size () : c.size ()) {}
  explicit PointSetView (const UncertainCloud& cloud)
    : PointSetView (cloud.means, cloud.covariances) {}
};
} // namespace pcl_probcollision
