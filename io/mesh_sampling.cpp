// SPDX-License-Identifier: BSD-3-Clause
#include "mesh_sampling.h"

#include <pcl_probcollision/detail/sample_spacing.h>
#include <pcl_probcollision/normal_distribution.h>

#include <pcl/kdtree/kdtree_flann.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pcl_probcollision::io
{
namespace
{
Eigen::Vector3d
vertex (const TriangleMesh& mesh, int i)
{
  const auto& v = mesh.vertices[static_cast<std::size_t> (i)];
  return {v[0], v[1], v[2]};
}

double
triangleArea (const TriangleMesh& mesh, const std::array<int, 3>& t)
{
  const Eigen::Vector3d a = vertex (mesh, t[0]);
  return 0.5 * (vertex (mesh, t[1]) - a).cross (vertex (mesh, t[2]) - a).norm ();
}
} // namespace

MeshEdges
meshEdges (const TriangleMesh& mesh)
{
  // Vertices welded by position: exporters split them where faces meet at a crease.
  std::map<std::array<double, 3>, int> welded;
  std::vector<int> id (mesh.vertices.size ());
  for (std::size_t i = 0; i < mesh.vertices.size (); ++i)
    id[i] = welded.emplace (mesh.vertices[i], static_cast<int> (welded.size ())).first->second;
  // Per undirected edge (low, high): how many triangles run it low -> high, and high -> low.
  std::map<std::pair<int, int>, std::array<int, 2>> edges;
  for (const auto& t : mesh.triangles)
  {
    if (!(triangleArea (mesh, t) > 0.0))
      continue;
    for (int k = 0; k < 3; ++k)
    {
      const int u = id[static_cast<std::size_t> (t[k])], v = id[static_cast<std::size_t> (t[(k + 1) % 3])];
      ++edges[{std::min (u, v), std::max (u, v)}][u < v ? 0 : 1];
    }
  }
  MeshEdges counts;
  for (const auto& [edge, runs] : edges)
  {
    const int total = runs[0] + runs[1];
    if (total == 1)
      ++counts.open;
    else if (total > 2)
      ++counts.fins;
    else if (runs[0] == 1)
      ++counts.closed;
    else
      ++counts.flipped;
  }
  return counts;
}

bool
isClosedMesh (const TriangleMesh& mesh)
{
  return meshEdges (mesh).isClosed ();
}

double
meshSignedVolume (const TriangleMesh& mesh)
{
  if (mesh.vertices.empty ())
    return 0.0;
  // About the centroid, so that a mesh far from its origin keeps its digits.
  Eigen::Vector3d c = Eigen::Vector3d::Zero ();
  for (std::size_t i = 0; i < mesh.vertices.size (); ++i)
    c += vertex (mesh, static_cast<int> (i));
  c /= static_cast<double> (mesh.vertices.size ());
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles)
    six_volume += (vertex (mesh, t[0]) - c).dot ((vertex (mesh, t[1]) - c).cross (vertex (mesh, t[2]) - c));
  return six_volume / 6.0;
}

double
meshArea (const TriangleMesh& mesh)
{
  double area = 0.0;
  for (const auto& t : mesh.triangles)
    area += triangleArea (mesh, t);
  return area;
}

double
meshPairSpacing (const TriangleMesh& a, const TriangleMesh& b)
{
  // Thin parts of the smaller object are what a wider spacing misses: FCL's piano legs (40 mm
  // across, through a 9 mm floor) read free at 1/100 of the room's diagonal, 90 mm, and
  // collision at 1/100 of the piano's, 18 mm.
  const double resolved = kMeshPairFraction * std::min (meshDiagonal (a), meshDiagonal (b));
  const double bounded = std::sqrt ((meshArea (a) + meshArea (b)) / kMeshPairSamples);
  return std::max (resolved, bounded);
}

double
meshDiagonal (const TriangleMesh& mesh)
{
  Eigen::Vector3d lo = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ());
  Eigen::Vector3d hi = -lo;
  for (const auto& t : mesh.triangles)
    for (const int i : t)
    {
      lo = lo.cwiseMin (vertex (mesh, i));
      hi = hi.cwiseMax (vertex (mesh, i));
    }
  return mesh.triangles.empty () ? 0.0 : (hi - lo).norm ();
}

