// SPDX-License-Identifier: BSD-3-Clause
// A consumer of the installed package, as a PCL user writes one: every point type the library is
// compiled for links without PCL_NO_PRECOMPILE, and the issue #15 checks hold through the
// installed headers and library (models rebuilt when a cloud changed in place is set again;
// the same answer for a scene exactly shifted by about 1 km), and the installed version header
// agrees with the library. Exits non-zero on any failure.
#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/covariance_estimation.h>
#include <pcl_probcollision/probabilistic_collision.h>
#include <pcl_probcollision/version.h>

#include <pcl/common/transforms.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

namespace
{
int failures = 0;

void
check (bool ok, const char* what)
{
  if (!ok)
  {
    std::fprintf (stderr, "downstream: FAILED: %s\n", what);
    ++failures;
  }
}

/** 121 random points on a 0.1 m square at height z, noise sigma, coordinates on a 2^-13 grid,
  * then moved by offset (exact for offsets that are multiples of 256 up to 2048). */
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr
sheet (unsigned seed, double z, double sigma, const Eigen::Vector3d& offset)
{
  const double q = std::ldexp (1.0, -13);
  std::mt19937 rng (seed);
  std::uniform_real_distribution<double> u (-0.05, 0.05);
  std::normal_distribution<double> noise (0.0, sigma);
  typename pcl::PointCloud<PointT>::Ptr c (new pcl::PointCloud<PointT>);
  for (int i = 0; i < 121; ++i)
  {
    const double x = u (rng), y = u (rng);
    const Eigen::Vector3d p = (Eigen::Vector3d (x, y, z + noise (rng)) / q).array ().round ().matrix () * q + offset;
    PointT point;
    point.x = static_cast<float> (p.x ());
    point.y = static_cast<float> (p.y ());
    point.z = static_cast<float> (p.z ());
    c->push_back (point);
  }
  return c;
}

/** The in-place check of issue #15 for one point type: clear, then A turned in place into a wall
  * through B and set again: no longer free. */
template <typename PointT>
void
inPlaceCheck (const char* name)
{
  const auto a = sheet<PointT> (1, 0.0, 0.0, Eigen::Vector3d::Zero ());
  const auto b = sheet<PointT> (2, -0.2, 0.0, Eigen::Vector3d::Zero ());
  pcl_probcollision::ProbabilisticCollision<PointT> pc;
  pc.setInputCloud (a);
  pc.setTargetCloud (b);
  pcl_probcollision::CollisionResult before, after;
  check (pc.compute (before) && before.verdict == pcl_probcollision::Verdict::Free, name);
  Eigen::Affine3f T = Eigen::Affine3f::Identity ();
  T.translate (Eigen::Vector3f (0.0f, 0.0f, -0.2f));
  T.rotate (Eigen::AngleAxisf (static_cast<float> (M_PI / 2), Eigen::Vector3f::UnitX ()));
  pcl::transformPointCloud (*a, *a, T);
  pc.setInputCloud (a);
  check (pc.compute (after) && after.verdict != pcl_probcollision::Verdict::Free, name);
  std::printf ("downstream: %s in place: P %g -> %g\n", name, before.probability, after.probability);
}

double
sheetsApart (const Eigen::Vector3d& offset)
{
  const double gap = 20.0 * std::ldexp (1.0, -13);
  pcl_probcollision::CloudModelParams params;
  params.noise = pcl_probcollision::SensorNoiseModel::isotropic (0.001);
  const auto a = pcl_probcollision::buildCloudModel (*sheet<pcl::PointXYZ> (1, 0.0, 0.001, offset), params);
  const auto b = pcl_probcollision::buildCloudModel (*sheet<pcl::PointXYZ> (2, gap, 0.001, offset), params);
  pcl_probcollision::CollisionRequest request;
  request.exhaustive = true;
  pcl_probcollision::CollisionResult r;
  check (pcl_probcollision::collide (*a, *b, Eigen::Isometry3d::Identity (), request, r), "collide");
  return r.probability;
}
} // namespace

int
main ()
{
  // The installed headers and library are one install's; a version that can be tested in #if.
  check (std::strcmp (pcl_probcollision::libraryVersion (), PCL_PROBCOLLISION_VERSION_STRING) == 0,
         "libraryVersion() is the headers' PCL_PROBCOLLISION_VERSION_STRING");
#if PCL_PROBCOLLISION_VERSION < 100
#error "PCL_PROBCOLLISION_VERSION is not 100000 MAJOR + 100 MINOR + PATCH"
#endif
  inPlaceCheck<pcl::PointXYZ> ("PointXYZ");
  inPlaceCheck<pcl::PointXYZI> ("PointXYZI");
  inPlaceCheck<pcl::PointXYZRGB> ("PointXYZRGB");
  inPlaceCheck<pcl::PointXYZRGBA> ("PointXYZRGBA");
  inPlaceCheck<pcl::PointNormal> ("PointNormal");
  inPlaceCheck<pcl::PointXYZRGBNormal> ("PointXYZRGBNormal");
  inPlaceCheck<pcl::PointXYZINormal> ("PointXYZINormal");

  const double origin = sheetsApart (Eigen::Vector3d::Zero ());
  const double far = sheetsApart (Eigen::Vector3d (768.0, -768.0, 768.0));
  std::printf ("downstream: P at the origin %g, 1.3 km away %g\n", origin, far);
  check (std::abs (origin - far) <= 0.01, "1 km: same P within 0.01");
  check (origin > 0.1 && origin < 0.99, "1 km scene reads contact");

  // The covariance estimation through its compiled instantiation.
  const auto grid = sheet<pcl::PointXYZ> (3, 0.0, 0.0, Eigen::Vector3d::Zero ());
  pcl_probcollision::CovarianceEstimation<pcl::PointXYZ> estimation;
  estimation.setInputCloud (grid);
  estimation.setSensorNoise (pcl_probcollision::SensorNoiseModel::isotropic (0.001));
  estimation.setSurfaceProjection (false);  // the measured model: the noise adds sigma^2 along z
  pcl::PointCloud<pcl_probcollision::Covariance> covariances;
  estimation.compute (covariances);
  check (covariances.size () == grid->size () && covariances[12].isFinite () && covariances[12].zz >= 0.9e-6f,
         "covariance estimation");
  if (failures == 0)
    std::printf ("downstream: all checks passed\n");
  return failures == 0 ? 0 : 1;
}
