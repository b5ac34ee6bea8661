// SPDX-License-Identifier: BSD-3-Clause
#include "ground_truth.h"

#include <pcl_probcollision/normal_distribution.h>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

namespace pcl_probcollision_eval
{
namespace detail
{
// Shared with baselines.cpp (declared there): the one place meshes become FCL models.
std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>>
makeObbrssModel (const TriangleMesh& mesh, Eigen::AlignedBox3d* box, std::size_t* bytes)
{
  if (mesh.triangles.empty ())
    throw std::invalid_argument ("ExactMeshPair: a mesh has no triangle");
  std::vector<fcl::Vector3d> vertices;
  vertices.reserve (mesh.vertices.size ());
  for (const auto& v : mesh.vertices)
    vertices.emplace_back (v[0], v[1], v[2]);
  std::vector<fcl::Triangle> triangles;
  triangles.reserve (mesh.triangles.size ());
  Eigen::AlignedBox3d b;
  const auto n = static_cast<int> (vertices.size ());
  for (const auto& t : mesh.triangles)
  {
    for (const int i : t)
    {
      if (i < 0 || i >= n)
        throw std::invalid_argument ("ExactMeshPair: a triangle refers to a missing vertex");
      b.extend (vertices[static_cast<std::size_t> (i)]);
    }
    triangles.emplace_back (t[0], t[1], t[2]);
  }
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>> ();
  model->beginModel (static_cast<int> (triangles.size ()), n);
  model->addSubModel (vertices, triangles);
  model->endModel ();
  model->computeLocalAABB ();
  if (box)
    *box = b;
  if (bytes)
    *bytes = sizeof (*model) + static_cast<std::size_t> (model->num_vertices) * sizeof (fcl::Vector3d) +
             static_cast<std::size_t> (model->num_tris) * (sizeof (fcl::Triangle) + sizeof (unsigned int)) +
             static_cast<std::size_t> (model->getNumBVs ()) * sizeof (fcl::BVNode<fcl::OBBRSSd>);
  return model;
}

bool
fclCollide (const fcl::CollisionGeometryd* a, const Eigen::Isometry3d& ta, const fcl::CollisionGeometryd* b,
            const Eigen::Isometry3d& tb)
{
  // Default request: one contact, no contact points, no cost sources: stops at the first hit.
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide (a, ta, b, tb, request, result);
  return result.isCollision ();
}
} // namespace detail

namespace
{
Eigen::Isometry3d
translated (const Eigen::Isometry3d& T, const Eigen::Vector3d& t)
{
  Eigen::Isometry3d out = T;
  out.translation () += t;
  return out;
}

std::vector<Eigen::Vector3d>
makeDirections ()
{
  std::vector<Eigen::Vector3d> d;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z)
          d.push_back (Eigen::Vector3d (x, y, z).normalized ());
  const double phi = 0.5 * (1.0 + std::sqrt (5.0));
  for (const double a : {1.0, 1.0 / phi})  // icosahedron (0, 1, phi), dodecahedron (0, 1/phi, phi)
    for (const double s1 : {-1.0, 1.0})
      for (const double s2 : {-1.0, 1.0})
      {
        const double p = s1 * a, q = s2 * phi;
        d.push_back (Eigen::Vector3d (0.0, p, q).normalized ());
        d.push_back (Eigen::Vector3d (p, q, 0.0).normalized ());
        d.push_back (Eigen::Vector3d (q, 0.0, p).normalized ());
      }
  return d;
}

template <typename F>
void
parallelFor (std::size_t count, unsigned threads, const F& f)
{
  threads = std::max (1u, std::min<unsigned> (threads, static_cast<unsigned> (std::max<std::size_t> (count, 1))));
  if (threads == 1)
  {
    for (std::size_t i = 0; i < count; ++i)
      f (i);
    return;
  }
  std::vector<std::exception_ptr> errors (threads);
  std::vector<std::thread> pool;
  for (unsigned k = 0; k < threads; ++k)
    pool.emplace_back ([&, k] {
      try
      {
        for (std::size_t i = k; i < count; i += threads)
          f (i);
      }
      catch (...)
      {
        errors[k] = std::current_exception ();
      }
    });
  for (auto& t : pool)
    t.join ();
  for (const auto& e : errors)
    if (e)
      std::rethrow_exception (e);
}

Eigen::Isometry3d
uniformPose (std::mt19937_64& rng, const Eigen::AlignedBox3d& robot_box, const Eigen::AlignedBox3d& env_box)
{
  const Eigen::Quaterniond q = uniformRotation (rng);
  Eigen::Vector3d u;
  for (int k = 0; k < 3; ++k)
    u[k] = pcl_probcollision::detail::uniformUnit (rng);
  const Eigen::Vector3d p = env_box.min () + env_box.sizes ().cwiseProduct (u);
  return Eigen::Translation3d (p) * q * Eigen::Translation3d (-robot_box.center ());
}
} // namespace

