// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl/memory.h>
#include <pcl/pcl_macros.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <ostream>

/** \brief The point types the library is compiled for (PCL's instantiation-list format).
  * Other types work with PCL_NO_PRECOMPILE or by including the impl/ headers. */
#define PCL_PROBCOLLISION_POINT_TYPES \
  (pcl::PointXYZ)(pcl::PointXYZI)(pcl::PointXYZRGB)(pcl::PointXYZRGBA)(pcl::PointNormal)             \
  (pcl::PointXYZRGBNormal)(pcl::PointXYZINormal)

namespace pcl_probcollision
{
/** \brief A symmetric 3x3 covariance (units squared, metres^2 for PCL scans), one per point.
  *
  * Six floats and no coordinates, like pcl::Normal: it travels through PCL containers, can be
  * joined to a cloud with pcl::concatenateFields and is saved to PCD as the fields
  * cov_xx cov_xy cov_xz cov_yy cov_yz cov_zz. NaN entries mark "no covariance" (a non-finite
  * input point).
  */
struct Covariance
{
  /** \var xx
    * \brief Variance along x (PCD field cov_xx).
    * \var xy
    * \brief Covariance of x and y (PCD field cov_xy).
    * \var xz
    * \brief Covariance of x and z (PCD field cov_xz).
    * \var yy
    * \brief Variance along y (PCD field cov_yy).
    * \var yz
    * \brief Covariance of y and z (PCD field cov_yz).
    * \var zz
    * \brief Variance along z (PCD field cov_zz). */
  float xx = 0.f, xy = 0.f, xz = 0.f, yy = 0.f, yz = 0.f, zz = 0.f;

  Covariance () = default;
  /** \brief From a matrix; only its upper triangle is read. */
  explicit Covariance (const Eigen::Matrix3d& m)
    : xx (static_cast<float> (m (0, 0))), xy (static_cast<float> (m (0, 1)))
    , xz (static_cast<float> (m (0, 2))), yy (static_cast<float> (m (1, 1)))
    , yz (static_cast<float> (m (1, 2))), zz (static_cast<float> (m (2, 2))) {}

  /** \brief The full symmetric matrix. */
  Eigen::Matrix3d matrix () const
  {
    Eigen::Matrix3d m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
  /** \brief True when all six entries are finite. */
  bool isFinite () const
  {
    return std::isfinite (xx) && std::isfinite (xy) && std::isfinite (xz) &&
           std::isfinite (yy) && std::isfinite (yz) && std::isfinite (zz);
  }
  /** \brief A covariance whose entries are all NaN ("not computed"). */
  static Covariance nan ()
  {
    Covariance c;
    c.xx = c.xy = c.xz = c.yy = c.yz = c.zz = std::numeric_limits<float>::quiet_NaN ();
    return c;
  }
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

std::ostream& operator<< (std::ostream& os, const Covariance& c);
} // namespace pcl_probcollision

POINT_CLOUD_REGISTER_POINT_STRUCT (pcl_probcollision::Covariance,
  (float, xx, cov_xx) (float, xy, cov_xy) (float, xz, cov_xz)
  (float, yy, cov_yy) (float, yz, cov_yz) (float, zz, cov_zz))
