// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/organized_sensor_pose.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace pcl_probcollision
{
namespace
{
/** \brief Rows and columns that span a plane, each: fewer say nothing reliable. */
constexpr std::size_t kMinLines = 3;
/** \brief A line's points span a plane when they spread across their best line by this many
  * times their spread off their best plane (a row over a flat table is a line). */
constexpr double kPlaneSpread = 10.0;
/** \brief The planes must meet in one point: the smallest eigenvalue of sum n n^T at least this
  * share of the largest. The two real organized scans of ../shared/data give 0.04 and 0.15. */
constexpr double kMinCondition = 1e-3;
/** \brief ... and pass within this share of the points' median range of it (RMS). A pinhole
  * image's back-projected rows are exact planes through the centre (the real scans: 1e-4). */
constexpr double kMaxMissRelative = 1e-3;
/** \brief The rows' planes must turn about a shared axis, and the columns' (sharedAxis): the
  * mean squared sine of their normals off the one direction at least this (about 2 degrees
  * RMS). */
constexpr double kMinTurn = 1e-3;

struct Plane
{
  Eigen::Vector3d normal;
  double offset;  ///< normal . x on the plane
};

/** \brief The plane of one row's or column's finite points, where they span one. */
bool
linePlane (const std::vector<Eigen::Vector3f>& points, std::size_t first, std::size_t step, std::size_t count, Plane& plane)
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero ();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero ();
  std::size_t n = 0;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero ();  // the first point: sums about it, for precision far from the origin
  for (std::size_t k = 0; k < count; ++k)
  {
    const Eigen::Vector3f& p = points[first + k * step];
    if (!p.allFinite ())
      continue;
    if (n == 0)
      shift = p.cast<double> ();
    const Eigen::Vector3d q = p.cast<double> () - shift;
    sum += q;
    outer += q * q.transpose ();
    ++n;
  }
  if (n < 3)
    return false;
  const Eigen::Vector3d mean = sum / double (n);
  const Eigen::Matrix3d cov = outer / double (n) - mean * mean.transpose ();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (cov);
  const Eigen::Vector3d l = eig.eigenvalues ();
  if (!(l (1) > kPlaneSpread * kPlaneSpread * std::max (l (0), 0.0)) || !(l (1) > 0.0))
    return false;
  plane.normal = eig.eigenvectors ().col (0);
  plane.offset = plane.normal.dot (mean + shift);
  return true;
}

/** \brief The direction every normal is across (the least eigenvector of sum n n^T), where the
  * normals turn about it (its middle eigenvalue at least kMinTurn of the count): the planes of a
  * pinhole image's rows turn about its horizontal axis. Zero where they do not: a lidar's rings
  * over a flat floor all lie in the floor's plane. */
Eigen::Vector3d
sharedAxis (const std::vector<Plane>& planes)
{
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero ();
  for (const Plane& p : planes)
    m += p.normal * p.normal.transpose ();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (m / double (planes.size ()));
  return eig.eigenvalues () (1) >= kMinTurn ? Eigen::Vector3d (eig.eigenvectors ().col (0)) : Eigen::Vector3d::Zero ();
}
} // namespace

std::optional<SensorPose>
organizedSensorPose (const std::vector<Eigen::Vector3f>& points, std::size_t width, std::size_t height)
{
  if (width < kMinLines || height < kMinLines || points.size () != width * height)
    return std::nullopt;
  std::vector<Plane> rows, columns;
  Plane plane;
  for (std::size_t v = 0; v < height; ++v)
    if (linePlane (points, v * width, 1, width, plane))
      rows.push_back (plane);
  for (std::size_t u = 0; u < width; ++u)
    if (linePlane (points, u, width, height, plane))
      columns.push_back (plane);
  if (rows.size () < kMinLines || columns.size () < kMinLines)
    return std::nullopt;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero ();
  Eigen::Vector3d b = Eigen::Vector3d::Zero ();
  for (const std::vector<Plane>* set : {&rows, &columns})
    for (const Plane& p : *set)
    {
      a += p.normal * p.normal.transpose ();
      b += p.normal * p.offset;
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (a);
  if (!(eig.eigenvalues () (0) >= kMinCondition * eig.eigenvalues () (2)))
    return std::nullopt;
  const Eigen::Vector3d centre = eig.eigenvectors () * (eig.eigenvectors ().transpose () * b).cwiseQuotient (eig.eigenvalues ());
  double miss2 = 0.0;
  for (const std::vector<Plane>* set : {&rows, &columns})
    for (const Plane& p : *set)
      miss2 += (p.normal.dot (centre) - p.offset) * (p.normal.dot (centre) - p.offset);
  const double miss = std::sqrt (miss2 / double (rows.size () + columns.size ()));
  // The points' median range and side of the centre, on a sample of at most about 4,096.
  std::vector<double> range, side;
  const Eigen::Vector3d across_rows = sharedAxis (rows), across_columns = sharedAxis (columns);
  if (across_rows.isZero () || across_columns.isZero ())
    return std::nullopt;
  const Eigen::Vector3d axis = across_rows.cross (across_columns).normalized ();
  const std::size_t stride = std::max<std::size_t> (1, points.size () / 4096);
  for (std::size_t i = 0; i < points.size (); i += stride)
    if (points[i].allFinite ())
    {
      const Eigen::Vector3d r = points[i].cast<double> () - centre;
      range.push_back (r.norm ());
      side.push_back (axis.dot (r));
    }
  if (range.empty () || !centre.allFinite () || !axis.allFinite ())
    return std::nullopt;
  const auto middle = [] (std::vector<double>& v) {
    std::nth_element (v.begin (), v.begin () + static_cast<std::ptrdiff_t> (v.size () / 2), v.end ());
    return v[v.size () / 2];
  };
  if (!(miss <= kMaxMissRelative * middle (range)))
    return std::nullopt;
  SensorPose pose;
  pose.origin = centre;
  pose.axis = middle (side) >= 0.0 ? axis : Eigen::Vector3d (-axis);  // toward the points
  return pose;
}
} // namespace pcl_probcollision