// ---------------------------------------------------------------------------------------------
struct ExactMeshPair::Impl
{
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> robot, env;
  Eigen::AlignedBox3d robot_box, env_box;
  std::size_t bytes = 0;
  double tolerance = 0.0;

  bool
  collide (const Eigen::Isometry3d& T) const
  {
    return detail::fclCollide (env.get (), Eigen::Isometry3d::Identity (), robot.get (), T);
  }
};

ExactMeshPair::ExactMeshPair () = default;
ExactMeshPair::ExactMeshPair (const TriangleMesh& robot, const TriangleMesh& env) { build (robot, env); }
ExactMeshPair::~ExactMeshPair () = default;
ExactMeshPair::ExactMeshPair (ExactMeshPair&&) noexcept = default;
ExactMeshPair& ExactMeshPair::operator= (ExactMeshPair&&) noexcept = default;

void
ExactMeshPair::build (const TriangleMesh& robot, const TriangleMesh& env)
{
  auto impl = std::make_unique<Impl> ();
  std::size_t robot_bytes = 0, env_bytes = 0;
  impl->robot = detail::makeObbrssModel (robot, &impl->robot_box, &robot_bytes);
  impl->env = detail::makeObbrssModel (env, &impl->env_box, &env_bytes);
  impl->bytes = robot_bytes + env_bytes;
  impl->tolerance = 1e-4 * impl->robot_box.diagonal ().norm ();
  if (!(impl->tolerance > 0.0))
    impl->tolerance = 1e-4 * std::max (1.0, impl->env_box.diagonal ().norm ());
  impl_ = std::move (impl);
}

bool
ExactMeshPair::built () const
{
  return static_cast<bool> (impl_);
}

const ExactMeshPair::Impl&
ExactMeshPair::impl () const
{
  if (!impl_)
    throw std::logic_error ("ExactMeshPair: query before build()");
  return *impl_;
}

bool
ExactMeshPair::collide (const Eigen::Isometry3d& T) const
{
  return impl ().collide (T);
}

double
ExactMeshPair::distance (const Eigen::Isometry3d& T, Eigen::Vector3d* point_on_robot, Eigen::Vector3d* point_on_env) const
{
  const Impl& m = impl ();
  // rel_err = abs_err = 0: exact for separated meshes (triangle-triangle distances, RSS bounds).
  fcl::DistanceRequestd request (point_on_robot || point_on_env);
  fcl::DistanceResultd result;
  fcl::distance (m.env.get (), Eigen::Isometry3d::Identity (), m.robot.get (), T, request, result);
  // FCL 0.7 returns the nearest points in the world frame, here the env frame; o1 is the env.
  if (point_on_env)
    *point_on_env = result.nearest_points[0];
  if (point_on_robot)
    *point_on_robot = result.nearest_points[1];
  return std::max (0.0, result.min_distance);
}

double
ExactMeshPair::penetrationDepth (const Eigen::Isometry3d& T, Eigen::Vector3d* direction) const
{
  const Impl& m = impl ();
  if (direction)
    direction->setZero ();
  if (!m.collide (T))
    return 0.0;
  const double tol = m.tolerance;
  // Beyond this every translation separates the bounding spheres: a safe end to the outward march.
  const Eigen::Vector3d robot_centre = T * m.robot_box.center ();
  const double limit = 2.0 * ((robot_centre - m.env_box.center ()).norm () + 0.5 * m.robot_box.diagonal ().norm () +
                              0.5 * m.env_box.diagonal ().norm ()) +
                       tol;
  const double first_step = std::max (tol, m.robot_box.diagonal ().norm () / 64.0);
  double best = std::numeric_limits<double>::infinity ();
  Eigen::Vector3d best_dir = Eigen::Vector3d::Zero ();
  // Shortest separating translation along u, kept when shorter than the best so far.
  auto tryDirection = [&] (const Eigen::Vector3d& u) {
    double lo = 0.0, hi;
    if (std::isfinite (best))
    {
      // Only a direction already free at the best length so far can improve on it: one query
      // prunes most directions.
      if (m.collide (translated (T, best * u)))
        return false;
      hi = best;
      // Improvements are mostly small: bracket the top eighth first (three bisection steps for one).
      if (m.collide (translated (T, 0.875 * best * u)))
        lo = 0.875 * best;
      else
        hi = 0.875 * best;
    }
    else
    {
      hi = first_step;
      while (hi <= limit && m.collide (translated (T, hi * u)))
      {
        lo = hi;
        hi *= 2.0;
      }
      if (hi > limit)
        return false;
    }
    while (hi - lo > tol)
    {
      const double mid = 0.5 * (lo + hi);
      if (m.collide (translated (T, mid * u)))
        lo = mid;
      else
        hi = mid;
    }
    if (hi >= best)
      return false;
    const bool significant = hi < best - tol;  // moves the pattern search's centre
    best = hi;
    best_dir = u;
    return significant;
  };
  for (const Eigen::Vector3d& u : penetrationDirections ())
    tryDirection (u);
  // Pattern search around the best direction: 8 directions on a cone, the cone halved from
  // about 11 degrees down to under 1 degree; the centre moves to any direction that improves.
  if (std::isfinite (best))
    for (double angle = 0.2; angle > 0.01; angle *= 0.5)
      for (int moves = 0; moves < 4; ++moves)
      {
        const Eigen::Vector3d c = best_dir;
        const Eigen::Vector3d e1 = c.unitOrthogonal (), e2 = c.cross (e1);
        bool improved = false;
        for (int k = 0; k < 8; ++k)
        {
          const double phi = 0.7853981633974483 * k;
          improved |= tryDirection (
              (std::cos (angle) * c + std::sin (angle) * (std::cos (phi) * e1 + std::sin (phi) * e2)).normalized ());
        }
        if (!improved)
          break;
      }
  if (!std::isfinite (best))
    best = limit;  // unreachable for finite meshes; keeps the bound meaningful
  if (direction)
    *direction = best_dir;
  return best;
}

