// SPDX-License-Identifier: BSD-3-Clause
// The command lines' warnings about their inputs (io/input_warnings.h), rule by rule at their
// limits. pcd_collision's tests (test_cli_reliability.cpp) and the Dask command line's
// (python/tests/test_dask.py) check that both print them.
#include "input_warnings.h"

#include <pcl_probcollision/cloud_model.h>

#include <pcl/common/io.h>

#include <gtest/gtest.h>

#include <array>

#include <cmath>
#include <limits>

using namespace pcl_probcollision::io;

namespace
{
InputFacts
cloud (const std::string& path, double diagonal, std::size_t finite = 1000, double sigma = 0.005)
{
  InputFacts in;
  in.path = path;
  in.finite = finite;
  in.diagonal = diagonal;
  in.sensor = "isotropic";
  in.sigma = sigma;
  return in;
}

InputFacts
mesh (const std::string& path, double diagonal)
{
  InputFacts in = cloud (path, diagonal, 0);
  in.cloud = false;
  return in;
}

bool
said (const std::string& warning, const std::string& part)
{
  return warning.find (part) != std::string::npos;
}
} // namespace

TEST (InputWarnings, SizesDifferingByMoreThanTheRatioAreWarnedOfNamingBothFiles)
{
  const InputFacts big = cloud ("big.pcd", 1000.0), small = cloud ("small.pcd", 1000.0 / kScaleWarningRatio);
  EXPECT_EQ (scaleWarning (big, small), "") << "a ratio of exactly kScaleWarningRatio is allowed";
  const std::string w = scaleWarning (big, cloud ("small.pcd", 0.9));
  EXPECT_TRUE (said (w, "differ by 1111x")) << w;
  EXPECT_TRUE (said (w, "'big.pcd'") && said (w, "'small.pcd'")) << w;
  // A cloud of a few points has no telling size; a mesh always has (its vertices span it).
  EXPECT_EQ (scaleWarning (big, cloud ("probe.pcd", 0.001, kScaleWarningMinPoints - 1)), "");
  EXPECT_NE (scaleWarning (big, mesh ("gripper.obj", 0.001)), "");
  EXPECT_EQ (scaleWarning (big, cloud ("point.pcd", 0.0)), "") << "a single point has no size";
  EXPECT_EQ (scaleWarning (big, cloud ("nan.pcd", std::numeric_limits<double>::quiet_NaN ())), "");
}

TEST (InputWarnings, AnIsotropicSigmaFarBelowTheCloudsSizeIsWarnedOf)
{
  // The default 0.005 on a 1,000 mm cloud: 5e-6 of its size.
  const std::string w = noiseWarning (cloud ("mm.pcd", 1000.0));
  EXPECT_TRUE (said (w, "the noise sigma 0.005 of 'mm.pcd' is 5e-06 of its size")) << w;
  EXPECT_EQ (noiseWarning (cloud ("m.pcd", 1.0)), "");
  InputFacts kinect = cloud ("mm.pcd", 1000.0);
  kinect.sensor = "kinect";
  EXPECT_EQ (noiseWarning (kinect), "") << "a depth sensor's model is in metres by definition";
  EXPECT_EQ (noiseWarning (mesh ("part.obj", 1000.0)), "");
  EXPECT_EQ (noiseWarning (cloud ("few.pcd", 1000.0, kScaleWarningMinPoints - 1)), "");
}

TEST (InputWarnings, AnIsotropicSigmaBeyondTheCloudsSizeIsWarnedOf)
{
  // -sigma 5 (millimetres) on a 1 m cloud in metres: five times its size.
  const std::string w = noiseWarning (cloud ("m.pcd", 1.0, 1000, 5.0));
  EXPECT_TRUE (said (w, "the noise sigma 5 of 'm.pcd' is 5 times its size (bounding-box diagonal 1)")) << w;
  EXPECT_TRUE (said (w, "-sigma 0.005")) << w;
  EXPECT_EQ (noiseWarning (cloud ("m.pcd", 1.0, 1000, kLargeNoiseWarningRatio * 1.0)), "") << "at the ratio: allowed";
  EXPECT_EQ (noiseWarning (cloud ("mug.pcd", 0.1, 1000, 0.015)), "") << "stereo noise on a mug is legitimate";
  EXPECT_EQ (noiseWarning (cloud ("few.pcd", 1.0, kScaleWarningMinPoints - 1, 5.0)), "");
  EXPECT_EQ (noiseWarning (cloud ("point.pcd", 0.0, 1000, 5.0)), "") << "points all in one place have no size";
}

