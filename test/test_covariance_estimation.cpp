// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/covariance_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>
#include <pcl/filters/filter.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

using pcl_probcollision::Covariance;
using pcl_probcollision::CovarianceEstimation;
using pcl_probcollision::SensorNoiseModel;
using pcl_probcollision::SensorPose;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace
{
Cloud::Ptr
grid (int nx, int ny, double h, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity (),
      double offset = 0.0)
{
  Cloud::Ptr c (new Cloud);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
    {
      const Eigen::Vector3d p = pose * Eigen::Vector3d (i * h, j * h, 0.0) + Eigen::Vector3d::Constant (offset);
      c->push_back (pcl::PointXYZ (static_cast<float> (p.x ()), static_cast<float> (p.y ()), static_cast<float> (p.z ())));
    }
  c->width = nx;
  c->height = ny;
  return c;
}

/** The measured-position model (the paper's: surface projection off). */
pcl::PointCloud<Covariance>
estimate (const Cloud::ConstPtr& cloud, int k, const SensorNoiseModel& noise = SensorNoiseModel (),
          bool discretization = true)
{
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setSurfaceProjection (false);
  est.setInputCloud (cloud);
  est.setKSearch (k);
  est.setSensorNoise (noise);
  est.setUseDiscretization (discretization);
  pcl::PointCloud<Covariance> out;
  est.compute (out);
  return out;
}

bool
isPsd (const Eigen::Matrix3d& m, double tol)
{
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> (m).eigenvalues ().minCoeff () >= -tol;
}
} // namespace

TEST (CovarianceEstimation, InteriorGridPointMatchesThePaulyClosedForm)
{
  // METHOD.md 11.7: spacing h, k = 8 (no distance ties), tau = 2 sqrt(k).
  const double h = 0.01;
  const auto cloud = grid (7, 7, h);
  const auto out = estimate (cloud, 8);
  const Eigen::Matrix3d psi = out[3 * 7 + 3].matrix ();
  const double e1 = std::exp (-1.0 / 8.0), e2 = std::exp (-1.0 / 4.0);
  const double expected = h * h * (2 * e1 + 4 * e2) / (4 * e1 + 4 * e2);
  EXPECT_NEAR (expected / (h * h), 0.734395, 1e-6);
  EXPECT_NEAR (psi (0, 0), expected, 1e-6 * expected);
  EXPECT_NEAR (psi (1, 1), expected, 1e-6 * expected);
  EXPECT_NEAR (psi (2, 2), 0.0, 1e-12);
  EXPECT_NEAR (psi (0, 1), 0.0, 1e-6 * expected);
}

TEST (CovarianceEstimation, TiltedPlaneSmallestEigenvectorIsTheNormalAndNoiseAddsAlongIt)
{
  const Eigen::Isometry3d pose (Eigen::AngleAxisd (0.6, Eigen::Vector3d (1, -2, 0.5).normalized ()));
  const Eigen::Vector3d normal = pose.linear () * Eigen::Vector3d::UnitZ ();
  const auto cloud = grid (15, 15, 0.01, pose);
  const double sigma = 0.002;
  const auto clean = estimate (cloud, 10);
  const auto noisy = estimate (cloud, 10, SensorNoiseModel::isotropic (sigma));
  for (std::size_t i = 0; i < cloud->size (); ++i)
  {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (clean[i].matrix ());
    EXPECT_NEAR (std::abs (eig.eigenvectors ().col (0).dot (normal)), 1.0, 1e-4) << i;
    EXPECT_NEAR (normal.dot (clean[i].matrix () * normal), 0.0, 1e-9) << i;
    // Isotropic noise adds sigma^2 I exactly (up to float storage).
    const Eigen::Matrix3d added = noisy[i].matrix () - clean[i].matrix ();
    EXPECT_TRUE ((added - sigma * sigma * Eigen::Matrix3d::Identity ()).cwiseAbs ().maxCoeff () < 1e-10) << i;
    EXPECT_NEAR (normal.dot (noisy[i].matrix () * normal), sigma * sigma, 1e-10) << i;
  }
}

TEST (CovarianceEstimation, SphereSamplesGiveRadialNormals)
{
  Cloud::Ptr cloud (new Cloud);
  const int n = 2000;
  const double golden = M_PI * (3.0 - std::sqrt (5.0));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt (1.0 - z * z), phi = golden * i;
    cloud->push_back (pcl::PointXYZ (static_cast<float> (0.1 * r * std::cos (phi)),
                                     static_cast<float> (0.1 * r * std::sin (phi)), static_cast<float> (0.1 * z)));
  }
  const auto out = estimate (cloud, 10);
  int radial = 0;
  for (int i = 0; i < n; ++i)
  {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (out[i].matrix ());
    const Eigen::Vector3d radius = (*cloud)[i].getVector3fMap ().cast<double> ().normalized ();
    radial += std::abs (eig.eigenvectors ().col (0).dot (radius)) > 0.99 ? 1 : 0;
  }
  EXPECT_EQ (radial, n);
}

