// SPDX-License-Identifier: BSD-3-Clause
// The surface model (surface_model.h) and the surface layer of collide() (CollisionRequest::
// surface, METHOD.md 10a): orientation, winding number, signed distance, containment, and the
// degenerate inputs that must still get an answer.
#include "scenes.h"
#include "seeded_draws.h"

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>

using namespace pcl_probcollision;
using pcl_probcollision_test::draw3;
using pcl_probcollision_test::fibonacci;

namespace
{
/** \brief A square sheet of side `size` on z = height, regular grid of spacing h, with the
  * sensor at `view` (the cloud's sensor_origin_). */
pcl::PointCloud<pcl::PointXYZ>
sheet (double size, double h, double height, const Eigen::Vector3f& view)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  const int n = static_cast<int> (std::round (size / h));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      cloud.push_back (pcl::PointXYZ (static_cast<float> (-0.5 * size + i * h), static_cast<float> (-0.5 * size + j * h),
                                      static_cast<float> (height)));
  cloud.sensor_origin_ = Eigen::Vector4f (view.x (), view.y (), view.z (), 0.0f);
  return cloud;
}

/** \brief n points on a sphere of radius r about c (Fibonacci lattice), optionally with their
  * outward (or, flipped, inward) normals. */
pcl::PointCloud<pcl::PointNormal>
sphere (int n, double r, const Eigen::Vector3d& c, bool flipped = false)
{
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (const Eigen::Vector3d& u : fibonacci (n))
  {
    pcl::PointNormal p;
    p.getVector3fMap () = (c + r * u).cast<float> ();
    p.getNormalVector3fMap () = (flipped ? -u : u).cast<float> ();
    cloud.push_back (p);
  }
  return cloud;
}

/** \brief A point at (x, y, z) with normal n. */
pcl::PointNormal
pointNormal (double x, double y, double z, const Eigen::Vector3f& n)
{
  pcl::PointNormal p;
  p.getVector3fMap () = Eigen::Vector3d (x, y, z).cast<float> ();
  p.getNormalVector3fMap () = n;
  return p;
}

pcl::PointCloud<pcl::PointXYZ>
xyz (const pcl::PointCloud<pcl::PointNormal>& in)
{
  pcl::PointCloud<pcl::PointXYZ> out;
  for (const auto& p : in)
    out.push_back (pcl::PointXYZ (p.x, p.y, p.z));
  return out;
}

/** \brief Models with a surface (CloudModelParams::surface), noise-free ... */
CloudModelParams
withSurface ()
{
  CloudModelParams p;
  p.surface = true;
  return p;
}

/** \brief ... or with isotropic sensor noise sigma. */
CloudModelParams
noisy (double sigma)
{
  CloudModelParams p = withSurface ();
  p.noise = SensorNoiseModel::isotropic (sigma);
  return p;
}

CollisionRequest
surfaceRequest ()
{
  CollisionRequest r;
  r.surface = true;
  r.exhaustive = true;
  return r;
}

/** \brief The same query as each way of answering it: the surface layer (per point, exhaustive
  * or not), the separators, both pooled, and the ladder. */
struct Answerers
{
  CollisionRequest surface, separators, pooled, ladder;
  explicit Answerers (bool exhaustive)
  {
    surface = surfaceRequest ();
    surface.exhaustive = exhaustive;
    surface.per_point = true;
    surface.surface_calibrated = false;
    separators = surface;
    separators.surface = false;
    pooled = surface;
    pooled.surface_pooled = true;
    ladder = surface;
    ladder.surface_ladder = true;
  }
};

Eigen::Isometry3d
shift (double x, double y, double z)
{
  return Eigen::Isometry3d (Eigen::Translation3d (x, y, z));
}
} // namespace

// A query exactly on a sample of no area (a point repeated past k times, spacing 0) is finite: the sample
// adds nothing instead of 0 / 0 (found in review: NaN, which the inside test read as inside). Exact
// copies are modelled once (detail::mergeCoincident); copies with normals of their own are not.
TEST (SurfaceModel, TheWindingNumberOnADuplicatedSampleIsFinite)
{
  auto cloud = sphere (800, 0.1, Eigen::Vector3d (1, 2, 3));
  for (int copy = 0; copy < 12; ++copy)  // more copies than k neighbours: a k-th neighbour at 0
  {
    pcl::PointNormal p = cloud[0];
    p.normal_x += 1e-3f * static_cast<float> (copy + 1);
    cloud.push_back (p);
  }
  const auto model = buildCloudModel (cloud, withSurface ());
  const SurfaceModel& s = model->surface ();
  const auto& means = model->hierarchy ().means ();
  std::size_t zero = means.size ();
  for (std::size_t i = 0; i < means.size () && zero == means.size (); ++i)
    if (s.spacing ()[i] == 0.0f && !s.normals ()[i].isZero ())
      zero = i;
  ASSERT_LT (zero, means.size ()) << "no sample of zero spacing: the case is not exercised";
  const double w = s.windingNumber (model->hierarchy (), means[zero]);
  EXPECT_TRUE (std::isfinite (w)) << w;
  EXPECT_NEAR (w, 0.5, 0.3);  // on the surface: about half
}

TEST (SurfaceModel, PropagationOrientsAClosedSurfaceOutward)
{
  // The sphere off the origin: PCL's default sensor_origin_ (0, 0, 0) lies outside it, but is
  // no scan's viewpoint (about half the samples lie behind the other half seen from there), so
  // Auto propagates.
  const auto model = buildCloudModel (xyz (sphere (800, 0.1, Eigen::Vector3d (1, 2, 3))), withSurface ());
  const SurfaceModel& s = model->surface ();
  ASSERT_FALSE (s.empty ());
  EXPECT_EQ (s.orientation (), NormalOrientation::Propagate);
  EXPECT_GT (s.hiddenFromViewpoint (), 0.3);
  const auto& points = model->hierarchy ().means ();  // local frame: the sphere's centre at ~0
  std::size_t outward = 0;
  for (std::size_t i = 0; i < points.size (); ++i)
    outward += s.normals ()[i].cast<double> ().dot (points[i]) > 0.0 ? 1 : 0;
  EXPECT_EQ (outward, points.size ());
  EXPECT_NEAR (s.windingNumber (model->hierarchy (), Eigen::Vector3d::Zero ()), 1.0, 0.25);
  EXPECT_NEAR (s.windingNumber (model->hierarchy (), Eigen::Vector3d (0.3, 0.0, 0.0)), 0.0, 0.05);
  // Spacing: 800 samples on 0.126 m^2 is about 12.5 mm apart.
  EXPECT_NEAR (s.medianSpacing (), std::sqrt (4.0 * M_PI * 0.01 / 800), 0.004);
}

// The dipoles are summed in double and stored in float: each oriented sample counts once
// (area() is the sum of their areas although leaves overlap), the root's moment is their summed
// area-weighted normal, and every node's rounded radius still bounds, from its rounded centre,
// the samples it can hold (the root all of them; a leaf's within it when no other leaf holds
// them). The wider far-field test is then exact on where a node's samples are.
TEST (SurfaceModel, SinglePrecisionDipolesBoundTheirSamples)
{
  const auto model = buildCloudModel (xyz (sphere (2000, 0.1, Eigen::Vector3d (1, 2, 3))), withSurface ());
  const SurfaceModel& s = model->surface ();
  const ProbabilisticBVH& bvh = model->hierarchy ();
  const auto& points = bvh.means ();
  double area = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero ();
  for (std::size_t i = 0; i < points.size (); ++i)
  {
    const double a = s.areas ()[i];
    area += s.normals ()[i].isZero () ? 0.0 : a;
    moment += a * s.normals ()[i].cast<double> ();
  }
  ASSERT_GT (area, 0.0);
  EXPECT_NEAR (s.area (), area, 1e-12 * area);
  const SurfaceModel::Dipole& root = s.dipoles ()[static_cast<std::size_t> (ProbabilisticBVH::rootId ())];
  EXPECT_LT ((root.moment.cast<double> () - moment).norm (), 1e-6 * area);
  // Points held by one leaf only.
  std::vector<int> holders (points.size (), 0);
  for (const auto& node : bvh.nodes ())
    if (node.isLeaf ())
      for (const int i : bvh.indices (node))
        ++holders[static_cast<std::size_t> (i)];
  std::size_t checked = 0;
  for (std::size_t id = 0; id < bvh.nodes ().size (); ++id)
  {
    const auto& node = bvh.nodes ()[id];
    const SurfaceModel::Dipole& d = s.dipoles ()[id];
    for (const int i : bvh.indices (node))
    {
      const std::size_t p = static_cast<std::size_t> (i);
      if (s.normals ()[p].isZero () || (static_cast<std::int32_t> (id) != ProbabilisticBVH::rootId () && holders[p] != 1))
        continue;
      ASSERT_FALSE (d.empty ()) << "node " << id;
      EXPECT_LE ((points[p] - d.center.cast<double> ()).norm (), static_cast<double> (d.radius)) << "node " << id;
      ++checked;
    }
  }
  EXPECT_GT (checked, points.size ());
}

TEST (SurfaceModel, GivenNormalsAreKeptEvenInsideOut)
{
  const auto model = buildCloudModel (sphere (400, 0.1, Eigen::Vector3d::Zero (), true), withSurface ());
  const SurfaceModel& s = model->surface ();
  EXPECT_EQ (s.orientation (), NormalOrientation::PointNormals);
  // Inward normals, as given: the winding number inside is -1 (within the area estimate's
  // error on a Fibonacci lattice), 0 outside.
  EXPECT_NEAR (s.windingNumber (model->hierarchy (), -model->origin ()), -1.0, 0.25);
  EXPECT_NEAR (s.windingNumber (model->hierarchy (), Eigen::Vector3d (0.3, 0.0, 0.0)), 0.0, 0.05);
}

// Normals of any finite length are taken (the surface model normalises them): the same orientation
// and the same answer as unit ones, at lengths 1e20 and 1e-20, whose float length overflows or
// leaves float's normal range (until 2026-12-06 such normals were set aside and the surface
// propagated: a probe's finding).
TEST (SurfaceModel, NormalsOfAnyFiniteLengthAreTaken)
{
  const auto unit = sphere (200, 0.1, Eigen::Vector3d::Zero ());
  const auto reference = buildCloudModel (unit, withSurface ());
  ASSERT_EQ (reference->surface ().orientation (), NormalOrientation::PointNormals);
  const Eigen::Vector3d probe (0.0, 0.0, 0.095);  // just inside the sphere
  const double inside = reference->surface ().windingNumber (reference->hierarchy (), probe);
  for (const float scale : {1e20f, 1e-20f})
  {
    SCOPED_TRACE (scale);
    auto scaled = unit;
    for (auto& p : scaled.points)
      p.getNormalVector3fMap () *= scale;
    const auto model = buildCloudModel (scaled, withSurface ());
    EXPECT_EQ (model->surface ().orientation (), NormalOrientation::PointNormals);
    EXPECT_NEAR (model->surface ().windingNumber (model->hierarchy (), probe), inside, 1e-6);
  }
}

// NaN or zero marks "no normal"; an infinite component is a broken normal, refused by point
// (it read as "none" until 2026-12-04), and only where the surface model reads normals.
TEST (SurfaceModel, AnInfiniteNormalIsRefusedByPoint)
{
  auto cloud = sphere (200, 0.1, Eigen::Vector3d::Zero ());
  cloud.points[17].normal_y = std::numeric_limits<float>::infinity ();
  try
  {
    buildCloudModel (cloud, withSurface (), nullptr, nullptr, "gripper");
    FAIL () << "an infinite normal was accepted";
  }
  catch (const pcl::BadArgumentException& e)
  {
    EXPECT_NE (std::string (e.what ()).find ("gripper point 17 has a normal with an infinite component"), std::string::npos)
        << e.what ();
  }
  cloud.points[17].normal_y = std::numeric_limits<float>::quiet_NaN ();
  EXPECT_EQ (buildCloudModel (cloud, withSurface ())->surface ().orientation (), NormalOrientation::PointNormals);
  cloud.points[17].normal_y = -std::numeric_limits<float>::infinity ();
  CloudModelParams no_surface = withSurface ();
  no_surface.surface = false;
  EXPECT_NO_THROW (buildCloudModel (cloud, no_surface));
}

TEST (SurfaceModel, ViewpointOrientsASheetTowardTheSensor)
{
  for (const float side : {1.0f, -1.0f})
  {
    const auto model = buildCloudModel (sheet (0.2, 0.01, 0.0, Eigen::Vector3f (0.0f, 0.0f, side)), noisy (0.001));
    const SurfaceModel& s = model->surface ();
    EXPECT_EQ (s.orientation (), NormalOrientation::Viewpoint);
    EXPECT_EQ (s.hiddenFromViewpoint (), 0.0);  // one scan hides nothing from its sensor
    for (const Eigen::Vector3f& n : s.normals ())
      ASSERT_GT (n.z () * side, 0.99f);
  }
}

// A randomly sampled noisy plane (3 sigma apart, seen from above): a plane fit to a point lifted
// off it among neighbours along a line lies about 90 degrees off (5 % of the fits here, 104 of
// 4,444 still after smoothing), a face of its own for the surface layer; the model takes its
// neighbours' normal instead.
TEST (SurfaceModel, StrayNormalsOfANoisyPlaneAreRepaired)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::mt19937_64 rng (3);
  std::uniform_real_distribution<double> across (-0.1, 0.1);
  std::normal_distribution<double> noise (0.0, 0.001);
  for (int i = 0; i < 4444; ++i)
  {
    const double x = across (rng), y = across (rng);
    cloud.push_back (pcl::PointXYZ (static_cast<float> (x), static_cast<float> (y), static_cast<float> (noise (rng))));
  }
  cloud.sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 1.0f, 0.0f);
  const auto model = buildCloudModel (cloud, noisy (0.001));
  const SurfaceModel& s = model->surface ();
  ASSERT_EQ (s.orientation (), NormalOrientation::Viewpoint);
  std::size_t off = 0;
  for (const Eigen::Vector3f& n : s.normals ())
    off += n.z () < 0.7071f ? 1 : 0;
  EXPECT_LT (off, cloud.size () / 100) << off << " of " << cloud.size () << " normals more than 45 degrees off";
}

TEST (SurfaceModel, OffByDefault)
{
  CloudModelParams p;
  EXPECT_FALSE (p.surface);
  EXPECT_FALSE (CollisionRequest ().surface);
  EXPECT_TRUE (buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f::Zero ()), p)->surface ().empty ());
}

TEST (SurfaceModel, DegenerateInputsStillAnswer)
{
  // One point, two points, collinear points: no normal can be fitted; the model builds and a
  // query answers.
  pcl::PointCloud<pcl::PointXYZ> one, line;
  one.push_back (pcl::PointXYZ (0, 0, 0));
  for (int i = 0; i < 20; ++i)
    line.push_back (pcl::PointXYZ (0.01f * i, 0, 0));
  const auto m1 = buildCloudModel (one, noisy (0.001));
  const auto m2 = buildCloudModel (line, noisy (0.001));
  EXPECT_EQ (m1->surface ().unorientedPoints (), 1u);
  const auto plate = buildCloudModel (sheet (0.2, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  for (const auto& m : {m1, m2})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*m, *plate, shift (0, 0, -0.05), surfaceRequest (), r));
    EXPECT_TRUE (r.ok ());
    EXPECT_TRUE (std::isfinite (r.probability));
  }
}

// A sheet seen edge-on (issue #16, "Bad input and limits"): 0.5 mm noise at 5 mm spacing, the
// sensor in its plane. The noise tilts a few normals toward the sensor or away at random, so
// the viewpoint, asked for (Viewpoint) or not (Auto, which weighs it by its hidden points),
// orients nothing and the surface is propagated, two-sided: a probe 1 cm from it reads free on
// either side. Seen from 30 degrees above, the viewpoint orients it, and the space under it,
// which the sensor never saw, reads occupied. Before, an explicit Viewpoint took the side of a
// single noisy normal and read one side occupied.
TEST (SurfaceModel, ASheetSeenEdgeOnIsTwoSided)
{
  std::mt19937 rng (7);
  std::normal_distribution<float> noise (0.0f, 0.0005f);
  auto scan = [&] (const Eigen::Vector3f& view) {
    auto cloud = sheet (0.2, 0.005, 0.0, view);
    for (auto& p : cloud)
      p.z += noise (rng);
    return cloud;
  };
  const auto probe = buildCloudModel (sheet (0.01, 0.005, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.0005));
  auto verdict = [&] (const CloudModel& surface, double above) {
    CollisionResult r;
    EXPECT_TRUE (collide (*probe, surface, shift (0, 0, -above), surfaceRequest (), r)) << r.message;
    return r.verdict;
  };
  for (const NormalOrientation mode : {NormalOrientation::Viewpoint, NormalOrientation::Auto})
  {
    CloudModelParams p = noisy (0.0005);
    p.orientation = mode;
    const auto edge_on = buildCloudModel (scan (Eigen::Vector3f (1, 0, 0)), p);
    EXPECT_EQ (edge_on->surface ().orientation (), NormalOrientation::Propagate) << orientationName (mode);
    EXPECT_FALSE (edge_on->surface ().insideKnown ());
    EXPECT_EQ (verdict (*edge_on, 0.01), Verdict::Free);
    EXPECT_EQ (verdict (*edge_on, -0.01), Verdict::Free);
    const auto seen = buildCloudModel (scan (Eigen::Vector3f (1, 0, std::tan (0.5236f))), p);
    EXPECT_EQ (seen->surface ().orientation (), NormalOrientation::Viewpoint) << orientationName (mode);
    EXPECT_TRUE (seen->surface ().insideKnown ());
    EXPECT_EQ (verdict (*seen, 0.01), Verdict::Free);
    EXPECT_EQ (verdict (*seen, -0.01), Verdict::InCollision);
  }
}

/** \brief A closed slab [-size/2, size/2]^2 x [0, thickness] sampled every h, with its outward
  * normals (a mesh's faces would give the same). */
