// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// The baselines of the evaluation suite (issue #6, methods 3 to 5), each split into a build step
// and a query so that the caller times them apart. FCL, octomap, FLANN and PCL's surface module
// stay in baselines.cpp. Method 2 (FCL on the exact meshes) is ExactMeshPair::collide in
// ground_truth.h. Pose convention: T = T_env_robot, as in ground_truth.h.

#include "ground_truth.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <memory>

namespace pcl_probcollision_eval
{
using CloudXYZ = pcl::PointCloud<pcl::PointXYZ>;

/** \brief Collision map as ROS / MoveIt build it: the env cloud's points marked occupied in an
  * octomap::OcTree (each occupied voxel updated once as a hit; no ray casting, so no free space
  * is carved: unknown counts as free, as FCL treats it), wrapped as fcl::OcTree, against the robot
  * mesh (BVHModel<OBBRSS>) or against the robot cloud's own octree at the same resolution. */
class OctomapBaseline
{
public:
  OctomapBaseline ();
  ~OctomapBaseline ();
  OctomapBaseline (OctomapBaseline&&) noexcept;
  OctomapBaseline& operator= (OctomapBaseline&&) noexcept;

  /** \brief Env octree of the finite points of env at the given voxel size (> 0, else
    * std::invalid_argument). Discards any robot octree (it must share the resolution). */
  void buildEnv (const CloudXYZ& env, double resolution);
  /** \brief Robot mesh as an FCL BVHModel<OBBRSS> (robot frame). */
  void setRobotMesh (const TriangleMesh& robot);
  /** \brief Robot cloud (robot frame) as its own octree at the env's resolution; after buildEnv. */
  void buildRobotCloud (const CloudXYZ& robot);

  /** \brief Env octree against the robot mesh at pose T (std::logic_error if either is missing). */
  bool collideMesh (const Eigen::Isometry3d& T) const;
  /** \brief Env octree against the robot cloud's octree at pose T. */
  bool collideCloud (const Eigen::Isometry3d& T) const;

  double resolution () const;
  /** \brief octomap::OcTree::memoryUsage() of the env / robot octree (0 if not built). */
  std::size_t envMemoryBytes () const;
  std::size_t robotCloudMemoryBytes () const;
  /** \brief Bytes of the robot mesh's BVH model (0 if not set). */
  std::size_t robotMeshMemoryBytes () const;
  /** \brief Occupied leaves of the env / robot octree. */
  std::size_t envOccupiedLeaves () const;
  std::size_t robotOccupiedLeaves () const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/** \brief Nearest-neighbour threshold (a union of spheres): the smallest distance from the
  * robot cloud at pose T to the env cloud, by an exact FLANN kd-tree (KDTreeSingleIndex, leaf
  * size 10) over the env cloud, the caller thresholding it at r (1, 2, 3 sigma).
  *
  * Queries go to FLANN in batches (flann::Matrix of 256 points, one call each) with cores = 1,
  * never one call per point: Debian's FLANN wraps every call in an OpenMP parallel region (when
  * compiled with OpenMP), which dominates single-point queries. Each batch is a radius search
  * (max_neighbors 1) bounded by the smallest distance found so far, so the kd-tree prunes
  * everything farther. */
class NearestNeighbourBaseline
{
public:
  NearestNeighbourBaseline ();
  ~NearestNeighbourBaseline ();
  NearestNeighbourBaseline (NearestNeighbourBaseline&&) noexcept;
  NearestNeighbourBaseline& operator= (NearestNeighbourBaseline&&) noexcept;

  /** \brief kd-tree over the finite points of env; the finite points of robot are kept (robot
    * frame) for the queries. std::invalid_argument if either has no finite point. */
  void build (const CloudXYZ& env, const CloudXYZ& robot);

  /** \brief min over robot points p of the distance from T * p to the env cloud. With a finite
    * cap, only distances below cap are searched: returns +infinity when none is below cap
    * (cheaper; the right call when the caller only thresholds at r <= cap). */
  double minDistance (const Eigen::Isometry3d& T,
                      double cap = std::numeric_limits<double>::infinity ()) const;

  /** \brief minDistance (T) < r, stopping at the first batch with a point closer than r. */
  bool within (const Eigen::Isometry3d& T, double r) const;

  std::size_t envPoints () const;
  std::size_t robotPoints () const;
  /** \brief FLANN index (usedMemory) plus the stored env and robot coordinates. */
  std::size_t memoryBytes () const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/** \brief Settings of reconstructMesh(): pcl::NormalEstimation then
  * pcl::GreedyProjectionTriangulation<pcl::PointNormal>. */
struct ReconstructionParams
{
  int normal_k = 20;               ///< neighbours of the normal estimate
  double radius_factor = 3.5;      ///< search radius (longest edge) = radius_factor * median spacing
  double search_radius = 0.0;      ///< absolute search radius; overrides radius_factor when > 0
  double mu = 2.5;                 ///< local radius = mu * distance to the nearest neighbour
  int max_nearest_neighbors = 100;
  double max_surface_angle = 0.7853981633974483;  ///< pi / 4
  double min_angle = 0.17453292519943295;         ///< pi / 18
  double max_angle = 2.0943951023931957;          ///< 2 pi / 3
  bool normal_consistency = false;  ///< normals of a noisy cloud are not consistently oriented
};

/** \brief Triangle mesh of a cloud (vertices are the cloud's finite points, unused ones
  * included). The search radius used is written to used_search_radius when given. Throws
  * std::invalid_argument for fewer than 3 finite points. The mesh may have no triangle. */
TriangleMesh reconstructMesh (const CloudXYZ& cloud, const ReconstructionParams& params = {},
                              double* used_search_radius = nullptr);

/** \brief Reconstruct then collide: both clouds triangulated by reconstructMesh(), then FCL
  * (BVHModel<OBBRSS>) on the two reconstructed meshes. The reconstruction is part of the build. */
class ReconstructBaseline
{
public:
  /** \brief std::runtime_error when a reconstruction has no triangle. */
  void build (const CloudXYZ& robot, const CloudXYZ& env, const ReconstructionParams& params = {});
  bool collide (const Eigen::Isometry3d& T) const { return meshes_.collide (T); }
  std::size_t robotTriangles () const { return meshes_.robotTriangles (); }
  std::size_t envTriangles () const { return meshes_.envTriangles (); }
  /** \brief Both BVH models. */
  std::size_t memoryBytes () const { return meshes_.memoryBytes (); }
  /** \brief The reconstructed pair, for distances or export. */
  const ExactMeshPair& meshes () const { return meshes_; }
  const TriangleMesh& robotMesh () const { return robot_mesh_; }
  const TriangleMesh& envMesh () const { return env_mesh_; }

private:
  TriangleMesh robot_mesh_, env_mesh_;
  ExactMeshPair meshes_;
};
} // namespace pcl_probcollision_eval