TEST (CovarianceEstimation, DepthModelGrowsAlongTheViewingRay)
{
  // Two fronto-parallel patches at 1 m and 2 m seen from the origin along +z.
  Cloud::Ptr cloud (new Cloud);
  for (double z : {1.0, 2.0})
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i)
        cloud->push_back (pcl::PointXYZ (static_cast<float> (0.01 * (i - 4)), static_cast<float> (0.01 * (j - 4)), static_cast<float> (z)));
  const auto out = estimate (cloud, 8, SensorNoiseModel::stereo (), /*discretization=*/false);
  const Eigen::Vector3d ray = Eigen::Vector3d::UnitZ ();
  const double near_var = ray.dot (out[40].matrix () * ray);       // centre of the z = 1 patch
  const double far_var = ray.dot (out[81 + 40].matrix () * ray);   // centre of the z = 2 patch
  EXPECT_NEAR (far_var / near_var, 16.0, 16.0 * 1e-5);  // sigma_a ~ z^2, variance ~ z^4
}

TEST (CovarianceEstimation, TranslationByOneHundredKilometresChangesNothing)
{
  // Spacing 0.25 keeps float coordinates exact at a 1e5 offset, so any difference is ours.
  const auto at_origin = estimate (grid (9, 9, 0.25), 10);
  const auto far = estimate (grid (9, 9, 0.25, Eigen::Isometry3d::Identity (), 1e5), 10);
  for (std::size_t i = 0; i < at_origin.size (); ++i)
    EXPECT_TRUE ((at_origin[i].matrix () - far[i].matrix ()).cwiseAbs ().maxCoeff () <= 1e-9) << i;
}

TEST (CovarianceEstimation, OrganizedCloudWithNaNKeepsItsShapeAndMatchesTheDenseCloud)
{
  auto cloud = grid (20, 10, 0.01);
  const float nan = std::numeric_limits<float>::quiet_NaN ();
  for (int i : {0, 17, 55, 56, 57, 120, 199})
    (*cloud)[i].x = (*cloud)[i].y = (*cloud)[i].z = nan;
  (*cloud)[88].z = std::numeric_limits<float>::infinity ();
  cloud->is_dense = false;
  const auto out = estimate (cloud, 10, SensorNoiseModel::isotropic (0.001));
  EXPECT_EQ (out.width, 20u);
  EXPECT_EQ (out.height, 10u);
  EXPECT_FALSE (out.is_dense);

  Cloud::Ptr dense (new Cloud);
  pcl::Indices kept;
  pcl::removeNaNFromPointCloud (*cloud, *dense, kept);
  // removeNaNFromPointCloud keeps Inf; drop it by hand so both see the same finite points.
  Cloud::Ptr finite (new Cloud);
  std::vector<int> source;
  for (std::size_t j = 0; j < dense->size (); ++j)
    if (pcl::isFinite ((*dense)[j]))
    {
      finite->push_back ((*dense)[j]);
      source.push_back (kept[j]);
    }
  const auto reference = estimate (finite, 10, SensorNoiseModel::isotropic (0.001));
  ASSERT_EQ (finite->size (), 192u);
  std::vector<bool> is_finite (cloud->size (), false);
  for (std::size_t j = 0; j < finite->size (); ++j)
  {
    is_finite[source[j]] = true;
    EXPECT_TRUE (out[source[j]].isFinite ());
    EXPECT_TRUE ((out[source[j]].matrix () - reference[j].matrix ()).cwiseAbs ().maxCoeff () < 1e-12) << source[j];
  }
  for (std::size_t i = 0; i < cloud->size (); ++i)
  {
    if (!is_finite[i])
    {
      EXPECT_FALSE (out[i].isFinite ()) << i;
    }
  }
}

TEST (CovarianceEstimation, SetIndicesComputesOnlyThoseInOrder)
{
  const auto cloud = grid (10, 10, 0.01);
  const auto all = estimate (cloud, 10);
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setInputCloud (cloud);
  pcl::IndicesPtr idx (new pcl::Indices {42, 7, 99});
  est.setIndices (idx);
  pcl::PointCloud<Covariance> out;
  est.compute (out);
  ASSERT_EQ (out.size (), 3u);
  for (std::size_t j = 0; j < 3; ++j)
    EXPECT_TRUE (out[j].matrix ().isApprox (all[(*idx)[j]].matrix (), 1e-12));
  EXPECT_EQ (est.getNeighbourRadii ().size (), 3u);
}

