// SPDX-License-Identifier: BSD-3-Clause
// Ground truth and baselines of the evaluation suite (evaluation/ground_truth.h, baselines.h):
// closed-form cases on tiny meshes and clouds, and consistency on FCL's piano-in-a-room models.
#include "baselines.h"
#include "fit_scenes.h"
#include "ground_truth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

using namespace pcl_probcollision_eval;

namespace
{
// Axis-aligned box [lo, hi] as 12 triangles.
TriangleMesh
boxMesh (const Eigen::Vector3d& lo, const Eigen::Vector3d& hi)
{
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back ({(i & 1) ? hi.x () : lo.x (), (i & 2) ? hi.y () : lo.y (), (i & 4) ? hi.z () : lo.z ()});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& q : quads)
  {
    m.triangles.push_back ({q[0], q[1], q[2]});
    m.triangles.push_back ({q[0], q[2], q[3]});
  }
  return m;
}

TriangleMesh
unitCube ()
{
  return boxMesh (Eigen::Vector3d::Zero (), Eigen::Vector3d::Ones ());
}

// Points on the faces of the unit cube on a grid of the given step.
CloudXYZ
unitCubeCloud (double step)
{
  CloudXYZ cloud;
  const int n = static_cast<int> (std::round (1.0 / step));
  for (int axis = 0; axis < 3; ++axis)
    for (const double side : {0.0, 1.0})
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
        {
          Eigen::Vector3d p;
          p[axis] = side;
          p[(axis + 1) % 3] = i * step;
          p[(axis + 2) % 3] = j * step;
          cloud.push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()),
                                          static_cast<float> (p.z ())));
        }
  return cloud;
}

// Fibonacci lattice on a sphere: near-uniform, deterministic.
CloudXYZ
sphereCloud (int n, double radius)
{
  CloudXYZ cloud;
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt (5.0));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt (1.0 - z * z);
    const double a = golden * i;
    cloud.push_back (pcl::PointXYZ (static_cast<float> (radius * r * std::cos (a)),
                                    static_cast<float> (radius * r * std::sin (a)), static_cast<float> (radius * z)));
  }
  return cloud;
}

Eigen::Isometry3d
translation (double x, double y, double z)
{
  return Eigen::Isometry3d (Eigen::Translation3d (x, y, z));
}

const std::string kMeshes = std::string (PCL_PROBCOLLISION_SHARED_DATA) + "/meshes/";

// The piano and the room, loaded once; null when the shared data is absent, which fails the test
// that needs them (as the other tests on shared data do): a skipped test would pass unseen.
const ExactMeshPair*
pianoRoom ()
{
  static const std::unique_ptr<ExactMeshPair> pair = [] {
    std::unique_ptr<ExactMeshPair> p;
    TriangleMesh rob, env;
    std::string error;
    if (pcl_probcollision::io::loadTriangleMesh (kMeshes + "piano_room_rob.obj", rob, error) &&
        pcl_probcollision::io::loadTriangleMesh (kMeshes + "piano_room_env.obj", env, error))
      p = std::make_unique<ExactMeshPair> (rob, env);
    return p;
  }();
  return pair.get ();
}

#define REQUIRE_PIANO_ROOM()                                                                                   \
  const ExactMeshPair* pr = pianoRoom ();                                                                      \
  if (!pr)                                                                                                     \
  FAIL () << "missing shared data: piano/room meshes not found under " << kMeshes
} // namespace

// ------------------------------------------------------------------------------------ exact pair
TEST (ExactMeshPair, SeparatedCubesDistanceIsTheGap)
{
  const ExactMeshPair pair (unitCube (), unitCube ());
  const Eigen::Isometry3d T = translation (1.5, 0.1, 0.2);  // gap 0.5 along x
  EXPECT_FALSE (pair.collide (T));
  EXPECT_NEAR (pair.distance (T), 0.5, 1e-9);
  EXPECT_NEAR (pair.signedDistance (T), 0.5, 1e-9);
  EXPECT_EQ (pair.penetrationDepth (T), 0.0);

  Eigen::Vector3d on_robot, on_env;
  pair.distance (T, &on_robot, &on_env);
  EXPECT_NEAR (on_robot.x (), 1.5, 1e-9);  // env frame
  EXPECT_NEAR (on_env.x (), 1.0, 1e-9);
}

