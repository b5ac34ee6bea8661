// SPDX-License-Identifier: BSD-3-Clause
// The shared test scenes (scenes.h). The arithmetic of each builder is exactly that of the test
// file it came from (operation order included): the tests' assertions were written for these
// values.
#include "scenes.h"

#include "seeded_draws.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pcl_probcollision_test
{
using pcl_probcollision::UncertainCloud;

CloudXYZ::Ptr
patch (double size, double h, double z, double sigma, unsigned seed, const Eigen::Vector3d& offset)
{
  std::mt19937 rng (seed);
  std::normal_distribution<double> noise (0.0, sigma);
  CloudXYZ::Ptr c (new CloudXYZ);
  const int n = static_cast<int> (std::round (size / h)) + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
    {
      // One declaration, three declarators: evaluated in order (x, y, z), as draw3 does.
      const double dx = sigma > 0 ? noise (rng) : 0.0, dy = sigma > 0 ? noise (rng) : 0.0, dz = sigma > 0 ? noise (rng) : 0.0;
      c->push_back (pcl::PointXYZ (static_cast<float> (offset.x () + i * h - size / 2 + dx),
                                   static_cast<float> (offset.y () + j * h - size / 2 + dy),
                                   static_cast<float> (offset.z () + z + dz)));
    }
  return c;
}

CloudXYZ::Ptr
organizedPatch (double size, double h, double z, double sigma, unsigned seed)
{
  CloudXYZ::Ptr c = patch (size, h, z, sigma, seed);
  const auto n = static_cast<std::uint32_t> (std::round (size / h)) + 1;
  c->width = n;
  c->height = n;
  return c;
}

CloudXYZ::Ptr
patchWithHole (int side, double h, const Eigen::Vector3d& centre, unsigned seed)
{
  std::mt19937 rng (seed);
  std::normal_distribution<double> noise (0.0, 0.0005);
  CloudXYZ::Ptr c (new CloudXYZ);
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
    {
      const Eigen::Vector3d e = draw3 (noise, rng);
      const Eigen::Vector3d p = centre + e + Eigen::Vector3d ((i - 0.5 * (side - 1)) * h, (j - 0.5 * (side - 1)) * h, 0.0);
      c->push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()), static_cast<float> (p.z ())));
    }
  (*c)[side + 1].x = std::numeric_limits<float>::quiet_NaN ();
  return c;
}

UncertainCloud
jitteredGrid (int side, double h, double sigma, unsigned seed)
{
  std::mt19937 rng (seed);
  std::normal_distribution<double> jitter (0.0, sigma);
  UncertainCloud c;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
    {
      const Eigen::Vector3d corner ((i - 0.5 * (side - 1)) * h, (j - 0.5 * (side - 1)) * h, 0.0);
      c.means.push_back (corner + draw3 (jitter, rng));
      c.covariances.push_back (Eigen::Matrix3d::Identity () * sigma * sigma);
      c.source_indices.push_back (j * side + i);
    }
  return c;
}

UncertainCloud
randomSheet (int n, double size, double height, double sigma, unsigned seed, const Eigen::Vector3d& offset)
{
  std::mt19937 rng (seed);
  std::uniform_real_distribution<double> u (-size / 2, size / 2);
  std::normal_distribution<double> dz (0.0, sigma);
  UncertainCloud c;
  for (int i = 0; i < n; ++i)
  {
    const double x = u (rng);  // one draw per statement: seeded_draws.h
    const double y = u (rng);
    c.means.push_back (offset + Eigen::Vector3d (x, y, height + dz (rng)));
    c.covariances.push_back (Eigen::Matrix3d::Identity () * sigma * sigma);
    c.source_indices.push_back (i);
  }
  return c;
}

const char*
shapeName (Shape shape)
{
  switch (shape)
  {
    case Shape::Box: return "Box";
    case Shape::Sphere: return "Sphere";
    case Shape::NoisyPlane: return "NoisyPlane";
  }
  return "?";
}

UncertainCloud
shapeCloud (Shape shape, std::size_t n, std::uint64_t seed, double sigma, bool weights)
{
  std::mt19937_64 rng (seed);
  std::uniform_real_distribution<double> u (-0.5, 0.5);
  std::normal_distribution<double> g (0.0, 1.0);
  UncertainCloud c;
  for (std::size_t i = 0; i < n; ++i)
  {
    Eigen::Vector3d x;
    switch (shape)
    {
      case Shape::Box: x = draw3 (u, rng); break;
      case Shape::Sphere:
      {
        const Eigen::Vector3d d = draw3 (g, rng);
        x = 0.5 * d.normalized () + 0.001 * draw3 (g, rng);
        break;
      }
      case Shape::NoisyPlane:
      {
        const double px = u (rng);
        const double py = 0.6 * u (rng);
        x = Eigen::Vector3d (px, py, 0.002 * g (rng));
        break;
      }
    }
    c.means.push_back (x);
    const Eigen::Matrix3d R = randomRotation (rng);
    const Eigen::Vector3d s = (sigma * (0.2 + 0.8 * (draw3 (u, rng).array () + 0.5))).matrix ();
    c.covariances.push_back (R * s.cwiseAbs2 ().asDiagonal () * R.transpose ());
    if (weights)
      c.area_weights.push_back (0.5 + (u (rng) + 0.5));
    c.source_indices.push_back (static_cast<int> (i));
  }
  return c;
}