TEST (InputWarnings, RoundingToFloatIsJudgedAgainstTheSigmaOrTheSize)
{
  InputFacts far = cloud ("far.pcd", 0.75, 1000, 0.002);
  far.rounding.largest_magnitude = 10000.0;
  const double limit = pcl_probcollision::CloudModel::kPrecisionWarningRatio * far.sigma;
  far.rounding.largest_change = limit;
  EXPECT_EQ (roundingWarning (far), "") << "at the limit";
  far.rounding.largest_change = 2.0 * limit;
  const std::string w = roundingWarning (far);
  EXPECT_TRUE (said (w, "'far.pcd' stores x y z in double precision up to 10000 from its origin")) << w;
  EXPECT_TRUE (said (w, "0.2 of its sigma 0.002")) << w;
  // Under a depth sensor's model against the size: 4e-4 mm is 5.3e-4 of 0.75.
  far.sensor = "stereo";
  EXPECT_TRUE (said (roundingWarning (far), "of its size, bounding-box diagonal 0.75")) << roundingWarning (far);
  far.rounding.largest_change = 0.5 * kNoiseWarningRatio * far.diagonal;
  EXPECT_EQ (roundingWarning (far), "");
  EXPECT_EQ (roundingWarning (cloud ("float32.pcd", 0.75)), "") << "a float32 file converts exactly";
}

TEST (InputWarnings, TheModelsPrecisionWarningIsNotRepeatedAfterTheFilesRounding)
{
  InputFacts in = cloud ("far.pcd", 0.75, 1000, 0.002);
  EXPECT_EQ (modelWarning (in, ""), "");
  EXPECT_EQ (modelWarning (in, "float spacing of 0.0078"), "'far.pcd': float spacing of 0.0078");
  in.rounding.largest_change = 0.001;  // half the sigma: warned of by roundingWarning
  ASSERT_NE (roundingWarning (in), "");
  EXPECT_EQ (modelWarning (in, "float spacing of 0.0078"), "");
}

TEST (InputWarnings, AFreeAnswerBetweenTwoMeshesSamplesIsWarnedOf)
{
  const std::string w = betweenSamplesWarning (true, true, 3, "pose 4", 90.0);
  EXPECT_TRUE (said (w, "pose 4 reads free, but both inputs are meshes sampled 90 apart")) << w;
  EXPECT_EQ (betweenSamplesWarning (false, true, 3, "pose 4", 90.0), "") << "a cloud's samples are what it is";
  EXPECT_EQ (betweenSamplesWarning (true, false, 3, "pose 4", 90.0), "");
  EXPECT_EQ (betweenSamplesWarning (true, true, 0, "pose 4", 90.0), "") << "nothing came within reach";
}

TEST (InputWarnings, ACloudsFactsCountAndSpanItsFinitePointsOnly)
{
  const float nan = std::numeric_limits<float>::quiet_NaN ();
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (const auto& xyz : {std::array<float, 3>{0, 0, 0}, {3, 4, 0}, {nan, 1, 1}, {1e9f, nan, 0}})
  {
    pcl::PointNormal p;
    p.x = xyz[0], p.y = xyz[1], p.z = xyz[2];
    cloud.push_back (p);
  }
  XyzRounding rounding;
  rounding.largest_change = 0.25;
  const InputFacts facts =
      cloudFacts ("scan.pcd", cloud, rounding, pcl_probcollision::SensorNoiseModel::isotropic (0.002));
  EXPECT_EQ (facts.path, "scan.pcd");
  EXPECT_TRUE (facts.cloud);
  EXPECT_EQ (facts.finite, 2u);
  EXPECT_DOUBLE_EQ (facts.diagonal, 5.0) << "NaN points stretch nothing";
  EXPECT_EQ (facts.rounding.largest_change, 0.25);
  EXPECT_EQ (facts.sensor, "isotropic");
  EXPECT_DOUBLE_EQ (facts.sigma, 0.002);

  const InputFacts kinect = cloudFacts ("scan.pcd", cloud, rounding, pcl_probcollision::SensorNoiseModel::kinect ());
  EXPECT_EQ (kinect.sensor, "kinect");
  EXPECT_EQ (kinect.sigma, 0.0) << "a depth sensor's sigma varies; the rounding is judged against the size";
  pcl::PointCloud<pcl::PointXYZ> xyz;
  pcl::copyPointCloud (cloud, xyz);
  EXPECT_EQ (finiteCount (xyz), 2u);
  EXPECT_DOUBLE_EQ (finiteDiagonal (xyz), 5.0);
}

