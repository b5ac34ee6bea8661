// SPDX-License-Identifier: BSD-3-Clause
// Seeded test scenes shared by the test programs (compiled once, in test/scenes.cpp).
//
// Every builder is a pure function of its arguments: the same seed gives the same points with
// every compiler and standard library version we build with (one draw per statement,
// seeded_draws.h). Tests assert on these exact scenes, so a builder's values never change: a
// test that needs another scene gets another builder, under its own name.
#pragma once

#include <pcl_probcollision/robust_classifier.h>
#include <pcl_probcollision/uncertain_points.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace pcl_probcollision_test
{
using CloudXYZ = pcl::PointCloud<pcl::PointXYZ>;

// ---------------------------------------------------------------------------------------------
// PointXYZ clouds, the input of ProbabilisticCollision

/** \brief A square patch of side `size` (metres) in the plane at height z: a grid of
  * (round(size / h) + 1)^2 points with spacing h, centred on (0, 0) plus `offset`, row by row
  * (x fastest), each moved by Gaussian noise sigma on x, y and z (std::mt19937 seeded with
  * `seed`; no draw when sigma is 0). Unorganized (one row). The offset is added in double,
  * before rounding to float, as a scan stored in a map frame would be. */
CloudXYZ::Ptr
patch (double size, double h, double z, double sigma, unsigned seed,
       const Eigen::Vector3d& offset = Eigen::Vector3d::Zero ());

/** \brief The points of patch (size, h, z, sigma, seed) as an organized cloud: width = height =
  * round(size / h) + 1. */
CloudXYZ::Ptr
organizedPatch (double size, double h, double z, double sigma, unsigned seed);

/** \brief A side x side grid of spacing h in the plane z = centre.z, centred on `centre`, each
  * point moved by Gaussian noise of 0.5 mm on x, y and z (std::mt19937 seeded with `seed`), and
  * point side + 1 (second row, second column) made NaN. Unorganized, is_dense left true. */
CloudXYZ::Ptr
patchWithHole (int side, double h, const Eigen::Vector3d& centre, unsigned seed);

// ---------------------------------------------------------------------------------------------
// UncertainCloud: Gaussians given directly, for collide() on CloudModel and for the hierarchy

/** \brief A side x side grid of spacing h at z = 0 centred on the origin, each point moved by
  * Gaussian jitter sigma on x, y and z and given the covariance sigma^2 I (std::mt19937 seeded
  * with `seed`); source indices 0 .. side^2 - 1. */
pcl_probcollision::UncertainCloud
jitteredGrid (int side, double h, double sigma, unsigned seed);

/** \brief n Gaussians on a noisy horizontal sheet: x and y uniform in [-size / 2, size / 2],
  * z = height + N(0, sigma^2), covariance sigma^2 I, all plus `offset` (std::mt19937 seeded with
  * `seed`); source indices 0 .. n - 1. */
pcl_probcollision::UncertainCloud
randomSheet (int n, double size, double height, double sigma, unsigned seed,
             const Eigen::Vector3d& offset = Eigen::Vector3d::Zero ());

/** \brief The shapes of shapeCloud(). */
enum class Shape
{
  Box,
  Sphere,
  NoisyPlane
};

/** \brief "Box", "Sphere" or "NoisyPlane" (for parameterised test names). */
const char*
shapeName (Shape shape);

/** \brief n random points with random anisotropic covariances (standard deviations between
  * 0.2 sigma and sigma, randomly rotated) and, when `weights`, random area weights in
  * [0.5, 1.5): uniform in the cube [-0.5, 0.5]^3 (Box), on the sphere of radius 0.5 with
  * Gaussian noise of 1 mm on each axis (Sphere), or on the patch [-0.5, 0.5] x [-0.3, 0.3] of the plane z = 0 with
  * 2 mm of noise along z (NoisyPlane). std::mt19937_64 seeded with `seed`; source indices
  * 0 .. n - 1. */
pcl_probcollision::UncertainCloud
shapeCloud (Shape shape, std::size_t n, std::uint64_t seed, double sigma = 0.002, bool weights = true);

/** \brief The cloud moved by T: means T x, covariances R Sigma R^T; weights and source indices
  * kept. */
pcl_probcollision::UncertainCloud
transformCloud (const pcl_probcollision::UncertainCloud& cloud, const Eigen::Isometry3d& T);

// ---------------------------------------------------------------------------------------------
// Gaussian point sets for RobustClassifier (METHOD.md 11's configurations)

/** \brief Points as the classifier takes them: means and covariances, index-aligned. */
struct ClassifierCloud
{
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> covariances;

  pcl_probcollision::PointSetView view () const { return pcl_probcollision::PointSetView (means, covariances); }
  void add (const Eigen::Vector3d& m, const Eigen::Matrix3d& c)
  {
    means.push_back (m);
    covariances.push_back (c);
  }
  std::size_t size () const { return means.size (); }
};

/** \brief sigma^2 I. */
Eigen::Matrix3d
iso (double sigma);

/** \brief n Fibonacci points on the unit sphere around the x axis: the first coordinate runs
  * from 1 to -1 (1 - 2 (k + 1/2) / n), the angle about x steps by pi (3 - sqrt 5). */
std::vector<Eigen::Vector3d>
fibonacci (int n);

/** \brief A random SPD covariance with standard deviations uniform in [lo, hi], rotated by
  * Euler angles (z, y, x) uniform in [0, 2 pi). */
Eigen::Matrix3d
randomCovariance (std::mt19937_64& rng, double lo, double hi);

/** \brief Two tilted, noisy patches over [0, 1]^2 with random anisotropic covariances
  * (standard deviations in [0.002, 0.02]): A, 150 points on z = 0.1 x - 0.05 y + U(0, 0.01);
  * B, 90 points 0.06 above. A generic configuration without symmetry, about 0.05 apart
  * (std::mt19937_64 seeded with `seed`). */
void
genericPatches (ClassifierCloud& a, ClassifierCloud& b, std::uint64_t seed = 7);

/** \brief A ball of radius 0.3 (n Fibonacci points) inside the lower half of a sphere of
  * radius 0.4 (a bowl: the points of fibonacci (2 n) below its equator), both about the
  * origin with the Fibonacci axis along z, gap 0.1; covariances sigma^2 I. */
void
bowl (int n, double sigma, ClassifierCloud& ball, ClassifierCloud& cup);

/** \brief The oracle configuration of METHOD.md 11: kernel Linear, C = 1e6, the given
  * training, other parameters at their defaults. */
pcl_probcollision::ClassifierParams
oracle (pcl_probcollision::TrainingMode training);

// ---------------------------------------------------------------------------------------------
// Poses

/** \brief A uniformly distributed rotation: a normalised quaternion of four standard normal
  * draws (w first). */
Eigen::Matrix3d
randomRotation (std::mt19937_64& rng);

/** \brief randomRotation() and a translation uniform in [-translation_scale,
  * translation_scale]^3 (rotation drawn first). */
Eigen::Isometry3d
randomPose (std::mt19937_64& rng, double translation_scale);

/** \brief x -> R x + t: R a rotation by an angle uniform in [-pi, pi] about an axis drawn
  * uniform in [-1, 1]^3 and normalised, t uniform in [-translation, translation]^3 (drawn in the
  * order axis, t, angle). */
Eigen::Isometry3d
randomAxisAnglePose (std::mt19937& rng, double translation);

/** \brief n poses of one sheet against another: heights falling linearly from 2 cm above to
  * 1 cm below (through), x and y shifted by up to 2 cm, tilted by up to 0.2 rad about a random
  * axis (std::mt19937 seeded with `seed`): free, contact and collision verdicts all occur for
  * two grids at z = 0. */
std::vector<Eigen::Isometry3d>
poseSweep (int n, unsigned seed);

// ---------------------------------------------------------------------------------------------
// Reference values

/** \brief The standard normal CDF from std::erfc, written independently of the library's
  * normalCdf: the reference of the analytic oracles. */
double
Phi (double z);
} // namespace pcl_probcollision_test