TEST (CovarianceEstimation, DegenerateNeighbourhoodsGiveFiniteDocumentedResults)
{
  // Fewer points than k: the neighbours there are.
  Cloud::Ptr few (new Cloud);
  for (int i = 0; i < 4; ++i)
    few->push_back (pcl::PointXYZ (0.01f * i, 0.005f * (i % 2), 0.0f));
  for (const auto& c : estimate (few, 10))
  {
    EXPECT_TRUE (c.isFinite ());
    EXPECT_TRUE (isPsd (c.matrix (), 1e-15));
    EXPECT_GT (c.matrix ().trace (), 0.0);
  }
  // A single point and all-identical points: Psi = 0, plus the sensor noise.
  Cloud::Ptr same (new Cloud);
  for (int i = 0; i < 12; ++i)
    same->push_back (pcl::PointXYZ (1.f, 2.f, 3.f));
  for (const auto& c : estimate (same, 10, SensorNoiseModel::isotropic (0.003)))
    EXPECT_TRUE (c.matrix ().isApprox (9e-6 * Eigen::Matrix3d::Identity (), 1e-6));
  Cloud::Ptr single (new Cloud);
  single->push_back (pcl::PointXYZ (1.f, 2.f, 3.f));
  const auto one = estimate (single, 10);
  ASSERT_EQ (one.size (), 1u);
  EXPECT_TRUE (one[0].matrix ().isZero (0.0));
  // Collinear points: rank one, along the line, finite.
  Cloud::Ptr line (new Cloud);
  const Eigen::Vector3d dir = Eigen::Vector3d (1, 2, 2) / 3.0;
  for (int i = 0; i < 30; ++i)
  {
    const Eigen::Vector3f p = (0.01 * i * dir).cast<float> ();
    line->push_back (pcl::PointXYZ (p.x (), p.y (), p.z ()));
  }
  for (const auto& c : estimate (line, 6))
  {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (c.matrix ());
    EXPECT_LT (eig.eigenvalues ()(1), 1e-10 * eig.eigenvalues ()(2));
    EXPECT_NEAR (std::abs (eig.eigenvectors ().col (2).dot (dir)), 1.0, 1e-6);
  }
}

TEST (CovarianceEstimation, BadParametersAndEmptyInputFailClearly)
{
  CovarianceEstimation<pcl::PointXYZ> est;
  EXPECT_THROW (est.setKSearch (0), pcl::BadArgumentException);
  EXPECT_THROW (est.setScale (-1.0), pcl::BadArgumentException);
  EXPECT_THROW (est.setScale (std::nan ("")), pcl::BadArgumentException);
  EXPECT_NEAR (est.getScale (), 2.0 * std::sqrt (10.0), 1e-12);

  pcl::PointCloud<Covariance> out;
  out.resize (5);  // stale content must not survive a failed compute
  est.setInputCloud (Cloud::Ptr (new Cloud));
  est.compute (out);
  EXPECT_TRUE (out.empty ());

  out.resize (5);
  est.setInputCloud (grid (5, 5, 0.01));
  est.setRadiusSearch (0.05);  // the method is defined on k neighbours
  est.compute (out);
  EXPECT_TRUE (out.empty ());
}

// A depth noise model with a non-finite sensor origin (the cloud's sensor_origin_, or
// setSensorPose) fails in initCompute, as PCL features fail, instead of writing NaN covariances
// at every point (a probe, 2026-12-04).
TEST (CovarianceEstimation, ADepthNoiseModelWithANonFiniteSensorOriginFailsClearly)
{
  Cloud::Ptr cloud = grid (5, 5, 0.01);
  cloud->sensor_origin_ = Eigen::Vector4f (std::nanf (""), 0.0f, 0.0f, 0.0f);
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setInputCloud (cloud);
  est.setKSearch (5);
  est.setSensorNoise (SensorNoiseModel::kinect ());
  pcl::PointCloud<Covariance> out;
  out.resize (5);
  est.compute (out);
  EXPECT_TRUE (out.empty ());
  SensorPose pose;
  pose.origin = Eigen::Vector3d (0.0, 0.0, 1.0);
  est.setSensorPose (pose);  // given, it replaces the cloud's
  est.compute (out);
  EXPECT_EQ (out.size (), 25u);
  pose.origin.z () = std::numeric_limits<double>::infinity ();
  est.setSensorPose (pose);
  est.compute (out);
  EXPECT_TRUE (out.empty ());
  // The rule's words, which buildCloudModel and initCompute both print.
  EXPECT_EQ (SensorNoiseModel::kinect ().sensorPoseError (pose),
             "sensor origin (0, 0, inf) is not finite: the kinect noise model measures each point's depth from it");
  EXPECT_EQ (SensorNoiseModel::isotropic (0.01).sensorPoseError (pose), "");
  // A non-finite sensor_orientation_ was taken for the identity without a word (the axis a
  // depth model measures along); a zero one is PCL's unset orientation, the identity.
  const SensorPose nan_axis = SensorPose::fromViewpoint (Eigen::Vector4f (0, 0, 1, 0), Eigen::Quaternionf (NAN, 0, 0, 0));
  EXPECT_EQ (SensorNoiseModel::stereo ().sensorPoseError (nan_axis),
             "sensor orientation is not finite (viewing axis (nan, nan, nan)): the stereo noise model measures each "
             "point's depth along it");
  EXPECT_EQ (SensorNoiseModel::isotropic (0.01).sensorPoseError (nan_axis), "");
  const SensorPose unset = SensorPose::fromViewpoint (Eigen::Vector4f (0, 0, 1, 0), Eigen::Quaternionf (0, 0, 0, 0));
  EXPECT_TRUE (unset.axis.isApprox (Eigen::Vector3d::UnitZ ()));
  EXPECT_EQ (SensorNoiseModel::kinect ().sensorPoseError (unset), "");
  cloud->sensor_origin_ = Eigen::Vector4f (0.0f, 0.0f, 1.0f, 0.0f);
  cloud->sensor_orientation_ = Eigen::Quaternionf (0.0f, std::nanf (""), 0.0f, 0.0f);
  est.setSensorPose (SensorPose::fromViewpoint (cloud->sensor_origin_, cloud->sensor_orientation_));
  est.compute (out);
  EXPECT_TRUE (out.empty ());
}