pcl::PointCloud<pcl::PointNormal>
slab (double size, double thickness, double h)
{
  pcl::PointCloud<pcl::PointNormal> cloud;
  const int n = static_cast<int> (std::round (size / h));
  for (const double z : {0.0, thickness})
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j)
        cloud.push_back (pointNormal (-0.5 * size + i * h, -0.5 * size + j * h, z,
                                      Eigen::Vector3f (0.0f, 0.0f, z > 0.0 ? 1.0f : -1.0f)));
  return cloud;
}

// Collide's pose T_a_b maps B into A's frame: shift (0, 0, -g) puts B g below A.
// A slab (exact, given normals) over a scanned table (B, sensor above, sigma 1 mm): the gap,
// then a penetration.
TEST (SurfaceLayer, SignedDistanceOfASlabOverATable)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto block = buildCloudModel (slab (0.1, 0.05, 0.01), withSurface ());
  EXPECT_EQ (block->surface ().orientation (), NormalOrientation::PointNormals);
  for (const double gap : {0.01, 0.003, -0.003, -0.02})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*block, *table, shift (0, 0, -gap), surfaceRequest (), r)) << gap;
    ASSERT_TRUE (r.ok ());
    ASSERT_TRUE (std::isfinite (r.signed_distance)) << gap;
    EXPECT_NEAR (r.signed_distance, gap, 3.0 * r.signed_distance_std + 1e-4) << gap;
    EXPECT_GT (r.signed_distance_std, 0.0);
    if (gap >= 0.01)
    {
      EXPECT_EQ (r.verdict, Verdict::Free) << gap;
    }
    if (gap <= -0.003)
    {
      EXPECT_EQ (r.verdict, Verdict::InCollision) << gap;
    }
  }
  // Without the surface layer, the separators answer and leave the distance unset.
  CollisionResult r;
  const CollisionRequest classifier_only;
  ASSERT_TRUE (collide (*block, *table, shift (0, 0, -0.02), classifier_only, r));
  EXPECT_TRUE (std::isnan (r.signed_distance));
}

// A distance asked for (CollisionRequest::distance) is an estimate, never the decision mode's
// bound: the slab tilted 1 cm into the table (its bottom 2.5-17.5 mm deep) stops at the first
// point that decides the collision without it, and is answered as exhaustively with it.
TEST (SurfaceLayer, AnAskedDistanceIsNeverTheFirstDecidingPoint)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto block = buildCloudModel (slab (0.1, 0.05, 0.01), withSurface ());
  const Eigen::Isometry3d T = shift (0, 0, 0.01) * Eigen::AngleAxisd (0.15, Eigen::Vector3d::UnitY ());
  CollisionRequest decision = surfaceRequest ();
  decision.exhaustive = false;
  CollisionRequest exhaustive = surfaceRequest ();
  CollisionRequest asked = decision;
  asked.distance = true;
  CollisionResult first, all, with_distance;
  ASSERT_TRUE (collide (*block, *table, T, decision, first)) << first.message;
  ASSERT_TRUE (collide (*block, *table, T, exhaustive, all)) << all.message;
  ASSERT_TRUE (collide (*block, *table, T, asked, with_distance)) << with_distance.message;
  ASSERT_TRUE (first.lower_bound);  // the pose exercises the early stop
  EXPECT_EQ (first.verdict, Verdict::InCollision);
  EXPECT_FALSE (with_distance.lower_bound);
  EXPECT_FALSE (with_distance.sample_distance);
  EXPECT_EQ (with_distance.verdict, Verdict::InCollision);
  EXPECT_EQ (with_distance.probability, all.probability);
  EXPECT_EQ (with_distance.signed_distance, all.signed_distance);
  EXPECT_EQ (with_distance.signed_distance_std, all.signed_distance_std);
  // The most significant point, at least as deep in deviations as the first deciding one.
  EXPECT_LE (with_distance.signed_distance / with_distance.signed_distance_std,
             first.signed_distance / first.signed_distance_std);
  EXPECT_LT (with_distance.signed_distance, -0.005);
}

// The ladder's separators answer a sure collision alone, with no distance. Asked for one, the
// caller gets the surface layer's as it gives alone (found in review: NaN), and the separators'
// P, verdict and witness stand.
TEST (SurfaceLayer, AnAskedDistanceIsGivenWhereTheLaddersSeparatorsAnswer)
{
  // Two copies of one ball of 10 cm radius, 3 cm into each other (normals given, 1 mm noise).
  const auto ball = buildCloudModel (sphere (800, 0.1, Eigen::Vector3d::Zero ()), noisy (0.001));
  const Eigen::Isometry3d T = shift (0.17, 0, 0);
  CollisionRequest ladder = surfaceRequest ();
  ladder.exhaustive = false;
  ladder.surface_ladder = true;
  CollisionRequest asked = ladder;
  asked.distance = true;
  CollisionRequest alone = asked;
  alone.surface_ladder = false;
  CollisionResult without, with_distance, surface_alone;
  ASSERT_TRUE (collide (*ball, *ball, T, ladder, without)) << without.message;
  ASSERT_TRUE (collide (*ball, *ball, T, asked, with_distance)) << with_distance.message;
  ASSERT_TRUE (collide (*ball, *ball, T, alone, surface_alone)) << surface_alone.message;
  ASSERT_EQ (without.answered_by, AnsweredBy::Separators) << "P " << without.probability;  // the case exercised
  ASSERT_EQ (without.verdict, Verdict::InCollision);
  EXPECT_TRUE (std::isnan (without.signed_distance));
  EXPECT_EQ (with_distance.answered_by, AnsweredBy::Separators);
  EXPECT_EQ (with_distance.probability, without.probability);
  EXPECT_EQ (with_distance.verdict, without.verdict);
  EXPECT_EQ (with_distance.witness_index, without.witness_index);
  EXPECT_FALSE (with_distance.sample_distance);
  ASSERT_TRUE (std::isfinite (surface_alone.signed_distance));
  EXPECT_EQ (with_distance.signed_distance, surface_alone.signed_distance);
  EXPECT_EQ (with_distance.signed_distance_std, surface_alone.signed_distance_std);
  EXPECT_LT (with_distance.signed_distance, -0.005);
  EXPECT_GT (with_distance.leaf_pairs_tested, without.leaf_pairs_tested);
}

// A sheet's opening (SurfaceModel::opening) says how far around a sample the surface is open:
// w the cosine of half the widest gap between its neighbours. At a straight edge the gap is
// 180 degrees (w about 0), at a corner 270 (w about cos 135 = -0.71): found in review, the
// corner read +0.71, an open cone of +-45 degrees instead of +-135.
TEST (SurfaceModel, ACornersOpeningIsWiderThanAnEdges)
{
  const auto m = buildCloudModel (sheet (0.2, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), withSurface ());
  const auto& means = m->hierarchy ().means ();
  auto openingAt = [&] (const Eigen::Vector3d& target) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < means.size (); ++i)
      if ((means[i] + m->origin () - target).norm () < (means[best] + m->origin () - target).norm ())
        best = i;
    return m->surface ().opening (best);
  };
  const Eigen::Vector4f inner = openingAt (Eigen::Vector3d (0.0, 0.0, 0.0));
  const Eigen::Vector4f edge = openingAt (Eigen::Vector3d (0.1, 0.0, 0.0));
  const Eigen::Vector4f corner = openingAt (Eigen::Vector3d (0.1, 0.1, 0.0));
  EXPECT_TRUE (inner.isZero ());
  EXPECT_NEAR (edge.w (), 0.0, 0.05);
  EXPECT_NEAR (corner.w (), -std::sqrt (0.5), 0.05);
  // Both point off the sheet: the edge along +x, the corner along the diagonal.
  EXPECT_GT (edge.x (), 0.0f);
  EXPECT_GT (corner.x (), 0.0f);
  EXPECT_GT (corner.y (), 0.0f);
}

// Per-point values (per_point) change nothing of the pair's answer: every point read beside an
// edge is searched for the surface beyond it, whether or not it could set the minimum, since its
// answer also decides whether it is a crossing's end (found in review: 2 of 400 exhaustive poses
// of a plate against a propagated table differed in P or distance).
TEST (SurfaceLayer, PerPointValuesDoNotChangeThePairsAnswer)
{
  const auto table = buildCloudModel (sheet (0.2, 0.01, 0.0, Eigen::Vector3f (0, 0, 0)), noisy (0.001));
  const auto plate = buildCloudModel (sheet (0.06, 0.008, 0.0, Eigen::Vector3f (0, 0, 0)), noisy (0.001));
  std::mt19937 rng (3);
  std::uniform_real_distribution<double> u (-1.0, 1.0);
  int reached = 0;
  for (int it = 0; it < 400; ++it)
  {
    const Eigen::Isometry3d T =
        shift (0.1 + 0.03 * u (rng), 0.1 * u (rng), 0.02 * u (rng)) *
        Eigen::AngleAxisd (1.2 + 0.4 * u (rng), Eigen::Vector3d (u (rng), u (rng), u (rng)).normalized ());
    CollisionRequest pair_only = surfaceRequest ();
    CollisionRequest per_point = pair_only;
    per_point.per_point = true;
    CollisionResult x, y;
    ASSERT_TRUE (collide (*table, *plate, T, pair_only, x)) << x.message;
    ASSERT_TRUE (collide (*table, *plate, T, per_point, y)) << y.message;
    if (x.no_leaf_tested)
      continue;
    ++reached;
    EXPECT_EQ (x.probability, y.probability) << "pose " << it;
    EXPECT_TRUE (x.signed_distance == y.signed_distance ||
                 (std::isnan (x.signed_distance) && std::isnan (y.signed_distance)))
        << "pose " << it << ": " << x.signed_distance << " against " << y.signed_distance;
  }
  EXPECT_GT (reached, 100);
}

// The separators' cap on leaf-pair fits (max_leaf_fits) is theirs: the surface layer still
// enumerates every pair within reach, so the table 2 cm into the slab reads the same collision
// with a cap of one pair as without one (found in review: it read free, P 1e-5, unflagged).
TEST (SurfaceLayer, TheSeparatorsCapDoesNotCutTheSurfaceLayer)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto block = buildCloudModel (slab (0.1, 0.05, 0.01), withSurface ());
  CollisionRequest uncapped = surfaceRequest ();
  CollisionResult free_run;
  ASSERT_TRUE (collide (*block, *table, shift (0.0, 0.0, 0.02), uncapped, free_run)) << free_run.message;
  ASSERT_EQ (free_run.verdict, Verdict::InCollision);
  for (const std::size_t cap : {std::size_t (1), std::size_t (3)})
  {
    CollisionRequest capped = uncapped;
    capped.max_leaf_fits = cap;
    CollisionResult r;
    ASSERT_TRUE (collide (*block, *table, shift (0.0, 0.0, 0.02), capped, r)) << r.message;
    EXPECT_EQ (r.verdict, Verdict::InCollision) << cap;
    EXPECT_EQ (r.probability, free_run.probability) << cap;
    EXPECT_EQ (r.signed_distance, free_run.signed_distance) << cap;
    EXPECT_EQ (r.leaf_pairs_tested, free_run.leaf_pairs_tested) << cap;
  }
}

// The surface layer's own cap (max_surface_pairs) stops it before its next query leaf and flags
// the answer: P is then a lower bound of the uncapped one, and the ladder keeps the separators'
// contact where its capped rung could not finish. A cap it never reaches changes nothing. A ball
// 1 mm (one deviation) over the table: the separators read contact, the surface layer free after
// visiting every leaf pair within reach (its slowest kind of answer).
TEST (SurfaceLayer, ItsCapStopsItFlaggedAndTheLadderKeepsTheSeparatorsContact)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto ball = buildCloudModel (sphere (800, 0.05, Eigen::Vector3d (0, 0, 0.05)), noisy (0.001));
  CollisionRequest alone;
  alone.surface = true;
  CollisionRequest ladder = alone;
  ladder.surface_ladder = true;
  CollisionRequest separators;
  CollisionResult full, full_ladder, theirs;
  const Eigen::Isometry3d pose = shift (0, 0, -0.001);
  ASSERT_TRUE (collide (*ball, *table, pose, alone, full)) << full.message;
  ASSERT_TRUE (collide (*ball, *table, pose, ladder, full_ladder)) << full_ladder.message;
  ASSERT_TRUE (collide (*ball, *table, pose, separators, theirs)) << theirs.message;
  ASSERT_FALSE (full.budget_exhausted);
  ASSERT_FALSE (full.lower_bound);
  ASSERT_GT (full.leaf_pairs_tested, 20u);
  ASSERT_EQ (theirs.verdict, Verdict::InContact);  // the ladder's surface rung runs
  ASSERT_EQ (full_ladder.answered_by, AnsweredBy::SurfaceLayer);
  for (const std::size_t cap : {std::size_t (1), std::size_t (8)})
  {
    alone.max_surface_pairs = ladder.max_surface_pairs = cap;
    CollisionResult r, l;
    ASSERT_TRUE (collide (*ball, *table, pose, alone, r)) << r.message;
    EXPECT_TRUE (r.budget_exhausted) << cap;
    EXPECT_TRUE (r.lower_bound) << cap;
    EXPECT_LE (r.probability, full.probability) << cap;
    EXPECT_LT (r.leaf_pairs_tested, full.leaf_pairs_tested) << cap;
    ASSERT_TRUE (collide (*ball, *table, pose, ladder, l)) << l.message;
    EXPECT_TRUE (l.budget_exhausted) << cap;
    EXPECT_EQ (l.answered_by, AnsweredBy::Separators) << cap;
    EXPECT_EQ (l.probability, theirs.probability) << cap;
    EXPECT_EQ (l.verdict, Verdict::InContact) << cap;
  }
  alone.max_surface_pairs = ladder.max_surface_pairs = 1000000;
  CollisionResult r, l;
  ASSERT_TRUE (collide (*ball, *table, pose, alone, r)) << r.message;
  ASSERT_TRUE (collide (*ball, *table, pose, ladder, l)) << l.message;
  EXPECT_FALSE (r.budget_exhausted);
  EXPECT_EQ (r.probability, full.probability);
  EXPECT_EQ (r.signed_distance, full.signed_distance);
  EXPECT_EQ (r.leaf_pairs_tested, full.leaf_pairs_tested);
  EXPECT_FALSE (l.budget_exhausted);
  EXPECT_EQ (l.probability, full_ladder.probability);
}

// A distance asked for far apart is the nearest samples' whichever way the pair is answered:
// two 3 cm patches 5 m apart are single leaves, whose pair the separators' weighted traversal
// still fits (it is not "no leaf tested" for them), but the surface layer reaches nothing, so
// the pool and the ladder give the distance as the surface layer alone does (found in review:
// NaN).
TEST (SurfaceLayer, AnAskedDistanceFarApartIsGivenPooledAndLaddered)
{
  const auto a = buildCloudModel (sheet (0.03, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto b = buildCloudModel (sheet (0.03, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  CollisionRequest alone;
  alone.surface = true;
  alone.distance = true;
  CollisionRequest pooled = alone;
  pooled.surface_pooled = true;
  CollisionRequest ladder = alone;
  ladder.surface_ladder = true;
  for (const double x : {0.5, 5.0})
  {
    CollisionResult r_alone, r_pooled, r_ladder;
    ASSERT_TRUE (collide (*a, *b, shift (x, 0, 0), alone, r_alone)) << r_alone.message;
    ASSERT_TRUE (collide (*a, *b, shift (x, 0, 0), pooled, r_pooled)) << r_pooled.message;
    ASSERT_TRUE (collide (*a, *b, shift (x, 0, 0), ladder, r_ladder)) << r_ladder.message;
    ASSERT_TRUE (r_alone.sample_distance) << x;
    EXPECT_NEAR (r_alone.signed_distance, x - 0.03, 0.005) << x;
    for (const CollisionResult* r : {&r_pooled, &r_ladder})
    {
      EXPECT_TRUE (r->sample_distance) << x;
      EXPECT_EQ (r->signed_distance, r_alone.signed_distance) << x;
      EXPECT_EQ (r->signed_distance_std, r_alone.signed_distance_std) << x;
      EXPECT_EQ (r->verdict, Verdict::Free) << x;
    }
  }
}

// A table without a viewpoint (its sensor origin within it) is oriented by propagation, which
// cannot say which side is solid: a ball 10 mm above it and one 10 mm below read free alike.
// Through its middle, the ball reads collision (its points on both sides of the table).
TEST (SurfaceLayer, APropagatedSurfaceIsTwoSided)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f::Zero ()), noisy (0.001));
  ASSERT_EQ (table->surface ().orientation (), NormalOrientation::Propagate);
  const auto ball = buildCloudModel (sphere (2000, 0.05, Eigen::Vector3d::Zero ()), withSurface ());
  std::vector<double> clearance;
  for (const double table_z : {-0.06, 0.06})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*ball, *table, shift (0, 0, table_z), surfaceRequest (), r)) << table_z;
    EXPECT_EQ (r.verdict, Verdict::Free) << table_z << ": P " << r.probability << ", d " << r.signed_distance;
    EXPECT_GT (r.signed_distance, 0.005) << table_z;
    clearance.push_back (r.signed_distance);
  }
  EXPECT_NEAR (clearance[0], clearance[1], 0.002);  // the same from either side
  CollisionResult through;
  ASSERT_TRUE (collide (*ball, *table, shift (0, 0, 0.0), surfaceRequest (), through));
  EXPECT_EQ (through.verdict, Verdict::InCollision) << "P " << through.probability << ", d " << through.signed_distance
                                                    << " +- " << through.signed_distance_std;
}