TEST (ExactMeshPair, OverlappingCubesDepthIsTheOverlap)
{
  const ExactMeshPair pair (unitCube (), unitCube ());
  const double tol = pair.penetrationTolerance ();
  EXPECT_NEAR (tol, 1e-4 * std::sqrt (3.0), 1e-12);
  const Eigen::Isometry3d T = translation (0.7, 0.1, 0.2);  // overlap 0.3 along x, 0.9 and 0.8 across
  ASSERT_TRUE (pair.collide (T));
  Eigen::Vector3d dir;
  const double depth = pair.penetrationDepth (T, &dir);
  EXPECT_GE (depth, 0.3 - 1e-9);  // an upper bound on the true depth
  EXPECT_LE (depth, 0.3 + tol + 1e-9);
  EXPECT_NEAR (dir.x (), 1.0, 1e-12);
  EXPECT_NEAR (pair.signedDistance (T), -depth, 0.0);
  EXPECT_FALSE (pair.collide (translation (0.7 + depth, 0.1, 0.2)));
  EXPECT_EQ (pair.distance (T), 0.0);

  // Deeper along y, from below: the separating move is 0.6 along -y.
  const double d2 = pair.penetrationDepth (translation (0.05, -0.4, 0.1), &dir);
  EXPECT_GE (d2, 0.6 - 1e-9);
  EXPECT_LE (d2, 0.6 + tol + 1e-9);
  EXPECT_NEAR (dir.y (), -1.0, 1e-12);
}

TEST (ExactMeshPair, SurfacesNotSolids)
{
  // A small cube wholly inside the unit cube: no triangle crosses, so free, as for surface clouds.
  const ExactMeshPair pair (boxMesh (Eigen::Vector3d::Constant (-0.25), Eigen::Vector3d::Constant (0.25)), unitCube ());
  const Eigen::Isometry3d T = translation (0.5, 0.5, 0.5);
  EXPECT_FALSE (pair.collide (T));
  EXPECT_NEAR (pair.signedDistance (T), 0.25, 1e-9);
}

TEST (ExactMeshPair, RejectsBadMeshes)
{
  TriangleMesh empty;
  EXPECT_THROW (ExactMeshPair (empty, unitCube ()), std::invalid_argument);
  TriangleMesh broken = unitCube ();
  broken.triangles.push_back ({0, 1, 42});
  EXPECT_THROW (ExactMeshPair (unitCube (), broken), std::invalid_argument);
  ExactMeshPair unbuilt;
  EXPECT_FALSE (unbuilt.built ());
  EXPECT_THROW (unbuilt.collide (Eigen::Isometry3d::Identity ()), std::logic_error);
}

TEST (ExactMeshPair, FiftyDirectionsUnitAndDistinct)
{
  const auto& dirs = ExactMeshPair::penetrationDirections ();
  ASSERT_EQ (dirs.size (), 50u);
  double closest = 0.0;  // largest cosine between two directions
  for (std::size_t i = 0; i < dirs.size (); ++i)
  {
    EXPECT_NEAR (dirs[i].norm (), 1.0, 1e-12);
    for (std::size_t j = i + 1; j < dirs.size (); ++j)
      closest = std::max (closest, dirs[i].dot (dirs[j]));
  }
  EXPECT_LT (closest, 0.99);
}

TEST (ExactMeshPair, PianoRoomSignAgreesWithCollide)
{
  REQUIRE_PIANO_ROOM ();
  const auto truths = uniformPoseTruths (*pr, 50, 11);
  ASSERT_EQ (truths.size (), 50u);
  int colliding = 0;
  for (const PoseTruth& t : truths)
  {
    EXPECT_EQ (t.collision, pr->collide (t.T));
    EXPECT_EQ (t.signed_distance < 0.0, t.collision);
    if (t.collision)
    {
      ++colliding;
      // The depth found ends on the free side: moving out by it separates.
      Eigen::Vector3d dir;
      const double depth = pr->penetrationDepth (t.T, &dir);
      EXPECT_DOUBLE_EQ (-depth, t.signed_distance);
      Eigen::Isometry3d out = t.T;
      out.translation () += depth * dir;
      EXPECT_FALSE (pr->collide (out));
    }
    else
      EXPECT_DOUBLE_EQ (t.signed_distance, pr->distance (t.T));
  }
  EXPECT_GT (colliding, 0);
  EXPECT_LT (colliding, 50);
}

TEST (ExactMeshPair, PianoFarAwayIsTheFclDistance)
{
  REQUIRE_PIANO_ROOM ();
  const Eigen::Vector3d up (0.0, 0.0, 2.0 * pr->envBox ().sizes ().z () + pr->robotDiagonal ());
  const Eigen::Isometry3d T (Eigen::Translation3d (pr->envBox ().center () + up - pr->robotBox ().center ()));
  const double sd = pr->signedDistance (T);
  EXPECT_GT (sd, 0.0);
  EXPECT_DOUBLE_EQ (sd, pr->distance (T));
  // Between the gap of the boxes and the distance of their centres.
  const double box_gap = (pr->robotBox ().min ().z () + T.translation ().z ()) - pr->envBox ().max ().z ();
  EXPECT_GE (sd, box_gap - 1e-9);
  EXPECT_LE (sd, up.norm ());
}

