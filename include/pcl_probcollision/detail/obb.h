// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Oriented bounding box: a centre, a right-handed orthonormal frame and half extents
  * along its three axes (METHOD.md 8.3).
  *
  * A point x lies inside when |axes().col(k)^T (x - center)| <= half_extents(k) for k = 0, 1, 2.
  * Lengths are in the units of the data (metres for PCL scans). In the hierarchy, axis 0 is the
  * longest principal direction e3, axis 1 is e2 and axis 2 is e1 (the normal of a surface patch).
  *
  * Only the first two axes are stored; the third is their cross product, so the frame is
  * right-handed by construction and a hierarchy node is 24 bytes smaller (issue #17's memory
  * target). Everything that reads the frame, the box's own fit included, reads axes(). The half
  * extents are stored in single precision, rounded up (setHalfExtents()): the box never shrinks
  * below what was fitted, and a node is 8 bytes smaller again.
  */
struct OrientedBox
{
  /** \brief Centre of the box, in the frame the box is expressed in (metres). */
  Eigen::Vector3d center = Eigen::Vector3d::Zero ();
  /** \brief The first two unit axes as columns (set through setAxes()). */
  Eigen::Matrix<double, 3, 2, Eigen::DontAlign> first_axes = Eigen::Matrix<double, 3, 2>::Identity ();
  /** \brief Half extents along the columns of axes() (metres, >= 0), in single precision (set
    * through setHalfExtents(), read through halfExtents()). */
  Eigen::Vector3f half_extents = Eigen::Vector3f::Zero ();

  /** \brief The half extents in double precision. */
  Eigen::Vector3d halfExtents () const { return half_extents.cast<double> (); }

  /** \brief Sets the half extents from h (>= 0), each rounded up to a float: the stored box
    * contains the box h describes. Zero stays zero. (Always one float step above the nearest
    * float, not only where the nearest lies below h: at most 2^-23 of h too large, and no
    * float-to-double comparison for a compiler to fold.) */
  void
  setHalfExtents (const Eigen::Vector3d& h)
  {
    for (int k = 0; k < 3; ++k)
      half_extents (k) = h (k) > 0.0 ? std::nextafter (static_cast<float> (h (k)), std::numeric_limits<float>::infinity ())
                                     : static_cast<float> (h (k));
  }

  /** \brief The unit axes as columns, a rotation (det +1) mapping box coordinates to the frame:
    * first_axes, then their cross product. */
  Eigen::Matrix3d
  axes () const
  {
    Eigen::Matrix3d a;
    a.leftCols<2> () = first_axes;
    a.col (2) = first_axes.col (0).cross (first_axes.col (1));
    return a;
  }

  /** \brief Sets the frame from a rotation's first two columns (its third is implied). */
  void
  setAxes (const Eigen::Matrix3d& rotation)
  {
    first_axes = rotation.leftCols<2> ();
  }

  /** \brief The same box expressed in another frame: T_dst_src maps this box's frame into dst. */
  OrientedBox
  transformed (const Eigen::Isometry3d& T_dst_src) const
  {
    OrientedBox out;
    out.center = T_dst_src * center;
    out.first_axes = T_dst_src.linear () * first_axes;
    out.half_extents = half_extents;  // the same floats: the box is only moved
    return out;
  }

  /** \brief p (in the box's frame) in box coordinates: axes()^T (p - center). */
  Eigen::Vector3d
  boxCoordinates (const Eigen::Vector3d& p) const
  {
    const Eigen::Vector3d d = p - center;
    return Eigen::Vector3d (first_axes.col (0).dot (d), first_axes.col (1).dot (d),
                            first_axes.col (0).cross (first_axes.col (1)).dot (d));
  }

  /** \brief True when p lies inside the box grown by tolerance (metres) on every side. */
  bool
  contains (const Eigen::Vector3d& p, double tolerance = 0.0) const
  {
    const Eigen::Vector3d local = boxCoordinates (p);
    for (int k = 0; k < 3; ++k)
      if (std::abs (local (k)) > static_cast<double> (half_extents (k)) + tolerance)
        return false;
    return true;
  }

  /** \brief The distance from p (in the box's frame) to the box, 0 inside it (metres). */
  double
  distanceTo (const Eigen::Vector3d& p) const
  {
    return (boxCoordinates (p).cwiseAbs () - halfExtents ()).cwiseMax (0.0).norm ();
  }

  /** \brief Volume (cubic metres). */
  double
  volume () const
  {
    const Eigen::Vector3d h = halfExtents ();
    return 8.0 * h (0) * h (1) * h (2);
  }