// A thin plate (2 mm, both faces sampled, 1 mm noise) without normals or a viewpoint: its two
// faces blur into one sheet whose normals scatter, and a few samples' faces (two or more
// normals alike) have planes that pass near points far from those samples. A face's plane holds
// only about its samples: a ball 8 mm (5.7 sigma_eff) over the plate reads free, not contact
// (W2's plate_sphere read P 0.17-0.46 there, d about 0 on such a face's extended plane).
TEST (SurfaceLayer, ATwoSidedFaceHoldsOnlyAboutItsSamples)
{
  const double sigma = 0.001;
  pcl::PointCloud<pcl::PointXYZ> plate;
  std::mt19937_64 rng (7);
  std::uniform_real_distribution<double> across (-0.1, 0.1);
  std::normal_distribution<double> noise (0.0, sigma);
  for (const double face : {-0.001, 0.001})
    for (int i = 0; i < 4444; ++i)
    {
      const double x = across (rng);  // one draw a statement (seeded_draws.h)
      const double y = across (rng);
      const Eigen::Vector3d p (x, y, 0.5 + face);
      const Eigen::Vector3d e = draw3 (noise, rng);
      plate.push_back (pcl::PointXYZ (static_cast<float> (p.x () + e.x ()), static_cast<float> (p.y () + e.y ()),
                                      static_cast<float> (p.z () + e.z ())));
    }
  plate.sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 0.5f, 0.0f);  // within it: no viewpoint
  const auto model = buildCloudModel (plate, noisy (sigma));
  ASSERT_EQ (model->surface ().orientation (), NormalOrientation::Propagate);
  pcl::PointCloud<pcl::PointXYZ> ball;
  std::normal_distribution<double> ball_noise (0.0, sigma);
  for (const Eigen::Vector3d& u : fibonacci (3000))
  {
    const Eigen::Vector3d e = draw3 (ball_noise, rng);
    const Eigen::Vector3d p = 0.05 * u + e;
    ball.push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()), static_cast<float> (p.z ())));
  }
  const auto sphere_model = buildCloudModel (ball, noisy (sigma));
  int free = 0;
  for (const double x : {-0.03, 0.0, 0.03})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*sphere_model, *model, shift (-x, 0.0, -(0.5 + 0.001 + 0.05 + 0.008)), surfaceRequest (), r));
    free += r.verdict == Verdict::Free ? 1 : 0;
    EXPECT_GT (r.signed_distance, 0.004) << "ball over x = " << x << ": P " << r.probability << ", d "
                                         << r.signed_distance << " +- " << r.signed_distance_std;
  }
  EXPECT_EQ (free, 3);
}

// A scanned sheet has an unseen back: a table 1 cm behind a sheet seen from above is not read
// free (the space behind a sheet counts as occupied within the near field's reach).
TEST (SurfaceLayer, BehindAScannedSheetIsNotFree)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto top = buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  CollisionResult r;
  ASSERT_TRUE (collide (*top, *table, shift (0, 0, -0.01), surfaceRequest (), r));
  EXPECT_NE (r.verdict, Verdict::Free);
  // ... and that space was never seen: the answer says so.
  EXPECT_TRUE (r.unobserved);
}

// A scan saved with its normals (PCL's normal estimation turns them toward the sensor) is still
// one scan: behind it no sample looked, whether the normals or the VIEWPOINT orient it. Normals
// facing away from the VIEWPOINT, or a closed object's, are no scan's (found by the probe of
// 2026-12-03: such a sheet never set `unobserved`).
TEST (SurfaceLayer, BehindAScanSavedWithItsNormalsIsUnobserved)
{
  auto withNormals = [] (const pcl::PointCloud<pcl::PointXYZ>& in, const Eigen::Vector3f& n) {
    pcl::PointCloud<pcl::PointNormal> out;
    for (const auto& p : in)
      out.push_back (pointNormal (p.x, p.y, p.z, n));
    out.sensor_origin_ = in.sensor_origin_;
    return out;
  };
  const Eigen::Vector3f up (0, 0, 1);
  const auto scan = buildCloudModel (withNormals (sheet (0.4, 0.01, 0.0, up), up), noisy (0.001));
  const auto turned = buildCloudModel (withNormals (sheet (0.4, 0.01, 0.0, -up), up), noisy (0.001));
  auto ball_cloud = sphere (2000, 0.1, Eigen::Vector3d::Zero ());
  ball_cloud.sensor_origin_ = Eigen::Vector4f (1, 0, 0, 0);
  const auto ball = buildCloudModel (ball_cloud, noisy (0.001));
  ASSERT_EQ (scan->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_TRUE (scan->surface ().seenFromViewpoint ());
  EXPECT_EQ (scan->surface ().hiddenFromViewpoint (), 0.0);
  EXPECT_FALSE (turned->surface ().seenFromViewpoint ());
  EXPECT_FALSE (ball->surface ().seenFromViewpoint ());

  // A plate 1 cm under the sheet, two-sided itself (propagated): only the sheet decides.
  CloudModelParams two_sided = noisy (0.001);
  two_sided.orientation = NormalOrientation::Propagate;
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 0.0, up), two_sided);
  CollisionResult behind_scan, behind_turned;
  ASSERT_TRUE (collide (*scan, *plate, shift (0, 0, -0.01), surfaceRequest (), behind_scan));
  ASSERT_TRUE (collide (*turned, *plate, shift (0, 0, -0.01), surfaceRequest (), behind_turned));
  EXPECT_EQ (behind_scan.verdict, Verdict::InCollision);
  EXPECT_TRUE (behind_scan.unobserved);
  // The same normals under a VIEWPOINT they do not face: behind them is inside, as given.
  EXPECT_EQ (behind_turned.verdict, Verdict::InCollision);
  EXPECT_FALSE (behind_turned.unobserved);
}

// Normals estimated without an orientation (Open3D's estimate_normals leaves each sign to its eigen
// solver; a probe of 2026-12-06 fed them to the surface model as outward) face a viewpoint that sees
// the cloud as one scan and away about as often, and disagree between neighbours: Auto keeps their
// directions and turns them toward the viewpoint, as for a scan without normals. Normals that agree
// between neighbours but face away from the viewpoint are an orientation under a stale VIEWPOINT
// (pcl::transformPointCloud leaves it behind): kept, with a warning.
TEST (SurfaceLayer, AScansNormalsWithUnorientedSidesAreTurnedTowardItsViewpoint)
{
  const Eigen::Vector3f up (0, 0, 1);
  std::mt19937 draw (3);
  auto withNormals = [] (const pcl::PointCloud<pcl::PointXYZ>& in, auto&& normal) {
    pcl::PointCloud<pcl::PointNormal> out;
    for (const auto& p : in)
      out.push_back (pointNormal (p.x, p.y, p.z, normal ()));
    out.sensor_origin_ = in.sensor_origin_;
    return out;
  };
  const auto random_sides = withNormals (sheet (0.4, 0.01, 0.0, up), [&] { return draw () % 2 ? up : Eigen::Vector3f (-up); });
  const auto unoriented = buildCloudModel (random_sides, noisy (0.001));
  EXPECT_TRUE (unoriented->surface ().givenNormalsMisoriented ());
  EXPECT_GT (unoriented->surface ().givenNormalSideDisagreement (), 0.3);
  EXPECT_EQ (unoriented->surface ().orientation (), NormalOrientation::Viewpoint);
  EXPECT_NE (unoriented->warning ().find ("taken as directions, turned toward the viewpoint"), std::string::npos)
      << unoriented->warning ();
  CloudModelParams as_given = noisy (0.001);
  as_given.orientation = NormalOrientation::PointNormals;
  const auto taken = buildCloudModel (random_sides, as_given);
  EXPECT_EQ (taken->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_NE (taken->warning ().find ("taken as given, as orientation point_normals asks"), std::string::npos)
      << taken->warning ();

  // Agreeing normals under a viewpoint below them: kept as given, and warned of.
  const auto stale = buildCloudModel (withNormals (sheet (0.4, 0.01, 0.0, -up), [&] { return up; }), noisy (0.001));
  EXPECT_FALSE (stale->surface ().givenNormalsMisoriented ());
  EXPECT_LT (stale->surface ().givenNormalSideDisagreement (), 0.01);
  EXPECT_EQ (stale->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_NE (stale->warning ().find ("face away from its viewpoint"), std::string::npos) << stale->warning ();

  // The unoriented scan answers as the same scan without normals: a plate 1 cm under it is in
  // the unobserved space behind it, one 1 cm over it is clear. (Taken as given, the plate under it
  // read free, P = 0.0017.)
  CloudModelParams two_sided = noisy (0.001);
  two_sided.orientation = NormalOrientation::Propagate;
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 0.0, up), two_sided);
  const auto bare = buildCloudModel (sheet (0.4, 0.01, 0.0, up), noisy (0.001));
  for (const double z : {-0.01, 0.01})
  {
    CollisionResult with_normals, without;
    ASSERT_TRUE (collide (*unoriented, *plate, shift (0, 0, z), surfaceRequest (), with_normals));
    ASSERT_TRUE (collide (*bare, *plate, shift (0, 0, z), surfaceRequest (), without));
    EXPECT_EQ (with_normals.verdict, without.verdict) << z;
    EXPECT_EQ (with_normals.verdict, z < 0.0 ? Verdict::InCollision : Verdict::Free) << z;
    EXPECT_EQ (with_normals.unobserved, z < 0.0) << z;
  }
}

// Sparse table (spacing 10 sigma): a point between four samples, 3 sigma under the surface, is
// inside; the surface is continuous between samples.
TEST (SurfaceLayer, SparseSurfaceIsContinuousBetweenSamples)
{
  const double sigma = 0.001;
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (sigma));
  pcl::PointCloud<pcl::PointXYZ> probe;
  probe.push_back (pcl::PointXYZ (0.005f, 0.005f, 0.0f));
  const auto point = buildCloudModel (probe, withSurface ());
  CollisionResult under, over;
  ASSERT_TRUE (collide (*point, *table, shift (0, 0, 0.004), surfaceRequest (), under));
  ASSERT_TRUE (collide (*point, *table, shift (0, 0, -0.004), surfaceRequest (), over));
  EXPECT_GT (under.probability, 0.9) << under.signed_distance << " +- " << under.signed_distance_std << " side "
                                     << under.witness_side << " at " << under.witness_point.transpose ();
  EXPECT_LT (over.probability, 0.1) << over.signed_distance << " +- " << over.signed_distance_std;
}

// Beside a sampled edge the surface may end anywhere within a gap past the last samples: a point
// in the table's plane, 0.9 spacings past its edge, is not read as on the extended table
// (P about 0.5 before the edge's mixture), while one between four samples inside the table is.
TEST (SurfaceLayer, BesideAnEdgeTheSurfaceMayEnd)
{
  const double sigma = 0.001;
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (sigma));
  // The table's samples on its rim are open toward the outside, inner ones are not.
  std::size_t open = 0;
  for (std::size_t i = 0; i < table->hierarchy ().size (); ++i)
    open += table->surface ().opening (i).head<3> ().isZero () ? 0u : 1u;
  EXPECT_EQ (open, table->surface ().openPoints ());
  EXPECT_GE (open, 4u * 40u - 4u);
  EXPECT_LE (open, 4u * 40u + 4u);
  pcl::PointCloud<pcl::PointXYZ> probe;
  probe.push_back (pcl::PointXYZ (0.0f, 0.0f, 0.0f));
  const auto point = buildCloudModel (probe, withSurface ());
  CollisionResult beside, inside;
  ASSERT_TRUE (collide (*point, *table, shift (-0.209, -0.005, 0.0), surfaceRequest (), beside));
  ASSERT_TRUE (collide (*point, *table, shift (-0.005, -0.005, 0.0), surfaceRequest (), inside));
  EXPECT_LT (beside.probability, 0.35) << beside.signed_distance << " +- " << beside.signed_distance_std;
  EXPECT_GT (beside.signed_distance, 0.0);
  EXPECT_GT (inside.probability, 0.35) << inside.signed_distance << " +- " << inside.signed_distance_std;
  EXPECT_LT (inside.probability, 0.65);
}

// A convex edge whose side face is sampled twice as sparsely: the solid x < 0, y < 0, its top
// face y = 0 (normal +y) every h, its side face x = 0 (normal +x) every 2h. A point 0.3 h in
// front of the side face and 0.3 h under the top face's plane is outside; among its 8 nearest
// samples one is the side face's, so that face counts only as corroborated by the pool's other
// samples on its plane (kCorroborationGaps). Without that the point read behind the top face.
TEST (SurfaceLayer, ASideFaceWithOneSampleAmongTheNearestCounts)
{
  const double h = 0.01;
  pcl::PointCloud<pcl::PointNormal> edge;
  for (int k = -10; k <= 10; ++k)
    for (int i = 0; i <= 10; ++i)
      edge.push_back (pointNormal (-i * h, 0.0, k * h, Eigen::Vector3f (0, 1, 0)));
  for (int k = -5; k <= 5; ++k)
    for (int j = 1; j <= 5; ++j)
      edge.push_back (pointNormal (0.0, -2.0 * j * h, 2.0 * k * h, Eigen::Vector3f (1, 0, 0)));
  const auto solid = buildCloudModel (edge, noisy (0.001));
  ASSERT_EQ (solid->surface ().orientation (), NormalOrientation::PointNormals);
  pcl::PointCloud<pcl::PointXYZ> probe;
  probe.push_back (pcl::PointXYZ (0.0f, 0.0f, 0.0f));
  const auto point = buildCloudModel (probe, withSurface ());
  CollisionResult outside, inside;
  ASSERT_TRUE (collide (*point, *solid, shift (-0.3 * h, 0.3 * h, 0.0), surfaceRequest (), outside));
  ASSERT_TRUE (collide (*point, *solid, shift (0.3 * h, 0.3 * h, 0.0), surfaceRequest (), inside));
  // Beside the edge the face may end anywhere within a gap (the edge's mixture and
  // discretisation term), so P stays between: 0.25 and 0.77 here; without the side face the
  // outside point read 2.7 mm deep, P = 0.68.
  EXPECT_GT (outside.signed_distance, 0.0);
  EXPECT_LT (outside.probability, 0.4) << outside.signed_distance << " +- " << outside.signed_distance_std;
  EXPECT_LT (inside.signed_distance, 0.0);
  EXPECT_GT (inside.probability, 0.6) << inside.signed_distance << " +- " << inside.signed_distance_std;
}

// A row of mesh vertices inside a flat face (a triangle edge): each sees its neighbours along
// the row, 180 degrees open on either side, which says nothing about where the face goes on.
TEST (SurfaceModel, ARowOfVerticesIsNoEdge)
{
  auto cloud = sheet (0.4, 0.02, 0.0, Eigen::Vector3f (0, 0, 1));
  for (int i = -50; i <= 50; ++i)
    cloud.push_back (pcl::PointXYZ (0.002f * static_cast<float> (i), 0.001f, 0.0f));
  const auto model = buildCloudModel (cloud, noisy (0.001));
  const auto& means = model->hierarchy ().means ();
  std::size_t row = 0, open = 0;
  for (std::size_t i = 0; i < means.size (); ++i)
  {
    const Eigen::Vector3d p = means[i] + model->origin ();
    if (std::abs (p.y () - 0.001) > 1e-4 || std::abs (p.x ()) > 0.08)
      continue;
    ++row;
    open += model->surface ().opening (i).head<3> ().isZero () ? 0u : 1u;
  }
  EXPECT_GE (row, 70u);
  EXPECT_EQ (open, 0u);
}

// A small ball entirely inside a big closed surface with given outward normals: no point is
// within reach, and the winding number reports the containment.
TEST (SurfaceLayer, ContainmentFromTheWindingNumber)
{
  const auto big = buildCloudModel (sphere (2000, 1.0, Eigen::Vector3d::Zero ()), withSurface ());
  const auto ball = buildCloudModel (sphere (200, 0.05, Eigen::Vector3d::Zero ()), withSurface ());
  CollisionResult inside, outside;
  ASSERT_TRUE (collide (*ball, *big, shift (0.2, 0.1, 0.0), surfaceRequest (), inside));
  ASSERT_TRUE (collide (*ball, *big, shift (2.0, 0.0, 0.0), surfaceRequest (), outside));
  EXPECT_EQ (inside.verdict, Verdict::InCollision);
  EXPECT_LT (inside.signed_distance, -0.5);  // about 0.75 deep: at least half of it
  EXPECT_FALSE (inside.unobserved);          // inside a closed surface, not behind a sheet
  EXPECT_EQ (outside.verdict, Verdict::Free);
  EXPECT_TRUE (outside.no_leaf_tested);
  // Pooled: the separators reach no leaf pair here, and their P = 0 says nothing. It was
  // averaged with the containment's P = 1 into contact 0.5 (a probe, 2026-12-04); the surface
  // layer's answer stands alone now.
  CollisionRequest pooled = surfaceRequest (), separators = surfaceRequest ();
  pooled.surface_pooled = true;
  separators.surface = false;
  CollisionResult by_separators, by_pool;
  ASSERT_TRUE (collide (*ball, *big, shift (0.2, 0.1, 0.0), separators, by_separators));
  ASSERT_TRUE (by_separators.no_leaf_tested) << "the case needs separators that reach nothing";
  ASSERT_TRUE (collide (*ball, *big, shift (0.2, 0.1, 0.0), pooled, by_pool));
  EXPECT_EQ (by_pool.verdict, Verdict::InCollision);
  EXPECT_EQ (by_pool.probability, inside.probability);
  EXPECT_EQ (by_pool.answered_by, AnsweredBy::SurfaceLayer);
}

