// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// MeshSampled mode (METHOD.md 9): a mesh becomes an exact point cloud, sampled uniformly by
// area plus every vertex, with zero covariance.

#include "mesh_input.h"

#include <pcl_probcollision/detail/sample_spacing.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstddef>
#include <cstdint>

namespace pcl_probcollision::io
{
/** \brief The samplers' default bound on the points produced. */
constexpr std::size_t kMaxMeshSamples = 20000000;

/** \brief Samples the surface: each triangle gets floor(area / spacing^2 + u) points (u uniform
  * in [0, 1)), uniform over the triangle, and every vertex used by a triangle is added once;
  * the expected density is one sample per spacing^2 of area. Deterministic for a given seed
  * (std::mt19937_64 and its raw bits only, so identical across standard libraries).
  * Throws std::runtime_error when more than max_points would be produced. */
pcl::PointCloud<pcl::PointXYZ> sampleMesh (const TriangleMesh& mesh, double spacing, std::uint64_t seed,
                                           std::size_t max_points = kMaxMeshSamples);

/** \brief sampleMesh's points (the same, for the same arguments) with outward normals: a
  * sample's is its triangle's, a vertex's the area-weighted mean of its triangles' (faces
  * wound counter-clockwise seen from outside). CloudModelParams' Auto orientation takes them.
  * Without `vertices`, the area samples alone (the same ones: the vertices draw nothing), so
  * that every position is new for a new seed. */
pcl::PointCloud<pcl::PointNormal> sampleMeshWithNormals (const TriangleMesh& mesh, double spacing, std::uint64_t seed,
                                                         std::size_t max_points = kMaxMeshSamples, bool vertices = true);

/** \brief Total triangle area. */
double meshArea (const TriangleMesh& mesh);

/** \brief Whether the mesh bounds a solid: with vertices at one position taken as one (a box
  * exported with split vertices per face is closed) and triangles without area left out, every
  * edge borders two triangles that run it in opposite directions. A bin or a box missing a face
  * (an edge bordering one triangle), a fin (three), or faces wound inconsistently are not closed;
  * their faces do not say where an inside is, and pcd_collision -surface warns of them
  * (openMeshWarning). A closed mesh wound inward (a cavity) is closed. */
bool isClosedMesh (const TriangleMesh& mesh);

/** \brief How a mesh's edges are bordered (vertices welded and triangles without area left out
  * as isClosedMesh does; each edge counted once): by two triangles that run it in opposite
  * directions (closed there), by one (open), by two that run it the same way (a face wound
  * against its neighbour: flipped), or by more than two (a fin). */
struct MeshEdges
{
  std::size_t closed = 0, open = 0, flipped = 0, fins = 0;
  /** \brief isClosedMesh's rule: edges, none of them open, flipped or a fin. */
  bool
  isClosed () const
  {
    return closed > 0 && open == 0 && flipped == 0 && fins == 0;
  }
};
MeshEdges meshEdges (const TriangleMesh& mesh);

/** \brief The volume the faces enclose by their winding (the divergence theorem, about the
  * vertices' centroid): positive for a closed mesh wound outward, negative for one wound inward
  * (a cavity, or a solid exported inside out; insideOutMeshWarning). Meaningful for a closed
  * mesh only. */
double meshSignedVolume (const TriangleMesh& mesh);

/** \brief Two meshes' sample spacing: 1/100 of the smaller bounding-box diagonal, so that the
  * smaller object (the robot, the part) is resolved whatever the scene around it; widened to
  * the spacing at which both meshes together expect kMeshPairSamples samples when it would
  * exceed that (a gripper against a room). 0 when both have no area. */
double meshPairSpacing (const TriangleMesh& a, const TriangleMesh& b);
/** \brief meshPairSpacing's share of the smaller diagonal. */
constexpr double kMeshPairFraction = 0.01;
/** \brief meshPairSpacing's bound on the two meshes' expected samples together. */
constexpr double kMeshPairSamples = 500000.0;

/** \brief Diagonal of the axis-aligned bounding box of the vertices used by triangles. */
double meshDiagonal (const TriangleMesh& mesh);

/** \brief Median over the finite points (at most max_queries of them, evenly strided) of the
  * distance to the nearest other finite point at a positive distance (within its 16 nearest);
  * 0 when there are fewer than two points or they all coincide (detail::medianNearestSpacing).
  * A built CloudModel gives the same number without a k-d tree of its own
  * (CloudModel::medianNeighbourSpacing). */
double medianSpacing (const pcl::PointCloud<pcl::PointXYZ>& cloud, std::size_t max_queries = detail::kSpacingQueries);
} // namespace pcl_probcollision::io