pcl::PointCloud<pcl::PointNormal>
sampleMeshWithNormals (const TriangleMesh& mesh, double spacing, std::uint64_t seed, std::size_t max_points,
                       bool vertices)
{
  if (!(spacing > 0.0) || !std::isfinite (spacing))
    throw std::runtime_error ("mesh sample spacing must be finite and > 0");
  const double expected = meshArea (mesh) / (spacing * spacing);
  if (!(expected < static_cast<double> (max_points)))
  {
    char why[200];
    std::snprintf (why, sizeof why, "sampling the mesh at spacing %g would give about %.3g points (limit %zu); raise -mesh_density",
                   spacing, expected, max_points);
    throw std::runtime_error (why);
  }

  pcl::PointCloud<pcl::PointNormal> cloud;
  // A vertex's normal: the area-weighted mean of its triangles' (an edge or corner gets the
  // direction between its faces); a sample's: its triangle's. Taken as outward: the faces'
  // winding is counter-clockwise seen from outside (OBJ, PLY, STL).
  std::vector<Eigen::Vector3d> vertex_normal (mesh.vertices.size (), Eigen::Vector3d::Zero ());
  for (const auto& t : mesh.triangles)
  {
    const Eigen::Vector3d a = vertex (mesh, t[0]);
    const Eigen::Vector3d area_normal = 0.5 * (vertex (mesh, t[1]) - a).cross (vertex (mesh, t[2]) - a);
    for (const int i : t)
      vertex_normal[static_cast<std::size_t> (i)] += area_normal;
  }
  auto point = [] (const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    pcl::PointNormal q;
    q.x = static_cast<float> (p.x ());
    q.y = static_cast<float> (p.y ());
    q.z = static_cast<float> (p.z ());
    const double norm = n.norm ();
    const Eigen::Vector3d u = norm > 0.0 ? Eigen::Vector3d (n / norm) : Eigen::Vector3d::Zero ();
    q.normal_x = static_cast<float> (u.x ());
    q.normal_y = static_cast<float> (u.y ());
    q.normal_z = static_cast<float> (u.z ());
    q.curvature = 0.0f;
    return q;
  };
  std::vector<char> used (mesh.vertices.size (), 0);
  for (const auto& t : mesh.triangles)
    for (const int i : t)
      used[static_cast<std::size_t> (i)] = 1;
  for (std::size_t i = 0; vertices && i < mesh.vertices.size (); ++i)
    if (used[i])
      cloud.push_back (point (vertex (mesh, static_cast<int> (i)), vertex_normal[i]));

  std::mt19937_64 rng (seed);
  for (const auto& t : mesh.triangles)
  {
    const double n_expected = triangleArea (mesh, t) / (spacing * spacing);
    // A triangle without area (a polygon repeating a vertex) draws nothing: the same surface
    // gives the same samples, however its faces were split.
    if (!(n_expected > 0.0))
      continue;
    const auto n = static_cast<std::size_t> (std::floor (n_expected + pcl_probcollision::detail::uniformUnit (rng)));
    const Eigen::Vector3d a = vertex (mesh, t[0]), b = vertex (mesh, t[1]), c = vertex (mesh, t[2]);
    const Eigen::Vector3d face_normal = (b - a).cross (c - a);
    for (std::size_t s = 0; s < n; ++s)
    {
      const double r1 = std::sqrt (pcl_probcollision::detail::uniformUnit (rng));
      const double r2 = pcl_probcollision::detail::uniformUnit (rng);
      const Eigen::Vector3d p = (1.0 - r1) * a + r1 * (1.0 - r2) * b + r1 * r2 * c;
      cloud.push_back (point (p, face_normal));
    }
  }
  cloud.width = static_cast<std::uint32_t> (cloud.size ());
  cloud.height = 1;
  cloud.is_dense = true;
  return cloud;
}

pcl::PointCloud<pcl::PointXYZ>
sampleMesh (const TriangleMesh& mesh, double spacing, std::uint64_t seed, std::size_t max_points)
{
  const pcl::PointCloud<pcl::PointNormal> oriented = sampleMeshWithNormals (mesh, spacing, seed, max_points);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.resize (oriented.size ());
  for (std::size_t i = 0; i < oriented.size (); ++i)
    cloud[i].getVector3fMap () = oriented[i].getVector3fMap ();
  cloud.width = oriented.width;
  cloud.height = oriented.height;
  cloud.is_dense = oriented.is_dense;
  return cloud;
}

double
medianSpacing (const pcl::PointCloud<pcl::PointXYZ>& cloud, std::size_t max_queries)
{
  auto finite = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>> ();
  for (const auto& p : cloud.points)
    if (std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z))
      finite->push_back (p);
  if (finite->size () < 2)
    return 0.0;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud (finite);
  pcl::Indices idx;
  std::vector<float> sq;
  return detail::medianNearestSpacing (finite->size (), max_queries, [&] (std::size_t i) {
    // The nearest other point at a positive distance: duplicates are skipped by asking for a
    // few more neighbours.
    for (int k = 2; k <= 16; k *= 2)
    {
      if (tree.nearestKSearch ((*finite)[i], k, idx, sq) <= 0)
        break;
      const auto it = std::find_if (sq.begin (), sq.end (), [] (float v) { return v > 0.f; });
      if (it != sq.end ())
        return std::sqrt (static_cast<double> (*it));
      if (static_cast<std::size_t> (k) >= finite->size ())
        break;
    }
    return 0.0;
  });
}
} // namespace pcl_probcollision::io