// ----------------------------------------------------------------------------------------- poses
TEST (Poses, SameSeedSamePoses)
{
  const Eigen::AlignedBox3d robot (Eigen::Vector3d (-1, -2, -3), Eigen::Vector3d (1, 2, 3));
  const Eigen::AlignedBox3d env (Eigen::Vector3d (0, 0, 0), Eigen::Vector3d (10, 20, 30));
  const auto a = uniformPoses (100, robot, env, 5), b = uniformPoses (100, robot, env, 5), c = uniformPoses (100, robot, env, 6);
  ASSERT_EQ (a.size (), 100u);
  int differ = 0;
  for (std::size_t i = 0; i < a.size (); ++i)
  {
    EXPECT_TRUE (a[i].matrix () == b[i].matrix ());
    differ += a[i].matrix () != c[i].matrix () ? 1 : 0;
    EXPECT_TRUE (env.contains (a[i] * robot.center ()));  // the robot's centre is placed in the env box
    EXPECT_NEAR ((a[i].linear () * a[i].linear ().transpose () - Eigen::Matrix3d::Identity ()).norm (), 0.0, 1e-12);
  }
  EXPECT_EQ (differ, 100);
  // A prefix of a longer draw: each pose depends on (seed, index) only.
  const auto longer = uniformPoses (150, robot, env, 5);
  EXPECT_TRUE (longer[99].matrix () == a[99].matrix ());
}

TEST (Poses, RotationsAreUniform)
{
  std::mt19937_64 rng (3);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero ();
  const int n = 4000;
  for (int i = 0; i < n; ++i)
  {
    const Eigen::Quaterniond q = uniformRotation (rng);
    EXPECT_NEAR (q.norm (), 1.0, 1e-12);
    mean += q * Eigen::Vector3d::UnitX ();
  }
  EXPECT_LT ((mean / n).norm (), 0.05);  // the image of a fixed axis has no preferred side

  std::mt19937_64 rng2 (4);
  double s = 0.0, s2 = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const double z = standardNormal (rng2);
    s += z;
    s2 += z * z;
  }
  EXPECT_NEAR (s / n, 0.0, 0.06);
  EXPECT_NEAR (s2 / n, 1.0, 0.08);
}

TEST (Poses, NearContactPosesAreWithinTheBand)
{
  REQUIRE_PIANO_ROOM ();
  NearContactOptions options;
  options.band = 0.05 * pr->robotDiagonal ();
  const auto poses = nearContactPoses (*pr, 12, 21, options);
  ASSERT_EQ (poses.size (), 12u);
  int colliding = 0;
  for (const PoseTruth& t : poses)
  {
    EXPECT_LE (std::abs (t.signed_distance), options.band);
    EXPECT_EQ (t.collision, pr->collide (t.T));
    EXPECT_DOUBLE_EQ (t.signed_distance, pr->signedDistance (t.T));
    colliding += t.collision ? 1 : 0;
  }
  EXPECT_GT (colliding, 0);
  EXPECT_LT (colliding, 12);

  // Deterministic whatever the thread count.
  options.threads = 2;
  const auto again = nearContactPoses (*pr, 4, 21, options);
  for (std::size_t i = 0; i < again.size (); ++i)
  {
    EXPECT_TRUE (again[i].T.matrix () == poses[i].T.matrix ());
    EXPECT_EQ (again[i].signed_distance, poses[i].signed_distance);
  }
  options.band = 0.0;
  EXPECT_THROW (nearContactPoses (*pr, 1, 21, options), std::invalid_argument);
}