// An open mesh oriented by its faces still encloses an inside to the surface layer: warned of,
// naming the file and the option that makes it two-sided; a closed one is not.
TEST (InputWarnings, AnOpenMeshIsWarnedOfNamingTheWayOut)
{
  MeshEdges closed, open, flipped;
  closed.closed = open.closed = flipped.closed = 18;
  open.open = 4;
  flipped.flipped = 3;
  EXPECT_TRUE (openMeshWarning ("box.obj", closed, "-orientation_a").empty ());
  const std::string w = openMeshWarning ("bin.obj", open, "-orientation_b");
  EXPECT_NE (w.find ("mesh 'bin.obj' is not closed (an edge does not border"), std::string::npos) << w;
  EXPECT_NE (w.find ("give -orientation_b propagate"), std::string::npos) << w;
  // Closed but for a face wound against its neighbours: named as flipped, not as a container.
  const std::string f = openMeshWarning ("box.obj", flipped, "-orientation_a");
  EXPECT_NE (f.find ("mesh 'box.obj' is not closed: at 3 of its edges both triangles run the same way"), std::string::npos)
      << f;
  EXPECT_NE (f.find ("give -orientation_a propagate"), std::string::npos) << f;
  EXPECT_EQ (f.find ("container"), std::string::npos) << f;
}

TEST (InputWarnings, ACoarseMeshIsWarnedOfWhereAFreeAnswerCameWithinReach)
{
  EXPECT_TRUE (coarseMeshWarning (false, 10, "pose 2", "ground.obj", 0.3, 0.002).empty ());  // not free
  EXPECT_TRUE (coarseMeshWarning (true, 0, "pose 2", "ground.obj", 0.3, 0.002).empty ());   // nothing within reach
  EXPECT_TRUE (coarseMeshWarning (true, 10, "pose 2", "ground.obj", 0.004, 0.002).empty ());  // 2x: the ratio's edge
  EXPECT_TRUE (coarseMeshWarning (true, 10, "pose 2", "ground.obj", 0.3, std::nan ("")).empty ());  // not measured
  const std::string w = coarseMeshWarning (true, 10, "pose 2", "ground.obj", 0.3, 0.002);
  EXPECT_NE (w.find ("pose 2 reads free, but mesh 'ground.obj' is sampled 0.3 apart, 150 times the other input's median "
                     "spacing 0.002"),
             std::string::npos) << w;
}

TEST (InputWarnings, AnInsideOutMeshIsWarnedOfNamingTheWayOut)
{
  EXPECT_TRUE (insideOutMeshWarning ("box.obj", true, 1.0, "-orientation_a", "-closed_a").empty ());
  EXPECT_TRUE (insideOutMeshWarning ("bin.obj", false, -1.0, "-orientation_a", "-closed_a").empty ());
  const std::string w = insideOutMeshWarning ("cavity.obj", true, -2.5, "-orientation_b", "-closed_b");
  EXPECT_NE (w.find ("mesh 'cavity.obj' is closed but its faces wind inward (it encloses 2.5 cubic units negatively)"),
             std::string::npos) << w;
  EXPECT_NE (w.find ("give -orientation_b propagate -closed_b"), std::string::npos) << w;
}
