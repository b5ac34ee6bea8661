// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>

#include <cmath>
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
  /** \brief Mean of each point's Gaussian (data units). */
  std::vector<Eigen::Vector3d> means;
  /** \brief Covariance of each point, index-aligned with means (units squared). */
  std::vector<Eigen::Matrix3d> covariances;
  /** \brief Surface area each point stands for, up to a common factor: r_k^2 with r_k the
    * distance to the k-th neighbour (METHOD.md 8.4). Empty means equal weights. */
  std::vector<double> area_weights;
  /** \brief Index of each point in the caller's input cloud (finite points only are kept). */
  std::vector<int> source_indices;

  /** \brief Number of points (of means). */
  std::size_t size () const { return means.size (); }
  /** \brief True when there is no point (no mean). */
  bool empty () const { return means.empty (); }
};

/** \brief A symmetric 3 x 3 covariance stored by its six distinct entries in single precision:
  * 24 bytes instead of the 72 of an Eigen::Matrix3d, for the copy a hierarchy keeps of every
  * point. Single precision loses nothing for covariances the library estimates, which PCL's
  * Covariance point type already holds as float; a caller's double covariance is rounded to
  * the nearest float (relative error at most 2^-24), far below any covariance's own
  * uncertainty. Arithmetic on the entries is in double. */
struct PackedCovariance
{
  /** \var xx
    * \brief Variance along x.
    * \var xy
    * \brief Covariance of x and y.
    * \var xz
    * \brief Covariance of x and z.
    * \var yy
    * \brief Variance along y.
    * \var yz
    * \brief Covariance of y and z.
    * \var zz
    * \brief Variance along z. */
  float xx = 0.0f, xy = 0.0f, xz = 0.0f, yy = 0.0f, yz = 0.0f, zz = 0.0f;

  PackedCovariance () = default;
  /** \brief The symmetric part (S + S^T) / 2 of s, rounded to float. */
  explicit PackedCovariance (const Eigen::Matrix3d& s)
    : xx (static_cast<float> (s (0, 0))), xy (static_cast<float> (0.5 * (s (0, 1) + s (1, 0)))),
      xz (static_cast<float> (0.5 * (s (0, 2) + s (2, 0)))), yy (static_cast<float> (s (1, 1))),
      yz (static_cast<float> (0.5 * (s (1, 2) + s (2, 1)))), zz (static_cast<float> (s (2, 2))) {}
  /** \brief The full matrix. */
  Eigen::Matrix3d
  matrix () const
  {
    Eigen::Matrix3d m;
    m << double (xx), double (xy), double (xz), double (xy), double (yy), double (yz), double (xz), double (yz), double (zz);
    return m;
  }
  /** \brief True when all six entries are finite. */
  bool
  allFinite () const
  {
    return std::isfinite (xx) && std::isfinite (xy) && std::isfinite (xz) && std::isfinite (yy) &&
           std::isfinite (yz) && std::isfinite (zz);
  }
  /** \brief a^T Sigma a: the variance along a (for a unit a). */
  double
  quadratic (const Eigen::Vector3d& a) const
  {
    return a.x () * a.x () * double (xx) + a.y () * a.y () * double (yy) + a.z () * a.z () * double (zz) +
           2.0 * (a.x () * a.y () * double (xy) + a.x () * a.z () * double (xz) + a.y () * a.z () * double (yz));
  }
};

/** \brief A non-owning view of n points with covariances, as the classifier consumes them. */
struct PointSetView
{
  /** \brief The n means (not owned). */
  const Eigen::Vector3d* means = nullptr;
  /** \brief The n covariances, index-aligned with means (not owned). */
  const Eigen::Matrix3d* covariances = nullptr;
  /** \brief Number of points n. */
  std::size_t size = 0;

  PointSetView () = default;
  /** \brief A view of n means at m and n covariances at c. */
  PointSetView (const Eigen::Vector3d* m, const Eigen::Matrix3d* c, std::size_t n)
    : means (m), covariances (c), size (n) {}
  /** \brief A view of the vectors' data, of the shorter vector's size; valid while neither is
    * resized or destroyed. */
  PointSetView (const std::vector<Eigen::Vector3d>& m, const std::vector<Eigen::Matrix3d>& c)
    : means (m.data ()), covariances (c.data ()), size (m.size () < c.size () ? m.size () : c.size ()) {}
  /** \brief A view of a cloud's means and covariances (as the vector constructor). */
  explicit PointSetView (const UncertainCloud& cloud)
    : PointSetView (cloud.means, cloud.covariances) {}
};
} // namespace pcl_probcollision