TEST (CovarianceEstimation, RealStereoScanKeepsAlignmentAndGivesFinitePsdCovariances)
{
  const std::string file = std::string (PCL_PROBCOLLISION_SHARED_DATA) + "/scans/table_scene_mug_stereo_textured.pcd";
  pcl::PointCloud<pcl::PointXYZRGBA>::Ptr scan (new pcl::PointCloud<pcl::PointXYZRGBA>);
  ASSERT_EQ (pcl::io::loadPCDFile (file, *scan), 0) << "missing shared data: " << file;
  ASSERT_EQ (scan->width, 640u);
  ASSERT_EQ (scan->height, 480u);
  CovarianceEstimation<pcl::PointXYZRGBA> est;
  est.setInputCloud (scan);
  est.setSensorNoise (SensorNoiseModel::stereo ());
  pcl::PointCloud<Covariance> out;
  est.compute (out);
  ASSERT_EQ (out.size (), scan->size ());
  EXPECT_EQ (out.width, 640u);
  EXPECT_EQ (out.height, 480u);
  std::size_t finite = 0, psd = 0;
  for (std::size_t i = 0; i < scan->size (); ++i)
  {
    const bool point_finite = pcl::isFinite ((*scan)[i]);
    EXPECT_EQ (out[i].isFinite (), point_finite) << i;
    if (point_finite)
    {
      ++finite;
      psd += isPsd (out[i].matrix (), 1e-12) && out[i].matrix ().trace () > 0.0 ? 1 : 0;
    }
  }
  EXPECT_EQ (finite, 209280u);  // SCENES.md: finite points of this scan
  EXPECT_EQ (psd, finite);
}

namespace
{
// A square grid in z = 0, spacing h, with Gaussian noise sigma on every axis.
Cloud::Ptr
noisyPlane (int n, double h, double sigma, std::uint64_t seed, double offset = 0.0)
{
  std::mt19937_64 rng (seed);
  std::normal_distribution<double> noise (0.0, sigma);
  Cloud::Ptr c (new Cloud);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      c->push_back (pcl::PointXYZ (static_cast<float> (offset + i * h + noise (rng)),
                                   static_cast<float> (offset + j * h + noise (rng)),
                                   static_cast<float> (offset + noise (rng))));
  return c;
}

struct Projected
{
  pcl::PointCloud<Covariance> covariances;
  std::vector<Eigen::Vector3d> displacements;
};

Projected
project (const Cloud::ConstPtr& cloud, const SensorNoiseModel& noise)
{
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setInputCloud (cloud);
  est.setSensorNoise (noise);
  est.setSurfaceProjection (true);
  Projected p;
  est.compute (p.covariances);
  p.displacements = est.getSurfaceDisplacements ();
  return p;
}
} // namespace

