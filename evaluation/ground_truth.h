// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Ground truth of the evaluation suite (issue #6): exact collision, distance and a signed-distance
// estimate between two triangle meshes with FCL, and seeded pose workloads labelled with them.
// FCL stays out of this header (pimpl) so the driver's translation units compile fast.
//
// Pose convention everywhere: T = T_env_robot maps robot (piano) coordinates into the env (room)
// frame; directions and nearest points are returned in the env frame.

#include "mesh_input.h"

#include <pcl_probcollision/normal_distribution.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

namespace pcl_probcollision_eval
{
using pcl_probcollision::io::TriangleMesh;

/** \brief Exact queries between a robot mesh and an env mesh, each an FCL BVHModel<OBBRSS>
  * (OBBRSS, not AABB: FCL refits AABB models on every query, hundreds of times slower).
  *
  * Collision is between the surfaces (triangles): a mesh wholly inside the other, without any
  * triangle crossing, is free, as it is for point clouds of the two surfaces.
  *
  * All queries are const and safe to call from several threads at once. collide() is also the
  * "FCL exact mesh" baseline (method 2 of issue #6): one request, stops at the first
  * intersecting triangle pair, no contact points. */
class ExactMeshPair
{
public:
  ExactMeshPair ();
  /** \brief Same as build (robot, env). */
  ExactMeshPair (const TriangleMesh& robot, const TriangleMesh& env);
  ~ExactMeshPair ();
  ExactMeshPair (ExactMeshPair&&) noexcept;
  ExactMeshPair& operator= (ExactMeshPair&&) noexcept;

  /** \brief Builds both hierarchies. Throws std::invalid_argument when a mesh has no triangle or
    * refers to a missing vertex. Sets the penetration tolerance to 1e-4 of the robot's diagonal. */
  void build (const TriangleMesh& robot, const TriangleMesh& env);

  /** \brief True once build() succeeded. */
  bool built () const;

  /** \brief Exact: do the surfaces intersect (touching counts) with the robot at pose T? */
  bool collide (const Eigen::Isometry3d& T) const;

  /** \brief Exact minimum distance between the surfaces (fcl::distance); 0 when they intersect.
    * Optionally the closest points, on the robot and on the env, in the env frame. */
  double distance (const Eigen::Isometry3d& T, Eigen::Vector3d* point_on_robot = nullptr,
                   Eigen::Vector3d* point_on_env = nullptr) const;

  /** \brief Penetration depth estimate for a colliding pose (0 when free): the shortest
    * translation that separates, searched by bisection (to within penetrationTolerance(), always
    * ending on the free side) along each of the 50 penetrationDirections(), then refined by a
    * pattern search on cones of 11 down to 0.7 degrees around the best direction. Each
    * direction after the first costs one collision query unless it improves the best.
    * It is an UPPER bound on the true depth: the true one is the minimum over all directions,
    * and a path through several contacts may hide a shorter free gap. On the piano and room
    * (about 60 colliding poses, against the best of 21 such searches in rotated frames) the 50
    * directions alone overestimated by a p90 of 7 to 9% (max 53%); with the refinement the p90
    * is about 1% and the max 5%.
    * \param[out] direction unit env-frame direction of the separating translation (optional) */
  double penetrationDepth (const Eigen::Isometry3d& T, Eigen::Vector3d* direction = nullptr) const;

  /** \brief Positive: exact separation distance (distance()). Negative: minus
    * penetrationDepth() (so never closer to zero than the truth). Negative if and only if
    * collide(T). */
  double signedDistance (const Eigen::Isometry3d& T) const;

  /** \brief Bisection tolerance of penetrationDepth(), absolute, in mesh units. */
  double penetrationTolerance () const;
  void setPenetrationTolerance (double tolerance);

  /** \brief The fixed search directions of penetrationDepth(), unit, env frame: the 26 directions
    * of the cube (faces, edges, corners), the 12 icosahedron vertices (0, +-1, +-phi) and the 12
    * remaining dodecahedron vertices (0, +-1/phi, +-phi), cyclic permutations included. */
  static const std::vector<Eigen::Vector3d>& penetrationDirections ();