double
ExactMeshPair::signedDistance (const Eigen::Isometry3d& T) const
{
  if (impl ().collide (T))
    return -penetrationDepth (T);
  return distance (T);
}

double
ExactMeshPair::penetrationTolerance () const
{
  return impl ().tolerance;
}

void
ExactMeshPair::setPenetrationTolerance (double tolerance)
{
  if (!(tolerance > 0.0) || !std::isfinite (tolerance))
    throw std::invalid_argument ("ExactMeshPair: the penetration tolerance must be positive and finite");
  if (!impl_)
    throw std::logic_error ("ExactMeshPair: setPenetrationTolerance before build()");
  impl_->tolerance = tolerance;
}

const std::vector<Eigen::Vector3d>&
ExactMeshPair::penetrationDirections ()
{
  static const std::vector<Eigen::Vector3d> directions = makeDirections ();
  return directions;
}

const Eigen::AlignedBox3d&
ExactMeshPair::robotBox () const
{
  return impl ().robot_box;
}

const Eigen::AlignedBox3d&
ExactMeshPair::envBox () const
{
  return impl ().env_box;
}

std::size_t
ExactMeshPair::robotTriangles () const
{
  return static_cast<std::size_t> (impl ().robot->num_tris);
}

std::size_t
ExactMeshPair::envTriangles () const
{
  return static_cast<std::size_t> (impl ().env->num_tris);
}

std::size_t
ExactMeshPair::memoryBytes () const
{
  return impl ().bytes;
}

// ---------------------------------------------------------------------------------------------
Eigen::Quaterniond
uniformRotation (std::mt19937_64& rng)
{
  // An isotropic 4-D Gaussian normalised is uniform on S^3, i.e. a uniform rotation.
  for (;;)
  {
    Eigen::Vector4d v;
    for (int k = 0; k < 4; ++k)
      v[k] = standardNormal (rng);
    const double n = v.norm ();
    if (n > 1e-12)
      return Eigen::Quaterniond (v[0] / n, v[1] / n, v[2] / n, v[3] / n);
  }
}