// On a flat noisy patch the projection removes most of each point's error across the surface,
// and the covariance says so: its spread across the surface shrinks, along it only the sensor's
// remains (the discretisation spread is dropped there).
TEST (CovarianceEstimation, SurfaceProjectionDenoisesAFlatPatchAndShrinksItsSpreadAcrossIt)
{
  const double sigma = 0.002, h = 0.01;
  const Cloud::ConstPtr cloud = noisyPlane (30, h, sigma, 7);
  const Projected p = project (cloud, SensorNoiseModel::isotropic (sigma));
  const auto measured = estimate (cloud, 10, SensorNoiseModel::isotropic (sigma));
  ASSERT_EQ (p.displacements.size (), cloud->size ());
  double before = 0.0, after = 0.0, zz_before = 0.0, zz_after = 0.0, xx_after = 0.0;
  for (std::size_t i = 0; i < cloud->size (); ++i)
  {
    const double z = (*cloud)[i].z;
    before += z * z;
    after += (z + p.displacements[i].z ()) * (z + p.displacements[i].z ());
    zz_before += measured[i].matrix () (2, 2);
    zz_after += p.covariances[i].matrix () (2, 2);
    xx_after += p.covariances[i].matrix () (0, 0);
    EXPECT_TRUE (isPsd (p.covariances[i].matrix (), 1e-15));
  }
  const double n = static_cast<double> (cloud->size ());
  const double rms_before = std::sqrt (before / n), rms_after = std::sqrt (after / n);
  EXPECT_NEAR (rms_before, sigma, 0.1 * sigma);
  EXPECT_LT (rms_after, 0.5 * sigma) << "measured " << rms_before;
  // Measured: discretisation (about 2 sigma^2 across) plus sensor; projected: about a tenth.
  EXPECT_GT (zz_before / n, 2.0 * sigma * sigma);
  EXPECT_LT (zz_after / n, 0.5 * sigma * sigma);
  // Along the surface the sensor's sigma^2 is what is left (the spacing h^2 = 25 sigma^2 is gone).
  EXPECT_NEAR (xx_after / n, sigma * sigma, 0.3 * sigma * sigma);
}