// A ball wholly inside a closed sphere, 5 mm to 4 cm from its wall: the separators reach leaf
// pairs there and read free or contact (no two surfaces cross), the surface layer collision (the
// ball's points inside by the winding number). Pooled, and in the ladder after their free
// answer, the mean read contact 0.50-0.65 (a probe, 2026-12-04); an answer inside by the
// winding number (SurfaceAnswer::inside_confirmed) now stands alone.
TEST (SurfaceLayer, APoolKeepsAPointInsideByTheWindingNumber)
{
  const auto big = buildCloudModel (sphere (4000, 0.3, Eigen::Vector3d::Zero ()), withSurface ());
  const auto ball = buildCloudModel (sphere (300, 0.05, Eigen::Vector3d::Zero ()), withSurface ());
  const Answerers q (false);
  int separators_free = 0;
  for (const double gap : {0.005, 0.01, 0.02, 0.04})
  {
    SCOPED_TRACE ("gap " + std::to_string (gap));
    const Eigen::Isometry3d T = shift (-(0.3 - 0.05 - gap), 0.0, 0.0);  // the big sphere in the ball's frame
    CollisionResult rc, rs, rp, rl;
    ASSERT_TRUE (collide (*ball, *big, T, q.separators, rc));
    ASSERT_TRUE (collide (*ball, *big, T, q.surface, rs));
    ASSERT_TRUE (collide (*ball, *big, T, q.pooled, rp));
    ASSERT_TRUE (collide (*ball, *big, T, q.ladder, rl));
    separators_free += rc.verdict == Verdict::Free ? 1 : 0;
    EXPECT_EQ (rs.verdict, Verdict::InCollision);
    for (const CollisionResult* r : {&rp, &rl})
    {
      EXPECT_EQ (r->verdict, Verdict::InCollision);
      EXPECT_EQ (r->answered_by, AnsweredBy::SurfaceLayer);
      EXPECT_EQ (r->probability, rs.probability);
    }
  }
  EXPECT_GE (separators_free, 2) << "the case needs separators that read free";
}

// The ladder's containment rung, where the separators reach no leaf pair, judged one point of
// each object, its first: an object of two balls, the one outside listed first, read free with
// the other ball wholly inside a closed sphere (a probe, 2026-12-04), and collision with the
// order reversed. It now judges every node clear of the other's surface, as the surface layer
// does out of reach: collision in either order, per point only the inside ball's points.
TEST (SurfaceLayer, TheLaddersContainmentDoesNotDependOnThePointOrder)
{
  const auto big = buildCloudModel (sphere (2000, 1.0, Eigen::Vector3d::Zero ()), withSurface ());
  const auto outside = sphere (200, 0.05, Eigen::Vector3d (2.5, 0.0, 0.0));
  const auto inside = sphere (200, 0.05, Eigen::Vector3d (0.2, 0.1, 0.0));
  pcl::PointCloud<pcl::PointNormal> outside_first = outside, inside_first = inside;
  outside_first += inside;
  inside_first += outside;
  for (const auto* cloud : {&outside_first, &inside_first})
  {
    const bool first_outside = cloud == &outside_first;
    SCOPED_TRACE (first_outside ? "the outside ball first" : "the inside ball first");
    const auto two = buildCloudModel (*cloud, withSurface ());
    const Answerers q (false);
    CollisionResult rc, rl;
    ASSERT_TRUE (collide (*two, *big, Eigen::Isometry3d::Identity (), q.separators, rc));
    ASSERT_TRUE (rc.no_leaf_tested) << "the case needs separators that reach nothing";
    ASSERT_TRUE (collide (*two, *big, Eigen::Isometry3d::Identity (), q.ladder, rl));
    EXPECT_EQ (rl.verdict, Verdict::InCollision);
    EXPECT_EQ (rl.answered_by, AnsweredBy::SurfaceLayer);
    EXPECT_LT (rl.signed_distance, -0.5);  // the inside ball about 0.75 deep
    CollisionRequest decision = q.ladder;  // without per-point values: the first node found decides
    decision.per_point = false;
    CollisionResult rd;
    ASSERT_TRUE (collide (*two, *big, Eigen::Isometry3d::Identity (), decision, rd));
    EXPECT_EQ (rd.verdict, Verdict::InCollision);
    EXPECT_TRUE (rd.lower_bound);
    // Per point (q asks for them): 1 for the inside ball's points, nothing for the outside one's.
    ASSERT_EQ (rl.probabilities_a.size (), 400u);
    for (std::size_t i = 0; i < 400; ++i)
    {
      const bool in = (i < 200) != first_outside;
      if (in)
        EXPECT_EQ (rl.probabilities_a[i], 1.0f) << i;
      else
        EXPECT_FALSE (rl.probabilities_a[i] > 0.0f) << i;
    }
  }
}

namespace
{
/** \brief The surface of the box of half extents h about c, sampled on a grid of about spacing
  * `step` on each face, every coordinate moved by N(0, sigma^2) (seeded): a solid's samples
  * without normals. */
pcl::PointCloud<pcl::PointXYZ>
boxSurface (const Eigen::Vector3d& c, const Eigen::Vector3d& h, double step, double sigma, unsigned seed)
{
  std::mt19937 rng (seed);
  std::normal_distribution<double> noise (0.0, sigma);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int axis = 0; axis < 3; ++axis)
    for (const double side : {-1.0, 1.0})
    {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int nu = static_cast<int> (std::ceil (2.0 * h (u) / step)), nv = static_cast<int> (std::ceil (2.0 * h (v) / step));
      for (int i = 0; i <= nu; ++i)
        for (int j = 0; j <= nv; ++j)
        {
          Eigen::Vector3d p;
          p (axis) = side * h (axis);
          p (u) = -h (u) + 2.0 * h (u) * i / nu;
          p (v) = -h (v) + 2.0 * h (v) * j / nv;
          p += c + Eigen::Vector3d (noise (rng), noise (rng), noise (rng));
          cloud.push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()), static_cast<float> (p.z ())));
        }
    }
  return cloud;
}

CloudModelParams
closedObjects (CloudModelParams p)
{
  p.closed_objects = true;
  return p;
}
} // namespace

// A sheet seen edge-on as in SurfaceModel.ASheetSeenEdgeOnIsTwoSided, with a coarser noise (2 mm
// at 1 cm spacing, drawn in all three coordinates) and the sensor at three places in the sheet's
// plane, eight draws each; a 20 cm box sampled every 1 cm with the same noise held 3 cm above it
// or under it. The noise tilts whole patches of normals (they share their neighbours) toward the
// sensor or away: neighbour pairs rarely point apart, but the patches disagree once one
// orientation is carried over the sheet (27-50 % of the facing points). Before 2026-12-02 (neighbour pairs counted) 6 of these 24
// kept the viewpoint, and each of them read the box 3 cm clear on one side as inside, P = 1.
TEST (SurfaceModel, ASheetSeenEdgeOnThroughCoarseNoiseIsTwoSided)
{
  const auto box = buildCloudModel (boxSurface (Eigen::Vector3d (0, 0, 0.1), Eigen::Vector3d::Constant (0.1), 0.01, 0.002, 1), noisy (0.002));
  CloudModelParams p = noisy (0.002);
  p.orientation = NormalOrientation::Viewpoint;
  for (const Eigen::Vector3f& view : {Eigen::Vector3f (1, 0, 0), Eigen::Vector3f (0, 0, 0), Eigen::Vector3f (0.3f, 0.3f, 0)})
    for (unsigned draw = 0; draw < 8; ++draw)
    {
      std::mt19937 rng (draw);
      std::normal_distribution<float> noise (0.0f, 0.002f);
      auto cloud = sheet (0.3, 0.01, 0.0, view);
      for (auto& q : cloud)
        q.getVector3fMap () += Eigen::Vector3f (noise (rng), noise (rng), noise (rng));
      const auto edge_on = buildCloudModel (cloud, p);
      EXPECT_EQ (edge_on->surface ().orientation (), NormalOrientation::Propagate) << view.transpose () << ", draw " << draw;
      for (const double z : {-0.03, 0.23})  // the sheet 3 cm under the box's bottom, then over its top
      {
        CollisionResult r;
        ASSERT_TRUE (collide (*box, *edge_on, shift (0, 0, z), surfaceRequest (), r)) << r.message;
        EXPECT_EQ (r.verdict, Verdict::Free) << view.transpose () << ", draw " << draw << ", " << z << " m: P " << r.probability;
      }
    }
}

// A closed object's samples (a 20 cm box, 1 cm spacing, 2 mm noise) with a viewpoint outside it,
// Viewpoint asked for: the far faces face the sensor from behind, and turned toward it they would
// point inward (Auto refuses such a viewpoint by the points it hides). Their side disagrees with
// the near faces' once one orientation is carried over the box, so the viewpoint orients nothing.
// Before 2026-12-02 it did, and a sheet 3 cm under the box read as inside it (P = 1).
TEST (SurfaceModel, AViewpointThatSeesAClosedObjectFromOutsideOrientsNothing)
{
  auto cloud = boxSurface (Eigen::Vector3d (0, 0, 0.1), Eigen::Vector3d::Constant (0.1), 0.01, 0.002, 1);
  cloud.sensor_origin_ = Eigen::Vector4f (1.0f, 0.2f, 0.5f, 0.0f);
  CloudModelParams p = noisy (0.002);
  p.orientation = NormalOrientation::Viewpoint;
  const auto box = buildCloudModel (cloud, p);
  EXPECT_EQ (box->surface ().orientation (), NormalOrientation::Propagate);
  const auto floor = buildCloudModel (sheet (0.3, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.002));
  CollisionResult r;
  ASSERT_TRUE (collide (*box, *floor, shift (0, 0, -0.03), surfaceRequest (), r)) << r.message;
  EXPECT_EQ (r.verdict, Verdict::Free) << "P " << r.probability;
}

// Declared closed objects (CloudModelParams::closed_objects), a propagated orientation is checked
// by the winding number in front of and behind its samples: a sphere and a noisy box check out
// and are trusted (the box's edge samples' probes behind come out of it: fewer read inside); an
// open sheet does not (about 1/2 on either side), nor does a plate thinner than the probes'
// offset (every probe behind it comes out beyond its other face). Undeclared, nothing is
// checked and the propagated surface stays two-sided.
TEST (SurfaceModel, ClosedObjectsCheckTheirPropagatedOrientation)
{
  const auto ball = buildCloudModel (xyz (sphere (800, 0.1, Eigen::Vector3d (1, 2, 3))), closedObjects (withSurface ()));
  ASSERT_EQ (ball->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_GE (ball->surface ().closedShare (), 0.95);
  EXPECT_GE (ball->surface ().solidShare (), 0.95);
  EXPECT_TRUE (ball->surface ().insideKnown ());
  const auto box = buildCloudModel (boxSurface (Eigen::Vector3d (1, 2, 3), Eigen::Vector3d (0.1, 0.08, 0.06), 0.006, 0.001, 7),
                                    closedObjects (noisy (0.001)));
  ASSERT_EQ (box->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_GE (box->surface ().closedShare (), 0.95);
  EXPECT_GT (box->surface ().solidShare (), 0.7);  // 0.89
  EXPECT_LT (box->surface ().solidShare (), box->surface ().closedShare ());
  EXPECT_TRUE (box->surface ().insideKnown ());
  const auto undeclared = buildCloudModel (xyz (sphere (800, 0.1, Eigen::Vector3d (1, 2, 3))), withSurface ());
  EXPECT_TRUE (std::isnan (undeclared->surface ().closedShare ()));
  EXPECT_FALSE (undeclared->surface ().insideKnown ());
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f::Zero ()), closedObjects (noisy (0.001)));
  ASSERT_EQ (table->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_LT (table->surface ().closedShare (), 0.1);  // 0.04
  EXPECT_FALSE (table->surface ().insideKnown ());
  // Refused, it says so in the model's warning (and so in every result's message), as
  // pcd_collision's Orienting line does; checked closed or undeclared, nothing is said.
  EXPECT_NE (table->warning ().find ("closed_objects was asked for, but its propagated orientation does not check closed"),
             std::string::npos)
      << table->warning ();
  EXPECT_EQ (ball->warning ().find ("closed_objects"), std::string::npos) << ball->warning ();
  EXPECT_EQ (box->warning ().find ("closed_objects"), std::string::npos) << box->warning ();
  EXPECT_EQ (undeclared->warning ().find ("closed_objects"), std::string::npos) << undeclared->warning ();
  CloudModelParams propagated = closedObjects (noisy (0.0005));
  propagated.orientation = NormalOrientation::Propagate;  // PCL's default origin would be its viewpoint
  const auto plate = buildCloudModel (boxSurface (Eigen::Vector3d (1, 2, 3), Eigen::Vector3d (0.1, 0.1, 0.001), 0.004, 0.0005, 8),
                                      propagated);
  ASSERT_EQ (plate->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_LT (plate->surface ().solidShare (), 0.1);
  EXPECT_FALSE (plate->surface ().insideKnown ());
  // Given normals and a viewpoint are trusted anyway, and not checked.
  const auto given = buildCloudModel (sphere (800, 0.1, Eigen::Vector3d (1, 2, 3)), closedObjects (withSurface ()));
  EXPECT_EQ (given->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_TRUE (std::isnan (given->surface ().closedShare ()));
  EXPECT_TRUE (given->surface ().insideKnown ());
}

// A closed object saved with PCL's normals: NormalEstimation turns each one toward the cloud's
// viewpoint (PCL's default origin, here beside the sphere), so those of the far side point in.
// Taken as outward, they made a ball inside the sphere read free in every setting, without a
// word (probe of 2026-12-04). Auto now sees normals that all face a viewpoint from which much
// of the cloud is hidden, sets their sides aside and propagates; `closed_objects` then checks
// the sphere closed and the ball reads collision.
TEST (SurfaceModel, NormalsTurnedTowardAViewpointBesideAClosedObjectAreNotOutward)
{
  const Eigen::Vector3d c (0.6, 0.0, 0.0);
  const auto outward = sphere (3000, 0.2, c);
  auto turned = outward;
  std::size_t inward = 0;
  for (auto& p : turned)
    if (p.getNormalVector3fMap ().dot (-p.getVector3fMap ()) < 0.0f)  // pcl::flipNormalTowardsViewpoint's rule
    {
      p.getNormalVector3fMap () = -p.getNormalVector3fMap ();
      ++inward;
    }
  ASSERT_GT (inward, turned.size () / 2);  // the sphere's origin side is the smaller cap
  const auto as_given = buildCloudModel (outward, withSurface ());
  EXPECT_EQ (as_given->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_FALSE (as_given->surface ().normalsTurnedToViewpoint ());
  const auto set_aside = buildCloudModel (turned, withSurface ());
  EXPECT_EQ (set_aside->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_TRUE (set_aside->surface ().normalsTurnedToViewpoint ());
  EXPECT_GT (set_aside->surface ().hiddenFromViewpoint (), SurfaceModel::kMaxHiddenShare);
  EXPECT_FALSE (set_aside->surface ().insideKnown ());  // two-sided until declared closed
  EXPECT_FALSE (set_aside->surface ().seenFromViewpoint ());
  // Asked for by name, the normals are taken as they are.
  CloudModelParams asked = withSurface ();
  asked.orientation = NormalOrientation::PointNormals;
  const auto taken = buildCloudModel (turned, asked);
  EXPECT_EQ (taken->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_FALSE (taken->surface ().normalsTurnedToViewpoint ());

  const auto closed = buildCloudModel (turned, closedObjects (withSurface ()));
  ASSERT_EQ (closed->surface ().orientation (), NormalOrientation::Propagate);
  ASSERT_TRUE (closed->surface ().insideKnown ()) << closed->surface ().closedShare ();
  const auto ball = buildCloudModel (xyz (sphere (400, 0.05, c)), withSurface ());
  for (const auto* model : {&as_given, &closed})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*ball, **model, Eigen::Isometry3d::Identity (), surfaceRequest (), r));
    EXPECT_EQ (r.verdict, Verdict::InCollision) << "P " << r.probability;
    EXPECT_LT (r.signed_distance, -0.1) << r.signed_distance;  // the wall is 0.15 from the ball
  }
  CollisionResult taken_answer;
  ASSERT_TRUE (collide (*ball, *taken, Eigen::Isometry3d::Identity (), surfaceRequest (), taken_answer));
  EXPECT_NE (taken_answer.verdict, Verdict::InCollision) << "the turned normals' inside is no longer the sphere's";
}

// A floor and a wall 3 m off, scanned from 30 cm above the floor (an organized scan's rays, 2 mm
// range noise): one bin of directions spans a stretch of floor many spacings long, all of it on
// one plane. Before 2026-12-04's sixth session the farther samples of such a bin counted as
// hidden behind the nearer (15 %), and the viewpoint was refused; the same happened to the
// shared Kinect scan after a 5 mm VoxelGrid. Hidden now means off the nearest sample's plane too
// (0.4 %), and a ball 2-9 cm over the floor, in front of what the sensor saw, reads free (over
// the sparser far floor some answers are `unobserved`: over a bridged gap between its rows).
// PCL's default origin a few millimetres from a solid sampled all round (W2's cylinder on a
// plane, its base 3 mm above the origin) is no sensor's: from so near, the bins of directions
// are too wide for the samples in front, the hidden share read 4 %, and Auto oriented the solid
// toward it (4 and 6 sigma_eff clear read contact). A sensor's samples lie many spacings away.
TEST (SurfaceModel, AViewpointBesideTheSamplesIsNoSensors)
{
  for (const double gap : {0.003, 0.5})
  {
    SCOPED_TRACE (gap);
    const auto solid = buildCloudModel (xyz (sphere (4000, 0.05, Eigen::Vector3d (0.0, 0.0, 0.05 + gap))), withSurface ());
    const SurfaceModel& s = solid->surface ();
    if (gap < 0.01)
    {
      EXPECT_EQ (s.orientation (), NormalOrientation::Propagate);
      EXPECT_FALSE (s.seenFromViewpoint ());
    }
    else  // half a metre away the origin sees the sphere's far half hidden, as before
    {
      EXPECT_GT (s.hiddenFromViewpoint (), SurfaceModel::kMaxHiddenShare);
      EXPECT_EQ (s.orientation (), NormalOrientation::Propagate);
    }
  }
}

TEST (SurfaceModel, AFloorSeenAtAGrazingAngleKeepsItsViewpoint)
{
  const Eigen::Vector3d sensor (0.0, 0.0, 0.3);
  pcl::PointCloud<pcl::PointXYZ> scan;
  std::mt19937 rng (3);
  std::normal_distribution<double> noise (0.0, 0.002);
  for (int a = 0; a < 240; ++a)
    for (int e = 0; e < 180; ++e)
    {
      const double azimuth = -0.4 + 0.8 * a / 239.0, elevation = -0.6 + 0.7 * e / 179.0;
      const Eigen::Vector3d d (std::cos (elevation) * std::cos (azimuth), std::cos (elevation) * std::sin (azimuth),
                               std::sin (elevation));
      double t = d.z () < 0.0 ? -sensor.z () / d.z () : std::numeric_limits<double>::infinity ();
      t = std::min (t, (3.0 - sensor.x ()) / d.x ());  // the wall
      const Eigen::Vector3d p = sensor + (t + noise (rng)) * d;
      if (p.z () <= 1.0)
        scan.push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()), static_cast<float> (p.z ())));
    }
  scan.sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 0.3f, 0.0f);
  const auto model = buildCloudModel (scan, noisy (0.002));
  EXPECT_EQ (model->surface ().orientation (), NormalOrientation::Viewpoint);
  EXPECT_LT (model->surface ().hiddenFromViewpoint (), 0.02);
  EXPECT_TRUE (model->surface ().seenFromViewpoint ());
  const auto ball = buildCloudModel (xyz (sphere (200, 0.01, Eigen::Vector3d::Zero ())), withSurface ());
  for (double x = 1.0; x < 2.85; x += 0.15)
    for (const double z : {0.03, 0.06, 0.1})
    {
      CollisionResult r;
      ASSERT_TRUE (collide (*ball, *model, shift (-x, -0.05, -z), surfaceRequest (), r));
      EXPECT_EQ (r.verdict, Verdict::Free) << "x " << x << " z " << z << " P " << r.probability;
    }
  // 10 cm under the floor, behind what the sensor saw and within the scan's bounding box
  // (oriented about floor and wall): unknown.
  CollisionResult under;
  ASSERT_TRUE (collide (*ball, *model, shift (-2.0, 0.0, 0.1), surfaceRequest (), under));
  EXPECT_EQ (under.verdict, Verdict::InContact) << "P " << under.probability;
  EXPECT_TRUE (under.unobserved);
}