  /** \brief Squared half diagonal (square metres): the size measure used to pick which node
    * of a pair to open. Unlike the volume it does not vanish for a flat patch. */
  double
  halfDiagonalSquared () const
  {
    return halfExtents ().squaredNorm ();
  }

  /** \brief The eight corners as columns (metres), corner c has sign (-1)^bit k on axis k. */
  Eigen::Matrix<double, 3, 8>
  corners () const
  {
    Eigen::Matrix<double, 3, 8> c;
    const Eigen::Matrix3d a = axes ();
    for (int i = 0; i < 8; ++i)
    {
      Eigen::Vector3d s ((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
      c.col (i) = center + a * s.cwiseProduct (halfExtents ());
    }
    return c;
  }
};

/** \brief Relative tolerance of the separating-axis test. A separation is only reported when it
  * exceeds kSatRelativeTolerance * (|t| + sum of half extents): rounding in the relative pose can
  * then never declare two touching or overlapping boxes disjoint (this matters for flat and
  * zero-thickness boxes, where the cross-product axes degenerate). The test is conservative by
  * that amount. */
constexpr double kSatRelativeTolerance = 1e-10;

/** \brief 15-axis separating-axis test (Gottschalk, Lin and Manocha 1996; the formulation of
  * Ericson, Real-Time Collision Detection, 4.4.1) for two boxes given in A's box coordinates.
  * \param[in] half_a half extents of A (metres)
  * \param[in] R rotation of B's axes in A's box coordinates, R(i, j) = a_i . b_j
  * \param[in] t centre of B minus centre of A, in A's box coordinates (metres)
  * \param[in] half_b half extents of B (metres)
  * \return true when a separating axis exists, i.e. the (closed) boxes are disjoint. */
inline bool
disjointLocal (const Eigen::Vector3d& half_a, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
               const Eigen::Vector3d& half_b)
{
  const double* a = half_a.data ();
  const double* b = half_b.data ();
  const Eigen::Matrix3d absR = R.cwiseAbs ();
  const double tol = kSatRelativeTolerance *
                     (t.cwiseAbs ().sum () + half_a.sum () + half_b.sum ());
  double ra, rb;
  // Face axes of A.
  for (int i = 0; i < 3; ++i)
  {
    ra = a[i];
    rb = b[0] * absR (i, 0) + b[1] * absR (i, 1) + b[2] * absR (i, 2);
    if (std::abs (t (i)) > ra + rb + tol)
      return true;
  }
  // Face axes of B.
  for (int j = 0; j < 3; ++j)
  {
    ra = a[0] * absR (0, j) + a[1] * absR (1, j) + a[2] * absR (2, j);
    rb = b[j];
    if (std::abs (t (0) * R (0, j) + t (1) * R (1, j) + t (2) * R (2, j)) > ra + rb + tol)
      return true;
  }
  // Edge-edge axes A_i x B_j.
  ra = a[1] * absR (2, 0) + a[2] * absR (1, 0);
  rb = b[1] * absR (0, 2) + b[2] * absR (0, 1);
  if (std::abs (t (2) * R (1, 0) - t (1) * R (2, 0)) > ra + rb + tol)
    return true;
  ra = a[1] * absR (2, 1) + a[2] * absR (1, 1);
  rb = b[0] * absR (0, 2) + b[2] * absR (0, 0);
  if (std::abs (t (2) * R (1, 1) - t (1) * R (2, 1)) > ra + rb + tol)
    return true;
  ra = a[1] * absR (2, 2) + a[2] * absR (1, 2);
  rb = b[0] * absR (0, 1) + b[1] * absR (0, 0);
  if (std::abs (t (2) * R (1, 2) - t (1) * R (2, 2)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (2, 0) + a[2] * absR (0, 0);
  rb = b[1] * absR (1, 2) + b[2] * absR (1, 1);
  if (std::abs (t (0) * R (2, 0) - t (2) * R (0, 0)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (2, 1) + a[2] * absR (0, 1);
  rb = b[0] * absR (1, 2) + b[2] * absR (1, 0);
  if (std::abs (t (0) * R (2, 1) - t (2) * R (0, 1)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (2, 2) + a[2] * absR (0, 2);
  rb = b[0] * absR (1, 1) + b[1] * absR (1, 0);
  if (std::abs (t (0) * R (2, 2) - t (2) * R (0, 2)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (1, 0) + a[1] * absR (0, 0);
  rb = b[1] * absR (2, 2) + b[2] * absR (2, 1);
  if (std::abs (t (1) * R (0, 0) - t (0) * R (1, 0)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (1, 1) + a[1] * absR (0, 1);
  rb = b[0] * absR (2, 2) + b[2] * absR (2, 0);
  if (std::abs (t (1) * R (0, 1) - t (0) * R (1, 1)) > ra + rb + tol)
    return true;
  ra = a[0] * absR (1, 2) + a[1] * absR (0, 2);
  rb = b[0] * absR (2, 1) + b[1] * absR (2, 0);
  if (std::abs (t (1) * R (0, 2) - t (0) * R (1, 2)) > ra + rb + tol)
    return true;
  return false;
}

/** \brief True when box a (in frame A) and box b (in frame B, mapped into A by T_a_b) are
  * disjoint, each grown by its own extra half extents first.
  * \param[in] a box in frame A
  * \param[in] extra_a added to a.halfExtents() (metres, >= 0)
  * \param[in] b box in frame B
  * \param[in] extra_b added to b.halfExtents() (metres, >= 0)
  * \param[in] T_a_b rigid transform mapping B-frame points into frame A */
inline bool
disjointInflated (const OrientedBox& a, const Eigen::Vector3d& extra_a, const OrientedBox& b,
                  const Eigen::Vector3d& extra_b, const Eigen::Isometry3d& T_a_b)
{
  // R(i, j) = a_i . (L b_j), L = T_a_b's rotation, from the two stored axes of each box: A's
  // third axis is the cross product of its first two, and so is R's third column (R is a
  // rotation). Fewer products than with the full frames, and no call to axes() in this hot path.
  const Eigen::Vector3d a2 = a.first_axes.col (0).cross (a.first_axes.col (1));
  const Eigen::Matrix<double, 3, 2> Lb = T_a_b.linear () * b.first_axes;
  Eigen::Matrix3d R;
  R.topLeftCorner<2, 2> () = a.first_axes.transpose () * Lb;
  R.block<1, 2> (2, 0) = a2.transpose () * Lb;
  R.col (2) = R.col (0).cross (R.col (1));
  const Eigen::Vector3d d = T_a_b * b.center - a.center;
  const Eigen::Vector3d t (a.first_axes.col (0).dot (d), a.first_axes.col (1).dot (d), a2.dot (d));
  return disjointLocal (a.halfExtents () + extra_a, R, t, b.halfExtents () + extra_b);
}

/** \brief True when box a (frame A) and box b (frame B, mapped into A by T_a_b) are disjoint
  * after both are grown by margin (metres, >= 0) on every side. */
inline bool
disjoint (const OrientedBox& a, const OrientedBox& b, const Eigen::Isometry3d& T_a_b,
          double margin = 0.0)
{
  const Eigen::Vector3d m = Eigen::Vector3d::Constant (margin);
  return disjointInflated (a, m, b, m, T_a_b);
}

/** \brief Fits the box with the given axes around Gaussian points: along each axis a the extent
  * is [min_j a^T x_j - k_sigma s_j, max_j a^T x_j + k_sigma s_j] with s_j = sqrt(a^T Sigma_j a)
  * (METHOD.md 8.3).
  * \param[in] axes box axes as columns (a rotation; its first two columns are kept and the
  *            third taken as their cross product, see OrientedBox)
  * \param[in] means point means (metres)
  * \param[in] covariances point covariances (square metres) or nullptr for exact points
  * \param[in] indices the points to use, or nullptr for 0 .. count-1
  * \param[in] count number of points; 0 gives a zero box at the origin
  * \param[in] k_sigma inflation in point standard deviations (>= 0) */
inline OrientedBox
fitOrientedBox (const Eigen::Matrix3d& axes, const Eigen::Vector3d* means,
                const Eigen::Matrix3d* covariances, const int* indices, std::size_t count,
                double k_sigma)
{
  OrientedBox box;
  box.setAxes (axes);
  if (count == 0)
    return box;
  const Eigen::Matrix3d A = box.axes ();
  // Project relative to the first point so large coordinates keep their precision.
  const Eigen::Vector3d origin = means[indices ? indices[0] : 0];
  Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ());
  Eigen::Vector3d hi = -lo;
  for (std::size_t n = 0; n < count; ++n)
  {
    const int j = indices ? indices[n] : static_cast<int> (n);
    const Eigen::Vector3d q = A.transpose () * (means[j] - origin);
    for (int k = 0; k < 3; ++k)
    {
      double s = 0.0;
      if (covariances)
        s = std::sqrt (std::max (0.0, A.col (k).dot (covariances[j] * A.col (k))));
      lo (k) = std::min (lo (k), q (k) - k_sigma * s);
      hi (k) = std::max (hi (k), q (k) + k_sigma * s);
    }
  }
  box.center = origin + A * (0.5 * (lo + hi));
  box.setHalfExtents (0.5 * (hi - lo));
  return box;
}
} // namespace detail
} // namespace pcl_probcollision