// ------------------------------------------------------------------------------------- baselines
TEST (OctomapBaseline, CubeCloudAgainstCubeMesh)
{
  const double res = 0.05;
  OctomapBaseline octo;
  octo.buildEnv (unitCubeCloud (0.02), res);
  octo.setRobotMesh (unitCube ());
  octo.buildRobotCloud (unitCubeCloud (0.02));
  EXPECT_GT (octo.envOccupiedLeaves (), 200u);
  EXPECT_GT (octo.envMemoryBytes (), 0u);
  EXPECT_GT (octo.robotMeshMemoryBytes (), 0u);
  EXPECT_EQ (octo.resolution (), res);

  const Eigen::Isometry3d overlap = translation (0.5, 0.1, 0.2);
  const Eigen::Isometry3d far = translation (1.0 + 10.0 * res, 0.1, 0.2);  // a gap of 10 voxels
  EXPECT_TRUE (octo.collideMesh (overlap));
  EXPECT_FALSE (octo.collideMesh (far));
  EXPECT_TRUE (octo.collideCloud (overlap));
  EXPECT_FALSE (octo.collideCloud (far));
  // Rotated 45 degrees about z and still overlapping.
  const Eigen::Isometry3d turned = translation (0.8, 0.5, 0.3) * Eigen::AngleAxisd (0.785398, Eigen::Vector3d::UnitZ ());
  EXPECT_TRUE (octo.collideMesh (turned));
  EXPECT_TRUE (octo.collideCloud (turned));
  EXPECT_THROW (OctomapBaseline ().collideMesh (overlap), std::logic_error);
  EXPECT_THROW (octo.buildEnv (unitCubeCloud (0.02), 0.0), std::invalid_argument);
}

TEST (NearestNeighbourBaseline, MinimumDistanceMatchesBruteForce)
{
  std::mt19937_64 rng (9);
  CloudXYZ env, robot;
  for (int i = 0; i < 400; ++i)
    env.push_back (pcl::PointXYZ (static_cast<float> (10.0 * standardNormal (rng)), static_cast<float> (10.0 * standardNormal (rng)),
                                  static_cast<float> (10.0 * standardNormal (rng))));
  for (int i = 0; i < 700; ++i)  // more than two batches
    robot.push_back (pcl::PointXYZ (static_cast<float> (standardNormal (rng)), static_cast<float> (standardNormal (rng)),
                                    static_cast<float> (standardNormal (rng))));
  robot.push_back (pcl::PointXYZ (std::numeric_limits<float>::quiet_NaN (), 0.f, 0.f));  // ignored
  NearestNeighbourBaseline nn;
  nn.build (env, robot);
  EXPECT_EQ (nn.envPoints (), 400u);
  EXPECT_EQ (nn.robotPoints (), 700u);
  EXPECT_GT (nn.memoryBytes (), 400u * 12u);

  for (int k = 0; k < 5; ++k)
  {
    const Eigen::Isometry3d T = Eigen::Translation3d (5.0 * standardNormal (rng), 5.0 * standardNormal (rng), 5.0 * standardNormal (rng)) *
                                uniformRotation (rng);
    double brute = std::numeric_limits<double>::infinity ();
    for (std::size_t i = 0; i < 700; ++i)
      for (const auto& e : env.points)
        brute = std::min (brute, (T * robot[i].getVector3fMap ().cast<double> () - e.getVector3fMap ().cast<double> ()).norm ());
    const double d = nn.minDistance (T);
    EXPECT_NEAR (d, brute, 1e-4 * (1.0 + brute));
    EXPECT_NEAR (nn.minDistance (T, 2.0 * brute + 1e-3), d, 1e-9);
    EXPECT_EQ (nn.minDistance (T, 0.5 * brute), std::numeric_limits<double>::infinity ());
    EXPECT_TRUE (nn.within (T, 1.01 * brute + 1e-4));
    EXPECT_FALSE (nn.within (T, 0.99 * brute));
  }
}

TEST (NearestNeighbourBaseline, KnownAnswer)
{
  CloudXYZ env, robot;
  env.push_back (pcl::PointXYZ (0.f, 0.f, 0.f));
  env.push_back (pcl::PointXYZ (10.f, 0.f, 0.f));
  robot.push_back (pcl::PointXYZ (1.f, 0.f, 0.f));
  NearestNeighbourBaseline nn;
  nn.build (env, robot);
  // Robot point (1, 0, 0) turned 90 degrees about z goes to (0, 1, 0), then up by 2: distance sqrt 5.
  const Eigen::Isometry3d T = translation (0.0, 0.0, 2.0) * Eigen::AngleAxisd (1.5707963267948966, Eigen::Vector3d::UnitZ ());
  EXPECT_NEAR (nn.minDistance (T), std::sqrt (5.0), 1e-6);
  EXPECT_NEAR (nn.minDistance (translation (6.0, 0.0, 0.0)), 3.0, 1e-6);
  EXPECT_THROW (nn.build (CloudXYZ (), robot), std::invalid_argument);
}

