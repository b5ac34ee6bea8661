// SPDX-License-Identifier: BSD-3-Clause
#include "baselines.h"

#include "mesh_sampling.h"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/octree/octree.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>

#include <flann/flann.hpp>

#include <octomap/OcTree.h>

#include <pcl/common/io.h>
#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/gp3.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace pcl_probcollision_eval
{
namespace detail
{
// Defined in ground_truth.cpp.
std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> makeObbrssModel (const TriangleMesh& mesh, Eigen::AlignedBox3d* box,
                                                              std::size_t* bytes);
bool fclCollide (const fcl::CollisionGeometryd* a, const Eigen::Isometry3d& ta, const fcl::CollisionGeometryd* b,
                 const Eigen::Isometry3d& tb);
} // namespace detail

namespace
{
bool
finite (const pcl::PointXYZ& p)
{
  return std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z);
}
} // namespace

// ---------------------------------------------------------------------------------------------
struct OctomapBaseline::Impl
{
  double resolution = 0.0;
  std::shared_ptr<octomap::OcTree> env_tree, robot_tree;
  std::shared_ptr<fcl::OcTreed> env, robot_cloud;
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> robot_mesh;
  std::size_t robot_mesh_bytes = 0;
};

namespace
{
std::shared_ptr<octomap::OcTree>
makeOcTree (const CloudXYZ& cloud, double resolution)
{
  auto tree = std::make_shared<octomap::OcTree> (resolution);
  // One hit per occupied voxel (log-odds of 0.7, above the 0.5 occupancy threshold): the set of
  // keys first, since updating a voxel once per point is many times slower on dense clouds.
  octomap::KeySet keys;
  for (const auto& p : cloud.points)
  {
    octomap::OcTreeKey key;
    if (finite (p) && tree->coordToKeyChecked (p.x, p.y, p.z, key))
      keys.insert (key);
  }
  for (const auto& key : keys)
    tree->updateNode (key, true, true);  // lazy: inner nodes once below
  tree->updateInnerOccupancy ();
  tree->prune ();
  return tree;
}

std::size_t
occupiedLeaves (const octomap::OcTree* tree)
{
  if (!tree)
    return 0;
  std::size_t n = 0;
  for (auto it = tree->begin_leafs (), end = tree->end_leafs (); it != end; ++it)
    n += tree->isNodeOccupied (*it) ? 1 : 0;
  return n;
}
} // namespace

OctomapBaseline::OctomapBaseline () : impl_ (std::make_unique<Impl> ()) {}
OctomapBaseline::~OctomapBaseline () = default;
OctomapBaseline::OctomapBaseline (OctomapBaseline&&) noexcept = default;
OctomapBaseline& OctomapBaseline::operator= (OctomapBaseline&&) noexcept = default;

void
OctomapBaseline::buildEnv (const CloudXYZ& env, double resolution)
{
  if (!(resolution > 0.0) || !std::isfinite (resolution))
    throw std::invalid_argument ("OctomapBaseline: the resolution must be positive and finite");
  impl_->resolution = resolution;
  impl_->env_tree = makeOcTree (env, resolution);
  impl_->env = std::make_shared<fcl::OcTreed> (impl_->env_tree);
  impl_->robot_tree.reset ();
  impl_->robot_cloud.reset ();
}

void
OctomapBaseline::setRobotMesh (const TriangleMesh& robot)
{
  impl_->robot_mesh = detail::makeObbrssModel (robot, nullptr, &impl_->robot_mesh_bytes);
}

void
OctomapBaseline::buildRobotCloud (const CloudXYZ& robot)
{
  if (!impl_->env)
    throw std::logic_error ("OctomapBaseline: buildRobotCloud before buildEnv");
  impl_->robot_tree = makeOcTree (robot, impl_->resolution);
  impl_->robot_cloud = std::make_shared<fcl::OcTreed> (impl_->robot_tree);
}

bool
OctomapBaseline::collideMesh (const Eigen::Isometry3d& T) const
{
  if (!impl_->env || !impl_->robot_mesh)
    throw std::logic_error ("OctomapBaseline: collideMesh needs buildEnv and setRobotMesh");
  return detail::fclCollide (impl_->env.get (), Eigen::Isometry3d::Identity (), impl_->robot_mesh.get (), T);
}

bool
OctomapBaseline::collideCloud (const Eigen::Isometry3d& T) const
{
  if (!impl_->env || !impl_->robot_cloud)
    throw std::logic_error ("OctomapBaseline: collideCloud needs buildEnv and buildRobotCloud");
  return detail::fclCollide (impl_->env.get (), Eigen::Isometry3d::Identity (), impl_->robot_cloud.get (), T);
}