// Neighbours on one line fix no plane: a point is not slid along its own surface onto their line.
// A three-point cloud (each point's two neighbours) and the end of an L of samples, both flat in
// z = 0, keep every point where it was (the normal was any direction across the line before, and
// a triangle's corner moved 0.15 of its 1 m side).
TEST (CovarianceEstimation, SurfaceProjectionDoesNotSlideAPointOntoCollinearNeighbours)
{
  Cloud::Ptr triangle (new Cloud);
  triangle->push_back (pcl::PointXYZ (0.086f, 0.237f, 0.0f));
  triangle->push_back (pcl::PointXYZ (0.9f, 0.1f, 0.0f));
  triangle->push_back (pcl::PointXYZ (0.3f, 0.8f, 0.0f));
  const Projected p = project (triangle, SensorNoiseModel::isotropic (0.01));
  ASSERT_EQ (p.displacements.size (), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_LT (p.displacements[i].norm (), 1e-12) << i << ": " << p.displacements[i].transpose ();
  // A row of ten samples and one beside its end: the lone point's ten neighbours are the row.
  Cloud::Ptr row (new Cloud);
  for (int j = 0; j < 10; ++j)
    row->push_back (pcl::PointXYZ (0.01f * static_cast<float> (j), 0.0f, 0.0f));
  row->push_back (pcl::PointXYZ (0.0f, 0.01f, 0.0f));
  const Projected q = project (row, SensorNoiseModel::isotropic (0.002));
  EXPECT_LT (q.displacements[10].norm (), 1e-12) << q.displacements[10].transpose ();
}

// Without a sensor model nothing is projected: the output equals the measured model's.
TEST (CovarianceEstimation, SurfaceProjectionWithoutSensorNoiseChangesNothing)
{
  const Cloud::ConstPtr cloud = noisyPlane (12, 0.01, 0.002, 3);
  const Projected p = project (cloud, SensorNoiseModel ());
  const auto measured = estimate (cloud, 10);
  for (std::size_t i = 0; i < cloud->size (); ++i)
  {
    EXPECT_EQ (p.displacements[i], Eigen::Vector3d::Zero ());
    EXPECT_TRUE (p.covariances[i].matrix ().isApprox (measured[i].matrix (), 1e-12));
  }
}

// At a 90 degree edge the neighbours' scatter across any plane is geometry, not noise: edge
// points stay near where they were measured instead of being pulled into the corner's chord.
TEST (CovarianceEstimation, SurfaceProjectionLeavesSharpEdgesInPlace)
{
  const double h = 0.01, sigma = 0.0005;
  std::mt19937_64 rng (5);
  std::normal_distribution<double> noise (0.0, sigma);
  Cloud::Ptr cloud (new Cloud);
  std::vector<std::size_t> edge;
  for (int j = 0; j < 20; ++j)
    for (int i = -10; i <= 10; ++i)
    {
      // z = 0 for x <= 0, then a vertical wall x = 0 going down (an edge along y at x = z = 0).
      const double x = i <= 0 ? i * h : 0.0, z = i <= 0 ? 0.0 : -i * h;
      if (i == 0)
        edge.push_back (cloud->size ());
      cloud->push_back (pcl::PointXYZ (static_cast<float> (x + noise (rng)), static_cast<float> (j * h + noise (rng)),
                                       static_cast<float> (z + noise (rng))));
    }
  const Projected p = project (cloud, SensorNoiseModel::isotropic (sigma));
  for (const std::size_t i : edge)
    EXPECT_LT (p.displacements[i].norm (), 4.0 * sigma) << "edge point " << i;
}

// Projection works in differences: a map-frame offset of 100 km moves nothing.
TEST (CovarianceEstimation, SurfaceProjectionIsTranslationInvariant)
{
  // Spacing 0.25 and noise in steps of 1/128 keep float coordinates exact at a 1e5 offset.
  const double sigma = 0.05;
  auto plane = [&] (double offset) {
    std::mt19937_64 rng (11);
    std::normal_distribution<double> noise (0.0, sigma);
    auto q = [&] () { return std::round (noise (rng) * 128.0) / 128.0; };
    Cloud::Ptr c (new Cloud);
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        c->push_back (pcl::PointXYZ (static_cast<float> (offset + i * 0.25 + q ()),
                                     static_cast<float> (offset + j * 0.25 + q ()), static_cast<float> (offset + q ())));
    return c;
  };
  const Projected p0 = project (plane (0.0), SensorNoiseModel::isotropic (sigma));
  const Projected p1 = project (plane (1e5), SensorNoiseModel::isotropic (sigma));
  ASSERT_EQ (p0.displacements.size (), p1.displacements.size ());
  double moved = 0.0;
  for (std::size_t i = 0; i < p0.displacements.size (); ++i)
  {
    EXPECT_LE ((p0.displacements[i] - p1.displacements[i]).norm (), 1e-9) << i;
    EXPECT_LE ((p0.covariances[i].matrix () - p1.covariances[i].matrix ()).cwiseAbs ().maxCoeff (), 1e-9) << i;
    moved = std::max (moved, p0.displacements[i].norm ());
  }
  EXPECT_GT (moved, 0.5 * sigma);  // the points did move
}

namespace
{
// A noisy plane with a few NaN points, stored in a scrambled order (as mesh samples are).
Cloud::Ptr
scrambledPlaneWithNaN ()
{
  Cloud::Ptr cloud = noisyPlane (40, 0.01, 0.002, 13);
  std::mt19937_64 rng (17);
  std::shuffle (cloud->begin (), cloud->end (), rng);
  const float nan = std::numeric_limits<float>::quiet_NaN ();
  for (std::size_t i = 0; i < cloud->size (); i += 97)
    (*cloud)[i].x = (*cloud)[i].y = (*cloud)[i].z = nan;
  cloud->is_dense = false;
  return cloud;
}
} // namespace

// The default search (PCL's FLANN k-d tree, queried in batches and in a spatial order) must give
// what an explicitly set pcl::search::KdTree gives, which pcl::Feature queries point by point.
TEST (CovarianceEstimation, DefaultSearchMatchesAnExplicitPclKdTree)
{
  const Cloud::Ptr cloud = scrambledPlaneWithNaN ();
  Cloud::Ptr half (new Cloud);
  for (std::size_t i = 0; i < cloud->size (); i += 2)
    half->push_back ((*cloud)[i]);
  pcl::IndicesPtr some (new pcl::Indices);
  for (std::size_t i = 0; i < cloud->size (); i += 3)
    some->push_back (static_cast<int> ((i * 7) % cloud->size ()));
  const SensorNoiseModel noises[] = {SensorNoiseModel (), SensorNoiseModel::isotropic (0.002),
                                     SensorNoiseModel::kinect ()};
  for (const SensorNoiseModel& noise : noises)
    for (int variant = 0; variant < 3; ++variant)
    {
      auto run = [&] (bool explicit_tree, std::vector<float>& radii, std::vector<Eigen::Vector3d>& moved) {
        CovarianceEstimation<pcl::PointXYZ> est;
        est.setInputCloud (cloud);
        est.setSensorNoise (noise);
        est.setSurfaceProjection (noise.type () != SensorNoiseModel::Type::None);
        if (variant == 1)
          est.setIndices (some);
        if (variant == 2)
          est.setSearchSurface (half);
        if (explicit_tree)
          est.setSearchMethod (pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>> (false));
        pcl::PointCloud<Covariance> out;
        est.compute (out);
        radii = est.getNeighbourRadii ();
        moved = est.getSurfaceDisplacements ();
        return out;
      };
      std::vector<float> radii, radii_pcl;
      std::vector<Eigen::Vector3d> moved, moved_pcl;
      const auto out = run (false, radii, moved);
      const auto out_pcl = run (true, radii_pcl, moved_pcl);
      ASSERT_EQ (out.size (), out_pcl.size ());
      ASSERT_EQ (moved.size (), moved_pcl.size ());
      for (std::size_t i = 0; i < out.size (); ++i)
      {
        ASSERT_EQ (out[i].isFinite (), out_pcl[i].isFinite ()) << variant << " " << i;
        if (!out[i].isFinite ())
          continue;
        EXPECT_EQ (radii[i], radii_pcl[i]) << variant << " " << i;
        EXPECT_TRUE (out[i].matrix () == out_pcl[i].matrix ()) << variant << " " << i;
        if (!moved.empty ())
        {
          EXPECT_TRUE (moved[i] == moved_pcl[i]) << variant << " " << i;
        }
      }
    }
}

// compute() leaves its default search in getSearchMethod(); it must answer as pcl::search::KdTree.
TEST (CovarianceEstimation, DefaultSearchAnswersSingleQueriesLikePclKdTree)
{
  const Cloud::Ptr cloud = scrambledPlaneWithNaN ();
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setInputCloud (cloud);
  pcl::PointCloud<Covariance> out;
  est.compute (out);
  const auto search = est.getSearchMethod ();
  ASSERT_TRUE (search);
  pcl::search::KdTree<pcl::PointXYZ> reference;
  reference.setInputCloud (cloud);
  pcl::Indices got, expected;
  std::vector<float> got_d, expected_d;
  for (std::size_t i = 1; i < cloud->size (); i += 37)
  {
    if (!pcl::isFinite ((*cloud)[i]))
      continue;
    EXPECT_EQ (search->nearestKSearch ((*cloud)[i], 12, got, got_d),
               reference.nearestKSearch ((*cloud)[i], 12, expected, expected_d));
    EXPECT_EQ (got, expected) << i;
    EXPECT_EQ (got_d, expected_d) << i;
    for (unsigned int max_nn : {0u, 5u})
    {
      EXPECT_EQ (search->radiusSearch ((*cloud)[i], 0.025, got, got_d, max_nn),
                 reference.radiusSearch ((*cloud)[i], 0.025, expected, expected_d, max_nn));
      std::sort (got.begin (), got.end ());
      std::sort (expected.begin (), expected.end ());
      EXPECT_EQ (got, expected) << i;
    }
  }
}

// setComputeNormals (false): the neighbours, radii and covariances of the default, without the
// normal fits (a cloud that brings its own normals, as a CloudModel's surface takes them).
TEST (CovarianceEstimation, NeighboursWithoutNormalFits)
{
  const Cloud::Ptr cloud = scrambledPlaneWithNaN ();
  auto run = [&] (bool normals, CovarianceEstimation<pcl::PointXYZ>& est) {
    est.setInputCloud (cloud);
    est.setSensorNoise (SensorNoiseModel::isotropic (0.002));
    est.setComputeSurface (true);
    est.setComputeNormals (normals);
    EXPECT_EQ (est.getComputeNormals (), normals);
    pcl::PointCloud<Covariance> out;
    est.compute (out);
    return out;
  };
  CovarianceEstimation<pcl::PointXYZ> with, without;
  const auto a = run (true, with);
  const auto b = run (false, without);
  ASSERT_EQ (a.size (), b.size ());
  EXPECT_EQ (with.getNormals ().size (), cloud->size ());
  EXPECT_TRUE (without.getNormals ().empty ());
  EXPECT_EQ (without.getNeighbours (), with.getNeighbours ());
  EXPECT_EQ (without.getNeighbours ().size (), cloud->size () * 10u);
  for (std::size_t i = 0; i < a.size (); ++i)
  {
    ASSERT_EQ (a[i].isFinite (), b[i].isFinite ()) << i;
    if (!a[i].isFinite ())
      continue;
    EXPECT_TRUE (a[i].matrix () == b[i].matrix ()) << i;
    EXPECT_EQ (with.getNeighbourRadii ()[i], without.getNeighbourRadii ()[i]) << i;
  }
}

// Blocks of points go to several threads; every output must be what one thread gives, bit for
// bit, including the NaN rows and is_dense.
// On threads the outputs are sized beside the k-d tree's build (initCompute): a second compute
// with other settings, into the same output cloud, must show nothing of the first.
TEST (CovarianceEstimation, ARepeatedComputeOnThreadsStartsAfresh)
{
  const Cloud::Ptr cloud = scrambledPlaneWithNaN ();
  CovarianceEstimation<pcl::PointXYZ> est;
  est.setNumberOfThreads (2);
  est.setInputCloud (cloud);
  est.setComputeSurface (true);
  pcl::PointCloud<Covariance> out;
  est.compute (out);
  ASSERT_EQ (out.size (), cloud->size ());
  ASSERT_EQ (est.getNormals ().size (), cloud->size ());
  ASSERT_EQ (est.getSurfaceDisplacements ().size (), cloud->size ());
  est.setComputeSurface (false);
  est.setSurfaceProjection (false);
  est.setSensorNoise (SensorNoiseModel::isotropic (0.01));
  est.compute (out);
  EXPECT_TRUE (est.getNormals ().empty ());
  EXPECT_TRUE (est.getNeighbours ().empty ());
  EXPECT_TRUE (est.getSurfaceDisplacements ().empty ());

  CovarianceEstimation<pcl::PointXYZ> fresh;  // one thread, the second compute's settings
  fresh.setInputCloud (cloud);
  fresh.setSurfaceProjection (false);
  fresh.setSensorNoise (SensorNoiseModel::isotropic (0.01));
  pcl::PointCloud<Covariance> ref;
  fresh.compute (ref);
  ASSERT_EQ (out.size (), ref.size ());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < out.size (); ++i)
  {
    const bool both_nan = !out[i].isFinite () && !ref[i].isFinite ();
    differing += both_nan ? 0 : (out[i].matrix () == ref[i].matrix () ? 0 : 1);
    differing += std::isnan (est.getNeighbourRadii ()[i]) == std::isnan (fresh.getNeighbourRadii ()[i]) ? 0 : 1;
  }
  EXPECT_EQ (differing, 0u);
  EXPECT_EQ (out.width, ref.width);
  EXPECT_EQ (out.height, ref.height);
}