  /** \brief Axis-aligned boxes of the vertices used by triangles, in each mesh's own frame. */
  const Eigen::AlignedBox3d& robotBox () const;
  const Eigen::AlignedBox3d& envBox () const;
  double robotDiagonal () const { return robotBox ().diagonal ().norm (); }
  double envDiagonal () const { return envBox ().diagonal ().norm (); }

  std::size_t robotTriangles () const;
  std::size_t envTriangles () const;
  /** \brief Bytes held by both BVH models (vertices, triangles, BV nodes, primitive indices). */
  std::size_t memoryBytes () const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Impl& impl () const;  // throws std::logic_error before build()
};

/** \brief A pose with its exact labels. */
struct PoseTruth
{
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  double signed_distance = 0.0;  ///< ExactMeshPair::signedDistance (T)
  bool collision = false;        ///< ExactMeshPair::collide (T)
};

/** \brief The library's portable standard normal draw (normal_distribution.h). */
using pcl_probcollision::detail::standardNormal;

/** \brief Uniform random rotation: unit quaternion of four standard normals. */
Eigen::Quaterniond uniformRotation (std::mt19937_64& rng);

/** \brief Seed of the independent stream of draw number index (splitmix64 of seed and index):
  * each pose depends on (seed, index) only, whatever the thread count. */
std::uint64_t streamSeed (std::uint64_t seed, std::uint64_t index);

/** \brief count uniform random rigid poses: rotation uniform about the centre of robot_box, that
  * centre uniform in env_box, i.e. T = Translation (p) * R * Translation (-robot_box.center ()).
  * Deterministic for a given seed. */
std::vector<Eigen::Isometry3d> uniformPoses (std::size_t count, const Eigen::AlignedBox3d& robot_box,
                                             const Eigen::AlignedBox3d& env_box, std::uint64_t seed);

/** \brief Labels the poses (signed distance and collision); threads > 1 splits the work. */
std::vector<PoseTruth> labelPoses (const ExactMeshPair& meshes, const std::vector<Eigen::Isometry3d>& poses,
                                   unsigned threads = 1);

/** \brief uniformPoses (count, meshes.robotBox (), meshes.envBox (), seed), labelled. */
std::vector<PoseTruth> uniformPoseTruths (const ExactMeshPair& meshes, std::size_t count, std::uint64_t seed,
                                          unsigned threads = 1);

/** \brief Settings of nearContactPoses(). */
struct NearContactOptions
{
  /** \brief Half-width of the band: every returned pose has |signed distance| <= band. */
  double band = 0.0;
  /** \brief A pose is accepted as soon as |signed distance - target| <= this; 0: 0.05 * band. */
  double target_tolerance = 0.0;
  /** \brief Signed-distance evaluations per attempt in the 1-D search. */
  int max_evaluations = 8;
  /** \brief Fresh starting poses tried per returned pose before giving up (std::runtime_error). */
  int max_attempts = 100;
  unsigned threads = 1;
};

/** \brief count poses near contact, the signed distance spread about uniformly over
  * [-band, band]. Each pose: a uniform pose (as uniformPoses); a target d* uniform in
  * [-band, band]; the robot then translated along the line of the closest points (for a
  * colliding start, first out along the penetration direction to contact), a 1-D secant /
  * bisection search on the translation for signedDistance = d*. On the free side this line is
  * exact: moving by s toward contact lowers the distance by exactly s. Accepted when within
  * target_tolerance of d*, otherwise the searched pose nearest d* with |sd| <= band, otherwise
  * a new start. Deterministic for a given seed, whatever options.threads. Throws
  * std::invalid_argument if band <= 0. */
std::vector<PoseTruth> nearContactPoses (const ExactMeshPair& meshes, std::size_t count, std::uint64_t seed,
                                         const NearContactOptions& options);
} // namespace pcl_probcollision_eval