double
OctomapBaseline::resolution () const
{
  return impl_->resolution;
}

std::size_t
OctomapBaseline::envMemoryBytes () const
{
  return impl_->env_tree ? impl_->env_tree->memoryUsage () : 0;
}

std::size_t
OctomapBaseline::robotCloudMemoryBytes () const
{
  return impl_->robot_tree ? impl_->robot_tree->memoryUsage () : 0;
}

std::size_t
OctomapBaseline::robotMeshMemoryBytes () const
{
  return impl_->robot_mesh ? impl_->robot_mesh_bytes : 0;
}

std::size_t
OctomapBaseline::envOccupiedLeaves () const
{
  return occupiedLeaves (impl_->env_tree.get ());
}

std::size_t
OctomapBaseline::robotOccupiedLeaves () const
{
  return occupiedLeaves (impl_->robot_tree.get ());
}

// ---------------------------------------------------------------------------------------------
struct NearestNeighbourBaseline::Impl
{
  using Index = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  std::vector<float> env;             // row-major n x 3; the index points into it
  std::vector<Eigen::Vector3d> robot; // robot frame
  std::unique_ptr<Index> index;

  static constexpr std::size_t batch = 256;

  // Smallest squared distance below cap_sq (else +inf); stops at the first batch with a hit
  // when stop_at_first.
  double
  search (const Eigen::Isometry3d& T, double cap_sq, bool stop_at_first) const
  {
    std::vector<float> q (batch * 3);
    std::vector<std::size_t> idx (batch);
    std::vector<float> dist (batch);
    flann::SearchParams params;
    params.checks = flann::FLANN_CHECKS_UNLIMITED;
    params.eps = 0.0f;
    params.sorted = false;
    params.max_neighbors = 1;
    params.cores = 1;
    double best = cap_sq;
    bool found = false;
    for (std::size_t start = 0; start < robot.size (); start += batch)
    {
      const std::size_t rows = std::min (batch, robot.size () - start);
      for (std::size_t i = 0; i < rows; ++i)
      {
        const Eigen::Vector3d p = T * robot[start + i];
        q[3 * i] = static_cast<float> (p.x ());
        q[3 * i + 1] = static_cast<float> (p.y ());
        q[3 * i + 2] = static_cast<float> (p.z ());
      }
      flann::Matrix<float> queries (q.data (), rows, 3);
      flann::Matrix<std::size_t> indices (idx.data (), rows, 1);
      flann::Matrix<float> dists (dist.data (), rows, 1);
      // The radius bounds the kd-tree descent: once a near pair is known, farther points cost
      // little. Squared, as L2_Simple's distances are.
      const float radius = std::isfinite (best) ? static_cast<float> (best) : std::numeric_limits<float>::infinity ();
      index->radiusSearch (queries, indices, dists, radius, params);
      for (std::size_t i = 0; i < rows; ++i)
        if (idx[i] != static_cast<std::size_t> (-1) && dist[i] < best)
        {
          best = dist[i];
          found = true;
        }
      if (found && stop_at_first)
        break;
    }
    return found ? best : std::numeric_limits<double>::infinity ();
  }
};

NearestNeighbourBaseline::NearestNeighbourBaseline () = default;
NearestNeighbourBaseline::~NearestNeighbourBaseline () = default;
NearestNeighbourBaseline::NearestNeighbourBaseline (NearestNeighbourBaseline&&) noexcept = default;
NearestNeighbourBaseline& NearestNeighbourBaseline::operator= (NearestNeighbourBaseline&&) noexcept = default;

void
NearestNeighbourBaseline::build (const CloudXYZ& env, const CloudXYZ& robot)
{
  auto impl = std::make_unique<Impl> ();
  impl->env.reserve (3 * env.size ());
  for (const auto& p : env.points)
    if (finite (p))
      impl->env.insert (impl->env.end (), {p.x, p.y, p.z});
  for (const auto& p : robot.points)
    if (finite (p))
      impl->robot.emplace_back (p.x, p.y, p.z);
  if (impl->env.empty () || impl->robot.empty ())
    throw std::invalid_argument ("NearestNeighbourBaseline: a cloud has no finite point");
  flann::Matrix<float> data (impl->env.data (), impl->env.size () / 3, 3);
  impl->index = std::make_unique<Impl::Index> (data, flann::KDTreeSingleIndexParams (10));
  impl->index->buildIndex ();
  impl_ = std::move (impl);
}