// Normals that were not moved with their points (pcl::transformPointCloud where
// transformPointCloudWithNormals was meant) lie along the surface where the rotation turned a
// face: a box's samples rotated 90 degrees about x, their face normals not, read the box's
// inside wherever those normals point. Auto sets them aside, with a warning, and the surface is
// oriented as a cloud's without normals (propagated here, and checked closed with -closed).
TEST (SurfaceModel, NormalsNotMovedWithTheirPointsAreSetAside)
{
  const Eigen::Vector3d c (0.5, 0.0, 0.3), h = Eigen::Vector3d::Constant (0.15);
  const Eigen::Matrix3d R = Eigen::AngleAxisd (0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitX ()).toRotationMatrix ();
  pcl::PointCloud<pcl::PointNormal> moved, stale;
  for (const pcl::PointXYZ& q : boxSurface (c, h, 0.01, 0.001, 21))
  {
    const Eigen::Vector3d p = q.getVector3fMap ().cast<double> ();
    const Eigen::Vector3d d = (p - c).cwiseQuotient (h);
    int a = 0;
    d.cwiseAbs ().maxCoeff (&a);
    Eigen::Vector3d n = Eigen::Vector3d::Zero ();
    n[a] = d[a] > 0.0 ? 1.0 : -1.0;
    const Eigen::Vector3d r = c + R * (p - c);
    moved.push_back (pointNormal (r.x (), r.y (), r.z (), (R * n).cast<float> ()));
    stale.push_back (pointNormal (r.x (), r.y (), r.z (), n.cast<float> ()));
  }
  const auto kept = buildCloudModel (moved, closedObjects (withSurface ()));
  EXPECT_LT (kept->surface ().givenNormalSpreadRatio (), 0.1);
  EXPECT_FALSE (kept->surface ().normalsOffSurface ());
  EXPECT_EQ (kept->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_TRUE (kept->warning ().empty ()) << kept->warning ();
  const auto set_aside = buildCloudModel (stale, closedObjects (withSurface ()));
  EXPECT_GT (set_aside->surface ().givenNormalSpreadRatio (), SurfaceModel::kMaxNormalSpreadRatio);
  EXPECT_TRUE (set_aside->surface ().normalsOffSurface ());
  EXPECT_EQ (set_aside->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_TRUE (set_aside->surface ().insideKnown ()) << set_aside->surface ().closedShare ();
  EXPECT_NE (set_aside->warning ().find ("lie along its surface"), std::string::npos) << set_aside->warning ();
  EXPECT_NE (set_aside->warning ().find ("set aside"), std::string::npos) << set_aside->warning ();
  // Asked for by name, they are taken as given, with the warning.
  CloudModelParams asked = closedObjects (withSurface ());
  asked.orientation = NormalOrientation::PointNormals;
  const auto taken = buildCloudModel (stale, asked);
  EXPECT_EQ (taken->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_FALSE (taken->surface ().normalsOffSurface ());
  EXPECT_NE (taken->warning ().find ("taken as given"), std::string::npos) << taken->warning ();
  // A ball at the box's centre, 10 cm from every face: inside, unless the stale normals are
  // taken (then free, P = 0, as Auto read it before 2026-12-04's sixth session).
  const auto ball = buildCloudModel (xyz (sphere (400, 0.05, c)), withSurface ());
  for (const auto* model : {&kept, &set_aside})
  {
    CollisionResult r;
    ASSERT_TRUE (collide (*ball, **model, Eigen::Isometry3d::Identity (), surfaceRequest (), r));
    EXPECT_EQ (r.verdict, Verdict::InCollision) << "P " << r.probability;
    EXPECT_LT (r.signed_distance, -0.08) << r.signed_distance;
  }
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *taken, Eigen::Isometry3d::Identity (), surfaceRequest (), r));
  EXPECT_NE (r.verdict, Verdict::InCollision) << "the stale normals' inside is not the box's";
}

// The same from a viewpoint inside the cloud's bounding box: two spheres either side of PCL's
// default origin, their normals turned toward it (83 % point in), hide their far sides from it,
// so the normals are set aside; declared closed, a ball inside one reads collision. From the
// centre of one sphere nothing is hidden: its normals turned inward are kept, as a room's
// scanned from within would be (the two cannot be told apart).
TEST (SurfaceModel, NormalsTurnedTowardAViewpointInsideANonConvexCloudAreNotOutward)
{
  pcl::PointCloud<pcl::PointNormal> turned;
  for (const double x : {-0.3, 0.3})
    for (pcl::PointNormal p : sphere (2000, 0.2, Eigen::Vector3d (x, 0.0, 0.0)))
    {
      if (p.getNormalVector3fMap ().dot (-p.getVector3fMap ()) < 0.0f)
        p.getNormalVector3fMap () = -p.getNormalVector3fMap ();
      turned.push_back (p);
    }
  const auto aside = buildCloudModel (turned, closedObjects (withSurface ()));
  EXPECT_TRUE (aside->surface ().normalsTurnedToViewpoint ());
  EXPECT_GT (aside->surface ().hiddenFromViewpoint (), 0.3);  // the far halves
  ASSERT_EQ (aside->surface ().orientation (), NormalOrientation::Propagate);
  ASSERT_TRUE (aside->surface ().insideKnown ()) << aside->surface ().closedShare ();
  const auto ball = buildCloudModel (xyz (sphere (300, 0.05, Eigen::Vector3d (0.3, 0.0, 0.0))), withSurface ());
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *aside, Eigen::Isometry3d::Identity (), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::InCollision) << "P " << r.probability;

  const auto convex = buildCloudModel (sphere (2000, 0.2, Eigen::Vector3d::Zero (), true), withSurface ());
  EXPECT_FALSE (convex->surface ().normalsTurnedToViewpoint ());
  EXPECT_EQ (convex->surface ().orientation (), NormalOrientation::PointNormals);
  EXPECT_EQ (convex->surface ().hiddenFromViewpoint (), 0.0);
  EXPECT_FALSE (convex->surface ().seenFromViewpoint ());  // a viewpoint inside marks nothing unobserved
}

// Uniformly random samples (not a lattice): the sample areas add up to about the surface's
// area, on a plane and on a sphere, so that a declared closed sphere checks out (its winding
// number at the centre about 1). Weighted by the squared spacings instead, the plane read 0.77
// m^2, the sphere's centre 0.76, and `closed_objects` refused the sphere (found in review).
TEST (SurfaceModel, RandomSamplesAddUpToTheirSurfacesArea)
{
  std::mt19937 rng (17);
  std::uniform_real_distribution<double> unit (-0.5, 0.5);
  pcl::PointCloud<pcl::PointXYZ> plane;
  for (int i = 0; i < 4000; ++i)
  {
    const Eigen::Vector3d u = draw3 (unit, rng);
    plane.push_back (pcl::PointXYZ (static_cast<float> (u.x ()), static_cast<float> (u.y ()), 0.0f));
  }
  const auto flat = buildCloudModel (plane, withSurface ());
  EXPECT_GT (flat->surface ().area (), 0.85) << "of 1 m^2";
  EXPECT_LT (flat->surface ().area (), 1.1) << "of 1 m^2";
  // Every sample three times (a noise-free triangle soup's shared vertices): the copies share
  // their cell (found in review: each copy took all of it, 1.3 of the area here). The copies
  // crowd the k neighbours, about 3 distinct positions of 10, so the cells read small: 0.44 of
  // the area (the squared spacings 0.41).
  pcl::PointCloud<pcl::PointXYZ> tripled;
  for (std::size_t i = 0; i < 1500; ++i)
    for (int copy = 0; copy < 3; ++copy)
      tripled.push_back (plane[i]);
  const auto copies = buildCloudModel (tripled, withSurface ());
  EXPECT_GT (copies->surface ().area (), 0.3) << "of 1 m^2";
  EXPECT_LT (copies->surface ().area (), 1.0) << "of 1 m^2";

  std::normal_distribution<double> normal;
  pcl::PointCloud<pcl::PointXYZ> ball;
  const Eigen::Vector3d centre (1, 2, 3);
  for (int i = 0; i < 2000; ++i)
  {
    const Eigen::Vector3d u = draw3 (normal, rng).normalized ();
    const Eigen::Vector3f p = (centre + 0.1 * u).cast<float> ();
    ball.push_back (pcl::PointXYZ (p.x (), p.y (), p.z ()));
  }
  const auto sphere_model = buildCloudModel (ball, closedObjects (withSurface ()));
  const SurfaceModel& s = sphere_model->surface ();
  ASSERT_EQ (s.orientation (), NormalOrientation::Propagate);
  const double area = 4.0 * M_PI * 0.01;
  EXPECT_GT (s.area (), 0.85 * area);
  EXPECT_LT (s.area (), 1.1 * area);
  const Eigen::Vector3d local_centre = centre - sphere_model->origin ();  // the model's local frame
  EXPECT_GT (s.windingNumber (sphere_model->hierarchy (), local_centre), 0.85);
  EXPECT_TRUE (s.insideKnown ()) << "closed share " << s.closedShare () << ", solid share " << s.solidShare ();
}

// A small box wholly inside a big noisy box sampled without normals, deeper than any point's
// reach of its surface: declared closed objects, the winding number finds it (collision, about
// as deep as it lies), with the surface layer and with the ladder; undeclared, the propagated
// surface is two-sided and says nothing about an inside, so the query reads free, as the
// separators do. Outside, both read free.
TEST (SurfaceLayer, AClosedObjectsInsideIsKnown)
{
  const auto solid = boxSurface (Eigen::Vector3d::Zero (), Eigen::Vector3d (0.3, 0.25, 0.2), 0.01, 0.002, 11);
  const auto declared = buildCloudModel (solid, closedObjects (noisy (0.002)));
  const auto undeclared = buildCloudModel (solid, noisy (0.002));
  ASSERT_TRUE (declared->surface ().insideKnown ()) << declared->surface ().closedShare ();
  ASSERT_FALSE (undeclared->surface ().insideKnown ());
  const auto small = buildCloudModel (boxSurface (Eigen::Vector3d::Zero (), Eigen::Vector3d::Constant (0.03), 0.01, 0.0, 12),
                                      withSurface ());
  CollisionResult inside, outside, two_sided;
  ASSERT_TRUE (collide (*small, *declared, shift (0.05, -0.02, 0.01), surfaceRequest (), inside));
  EXPECT_EQ (inside.verdict, Verdict::InCollision) << "P " << inside.probability;
  EXPECT_LT (inside.signed_distance, -0.1) << inside.signed_distance;  // the nearest face is 0.16 away
  EXPECT_FALSE (inside.unobserved);
  EXPECT_FALSE (inside.lower_bound);
  // In decision mode the first node found inside decides: its depth is a bound, and says so
  // (found in review: lower_bound was false).
  CollisionRequest decision = surfaceRequest ();
  decision.exhaustive = false;
  CollisionResult decided;
  ASSERT_TRUE (collide (*small, *declared, shift (0.05, -0.02, 0.01), decision, decided));
  EXPECT_EQ (decided.verdict, Verdict::InCollision) << "P " << decided.probability;
  EXPECT_TRUE (decided.lower_bound);
  EXPECT_LE (decided.signed_distance, 0.0);
  ASSERT_TRUE (collide (*small, *undeclared, shift (0.05, -0.02, 0.01), surfaceRequest (), two_sided));
  EXPECT_EQ (two_sided.verdict, Verdict::Free) << "P " << two_sided.probability;
  ASSERT_TRUE (collide (*small, *declared, shift (0.5, 0.0, 0.0), surfaceRequest (), outside));
  EXPECT_EQ (outside.verdict, Verdict::Free) << "P " << outside.probability;
  // The ladder: the separators reach no leaf pair, and the two winding numbers of its
  // containment check find the box inside the declared solid (every point of it, per point).
  CollisionRequest ladder = surfaceRequest ();
  ladder.surface_ladder = true;
  ladder.per_point = true;
  CollisionResult climbed, stays, apart;
  ASSERT_TRUE (collide (*small, *declared, shift (0.05, -0.02, 0.01), ladder, climbed));
  EXPECT_EQ (climbed.verdict, Verdict::InCollision) << "P " << climbed.probability;
  EXPECT_EQ (climbed.answered_by, AnsweredBy::SurfaceLayer);
  EXPECT_FALSE (climbed.no_leaf_tested);
  EXPECT_EQ (climbed.leaf_pairs_tested, 0u);
  EXPECT_NEAR (climbed.signed_distance, inside.signed_distance, 0.05);
  ASSERT_EQ (climbed.probabilities_a.size (), small->sourceSize ());
  EXPECT_TRUE (std::all_of (climbed.probabilities_a.begin (), climbed.probabilities_a.end (), [] (float p) { return p == 1.0f; }));
  ASSERT_TRUE (collide (*small, *undeclared, shift (0.05, -0.02, 0.01), ladder, stays));
  EXPECT_EQ (stays.verdict, Verdict::Free);
  EXPECT_EQ (stays.answered_by, AnsweredBy::Separators);
  EXPECT_TRUE (stays.no_leaf_tested);
  ASSERT_TRUE (collide (*small, *declared, shift (0.5, 0.0, 0.0), ladder, apart));
  EXPECT_EQ (apart.verdict, Verdict::Free);
  EXPECT_EQ (apart.answered_by, AnsweredBy::Separators);
  // A small box half way through a face: both read collision (its points on both sides).
  for (const auto* model : {&declared, &undeclared})
  {
    CollisionResult through;
    ASSERT_TRUE (collide (*small, **model, shift (0.3, 0.0, 0.0), surfaceRequest (), through));
    EXPECT_EQ (through.verdict, Verdict::InCollision) << "P " << through.probability;
  }
}

// One scanned view of a solid box (its top and the two sides a sensor above a corner sees): a ball
// 5 cm over the unseen bottom, wholly out of the surface's reach, lies behind the view, in space
// the scan counts as occupied, as near the surface. Its winding number there is between 1/4 and
// 1/2 (three faces of six), and under 1/2 such a part read free, unmarked (a probe, 2026-12-04).
namespace
{
/** \brief One scanned view of a 20 cm box standing on z = 0, seen from sensor (by default
  * (0.6, -0.6, 0.7)): its top and the sides facing +x and -y where the sensor sees them, sampled
  * every 1 cm with 1 mm noise; with_table, the table it stands on (60 cm square) where the
  * sensor sees it, not under the box or in its shadow, and not within 1.5 cm of its sides (with
  * the table's grid touching them the viewpoint is refused: over a tenth of the points disagree
  * with their part's side there). Modelled with model_sigma of isotropic noise. */
pcl::PointCloud<pcl::PointXYZ>
oneScannedViewOfABoxCloud (bool with_table, const Eigen::Vector3d& sensor)
{
  pcl::PointCloud<pcl::PointXYZ> view;
  std::mt19937 rng (5);
  std::normal_distribution<double> noise (0.0, 0.001);
  auto add = [&] (double x, double y, double z) {
    view.push_back (pcl::PointXYZ (static_cast<float> (x + noise (rng)), static_cast<float> (y + noise (rng)),
                                   static_cast<float> (z + noise (rng))));
  };
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
    {
      add (-0.1 + 0.01 * i, -0.1 + 0.01 * j, 0.2);  // top
      if (sensor.x () > 0.1)
        add (0.1, -0.1 + 0.01 * i, 0.01 * j);  // the side facing +x
      if (sensor.y () < -0.1)
        add (-0.1 + 0.01 * i, -0.1, 0.01 * j);  // the side facing -y
    }
  // The line of sight from the sensor to p meets the box (a slab test) before p.
  auto hidden = [&] (const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - sensor;
    double enter = 0.0, leave = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      const double lo = a < 2 ? -0.1 : 0.0, hi = a < 2 ? 0.1 : 0.2;
      const double t0 = (lo - sensor[a]) / d[a], t1 = (hi - sensor[a]) / d[a];
      enter = std::max (enter, std::min (t0, t1));
      leave = std::min (leave, std::max (t0, t1));
    }
    return enter < leave;
  };
  for (int i = 0; with_table && i <= 60; ++i)
    for (int j = 0; j <= 60; ++j)
    {
      const double x = -0.3 + 0.01 * i, y = -0.3 + 0.01 * j;
      if (!hidden (Eigen::Vector3d (x, y, 0.0)) && std::max (std::abs (x), std::abs (y)) > 0.115)
        add (x, y, 0.0);
    }
  view.sensor_origin_ = Eigen::Vector4f (sensor.x (), sensor.y (), sensor.z (), 0.0).cast<float> ();
  return view;
}