TEST (CovarianceEstimation, AnyThreadCountGivesTheOneThreadOutput)
{
  const Cloud::Ptr cloud = scrambledPlaneWithNaN ();  // 1,600 points: 7 blocks of 256
  auto run = [&] (int threads, CovarianceEstimation<pcl::PointXYZ>& est) {
    est.setInputCloud (cloud);
    est.setSensorNoise (SensorNoiseModel::kinect ());
    est.setComputeSurface (true);
    est.setNumberOfThreads (threads);
    EXPECT_EQ (est.getNumberOfThreads (), threads);
    pcl::PointCloud<Covariance> out;
    est.compute (out);
    return out;
  };
  CovarianceEstimation<pcl::PointXYZ> one;
  const auto ref = run (1, one);
  ASSERT_EQ (ref.size (), cloud->size ());
  EXPECT_FALSE (ref.is_dense);
  for (const int threads : {2, 3, 0})
  {
    CovarianceEstimation<pcl::PointXYZ> est;
    const auto out = run (threads, est);
    ASSERT_EQ (out.size (), ref.size ());
    EXPECT_EQ (out.is_dense, ref.is_dense);
    std::size_t finite = 0;
    for (std::size_t i = 0; i < out.size (); ++i)
    {
      ASSERT_EQ (out[i].isFinite (), ref[i].isFinite ()) << threads << " " << i;
      if (!out[i].isFinite ())
        continue;
      ++finite;
      EXPECT_TRUE (out[i].matrix () == ref[i].matrix ()) << threads << " " << i;
      EXPECT_EQ (est.getNeighbourRadii ()[i], one.getNeighbourRadii ()[i]);
      EXPECT_TRUE (est.getSurfaceDisplacements ()[i] == one.getSurfaceDisplacements ()[i]);
      EXPECT_TRUE (est.getNormals ()[i] == one.getNormals ()[i]);
    }
    EXPECT_EQ (finite, cloud->size () - 17u);  // every 97th point is NaN
    EXPECT_EQ (est.getNeighbours (), one.getNeighbours ());
  }
  // With indices: the order computed beside the k-d tree's build follows them.
  pcl::IndicesPtr some (new pcl::Indices);
  for (std::size_t i = 0; i < cloud->size (); i += 3)
    some->push_back (static_cast<int> ((i * 7) % cloud->size ()));
  pcl::PointCloud<Covariance> by_indices[2];
  for (const int threads : {1, 2})
  {
    CovarianceEstimation<pcl::PointXYZ> est;
    est.setInputCloud (cloud);
    est.setIndices (some);
    est.setSensorNoise (SensorNoiseModel::isotropic (0.002));
    est.setNumberOfThreads (threads);
    est.compute (by_indices[threads - 1]);
  }
  ASSERT_EQ (by_indices[0].size (), some->size ());
  ASSERT_EQ (by_indices[1].size (), some->size ());
  for (std::size_t i = 0; i < some->size (); ++i)
    EXPECT_TRUE (by_indices[0][i].matrix () == by_indices[1][i].matrix () ||
                 (!by_indices[0][i].isFinite () && !by_indices[1][i].isFinite ()))
        << i;
  CovarianceEstimation<pcl::PointXYZ> est;
  EXPECT_THROW (est.setNumberOfThreads (-1), pcl::BadArgumentException);
}