UncertainCloud
transformCloud (const UncertainCloud& c, const Eigen::Isometry3d& T)
{
  UncertainCloud out = c;
  const Eigen::Matrix3d R = T.linear ();
  for (std::size_t i = 0; i < c.size (); ++i)
  {
    out.means[i] = T * c.means[i];
    out.covariances[i] = R * c.covariances[i] * R.transpose ();
  }
  return out;
}

Eigen::Matrix3d
randomRotation (std::mt19937_64& rng)
{
  std::normal_distribution<double> g (0.0, 1.0);
  const double w = g (rng);  // one draw per statement: seeded_draws.h
  const Eigen::Vector3d v = draw3 (g, rng);
  Eigen::Quaterniond q (w, v.x (), v.y (), v.z ());
  q.normalize ();
  return q.toRotationMatrix ();
}

Eigen::Isometry3d
randomPose (std::mt19937_64& rng, double translation_scale)
{
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity ();
  T.linear () = randomRotation (rng);
  T.translation () = translation_scale * draw3 (u, rng);
  return T;
}

Eigen::Isometry3d
randomAxisAnglePose (std::mt19937& rng, double translation)
{
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  const Eigen::Vector3d axis = draw3 (u, rng).normalized ();
  const Eigen::Vector3d t = translation * draw3 (u, rng);
  return Eigen::Translation3d (t) * Eigen::AngleAxisd (M_PI * u (rng), axis);
}

std::vector<Eigen::Isometry3d>
poseSweep (int n, unsigned seed)
{
  std::mt19937 rng (seed);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i)
  {
    const double x = 0.02 * u (rng);
    const double y = 0.02 * u (rng);
    const double z = 0.02 - 0.03 * i / std::max (1, n - 1);
    const Eigen::Vector3d axis = draw3 (u, rng).normalized ();
    const double angle = 0.2 * u (rng);
    poses.push_back (Eigen::Translation3d (x, y, z) * Eigen::AngleAxisd (angle, axis));
  }
  return poses;
}

Eigen::Matrix3d
iso (double sigma)
{
  return sigma * sigma * Eigen::Matrix3d::Identity ();
}

std::vector<Eigen::Vector3d>
fibonacci (int n)
{
  const double kPi = 3.14159265358979323846;
  std::vector<Eigen::Vector3d> p;
  const double golden = kPi * (3.0 - std::sqrt (5.0));
  for (int k = 0; k < n; ++k)
  {
    const double t = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt (1.0 - t * t), a = k * golden;
    p.emplace_back (t, r * std::cos (a), r * std::sin (a));
  }
  return p;
}

Eigen::Matrix3d
randomCovariance (std::mt19937_64& rng, double lo, double hi)
{
  const double kPi = 3.14159265358979323846;
  std::uniform_real_distribution<double> u (lo, hi);
  const Eigen::Vector3d s = draw3 (u, rng);  // one draw per statement: seeded_draws.h
  std::uniform_real_distribution<double> angle (0.0, 2.0 * kPi);
  const Eigen::Vector3d zyx = draw3 (angle, rng);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd (zyx (0), Eigen::Vector3d::UnitZ ()) *
                             Eigen::AngleAxisd (zyx (1), Eigen::Vector3d::UnitY ()) *
                             Eigen::AngleAxisd (zyx (2), Eigen::Vector3d::UnitX ()))
                                .toRotationMatrix ();
  return r * s.cwiseAbs2 ().asDiagonal () * r.transpose ();
}

void
genericPatches (ClassifierCloud& a, ClassifierCloud& b, std::uint64_t seed)
{
  std::mt19937_64 rng (seed);
  std::uniform_real_distribution<double> u (0.0, 1.0);
  a = ClassifierCloud ();
  b = ClassifierCloud ();
  for (int k = 0; k < 150; ++k)
  {
    const double x = u (rng), y = u (rng);
    const double z = 0.1 * x - 0.05 * y + 0.01 * u (rng);
    a.add (Eigen::Vector3d (x, y, z), randomCovariance (rng, 0.002, 0.02));
  }
  for (int k = 0; k < 90; ++k)
  {
    const double x = u (rng), y = u (rng);
    const double z = 0.1 * x - 0.05 * y + 0.06 + 0.01 * u (rng);
    b.add (Eigen::Vector3d (x, y, z), randomCovariance (rng, 0.002, 0.02));
  }
}

void
bowl (int n, double sigma, ClassifierCloud& ball, ClassifierCloud& cup)
{
  ball = ClassifierCloud ();
  cup = ClassifierCloud ();
  for (const Eigen::Vector3d& u : fibonacci (n))
    ball.add (0.3 * Eigen::Vector3d (u.y (), u.z (), u.x ()), iso (sigma));
  for (const Eigen::Vector3d& u : fibonacci (2 * n))
    if (u.x () < 0.0)
      cup.add (0.4 * Eigen::Vector3d (u.y (), u.z (), u.x ()), iso (sigma));
}

pcl_probcollision::ClassifierParams
oracle (pcl_probcollision::TrainingMode training)
{
  pcl_probcollision::ClassifierParams p;
  p.kernel = pcl_probcollision::KernelMode::Linear;
  p.training = training;
  p.C = 1e6;
  return p;
}

double
Phi (double z)
{
  return 0.5 * std::erfc (-z / std::sqrt (2.0));
}
} // namespace pcl_probcollision_test