std::shared_ptr<const CloudModel>
oneScannedViewOfABox (bool with_table = false, const Eigen::Vector3d& sensor = Eigen::Vector3d (0.6, -0.6, 0.7),
                      double model_sigma = 0.001)
{
  return buildCloudModel (oneScannedViewOfABoxCloud (with_table, sensor), noisy (model_sigma));
}
} // namespace

// A scan moved with pcl::transformPointCloud keeps its old normals and its old VIEWPOINT. Where
// the normals are set aside (they lie along the surface) and that VIEWPOINT then orients the
// surface, the warning says it may be stale too (a probe of 2026-12-04: with both stale, a
// collision 1.8 cm deep read free). Here the view's normals are turned 90 degrees about x, its
// VIEWPOINT kept: the model is the plain view's, and the warning names the VIEWPOINT.
TEST (SurfaceModel, NormalsSetAsideWhereTheViewpointOrientsSayTheViewpointMayBeStaleToo)
{
  const Eigen::Vector3d sensor (0.6, -0.6, 0.7);
  const Eigen::Matrix3d R = Eigen::AngleAxisd (0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitX ()).toRotationMatrix ();
  pcl::PointCloud<pcl::PointNormal> view;
  std::mt19937 rng (5);
  std::normal_distribution<double> noise (0.0, 0.001);
  auto add = [&] (double x, double y, double z, const Eigen::Vector3d& n) {
    view.push_back (pointNormal (x + noise (rng), y + noise (rng), z + noise (rng), (R * n).cast<float> ()));
  };
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
    {
      add (-0.1 + 0.01 * i, -0.1 + 0.01 * j, 0.2, Eigen::Vector3d::UnitZ ());  // top
      add (0.1, -0.1 + 0.01 * i, 0.01 * j, Eigen::Vector3d::UnitX ());         // the side facing +x
      add (-0.1 + 0.01 * i, -0.1, 0.01 * j, -Eigen::Vector3d::UnitY ());       // the side facing -y
    }
  view.sensor_origin_ = Eigen::Vector4f (sensor.x (), sensor.y (), sensor.z (), 0.0).cast<float> ();
  const auto model = buildCloudModel (view, noisy (0.001));
  ASSERT_TRUE (model->surface ().normalsOffSurface ()) << model->surface ().givenNormalSpreadRatio ();
  EXPECT_EQ (model->surface ().orientation (), NormalOrientation::Viewpoint);
  EXPECT_NE (model->warning ().find ("set aside"), std::string::npos) << model->warning ();
  EXPECT_NE (model->warning ().find ("its VIEWPOINT orients the surface instead"), std::string::npos) << model->warning ();
  // A VIEWPOINT inside the cloud's box orients nothing: the surface is propagated, and the warning
  // says nothing of a VIEWPOINT.
  view.sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 0.1f, 0.0f);
  const auto propagated = buildCloudModel (view, noisy (0.001));
  ASSERT_TRUE (propagated->surface ().normalsOffSurface ());
  EXPECT_EQ (propagated->surface ().orientation (), NormalOrientation::Propagate);
  EXPECT_NE (propagated->warning ().find ("set aside"), std::string::npos) << propagated->warning ();
  EXPECT_EQ (propagated->warning ().find ("VIEWPOINT"), std::string::npos) << propagated->warning ();
}

TEST (SurfaceLayer, DeepBehindOneScannedViewIsOccupied)
{
  const auto scan = oneScannedViewOfABox ();
  ASSERT_EQ (scan->surface ().orientation (), NormalOrientation::Viewpoint);
  ASSERT_TRUE (scan->surface ().seenFromViewpoint ());
  const auto ball = buildCloudModel (xyz (sphere (300, 0.02, Eigen::Vector3d::Zero ())), withSurface ());
  CollisionResult behind, above;
  // T_a_b: the scan's frame seen from the ball's, so the ball sits at z = 0.05 in the scan's.
  ASSERT_TRUE (collide (*ball, *scan, shift (0.0, 0.0, -0.05), surfaceRequest (), behind));
  EXPECT_EQ (behind.verdict, Verdict::InCollision) << "P " << behind.probability;
  EXPECT_TRUE (behind.unobserved);
  EXPECT_LT (behind.signed_distance, -0.05) << behind.signed_distance;  // 8 cm from the nearest seen side
  ASSERT_TRUE (collide (*ball, *scan, shift (0.0, 0.0, -0.3), surfaceRequest (), above));
  EXPECT_EQ (above.verdict, Verdict::Free) << "P " << above.probability;
  EXPECT_FALSE (above.unobserved);
}

// A depth camera 80 cm above a table top sees it 2.5 mm apart with 2 mm noise: a fitted normal
// (the plane about its sample) then lies in the surface for a few percent of the samples, where
// the noise lifted the sample off its neighbours. behindView read a point 5 cm under the top in
// front of it wherever such a sample was its bin's nearest (a part deep in a box read free):
// each bin's plane is its nearest sample's neighbours' about their centroid.
TEST (SurfaceModel, BehindViewReadsTheDepthUnderANoisyTopSeenFromAbove)
{
  pcl::PointCloud<pcl::PointXYZ> view;
  std::mt19937 rng (11);
  std::normal_distribution<double> noise (0.0, 0.002);
  for (int i = 0; i < 120; ++i)
    for (int j = 0; j < 120; ++j)
      view.push_back (pcl::PointXYZ (static_cast<float> (-0.15 + 0.0025 * i), static_cast<float> (-0.15 + 0.0025 * j),
                                     static_cast<float> (0.2 + noise (rng))));
  view.sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 1.0f, 0.0f);
  const auto top = buildCloudModel (view, noisy (0.005));
  const SurfaceModel& surface = top->surface ();
  ASSERT_TRUE (surface.seenFromViewpoint ());
  // The rule's margin behind the view (a tilted plane fitted through the noise reads less than
  // the 5 cm; a plane in the surface read about 0).
  const double margin = SurfaceModel::kHiddenSpacings * surface.medianSpacing ();
  std::size_t read_in_front = 0, positions = 0;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j, ++positions)
    {
      const Eigen::Vector3d x (-0.1 + 0.005 * i, -0.1 + 0.005 * j, 0.15);
      read_in_front += surface.behindView (top->hierarchy (), x - top->origin ()) > margin ? 0 : 1;
    }
  EXPECT_EQ (read_in_front, 0u) << "of " << positions << " positions 5 cm under the top, margin " << margin;
}

// Low in the box, beside its unseen sides, one view's winding number falls under the 1/4 that
// reads occupied, and a ball there read free. The sensor's line of sight to it passes through
// the seen faces: the space was never observed, so it reads unknown (P = 1/2, unobserved), with
// the way back toward the sensor. A ball the sensor could see reads free.
TEST (SurfaceLayer, BehindOneScannedViewOutOfTheOccupiedIsUnknown)
{
  const auto scan = oneScannedViewOfABox (true);
  const SurfaceModel& surface = scan->surface ();
  ASSERT_EQ (surface.orientation (), NormalOrientation::Viewpoint);
  ASSERT_TRUE (surface.seenFromViewpoint ());
  // Low in the box near its unseen sides; beside the seen side facing +x, 3 cm off it.
  const Eigen::Vector3d low (-0.07, 0.07, 0.03), seen (0.15, 0.0, 0.1);
  const Eigen::Vector3d o = scan->origin ();
  EXPECT_LT (surface.windingNumber (scan->hierarchy (), low - o), 0.25);
  // Behind the seen faces' planes about the corner nearest the sensor (7 cm the least of the nine bins).
  EXPECT_GT (surface.behindView (scan->hierarchy (), low - o), 0.05);
  EXPECT_LT (surface.behindView (scan->hierarchy (), seen - o), 0.0);  // in front of what it saw
  EXPECT_TRUE (std::isnan (surface.behindView (scan->hierarchy (), Eigen::Vector3d (0.6, 0.6, 0.0) - o)));  // no sample that way
  const auto ball = buildCloudModel (xyz (sphere (300, 0.02, Eigen::Vector3d::Zero ())), withSurface ());
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *scan, shift (-low.x (), -low.y (), -low.z ()), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::InContact) << "P " << r.probability;
  EXPECT_DOUBLE_EQ (r.probability, 0.5);
  EXPECT_TRUE (r.unobserved);
  EXPECT_EQ (r.signed_distance, 0.0);
  EXPECT_GT (r.signed_distance_std, 0.05);
  ASSERT_EQ (r.witness_side, 1);
  const Eigen::Vector3d toward_sensor = (Eigen::Vector3d (0.6, -0.6, 0.7) - low).normalized ();
  EXPECT_GT (r.witness_normal.dot (toward_sensor), 0.99) << r.witness_normal.transpose ();
  // The ladder and the pool do not read it free either.
  for (const bool pooled : {false, true})
  {
    CollisionRequest request = surfaceRequest ();
    request.surface_ladder = !pooled;
    request.surface_pooled = pooled;
    ASSERT_TRUE (collide (*ball, *scan, shift (-low.x (), -low.y (), -low.z ()), request, r));
    EXPECT_NE (r.verdict, Verdict::Free) << (pooled ? "pooled" : "ladder") << " P " << r.probability;
    EXPECT_TRUE (r.unobserved);
  }
  ASSERT_TRUE (collide (*ball, *scan, shift (-seen.x (), -seen.y (), -seen.z ()), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::Free) << "P " << r.probability;
  EXPECT_FALSE (r.unobserved);
}

// Behind one scanned view the unobserved space reaches past the scan's bounding box by a shell
// ten median spacings deep along the line of sight (SurfaceModel::hiddenShell). The scan's box
// lies on the principal axes of the three faces seen, and 56 of 343 points of a grid in the box
// lie outside it, low by its unseen sides and under its far corner; 3 of them lie within the
// shell. A 5 mm ball at one read free and unmarked (as 8 of 104 occluded collisions of a cube, at a
// table's unseen faces and under it, did on a rendered scan from 45 degrees above, where the
// scan's box tilted). Farther along the line of sight, outside the box, a ball still reads free.
TEST (SurfaceLayer, BehindOneScannedViewPastItsBoundingBoxIsUnknown)
{
  const auto scan = oneScannedViewOfABox ();
  const SurfaceModel& surface = scan->surface ();
  ASSERT_TRUE (surface.seenFromViewpoint ());
  EXPECT_DOUBLE_EQ (surface.hiddenShell (), SurfaceModel::kHiddenShellSpacings * surface.medianSpacing ());
  const Eigen::Vector3d o = scan->origin ();
  const detail::OrientedBox& bound = scan->hierarchy ().node (ProbabilisticBVH::rootId ()).box;
  const Eigen::Vector3d sensor (0.6, -0.6, 0.7), low (-0.09, -0.06, 0.01);
  ASSERT_FALSE (bound.contains (low - o));
  double beyond = 0.0;
  EXPECT_GT (surface.behindView (scan->hierarchy (), low - o, &beyond), 0.03);
  EXPECT_LT (beyond, surface.hiddenShell ());
  const auto ball = buildCloudModel (xyz (sphere (300, 0.005, Eigen::Vector3d::Zero ())), withSurface ());  // clear of the box
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *scan, shift (-low.x (), -low.y (), -low.z ()), surfaceRequest (), r));
  EXPECT_NE (r.verdict, Verdict::Free) << "P " << r.probability << " d " << r.signed_distance;
  EXPECT_GE (r.probability, 0.5);
  EXPECT_TRUE (r.unobserved);
  // Along the same line of sight, past the shell (under the box).
  const Eigen::Vector3d far = low + (low - sensor).normalized () * 0.05;
  ASSERT_FALSE (bound.contains (far - o));
  EXPECT_GT (surface.behindView (scan->hierarchy (), far - o, &beyond), 0.03);
  EXPECT_GT (beyond, surface.hiddenShell () + 0.02);
  ASSERT_TRUE (collide (*ball, *scan, shift (-far.x (), -far.y (), -far.z ()), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::Free) << "P " << r.probability;
  EXPECT_FALSE (r.unobserved);
}

// The view's bins lie on the cloud's principal axes (the hierarchy's root box), so turning the
// whole scan, points and viewpoint, turns them with it: how far a point lies behind what the
// sensor saw is the same in any frame. On the data frame's axes, bins at other angles held
// other samples, and turning a real stereo scene moved 1 of 100 verdicts.
TEST (SurfaceModel, TheViewBinsTurnWithTheScan)
{
  const Eigen::Vector3d sensor (0.6, -0.6, 0.7);
  const pcl::PointCloud<pcl::PointXYZ> view = oneScannedViewOfABoxCloud (true, sensor);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd (0.7, Eigen::Vector3d (1.0, 2.0, 3.0).normalized ()) *
                             Eigen::AngleAxisd (2.1, Eigen::Vector3d::UnitZ ()))
                                .toRotationMatrix ();
  pcl::PointCloud<pcl::PointXYZ> turned = view;
  for (pcl::PointXYZ& p : turned.points)
    p.getVector3fMap () = (R * p.getVector3fMap ().cast<double> ()).cast<float> ();
  turned.sensor_origin_.head<3> () = (R * sensor).cast<float> ();
  const auto a = buildCloudModel (view, noisy (0.001)), b = buildCloudModel (turned, noisy (0.001));
  ASSERT_TRUE (a->surface ().seenFromViewpoint () && b->surface ().seenFromViewpoint ());
  int behind = 0, compared = 0;
  for (double x = -0.29; x < 0.3; x += 0.02)
    for (double y = -0.29; y < 0.3; y += 0.02)
      for (double z = -0.09; z < 0.25; z += 0.02)
      {
        const Eigen::Vector3d p (x, y, z);
        const double da = a->surface ().behindView (a->hierarchy (), p - a->origin ());
        const double db = b->surface ().behindView (b->hierarchy (), R * p - b->origin ());
        // Off a bin's edge by rounding only (the points were turned in single precision).
        if (std::isnan (da) != std::isnan (db) || (!std::isnan (da) && std::abs (da - db) > 1e-5))
          ADD_FAILURE () << "at " << p.transpose () << ": " << da << " turned " << db;
        compared += std::isnan (da) ? 0 : 1;
        behind += da > 0.0 ? 1 : 0;
      }
  EXPECT_GT (behind, 1000);
  EXPECT_GT (compared, 2000);
}

// Near the surface, a point behind what a scan's sensor saw reads unknown (P = 1/2) however clear
// its local answer. It was looked for only where that answer would set the pair's least z, so
// whether it was found followed the visiting order: the real stereo table against its mug scan
// (../shared/data/scenes), the mug at a pose near the table, read 0.164 alone and 0.5 with
// per-point values, and turning the whole scene moved it between the two in 3 of 9 frames.
TEST (SurfaceLayer, AHiddenPointIsFoundWhateverTheVisitingOrder)
{
  const std::string dir = std::string (PCL_PROBCOLLISION_SHARED_DATA) + "/scenes/";
  pcl::PointCloud<pcl::PointXYZ> table, mug;
  ASSERT_EQ (pcl::io::loadPCDFile (dir + "stereo_mug_table.pcd", table), 0) << "missing shared data: " << dir;
  ASSERT_EQ (pcl::io::loadPCDFile (dir + "stereo_mug_object0.pcd", mug), 0);
  CloudModelParams params = withSurface ();
  params.noise = SensorNoiseModel::stereo ();
  const auto a = buildCloudModel (table, params), b = buildCloudModel (mug, params);
  ASSERT_TRUE (a->surface ().seenFromViewpoint () && b->surface ().seenFromViewpoint ());
  Eigen::Matrix4d m;
  m << 0.9670654960013004, 0.13900852798975763, -0.21321574892554193, 0.1620762459031982,  //
      -0.13999696832747852, 0.9900959199609106, 0.01053176793672902, -0.01242508751462111,   //
      0.21256804864060339, 0.01966464906574516, 0.9769483744160934, 0.01424631876778359,     //
      0.0, 0.0, 0.0, 1.0;
  const Eigen::Isometry3d pose (m);
  CollisionRequest request;
  request.surface = true;
  CollisionResult alone, with_values;
  ASSERT_TRUE (collide (*a, *b, pose, request, alone));
  request.per_point = true;
  ASSERT_TRUE (collide (*a, *b, pose, request, with_values));
  EXPECT_EQ (alone.probability, with_values.probability);
  EXPECT_DOUBLE_EQ (alone.probability, 0.5);
  EXPECT_TRUE (alone.unobserved);
  EXPECT_EQ (alone.witness_side, 1);  // a table point behind the mug's seen side
}