std::uint64_t
streamSeed (std::uint64_t seed, std::uint64_t index)
{
  std::uint64_t z = seed + (index + 1) * 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::vector<Eigen::Isometry3d>
uniformPoses (std::size_t count, const Eigen::AlignedBox3d& robot_box, const Eigen::AlignedBox3d& env_box,
              std::uint64_t seed)
{
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve (count);
  for (std::size_t i = 0; i < count; ++i)
  {
    std::mt19937_64 rng (streamSeed (seed, i));
    poses.push_back (uniformPose (rng, robot_box, env_box));
  }
  return poses;
}

std::vector<PoseTruth>
labelPoses (const ExactMeshPair& meshes, const std::vector<Eigen::Isometry3d>& poses, unsigned threads)
{
  std::vector<PoseTruth> out (poses.size ());
  parallelFor (poses.size (), threads, [&] (std::size_t i) {
    out[i].T = poses[i];
    out[i].signed_distance = meshes.signedDistance (poses[i]);
    out[i].collision = out[i].signed_distance < 0.0;  // negative exactly when collide()
  });
  return out;
}

std::vector<PoseTruth>
uniformPoseTruths (const ExactMeshPair& meshes, std::size_t count, std::uint64_t seed, unsigned threads)
{
  return labelPoses (meshes, uniformPoses (count, meshes.robotBox (), meshes.envBox (), seed), threads);
}

namespace
{
// One near-contact pose from one stream; false when every attempt failed.
bool
nearContactPose (const ExactMeshPair& meshes, std::mt19937_64& rng, const NearContactOptions& o, double tol,
                 PoseTruth& out)
{
  for (int attempt = 0; attempt < o.max_attempts; ++attempt)
  {
    Eigen::Isometry3d base = uniformPose (rng, meshes.robotBox (), meshes.envBox ());
    const double target = o.band * (2.0 * pcl_probcollision::detail::uniformUnit (rng) - 1.0);

    // A start pose `base` at exact distance d0 >= 0 and the unit direction n of its closest
    // points: translating by s * n (s <= d0) leaves the distance exactly d0 - s, since the closest
    // pair closes by s and no pair can close faster than the translation.
    Eigen::Vector3d out_dir;
    const double depth = meshes.penetrationDepth (base, &out_dir);
    if (depth > 0.0)
      base = translated (base, depth * out_dir);  // just free (bisection ends on the free side)
    Eigen::Vector3d p_robot, p_env;
    const double d0 = meshes.distance (base, &p_robot, &p_env);
    Eigen::Vector3d n;
    if (d0 > 0.0 && (p_env - p_robot).norm () > 0.0)
      n = (p_env - p_robot).normalized ();
    else if (out_dir.squaredNorm () > 0.0)
      n = -out_dir;
    else
      continue;  // touching with no usable direction: draw another start
    auto signedAt = [&] (double s) { return meshes.signedDistance (translated (base, s * n)); };

    bool have = false;
    PoseTruth best;
    auto consider = [&] (double s, double sd) {
      if (std::abs (sd) <= o.band && (!have || std::abs (sd - target) < std::abs (best.signed_distance - target)))
      {
        best.T = translated (base, s * n);
        best.signed_distance = sd;
        best.collision = sd < 0.0;
        have = true;
      }
    };

    // 1-D search on g(s) = sd(s) - target, which decreases in s near contact (s moves inward).
    // Known without a query: g(0) = d0 - target and, at contact, g(d0) ~ -target.
    double pos_s = 0.0, pos_g = 0.0, neg_s = 0.0, neg_g = 0.0;
    bool has_pos = false, has_neg = false;
    auto record = [&] (double s, double g) {
      if (g > 0.0)
      {
        if (!has_pos || s > pos_s)
          pos_s = s, pos_g = g;
        has_pos = true;
      }
      else
      {
        if (!has_neg || s < neg_s)
          neg_s = s, neg_g = g;
        has_neg = true;
      }
    };
    record (0.0, d0 - target);
    if (target < 0.0)
      record (d0, -target);
    double s = d0 - target;  // exact whenever 0 <= target <= d0
    for (int k = 0; k < o.max_evaluations; ++k)
    {
      const double sd = signedAt (s);
      consider (s, sd);
      const double g = sd - target;
      if (std::abs (g) <= tol)
        break;
      record (s, g);
      if (has_pos && has_neg && neg_s > pos_s)
      {
        // Regula falsi inside the bracket, kept off its ends so that it always shrinks.
        const double w = std::clamp (pos_g / (pos_g - neg_g), 0.1, 0.9);
        s = pos_s + w * (neg_s - pos_s);
      }
      else
        s += g;  // slope -1 (exact on the free side): step by the remaining error
    }
    if (have)
    {
      out = best;
      return true;
    }
  }
  return false;
}
} // namespace

std::vector<PoseTruth>
nearContactPoses (const ExactMeshPair& meshes, std::size_t count, std::uint64_t seed, const NearContactOptions& options)
{
  if (!(options.band > 0.0) || !std::isfinite (options.band))
    throw std::invalid_argument ("nearContactPoses: band must be positive and finite");
  const double tol = options.target_tolerance > 0.0 ? options.target_tolerance : 0.05 * options.band;
  std::vector<PoseTruth> out (count);
  // A stream apart from uniformPoses' with the same seed.
  const std::uint64_t base_seed = streamSeed (seed, 0x6e656172636f6e74ull);
  parallelFor (count, options.threads, [&] (std::size_t i) {
    std::mt19937_64 rng (streamSeed (base_seed, i));
    if (!nearContactPose (meshes, rng, options, tol, out[i]))
      throw std::runtime_error ("nearContactPoses: no pose within the band after " +
                                std::to_string (options.max_attempts) + " attempts (pose " + std::to_string (i) + ")");
  });
  return out;
}
} // namespace pcl_probcollision_eval