TEST (ReconstructBaseline, SpheresCollideWhenOverlapping)
{
  const CloudXYZ sphere = sphereCloud (3000, 1.0);
  double radius = 0.0;
  const TriangleMesh mesh = reconstructMesh (sphere, {}, &radius);
  EXPECT_GT (mesh.triangles.size (), 3000u);  // a closed lattice has about 2 triangles per point
  EXPECT_GT (radius, 0.0);
  // Vertices stay on the sphere.
  for (const auto& v : mesh.vertices)
    EXPECT_NEAR (std::sqrt (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 1.0, 1e-5);

  ReconstructBaseline rec;
  rec.build (sphere, sphere);
  EXPECT_GT (rec.robotTriangles (), 3000u);
  EXPECT_GT (rec.memoryBytes (), 0u);
  EXPECT_TRUE (rec.collide (translation (1.0, 0.2, 0.0)));
  EXPECT_TRUE (rec.collide (translation (0.0, 1.9, 0.0)));  // shallow
  EXPECT_FALSE (rec.collide (translation (3.0, 0.0, 0.0)));
  EXPECT_FALSE (rec.collide (translation (0.0, 0.0, 2.2)));
  EXPECT_THROW (reconstructMesh (CloudXYZ ()), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// The calibration's fit scenes (fit_scenes.h): a seed gives one scene, every part a closed box
// with outward faces, the lid opened above the body, nothing of the scene reported.

namespace
{
/** \brief Signed volume of triangles [first, first + 12) (the divergence theorem), and the
  * volume of the box their 8 vertices [8 b, 8 b + 8) span. */
std::pair<double, double>
boxVolumes (const pcl_probcollision::io::TriangleMesh& mesh, std::size_t b)
{
  auto v = [&] (std::size_t i) {
    const auto& p = mesh.vertices[i];
    return Eigen::Vector3d (p[0], p[1], p[2]);
  };
  double signed_volume = 0.0;
  for (std::size_t t = 12 * b; t < 12 * b + 12; ++t)
  {
    const auto& tri = mesh.triangles[t];
    signed_volume += v (static_cast<std::size_t> (tri[0])).dot (
                         v (static_cast<std::size_t> (tri[1])).cross (v (static_cast<std::size_t> (tri[2])))) / 6.0;
  }
  const Eigen::Vector3d o = v (8 * b);
  const double box = std::abs ((v (8 * b + 1) - o).dot ((v (8 * b + 2) - o).cross (v (8 * b + 4) - o)));
  return {signed_volume, box};
}
} // namespace

TEST (FitScene, ASeedGivesOneSceneOfOutwardBoxes)
{
  const FitScene a = makeFitScene (3), again = makeFitScene (3), other = makeFitScene (4);
  EXPECT_EQ (a.env.vertices, again.env.vertices);
  EXPECT_EQ (a.robot.vertices, again.robot.vertices);
  EXPECT_NE (a.env.vertices, other.env.vertices);
  for (const auto* mesh : {&a.env, &a.robot})
  {
    ASSERT_EQ (mesh->vertices.size () % 8, 0u);
    ASSERT_EQ (mesh->triangles.size (), mesh->vertices.size () / 8 * 12);
    for (std::size_t b = 0; b < mesh->vertices.size () / 8; ++b)
    {
      const auto [signed_volume, box] = boxVolumes (*mesh, b);
      EXPECT_GT (box, 0.0) << "box " << b;
      EXPECT_NEAR (signed_volume, box, 1e-9 * box) << "box " << b << " is not closed with outward faces";
    }
  }
  // The robot: centred on the origin, about a piano's size; its lid (the part after the legs)
  // lies on or above the body's top.
  Eigen::AlignedBox3d robot_box;
  for (const auto& p : a.robot.vertices)
    robot_box.extend (Eigen::Vector3d (p[0], p[1], p[2]));
  EXPECT_LT (robot_box.center ().norm (), 1e-9);
  EXPECT_GT (robot_box.diagonal ().norm (), 1000.0);
  EXPECT_LT (robot_box.diagonal ().norm (), 2500.0);
  double body_top = -1e300;
  for (std::size_t i = 0; i < 8; ++i)
    body_top = std::max (body_top, a.robot.vertices[i][2]);
  const std::size_t lid = a.robot.vertices.size () - 16;  // the lid, then the block
  for (std::size_t i = lid; i < lid + 8; ++i)
    EXPECT_GE (a.robot.vertices[i][2], body_top - 1e-9);
  // FCL takes both; the robot lifted 3 m above the floor and furniture is clear of them.
  ExactMeshPair exact (a.robot, a.env);
  Eigen::Isometry3d up = Eigen::Isometry3d::Identity ();
  up.translation () = Eigen::Vector3d (0.0, 0.0, 3000.0);
  EXPECT_FALSE (exact.collide (up));
  EXPECT_GT (exact.distance (up), 500.0);
}