// A box on a table seen from straight above: the sensor sees the box's top and the table around
// it, not its sides, nor the table in its shadow. 1-2 cm under the top the winding number of
// the top and the table about it is near 0.1 (the two sheets cancel), and past the seen table's
// edge, low inside the box 5 mm from an unseen side, a point is outside the table's samples: a
// ball in either place read free, unmarked (a 1 cm cube 10-20 mm under the top of such a scan
// sampled every 6 mm, 73 of 81 positions). The sensor's line of sight to either crosses the top:
// unknown. Both clouds at pcd_collision's default noise (5 mm).
TEST (SurfaceLayer, BehindTheTopOfABoxSeenFromAboveIsNotFree)
{
  const Eigen::Vector3d sensor (0.0, 0.0, 1.0);
  const auto scan = oneScannedViewOfABox (true, sensor, 0.005);  // the top and the table around it
  ASSERT_EQ (scan->surface ().orientation (), NormalOrientation::Viewpoint);
  ASSERT_TRUE (scan->surface ().seenFromViewpoint ());
  const auto ball = buildCloudModel (xyz (sphere (300, 0.005, Eigen::Vector3d::Zero ())), noisy (0.005));
  const Eigen::Vector3d under_top (0.05, 0.03, 0.185), low_inside (0.09, 0.0, 0.008), seen (0.2, 0.0, 0.03);
  for (const Eigen::Vector3d& c : {under_top, low_inside})
  {
    SCOPED_TRACE (c.transpose ());
    CollisionResult r;
    ASSERT_TRUE (collide (*ball, *scan, shift (-c.x (), -c.y (), -c.z ()), surfaceRequest (), r));
    EXPECT_NE (r.verdict, Verdict::Free) << "P " << r.probability << " d " << r.signed_distance;
    EXPECT_GE (r.probability, 0.5);
    EXPECT_TRUE (r.unobserved);
    ASSERT_EQ (r.witness_side, 1);
    EXPECT_GT (r.witness_normal.dot ((sensor - c).normalized ()), 0.99) << r.witness_normal.transpose ();  // toward the sensor
    // The calibration map was fitted on answers the samples show: an unobserved answer keeps its
    // P (the unknown 1/2 read 0.576 through it).
    CollisionRequest calibrated = surfaceRequest ();
    calibrated.surface_calibrated = true;
    CollisionResult rc;
    ASSERT_TRUE (collide (*ball, *scan, shift (-c.x (), -c.y (), -c.z ()), calibrated, rc));
    EXPECT_TRUE (rc.unobserved);
    EXPECT_EQ (rc.probability, r.probability);
  }
  // The table the sensor saw beside the box, 2.5 cm under the ball: free.
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *scan, shift (-seen.x (), -seen.y (), -seen.z ()), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::Free) << "P " << r.probability;
  EXPECT_FALSE (r.unobserved);
}

// A small ball half inside a big closed surface: its far side lies deeper than any point's
// reach of the big surface, and only the winding number of the nodes out of reach sees it.
TEST (SurfaceLayer, DeepPointsOutOfReachAreFound)
{
  const auto big = buildCloudModel (sphere (2000, 1.0, Eigen::Vector3d::Zero ()), withSurface ());
  const auto ball = buildCloudModel (sphere (4000, 0.5, Eigen::Vector3d::Zero ()), withSurface ());
  CollisionRequest request = surfaceRequest ();
  request.exhaustive = true;
  CollisionResult r;
  ASSERT_TRUE (collide (*ball, *big, shift (0.7, 0.0, 0.0), request, r));
  EXPECT_EQ (r.verdict, Verdict::InCollision);
  // The ball's far side is 0.8 inside the big sphere; the points of leaves within reach of its
  // surface are at most a leaf's size (about 0.2) deep.
  EXPECT_LT (r.signed_distance, -0.5) << r.signed_distance << " witness side " << r.witness_side;
}

// Out of reach of the other's surface, a node's points lie on one side of it, and with a
// distance asked for, the deepest of them sets it: the largest distance from a point of the ball
// to the big sphere's nearest sample (brute force here), whatever the ball's point order. (It was
// the depth of each inside node's first point in input order: four orders of the same ball read
// -0.688 to -0.707, against the deepest point's -0.725.)
TEST (SurfaceLayer, TheDeepestPointOutOfReachSetsTheDistanceWhateverTheOrder)
{
  const auto big_cloud = sphere (2000, 1.0, Eigen::Vector3d::Zero ());
  const auto big = buildCloudModel (big_cloud, withSurface ());
  const auto ball_cloud = sphere (300, 0.1, Eigen::Vector3d::Zero ());
  const Eigen::Isometry3d pose = shift (0.3, 0.1, -0.2);
  double deepest = 0.0;
  for (const auto& p : ball_cloud)
  {
    const Eigen::Vector3d x = pose * p.getVector3fMap ().cast<double> ();
    double nearest = std::numeric_limits<double>::infinity ();
    for (const auto& q : big_cloud)
      nearest = std::min (nearest, (x - q.getVector3fMap ().cast<double> ()).norm ());
    deepest = std::max (deepest, nearest);
  }
  ASSERT_GT (deepest, 0.5);
  CollisionRequest request = surfaceRequest ();
  request.exhaustive = false;
  request.distance = true;
  std::mt19937 rng (11);
  for (int order = 0; order < 4; ++order)
  {
    auto permuted = ball_cloud;
    if (order > 0)
      std::shuffle (permuted.begin (), permuted.end (), rng);
    const auto ball = buildCloudModel (permuted, withSurface ());
    CollisionResult r;
    ASSERT_TRUE (collide (*big, *ball, pose, request, r));
    EXPECT_EQ (r.verdict, Verdict::InCollision);
    EXPECT_NEAR (r.signed_distance, -deepest, 1e-6) << "order " << order;
  }
}

// Pooled with the separators, P is the mean of the surface layer's and the separators' on the
// same pair, per point too; the signed distance stays the surface layer's. (Raw: the
// calibration map, tested below, acts on the pool's mean.)
TEST (SurfaceLayer, PooledIsTheMeanOfBothAnswers)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  for (const double z : {0.0005, 0.002, -0.002})
  {
    const Answerers q (true);
    CollisionResult rs, rc, rp;
    ASSERT_TRUE (collide (*plate, *table, shift (0, 0, z), q.surface, rs));
    ASSERT_TRUE (collide (*plate, *table, shift (0, 0, z), q.separators, rc));
    ASSERT_TRUE (collide (*plate, *table, shift (0, 0, z), q.pooled, rp));
    EXPECT_DOUBLE_EQ (rp.probability, 0.5 * (rs.probability + rc.probability)) << "z = " << z;
    EXPECT_EQ (rp.signed_distance, rs.signed_distance);
    EXPECT_EQ (rp.verdict, verdictFor (rp.probability, q.pooled));
    ASSERT_EQ (rp.probabilities_a.size (), rs.probabilities_a.size ());
    for (std::size_t i = 0; i < rp.probabilities_a.size (); ++i)
    {
      const float s = rs.probabilities_a[i], c = rc.probabilities_a[i];
      const float expected = std::isnan (s) ? c : std::isnan (c) ? s : 0.5f * (s + c);
      if (std::isnan (expected))
        EXPECT_TRUE (std::isnan (rp.probabilities_a[i]));
      else
        EXPECT_FLOAT_EQ (rp.probabilities_a[i], expected) << "point " << i << " at z = " << z;
    }
  }
}

// The ladder (CollisionRequest::surface_ladder) answers as one of its rungs: the separators'
// answer where they reached no leaf pair or read collision; otherwise the surface layer's, alone
// where the separators read contact and pooled with theirs where they read free. A plate over,
// touching and under a scanned table (the space under a scanned sheet is occupied), and upright
// through it, in decision mode as a planner asks.
TEST (SurfaceLayer, LadderAnswersAsTheRungItReaches)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  std::vector<Eigen::Isometry3d> poses;
  for (double z = -0.01; z <= 0.0301; z += 0.001)
    poses.push_back (shift (0.0, 0.0, z));
  Eigen::Isometry3d upright = shift (0.0, 0.0, 0.0);
  upright.rotate (Eigen::AngleAxisd (0.5 * M_PI, Eigen::Vector3d::UnitX ()));
  poses.push_back (upright);
  int far = 0, sure = 0, contact = 0, free = 0;
  for (const Eigen::Isometry3d& T : poses)
  {
    SCOPED_TRACE ("pose z = " + std::to_string (T.translation ().z ()));
    const Answerers q (false);
    CollisionResult rs, rc, rp, rl;
    ASSERT_TRUE (collide (*plate, *table, T, q.surface, rs));
    ASSERT_TRUE (collide (*plate, *table, T, q.separators, rc));
    ASSERT_TRUE (collide (*plate, *table, T, q.pooled, rp));
    ASSERT_TRUE (collide (*plate, *table, T, q.ladder, rl));
    // Each setting names itself as the answerer; the ladder names the rung it reached.
    EXPECT_EQ (rs.answered_by, AnsweredBy::SurfaceLayer);
    EXPECT_EQ (rc.answered_by, AnsweredBy::Separators);
    EXPECT_EQ (rp.answered_by, AnsweredBy::Pooled);
    const CollisionResult* expected = nullptr;
    // The separators' answer stands where they are sure or reached nothing, and where the
    // surface layer reached no point (it has nothing to say).
    if (rc.no_leaf_tested || rc.probability > q.ladder.collision_above || rs.no_leaf_tested)
    {
      (rc.no_leaf_tested || rs.no_leaf_tested ? far : sure) += 1;
      expected = &rc;
      EXPECT_TRUE (std::isnan (rl.signed_distance));
    }
    else if (rc.probability >= q.ladder.free_below)
    {
      ++contact;
      expected = &rs;
    }
    else
    {
      ++free;
      expected = &rp;
    }
    EXPECT_EQ (rl.answered_by, expected->answered_by);
    EXPECT_DOUBLE_EQ (rl.probability, expected->probability);
    EXPECT_EQ (rl.verdict, expected->verdict);
    if (!std::isnan (expected->signed_distance))
    {
      EXPECT_EQ (rl.signed_distance, expected->signed_distance);
    }
    ASSERT_EQ (rl.probabilities_a.size (), expected->probabilities_a.size ());
    for (std::size_t i = 0; i < rl.probabilities_a.size (); ++i)
    {
      if (std::isnan (expected->probabilities_a[i]))
      {
        EXPECT_TRUE (std::isnan (rl.probabilities_a[i])) << "point " << i;
      }
      else
      {
        EXPECT_FLOAT_EQ (rl.probabilities_a[i], expected->probabilities_a[i]) << "point " << i;
      }
    }
    // The work of every rung it ran is counted.
    EXPECT_GE (rl.bv_tests, rc.bv_tests);
  }
  std::cout << "[ ladder ] rungs: far " << far << ", separators sure " << sure << ", contact band " << contact
            << ", free after a fit " << free << "\n";
  EXPECT_GT (far, 0);
  EXPECT_GT (contact, 0);
}

// Found probing as a new user (2026-12-03): two coincident clouds of two points each. The
// separators read contact (P = 0.5); the surface layer reaches no point of either and read
// P = 0, and the ladder used to hand that "free" on. It now keeps the separators' answer (as the
// surface layer alone does since 2026-12-04: CloudsWithoutASurfaceAreAnsweredByTheSeparators).
TEST (SurfaceLayer, LadderKeepsTheSeparatorsWhereTheSurfaceLayerReachesNothing)
{
  pcl::PointCloud<pcl::PointXYZ> two;
  two.push_back (pcl::PointXYZ (0.0f, 0.0f, 0.0f));
  two.push_back (pcl::PointXYZ (0.01f, 0.0f, 0.0f));
  CloudModelParams params = noisy (0.001);
  const auto model = buildCloudModel (two, params);
  const Answerers q (false);
  CollisionResult rs, rc, rl;
  ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.surface, rs));
  ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.separators, rc));
  ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.ladder, rl));
  ASSERT_EQ (rs.answered_by, AnsweredBy::Separators) << "the case needs a surface layer that reaches nothing";
  ASSERT_FALSE (rc.no_leaf_tested);
  EXPECT_EQ (rc.verdict, Verdict::InContact);
  EXPECT_EQ (rl.answered_by, AnsweredBy::Separators);
  EXPECT_EQ (rl.verdict, rc.verdict);
  EXPECT_DOUBLE_EQ (rl.probability, rc.probability);
}

// Clouds with no surface: coincident copies of one point, or two points (no sample has a normal).
// The surface layer meets their leaves but can judge no point against samples without a normal,
// and it read "free" (P = 0, "no leaf pair tested") where the separators read contact (a probe,
// 2026-12-04: coincident clouds of 1-100 identical points). It now hands the query to the
// separators, alone and pooled, as the ladder does; their leaf pair is counted.
TEST (SurfaceLayer, CloudsWithoutASurfaceAreAnsweredByTheSeparators)
{
  std::vector<pcl::PointCloud<pcl::PointXYZ>> clouds;
  for (const int n : {1, 5, 100})
    clouds.emplace_back (static_cast<std::uint32_t> (n), 1, pcl::PointXYZ (0.3f, -0.2f, 1.0f));
  clouds.emplace_back ();
  clouds.back ().push_back (pcl::PointXYZ (0.0f, 0.0f, 0.0f));
  clouds.back ().push_back (pcl::PointXYZ (0.01f, 0.0f, 0.0f));
  for (const auto& cloud : clouds)
  {
    SCOPED_TRACE (std::to_string (cloud.size ()) + " points");
    const auto model = buildCloudModel (cloud, noisy (0.001));
    ASSERT_FALSE (model->surface ().empty ());
    for (const bool exhaustive : {false, true})
    {
      const Answerers q (exhaustive);
      CollisionResult rs, rp, rc;
      ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.separators, rc));
      ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.surface, rs));
      ASSERT_TRUE (collide (*model, *model, Eigen::Isometry3d::Identity (), q.pooled, rp));
      ASSERT_FALSE (rc.no_leaf_tested);
      EXPECT_NE (rc.verdict, Verdict::Free);
      for (const CollisionResult* r : {&rs, &rp})
      {
        EXPECT_EQ (r->answered_by, AnsweredBy::Separators);
        EXPECT_EQ (r->verdict, rc.verdict);
        EXPECT_DOUBLE_EQ (r->probability, rc.probability);
        EXPECT_FALSE (r->no_leaf_tested);
        EXPECT_EQ (r->leaf_pairs_tested, rc.leaf_pairs_tested);
        EXPECT_GT (r->bv_tests, rc.bv_tests);  // the surface layer's node tests counted too
        ASSERT_EQ (r->probabilities_a.size (), cloud.size ());
        for (std::size_t i = 0; i < cloud.size (); ++i)
          EXPECT_EQ (r->probabilities_a[i], rc.probabilities_a[i]) << "point " << i;
      }
    }
  }
}

// A known limit of the separators, and so of the ladder (docs/SURFACE.md, "The ladder"): a small
// ball pushed 10 mm through a sparse scanned table (samples 60 mm apart, 60 times the noise) at
// positions between the samples. Where it passes between the table's leaf boxes the separators
// reach no leaf pair and read P = 0, and the ladder keeps their answer. The surface layer, whose
// reach is grown by a sample spacing, reads every such position as collision.
TEST (SurfaceLayer, APartBetweenSparseSamplesIsSeenByTheSurfaceLayerAlone)
{
  const auto table = buildCloudModel (sheet (1.0, 0.06, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto ball = buildCloudModel (sphere (300, 0.015, Eigen::Vector3d::Zero ()), noisy (0.001));
  const Answerers q (false);
  int positions = 0, between = 0;
  for (double x = -0.06; x <= 0.0601; x += 0.006)
    for (double y = -0.06; y <= 0.0601; y += 0.006)
    {
      ++positions;
      SCOPED_TRACE ("ball at x = " + std::to_string (x) + ", y = " + std::to_string (y));
      // T_a_b places the table in the ball's frame: the ball's centre at (x, y, 5 mm) over the
      // table, its bottom 10 mm under the table's top.
      const Eigen::Isometry3d T = shift (-x, -y, -0.005);
      CollisionResult rc, rl, rs;
      ASSERT_TRUE (collide (*ball, *table, T, q.separators, rc));
      ASSERT_TRUE (collide (*ball, *table, T, q.surface, rs));
      EXPECT_EQ (rs.verdict, Verdict::InCollision) << "P = " << rs.probability;
      EXPECT_LT (rs.signed_distance, 0.0);
      if (!rc.no_leaf_tested)
        continue;
      ++between;
      ASSERT_TRUE (collide (*ball, *table, T, q.ladder, rl));
      EXPECT_EQ (rl.answered_by, AnsweredBy::Separators);
      EXPECT_EQ (rl.verdict, Verdict::Free);
    }
  std::cout << "[ ladder ] ball between the separators' leaves (read free by them and the ladder) at " << between
            << " of " << positions << " positions\n";
  EXPECT_GT (between, 0);
}

// A surface request on models built without the surface model (CloudModelParams::surface off)
// falls back to the separators, and the result says so rather than passing their answer off as
// the surface layer's; a failed query names no answerer.
TEST (SurfaceLayer, WithoutASurfaceModelTheResultNamesTheSeparators)
{
  CloudModelParams plain;
  plain.noise = SensorNoiseModel::isotropic (0.001);
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), plain);
  const auto surfaced = buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  ASSERT_TRUE (table->surface ().empty ());
  ASSERT_FALSE (surfaced->surface ().empty ());
  const Answerers q (false);
  for (const CollisionRequest* request : {&q.surface, &q.pooled, &q.ladder})
  {
    CollisionResult r, separators;
    ASSERT_TRUE (collide (*surfaced, *table, shift (0, 0, 0.0005), *request, r));
    ASSERT_TRUE (collide (*surfaced, *table, shift (0, 0, 0.0005), q.separators, separators));
    EXPECT_EQ (r.answered_by, AnsweredBy::Separators);
    EXPECT_EQ (r.probability, separators.probability);
    EXPECT_FALSE (separators.no_leaf_tested);  // the pose reaches a leaf pair: a real answer
    EXPECT_TRUE (std::isnan (r.signed_distance));
    EXPECT_STREQ (answeredByName (r.answered_by), "separators");
  }
  CollisionResult failed;
  EXPECT_FALSE (collide (*surfaced, *table, shift (0, 0, std::numeric_limits<double>::quiet_NaN ()), q.surface, failed));
  EXPECT_EQ (failed.answered_by, AnsweredBy::Unknown);
  EXPECT_STREQ (answeredByName (failed.answered_by), "unknown");
}