double
NearestNeighbourBaseline::minDistance (const Eigen::Isometry3d& T, double cap) const
{
  if (!impl_)
    throw std::logic_error ("NearestNeighbourBaseline: query before build()");
  const double cap_sq = std::isfinite (cap) ? cap * cap : std::numeric_limits<double>::infinity ();
  return std::sqrt (impl_->search (T, cap_sq, false));
}

bool
NearestNeighbourBaseline::within (const Eigen::Isometry3d& T, double r) const
{
  if (!impl_)
    throw std::logic_error ("NearestNeighbourBaseline: query before build()");
  return std::isfinite (impl_->search (T, r * r, true));
}

std::size_t
NearestNeighbourBaseline::envPoints () const
{
  return impl_ ? impl_->env.size () / 3 : 0;
}

std::size_t
NearestNeighbourBaseline::robotPoints () const
{
  return impl_ ? impl_->robot.size () : 0;
}

std::size_t
NearestNeighbourBaseline::memoryBytes () const
{
  if (!impl_)
    return 0;
  return static_cast<std::size_t> (impl_->index->usedMemory ()) + impl_->env.size () * sizeof (float) +
         impl_->robot.size () * sizeof (Eigen::Vector3d);
}

// ---------------------------------------------------------------------------------------------
TriangleMesh
reconstructMesh (const CloudXYZ& cloud, const ReconstructionParams& params, double* used_search_radius)
{
  CloudXYZ::Ptr points (new CloudXYZ);
  for (const auto& p : cloud.points)
    if (finite (p))
      points->push_back (p);
  if (points->size () < 3)
    throw std::invalid_argument ("reconstructMesh: fewer than 3 finite points");

  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree (new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> normal_estimation;
  normal_estimation.setInputCloud (points);
  normal_estimation.setSearchMethod (tree);
  normal_estimation.setKSearch (params.normal_k);
  pcl::PointCloud<pcl::Normal> normals;
  normal_estimation.compute (normals);

  // Points whose normal could not be estimated (too few neighbours) would poison the projection.
  pcl::PointCloud<pcl::PointNormal>::Ptr with_normals (new pcl::PointCloud<pcl::PointNormal>);
  pcl::PointCloud<pcl::PointNormal> all;
  pcl::concatenateFields (*points, normals, all);
  for (const auto& p : all.points)
    if (std::isfinite (p.normal_x) && std::isfinite (p.normal_y) && std::isfinite (p.normal_z))
      with_normals->push_back (p);

  const double radius = params.search_radius > 0.0
                            ? params.search_radius
                            : params.radius_factor * pcl_probcollision::io::medianSpacing (*points);
  if (used_search_radius)
    *used_search_radius = radius;
  TriangleMesh mesh;
  for (const auto& p : with_normals->points)
    mesh.vertices.push_back ({p.x, p.y, p.z});
  if (!(radius > 0.0) || with_normals->size () < 3)
    return mesh;

  pcl::search::KdTree<pcl::PointNormal>::Ptr tree2 (new pcl::search::KdTree<pcl::PointNormal>);
  pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
  gp3.setSearchRadius (radius);
  gp3.setMu (params.mu);
  gp3.setMaximumNearestNeighbors (params.max_nearest_neighbors);
  gp3.setMaximumSurfaceAngle (params.max_surface_angle);
  gp3.setMinimumAngle (params.min_angle);
  gp3.setMaximumAngle (params.max_angle);
  gp3.setNormalConsistency (params.normal_consistency);
  gp3.setInputCloud (with_normals);
  gp3.setSearchMethod (tree2);
  std::vector<pcl::Vertices> polygons;
  gp3.reconstruct (polygons);
  for (const auto& poly : polygons)
    if (poly.vertices.size () == 3)
      mesh.triangles.push_back ({static_cast<int> (poly.vertices[0]), static_cast<int> (poly.vertices[1]),
                                 static_cast<int> (poly.vertices[2])});
  return mesh;
}

void
ReconstructBaseline::build (const CloudXYZ& robot, const CloudXYZ& env, const ReconstructionParams& params)
{
  robot_mesh_ = reconstructMesh (robot, params);
  env_mesh_ = reconstructMesh (env, params);
  if (robot_mesh_.triangles.empty () || env_mesh_.triangles.empty ())
    throw std::runtime_error ("ReconstructBaseline: a reconstruction has no triangle");
  meshes_.build (robot_mesh_, env_mesh_);
}
} // namespace pcl_probcollision_eval
