// SPDX-License-Identifier: BSD-3-Clause
#include "fit_scenes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

namespace pcl_probcollision_eval
{
namespace
{
using pcl_probcollision::io::TriangleMesh;

/** \brief Appends a closed box (centre, half extents, orientation) with outward triangles. */
void
addBox (TriangleMesh& mesh, const Eigen::Vector3d& center, const Eigen::Vector3d& half,
        const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity ())
{
  const int base = static_cast<int> (mesh.vertices.size ());
  for (int i = 0; i < 8; ++i)
  {
    const Eigen::Vector3d s ((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
    const Eigen::Vector3d v = center + R * s.cwiseProduct (half);
    mesh.vertices.push_back ({v.x (), v.y (), v.z ()});
  }
  // Corner i has bit 0 = +x, bit 1 = +y, bit 2 = +z; each face counter-clockwise from outside.
  static const std::array<std::array<int, 4>, 6> faces {{{0, 2, 3, 1},   // -z
                                                         {4, 5, 7, 6},   // +z
                                                         {0, 1, 5, 4},   // -y
                                                         {2, 6, 7, 3},   // +y
                                                         {0, 4, 6, 2},   // -x
                                                         {1, 3, 7, 5}}}; // +x
  for (const auto& f : faces)
  {
    mesh.triangles.push_back ({base + f[0], base + f[1], base + f[2]});
    mesh.triangles.push_back ({base + f[0], base + f[2], base + f[3]});
  }
}

Eigen::Matrix3d
aboutZ (double angle)
{
  return Eigen::AngleAxisd (angle, Eigen::Vector3d::UnitZ ()).toRotationMatrix ();
}
} // namespace

FitScene
makeFitScene (std::uint64_t seed)
{
  std::mt19937_64 rng (seed * 7919 + 17);
  auto uniform = [&] (double lo, double hi) { return std::uniform_real_distribution<double> (lo, hi) (rng); };
  FitScene scene;

  // The floor and its walls.
  const double half_x = uniform (2700.0, 3200.0), half_y = uniform (2700.0, 3200.0), floor_top = 15.0;
  addBox (scene.env, {0.0, 0.0, 0.0}, {half_x, half_y, floor_top});  // 30 mm thick, centred on z = 0
  const int walls = 2 + static_cast<int> (uniform (0.0, 2.0));
  for (int w = 0; w < walls; ++w)
  {
    const double t = uniform (10.0, 20.0);
    const Eigen::Vector3d half = w % 2 == 0 ? Eigen::Vector3d (half_x, t, 500.0) : Eigen::Vector3d (t, half_y, 500.0);
    const double sign = w < 2 ? 1.0 : -1.0;
    const Eigen::Vector3d c = w % 2 == 0 ? Eigen::Vector3d (0.0, sign * (half_y - t), floor_top + 500.0)
                                         : Eigen::Vector3d (sign * (half_x - t), 0.0, floor_top + 500.0);
    addBox (scene.env, c, half);
  }
  // Furniture, each piece in its own frame (turned about z), on the floor inside the walls and
  // clear of the pieces placed before it (its footprint's circle; up to 50 draws, else left out).
  struct Part
  {
    Eigen::Vector3d center, half;
  };
  std::vector<std::pair<Eigen::Vector2d, double>> placed;  // centre and footprint radius
  const int pieces = 6 + static_cast<int> (uniform (0.0, 4.0));
  for (int p = 0; p < pieces; ++p)
  {
    std::vector<Part> parts;
    switch (static_cast<int> (uniform (0.0, 4.0)))
    {
      case 0:  // table: a top on four legs
      {
        const double w = uniform (300.0, 700.0), d = uniform (250.0, 450.0), h = uniform (600.0, 800.0);
        const double top = uniform (12.0, 25.0), leg = uniform (20.0, 35.0);
        parts.push_back ({{0.0, 0.0, h - top}, {w, d, top}});
        for (const double sx : {-1.0, 1.0})
          for (const double sy : {-1.0, 1.0})
            parts.push_back ({{sx * (w - leg), sy * (d - leg), 0.5 * (h - 2.0 * top)}, {leg, leg, 0.5 * (h - 2.0 * top)}});
        break;
      }
      case 1:  // cabinet
      {
        const Eigen::Vector3d half (uniform (200.0, 500.0), uniform (150.0, 300.0), uniform (250.0, 500.0));
        parts.push_back ({{0.0, 0.0, half.z ()}, half});
        break;
      }
      case 2:  // low box
      {
        const Eigen::Vector3d half (uniform (150.0, 400.0), uniform (150.0, 400.0), uniform (60.0, 200.0));
        parts.push_back ({{0.0, 0.0, half.z ()}, half});
        break;
      }
      default:  // open shelf: two sides and three boards between them
      {
        const double w = uniform (300.0, 600.0), d = uniform (120.0, 200.0), h = uniform (400.0, 500.0);
        const double t = uniform (8.0, 15.0);
        for (const double sx : {-1.0, 1.0})
          parts.push_back ({{sx * (w - t), 0.0, h}, {t, d, h}});
        for (int b = 0; b < 3; ++b)
          parts.push_back ({{0.0, 0.0, t + b * (h - t)}, {w - 2.0 * t, d, t}});
        break;
      }
    }
    double radius = 0.0;
    for (const Part& part : parts)
      radius = std::max (radius, part.center.head<2> ().norm () + part.half.head<2> ().norm ());
    const Eigen::Matrix3d R = aboutZ (uniform (0.0, 2.0 * M_PI));
    for (int attempt = 0; attempt < 50; ++attempt)
    {
      const Eigen::Vector2d c (uniform (-half_x + radius + 100.0, half_x - radius - 100.0),
                               uniform (-half_y + radius + 100.0, half_y - radius - 100.0));
      bool clear = true;
      for (const auto& q : placed)
        clear = clear && (c - q.first).norm () > radius + q.second + 100.0;
      if (!clear)
        continue;
      placed.emplace_back (c, radius);
      for (const Part& part : parts)
        addBox (scene.env, Eigen::Vector3d (c.x (), c.y (), floor_top) + R * part.center, part.half, R);
      break;
    }
  }

  // The robot: a body on legs, an opened lid, a block on one side; centred near the origin.
  const Eigen::Vector3d body (uniform (350.0, 600.0), uniform (250.0, 450.0), uniform (100.0, 200.0));
  const double leg_height = uniform (250.0, 450.0), leg = uniform (25.0, 45.0);
  const double body_z = leg_height + body.z ();
  addBox (scene.robot, {0.0, 0.0, body_z}, body);
  const int legs = 3 + static_cast<int> (uniform (0.0, 2.0));
  const std::array<Eigen::Vector2d, 4> corners {{{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}};
  for (int l = 0; l < legs; ++l)
  {
    const Eigen::Vector2d c = legs == 3 && l == 2 ? Eigen::Vector2d (0.0, 1.0) : corners[static_cast<std::size_t> (l)];
    addBox (scene.robot, {c.x () * (body.x () - 2.0 * leg), c.y () * (body.y () - 2.0 * leg), 0.5 * leg_height},
            {leg, leg, 0.5 * leg_height});
  }
  // The lid: hinged on the body's top along its +y edge, its -y edge lifted by the angle.
  const double lid = uniform (7.5, 12.5), angle = uniform (15.0, 50.0) * M_PI / 180.0;
  const Eigen::Matrix3d R_lid = Eigen::AngleAxisd (-angle, Eigen::Vector3d::UnitX ()).toRotationMatrix ();
  const Eigen::Vector3d hinge (0.0, body.y (), body_z + body.z ());
  addBox (scene.robot, hinge + R_lid * Eigen::Vector3d (0.0, -body.y (), lid), {body.x (), body.y (), lid}, R_lid);
  // A block against the body's -x side.
  const Eigen::Vector3d block (uniform (60.0, 120.0), uniform (120.0, 0.8 * body.y ()), uniform (40.0, 0.8 * body.z ()));
  addBox (scene.robot, {-body.x () - block.x (), uniform (-0.2, 0.2) * body.y (), body_z - body.z () + block.z ()}, block);
  // Centre the robot's box on the origin (the poses turn it about its box centre anyway).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant (1e300), hi = -lo;
  for (const auto& v : scene.robot.vertices)
  {
    const Eigen::Vector3d p (v[0], v[1], v[2]);
    lo = lo.cwiseMin (p);
    hi = hi.cwiseMax (p);
  }
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  for (auto& v : scene.robot.vertices)
    for (int k = 0; k < 3; ++k)
      v[static_cast<std::size_t> (k)] -= mid (k);
  return scene;
}
} // namespace pcl_probcollision_eval