// The calibration map (CollisionRequest::surface_calibrated) moves the pair's P inside the
// default contact band only, keeps its order and the verdicts, and leaves the distance, its
// deviation and the per-point values as the model gives them.
TEST (SurfaceLayer, CalibrationMovesOnlyTheContactBand)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.002));
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.002));
  for (const bool pooled : {false, true})
  {
    std::vector<std::pair<double, double>> raw_and_mapped;
    std::size_t moved = 0;
    for (double z = -0.006; z <= 0.0081; z += 0.0005)
    {
      CollisionRequest raw = surfaceRequest ();
      raw.per_point = true;
      raw.surface_pooled = pooled;
      raw.surface_calibrated = false;
      CollisionRequest calibrated = raw;
      calibrated.surface_calibrated = true;
      CollisionResult r0, r1;
      ASSERT_TRUE (collide (*plate, *table, shift (0, 0, z), raw, r0));
      ASSERT_TRUE (collide (*plate, *table, shift (0, 0, z), calibrated, r1));
      const double p0 = r0.probability, p1 = r1.probability;
      if (p0 < raw.free_below || p0 > raw.collision_above)
        EXPECT_EQ (p1, p0) << "z = " << z;
      else
      {
        EXPECT_GE (p1, raw.free_below) << "z = " << z;
        EXPECT_LE (p1, raw.collision_above) << "z = " << z;
        moved += std::abs (p1 - p0) > 0.01 ? 1 : 0;
      }
      EXPECT_EQ (r1.verdict, r0.verdict) << "z = " << z;
      EXPECT_EQ (r1.signed_distance, r0.signed_distance);
      EXPECT_EQ (r1.signed_distance_std, r0.signed_distance_std);
      ASSERT_EQ (r1.probabilities_a.size (), r0.probabilities_a.size ());
      for (std::size_t i = 0; i < r0.probabilities_a.size (); ++i)
      {
        if (!std::isnan (r0.probabilities_a[i]))
        {
          EXPECT_EQ (r1.probabilities_a[i], r0.probabilities_a[i]);
        }
      }
      raw_and_mapped.emplace_back (p0, p1);
    }
    // Strictly increasing: a higher raw P never maps lower, a different one never to the same.
    std::sort (raw_and_mapped.begin (), raw_and_mapped.end ());
    for (std::size_t i = 1; i < raw_and_mapped.size (); ++i)
    {
      if (raw_and_mapped[i].first > raw_and_mapped[i - 1].first + 1e-9)
      {
        EXPECT_GT (raw_and_mapped[i].second, raw_and_mapped[i - 1].second)
            << "pooled " << pooled << ": raw " << raw_and_mapped[i - 1].first << " and " << raw_and_mapped[i].first;
      }
    }
    // The sweep crosses the band: some answers inside it were moved.
    EXPECT_GE (moved, 1u) << "pooled " << pooled;
  }
}

// Per-point values and the witness come back in the callers' frames.
TEST (SurfaceLayer, PerPointValuesAndWitness)
{
  const auto table = buildCloudModel (sheet (0.4, 0.01, 0.0, Eigen::Vector3f (0, 0, 1)), noisy (0.001));
  const auto plate = buildCloudModel (sheet (0.1, 0.01, 5.0, Eigen::Vector3f (0, 0, 6)), noisy (0.001));
  CollisionRequest request = surfaceRequest ();
  request.per_point = true;
  CollisionResult r;
  ASSERT_TRUE (collide (*plate, *table, shift (0, 0, 5.01), request, r));
  ASSERT_EQ (r.probabilities_a.size (), plate->sourceSize ());
  std::size_t high = 0;
  for (const float p : r.probabilities_a)
    high += p > 0.9f ? 1 : 0;
  EXPECT_EQ (high, plate->size ());  // every plate point is 1 cm under the table top
  ASSERT_NE (r.witness_side, 0);
  // The witness is in A's frame: the plate's points sit at z = 5 there.
  if (r.witness_side > 0)
  {
    EXPECT_NEAR (r.witness_point.z (), 5.0, 0.01);
  }
}

/** \brief A vertical plate x in [x0, x0 + 0.4], faces y = +-0.01 (given normals +-y), sampled
  * every 0.04 in x and at the heights zs. */
pcl::PointCloud<pcl::PointNormal>
plate (double x0, const std::vector<double>& zs)
{
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (const double y : {-0.01, 0.01})
    for (int i = 0; i <= 10; ++i)
      for (const double z : zs)
        cloud.push_back (pointNormal (x0 + 0.04 * i, y, z, Eigen::Vector3f (0.0f, y > 0.0 ? 1.0f : -1.0f, 0.0f)));
  return cloud;
}

// Two thin sheets crossing: a plate through a wall three noise deviations thick (sigma 1 cm,
// wall 3 cm, both sampled every 4-5 cm). No sample of either lies inside the other: the plate's
// nearest samples are 2 sigma in front of each face. The crossing test reads collision from the
// pairs on either side; the same plate beside the wall's edge (6 cm clear) reads free.
TEST (SurfaceLayer, ThinSheetsCrossingWithoutDeepSamples)
{
  const double sigma = 0.01;
  const auto wall = buildCloudModel (slab (1.0, 0.03, 0.05), noisy (sigma));
  const std::vector<double> zs {-0.14, -0.10, -0.06, -0.02, 0.05, 0.09, 0.13, 0.17};
  const auto through = buildCloudModel (plate (-0.2, zs), noisy (sigma));
  const auto beside = buildCloudModel (plate (0.56, zs), noisy (sigma));
  CollisionResult crossing, clear;
  ASSERT_TRUE (collide (*through, *wall, Eigen::Isometry3d::Identity (), surfaceRequest (), crossing));
  ASSERT_TRUE (collide (*beside, *wall, Eigen::Isometry3d::Identity (), surfaceRequest (), clear));
  EXPECT_EQ (crossing.verdict, Verdict::InCollision) << crossing.probability << " d " << crossing.signed_distance;
  // The depth is a bound: the wall's thickness and the smaller clearance.
  EXPECT_LT (crossing.signed_distance, -0.03) << crossing.signed_distance;
  EXPECT_EQ (clear.verdict, Verdict::Free) << clear.probability << " d " << clear.signed_distance;
}

// A plate through the same wall, 14 cm out below it and 2 cm above (true depth 5 cm: pushed
// down by the wall and the 2 cm). In decision mode the first sure crossing decides, at its depth
// bound: the wall's thickness and the smaller clearance, as the pair sees them. The depth lies
// anywhere from 0 to that bound and the pair's ends are as uncertain as their noise, so the
// +-2 deviation interval reaches past 0 and past the bound by that noise (half the bound and
// the pair's deviation in quadrature; their maximum, before, ended at 0 exactly).
TEST (SurfaceLayer, ACrossingAtItsDepthBoundIsUncertainBothWays)
{
  const double sigma = 0.01;
  const auto wall = buildCloudModel (slab (1.0, 0.03, 0.05), noisy (sigma));
  const auto through = buildCloudModel (plate (-0.2, {-0.14, -0.10, -0.06, -0.02, 0.05}), noisy (sigma));
  CollisionRequest decision = surfaceRequest ();
  decision.exhaustive = false;
  CollisionResult r;
  ASSERT_TRUE (collide (*through, *wall, Eigen::Isometry3d::Identity (), decision, r));
  EXPECT_EQ (r.verdict, Verdict::InCollision) << r.probability;
  EXPECT_EQ (r.witness_side, 1);  // the plate's pair
  const double bound = -r.signed_distance;
  EXPECT_GT (bound, 0.03) << r.signed_distance;  // at least the wall
  EXPECT_GT (r.signed_distance_std, 0.5 * bound);
  EXPECT_GT (r.signed_distance + 2.0 * r.signed_distance_std, 0.25 * sigma) << r.signed_distance << " +- " << r.signed_distance_std;
  EXPECT_LT (r.signed_distance + 2.0 * r.signed_distance_std, bound) << r.signed_distance << " +- " << r.signed_distance_std;
  EXPECT_LT (std::abs (r.signed_distance + 0.05), 2.0 * r.signed_distance_std) << r.signed_distance << " +- " << r.signed_distance_std;
  // Every pair visited: the wall's own pair, two of its samples either side of the 2 cm plate,
  // is the surest crossing, just short of its bound (the plate's thickness and the wall's reach
  // along the plate's normal, about 15 cm). Its z sigma (15 cm, +- 1 cm with the pair's
  // deviation alone) is how sure it is, not how deep: the deviation carries the bound, and the
  // interval holds the true 5 cm.
  CollisionResult all;
  ASSERT_TRUE (collide (*through, *wall, Eigen::Isometry3d::Identity (), surfaceRequest (), all));
  EXPECT_EQ (all.witness_side, -1);
  EXPECT_LT (all.signed_distance, -0.1) << all.signed_distance;
  EXPECT_LT (std::abs (all.signed_distance + 0.05), 2.0 * all.signed_distance_std) << all.signed_distance << " +- " << all.signed_distance_std;
}

// The same crossing with both hierarchies split down to leaves of at most 2 points: the pairs
// that straddle the wall lie in different leaves, and are found across them (within leaves
// alone P = 0.46).
TEST (SurfaceLayer, CrossingsAcrossLeaves)
{
  const double sigma = 0.01;
  const std::vector<double> zs {-0.14, -0.10, -0.06, -0.02, 0.05, 0.09, 0.13, 0.17};
  CloudModelParams small_leaves = noisy (sigma);
  small_leaves.hierarchy.n_max = 2;
  small_leaves.hierarchy.n_min = 1;
  const auto wall = buildCloudModel (slab (1.0, 0.03, 0.05), small_leaves);
  const auto through = buildCloudModel (plate (-0.2, zs), small_leaves);
  CollisionResult crossing;
  ASSERT_TRUE (collide (*through, *wall, Eigen::Isometry3d::Identity (), surfaceRequest (), crossing));
  EXPECT_EQ (crossing.verdict, Verdict::InCollision) << crossing.probability << " d " << crossing.signed_distance;
}

// A plate pushed 10 cm through the wall (heights every 4 cm, 10 cm on either side): the pairs
// nearest the wall alone bound the depth by the wall and their own 2 cm clearance (d = -5 cm).
// The pair's ends extended along the plate's own surface reach its ends: the depth (the smaller
// of the two ways out, 13 cm) reads within one of the plate's sample spacings.
TEST (SurfaceLayer, ACrossingReachesAlongTheCrossingSurface)
{
  const double sigma = 0.01;
  const auto wall = buildCloudModel (slab (1.0, 0.03, 0.05), noisy (sigma));
  const std::vector<double> zs {-0.10, -0.06, -0.02, 0.05, 0.09, 0.13};
  const auto through = buildCloudModel (plate (-0.2, zs), noisy (sigma));
  CollisionResult r;
  ASSERT_TRUE (collide (*through, *wall, Eigen::Isometry3d::Identity (), surfaceRequest (), r));
  EXPECT_EQ (r.verdict, Verdict::InCollision) << r.probability;
  const double depth = 0.10 + 0.03;
  EXPECT_NEAR (r.signed_distance, -depth, 0.04) << r.signed_distance << " +- " << r.signed_distance_std;
}

/** \brief A closed wedge (given normals): its tip along y at x = 0, z = 0, its two faces opening
  * toward -x at half-angle alpha (outward normals (sin a, 0, +-cos a): 180 - 2 alpha degrees
  * apart, where a slab's are 180), closed by a back face at x = -length; sampled every h. */
pcl::PointCloud<pcl::PointNormal>
wedge (double alpha, double length, double width, double h)
{
  pcl::PointCloud<pcl::PointNormal> cloud;
  const float sa = static_cast<float> (std::sin (alpha)), ca = static_cast<float> (std::cos (alpha));
  const int nx = static_cast<int> (std::round (length / h)), ny = static_cast<int> (std::round (width / h));
  for (int j = 0; j <= ny; ++j)
  {
    const double y = -0.5 * width + j * h;
    for (int i = 0; i <= nx; ++i)
    {
      const double x = -i * h, z = -x * std::tan (alpha);
      cloud.push_back (pointNormal (x, y, z, Eigen::Vector3f (sa, 0.0f, ca)));
      if (i > 0)
        cloud.push_back (pointNormal (x, y, -z, Eigen::Vector3f (sa, 0.0f, -ca)));
    }
    const double half = length * std::tan (alpha);
    for (double z = -half + h; z < half; z += h)
      cloud.push_back (pointNormal (-length, y, z, Eigen::Vector3f (-1.0f, 0.0f, 0.0f)));
  }
  return cloud;
}

/** \brief A thin plate x in [x0 - 0.01, x0 + 0.01] (given normals +-x), sampled every 0.07 in
  * y over [-0.21, 0.21] and at the heights zs. */
pcl::PointCloud<pcl::PointNormal>
upright (double x0, const std::vector<double>& zs)
{
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (const double dx : {-0.01, 0.01})
    for (int j = 0; j <= 6; ++j)
      for (const double z : zs)
        cloud.push_back (pointNormal (x0 + dx, -0.21 + 0.07 * j, z, Eigen::Vector3f (dx > 0.0 ? 1.0f : -1.0f, 0.0f, 0.0f)));
  return cloud;
}

// A sparse plate passing 0.8 sigma beyond a noisy wedge's tip (faces 137 degrees apart, like a
// box's corner seen edge on or a tapered part): its points above and below the tip lie in front
// of the wedge's two faces, and each behind the other face's plane, as for a sheet crossed; but
// the planes meet at the tip, so the plate may pass beyond it and the answer must not be a
// certain collision. Pushed 10 cm over the tip, where the wedge is 8 cm thick, it collides.
// (On this wedge the edge term already keeps the first answer uncertain: the samples do not
// surround the tip. The evaluation's case where they did, a piano's corner, is in
// docs/SURFACE.md, step 4.)
TEST (SurfaceLayer, CrossingsOfAWedge)
{
  const double sigma = 0.01;
  // The wedge's samples carry the noise (its normals are exact): the tip blurs.
  auto jittered = wedge (21.5 * M_PI / 180.0, 0.4, 0.4, 0.01);
  std::mt19937 rng (3);
  std::normal_distribution<double> noise (0.0, sigma);
  for (auto& p : jittered)
    p.getVector3fMap () += draw3 (noise, rng).cast<float> ();
  const auto tip = buildCloudModel (jittered, noisy (sigma));
  const std::vector<double> zs {-0.125, -0.075, -0.025, 0.025, 0.075, 0.125, 0.175, 0.225};
  const auto clear = buildCloudModel (upright (0.018, zs), noisy (sigma));
  const auto through = buildCloudModel (upright (-0.1, zs), noisy (sigma));
  CollisionResult beside, crossing;
  ASSERT_TRUE (collide (*clear, *tip, Eigen::Isometry3d::Identity (), surfaceRequest (), beside));
  ASSERT_TRUE (collide (*through, *tip, Eigen::Isometry3d::Identity (), surfaceRequest (), crossing));
  EXPECT_NE (beside.verdict, Verdict::InCollision) << beside.probability << " d " << beside.signed_distance;
  EXPECT_EQ (crossing.verdict, Verdict::InCollision) << crossing.probability << " d " << crossing.signed_distance;
}

// A closed slab (given normals) whose top face has a hole 4 spacings wide (an occlusion
// shadow): a point just under the top face reads inside both over the hole (the surface bridges
// it; the point 1.2 spacings from the rim, within the query's reach) and under sampled top; only
// the first answer rests on surface no sample showed.
TEST (SurfaceLayer, AnswersOverABridgedHoleAreUnobserved)
{
  const double h = 0.01, sigma = 0.001;
  pcl::PointCloud<pcl::PointNormal> holed;
  for (const auto& p : slab (0.4, 0.05, h))
    if (!(p.normal_z > 0.0f && std::abs (p.x) < 0.015f && std::abs (p.y) < 0.015f))
      holed.push_back (p);
  const auto box = buildCloudModel (holed, noisy (sigma));
  pcl::PointCloud<pcl::PointXYZ> probe;
  probe.push_back (pcl::PointXYZ (0.0f, 0.0f, 0.0f));
  const auto point = buildCloudModel (probe, withSurface ());
  CollisionResult hole, sampled;
  // 8 sigma under the top face (z = 0.05): over the hole, and 0.1 away from it.
  ASSERT_TRUE (collide (*point, *box, shift (-0.008, 0, -0.042), surfaceRequest (), hole));
  ASSERT_TRUE (collide (*point, *box, shift (-0.1, 0, -0.042), surfaceRequest (), sampled));
  EXPECT_EQ (hole.verdict, Verdict::InCollision) << hole.probability << " d " << hole.signed_distance << " +- " << hole.signed_distance_std;
  EXPECT_EQ (sampled.verdict, Verdict::InCollision) << sampled.probability;
  EXPECT_TRUE (hole.unobserved);
  EXPECT_FALSE (sampled.unobserved);
}

// A capped surface layer (max_surface_pairs) enumerates only the leaf pairs its cap lets it
// reach: two noisy overlapping sheets whose pairs within reach number many times the cap. Its
// box tests were those of the whole enumeration (a W2 query at 4 mm noise took 0.7 s capped at
// 256, as uncapped); the answer is the same either way (the enumeration stops where the cap
// would, docs/PERFORMANCE.md).
TEST (SurfaceLayer, ACappedQueryEnumeratesOnlyThePairsItCanReach)
{
  const auto sheet = [] (unsigned seed) {
    pcl::PointCloud<pcl::PointXYZ> c;
    std::mt19937 rng (seed);
    std::normal_distribution<float> noise (0.0f, 0.004f);
    for (int i = 0; i < 100; ++i)
      for (int j = 0; j < 100; ++j)
        c.push_back (pcl::PointXYZ (0.002f * i + noise (rng), 0.002f * j + noise (rng), noise (rng)));
    return c;
  };
  CloudModelParams params = withSurface ();
  params.noise = SensorNoiseModel::isotropic (0.004);
  const auto a = buildCloudModel (sheet (1), params);
  const auto b = buildCloudModel (sheet (2), params);
  CollisionRequest uncapped = surfaceRequest ();
  uncapped.exhaustive = true;
  CollisionResult all;
  ASSERT_TRUE (collide (*a, *b, shift (0.0, 0.0, 0.003), uncapped, all));
  CollisionRequest capped = uncapped;
  capped.max_surface_pairs = 64;
  CollisionResult some;
  ASSERT_TRUE (collide (*a, *b, shift (0.0, 0.0, 0.003), capped, some));
  ASSERT_GT (all.leaf_pairs_tested, 20u * capped.max_surface_pairs);
  EXPECT_TRUE (some.budget_exhausted);
  EXPECT_LT (some.leaf_pairs_tested, 4u * capped.max_surface_pairs);
  EXPECT_LT (some.bv_tests * 10, all.bv_tests) << some.bv_tests << " box tests capped, " << all.bv_tests << " uncapped";
}

