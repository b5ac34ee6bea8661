// SPDX-License-Identifier: BSD-3-Clause
// io/mesh_sampling's median spacing, against the number a built CloudModel reads from its own
// neighbour search (CloudModel::medianNeighbourSpacing): pcd_collision samples a mesh at the
// latter when it has it, so the two must agree bit for bit.

#include "mesh_sampling.h"

#include <pcl_probcollision/cloud_model.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace
{
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

pcl_probcollision::CloudModelParams
noisyParams ()
{
  pcl_probcollision::CloudModelParams params;
  params.noise = pcl_probcollision::SensorNoiseModel::isotropic (0.001);
  return params;
}

/** \brief n points on a noisy wavy sheet, every 97th not finite, every 50th doubled. */
Cloud
sheet (std::size_t n, unsigned seed)
{
  std::mt19937 rng (seed);
  std::uniform_real_distribution<float> u (0.0f, 1.0f);
  std::normal_distribution<float> noise (0.0f, 0.001f);
  Cloud cloud;
  const float nan = std::numeric_limits<float>::quiet_NaN ();
  for (std::size_t i = 0; i < n; ++i)
  {
    const float x = u (rng), y = u (rng);
    cloud.push_back (i % 97 == 5 ? pcl::PointXYZ (nan, 0.0f, 0.0f)
                                 : pcl::PointXYZ (x, y, 0.05f * std::sin (6.0f * x) + noise (rng)));
    if (i % 50 == 7)
      cloud.push_back (cloud.back ());
  }
  return cloud;
}
} // namespace

TEST (MedianSpacing, ABuiltModelReadsTheSameSpacingFromItsNeighbourSearch)
{
  // Above and below io's 20,000 queries (strided and not), a regular grid (ties everywhere) and
  // a cloud with duplicates and non-finite points.
  Cloud grid;
  for (int i = 0; i < 120; ++i)
    for (int j = 0; j < 110; ++j)
      grid.push_back (pcl::PointXYZ (0.01f * i, 0.01f * j, 0.0f));
  for (const Cloud& cloud : {sheet (30011, 1), sheet (5000, 2), grid})
  {
    const double io = pcl_probcollision::io::medianSpacing (cloud);
    ASSERT_GT (io, 0.0);
    for (const int threads : {1, 2})
    {
      pcl_probcollision::CloudModelParams params = noisyParams ();
      params.threads = threads;
      EXPECT_EQ (pcl_probcollision::buildCloudModel (cloud, params)->medianNeighbourSpacing (), io)
          << cloud.size () << " points, " << threads << " threads";
    }
    pcl_probcollision::CloudModelParams surface = noisyParams ();
    surface.surface = true;
    EXPECT_EQ (pcl_probcollision::buildCloudModel (cloud, surface)->medianNeighbourSpacing (), io);
  }
}

TEST (MedianSpacing, AModelThatCannotTellSaysSo)
{
  // A point with more coincident copies than the k + 1 = 11 neighbours the build searches:
  // io looks further (16), the model cannot, and says NaN.
  Cloud cloud = sheet (300, 3);
  for (int c = 0; c < 12; ++c)
    cloud.push_back (cloud[0]);
  const double io = pcl_probcollision::io::medianSpacing (cloud);
  EXPECT_GT (io, 0.0);
  EXPECT_TRUE (std::isnan (pcl_probcollision::buildCloudModel (cloud, noisyParams ())->medianNeighbourSpacing ()));

  // Not the whole cloud's search: indices, covariances given (no estimation), merged samples.
  const Cloud plain = sheet (400, 4);
  const pcl::Indices half = [] {
    pcl::Indices idx;
    for (int i = 0; i < 200; ++i)
      idx.push_back (i);
    return idx;
  }();
  EXPECT_TRUE (std::isnan (pcl_probcollision::buildCloudModel (plain, noisyParams (), &half)->medianNeighbourSpacing ()));
  const pcl::PointCloud<pcl_probcollision::Covariance> exact (plain.width, plain.height);
  EXPECT_TRUE (std::isnan (pcl_probcollision::buildCloudModel (plain, noisyParams (), nullptr, &exact)->medianNeighbourSpacing ()));
  pcl_probcollision::CloudModelParams merged = noisyParams ();
  merged.noise = pcl_probcollision::SensorNoiseModel::isotropic (0.05);  // far above the spacing: samples merge
  merged.noise_resolution = 2.0;
  merged.noise_resolution_gate = pcl_probcollision::CloudModelParams::ResolutionGate::Everywhere;
  const auto model = pcl_probcollision::buildCloudModel (plain, merged);
  ASSERT_GT (model->mergedSamples (), 0u);
  EXPECT_TRUE (std::isnan (model->medianNeighbourSpacing ()));
}

TEST (MedianSpacing, AMergedModelKeepsTheCloudsSpacingInItsFullResolutionRung)
{
  // The default whole-cloud gate merges a cloud sampled finer than its noise and keeps it
  // unmerged beside (built on a thread of its own with two): pcd_collision reads the spacing
  // there rather than search the cloud again. One thread builds the two in turn: the same.
  const Cloud cloud = sheet (5000, 2);
  const double io = pcl_probcollision::io::medianSpacing (cloud);
  ASSERT_GT (io, 0.0);
  for (const int threads : {1, 2})
  {
    pcl_probcollision::CloudModelParams params = noisyParams ();
    params.noise = pcl_probcollision::SensorNoiseModel::isotropic (0.05);  // far above the spacing: samples merge
    params.threads = threads;
    const auto model = pcl_probcollision::buildCloudModel (cloud, params);
    ASSERT_GT (model->mergedSamples (), 0u) << threads << " threads";
    ASSERT_NE (model->fullResolution (), nullptr) << threads << " threads";
    EXPECT_TRUE (std::isnan (model->medianNeighbourSpacing ()));
    EXPECT_EQ (model->fullResolution ()->medianNeighbourSpacing (), io) << threads << " threads";
    EXPECT_EQ (model->fullResolution ()->size () + model->fullResolution ()->skippedPoints () +
                   model->fullResolution ()->coincidentSamples (),
               cloud.size ());
  }
}

// Without vertices the sampler gives its area samples alone, the same ones: the evaluation's
// re-scans use it so that no sample sits at the same place in every re-scan.
TEST (MeshSampling, WithoutVerticesGivesTheSameAreaSamples)
{
  pcl_probcollision::io::TriangleMesh mesh;
  mesh.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {1.0, 1.0, 0.0}, {5.0, 5.0, 5.0}};  // the last unused
  mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  const auto with = pcl_probcollision::io::sampleMeshWithNormals (mesh, 0.05, 7);
  const auto without = pcl_probcollision::io::sampleMeshWithNormals (mesh, 0.05, 7, pcl_probcollision::io::kMaxMeshSamples, false);
  ASSERT_EQ (with.size (), without.size () + 4u);  // the four used vertices come first
  ASSERT_GT (without.size (), 300u);
  for (std::size_t i = 0; i < without.size (); ++i)
  {
    EXPECT_EQ (with[i + 4].getVector3fMap (), without[i].getVector3fMap ()) << i;
    EXPECT_EQ (with[i + 4].getNormalVector3fMap (), without[i].getNormalVector3fMap ()) << i;
  }
  const auto other = pcl_probcollision::io::sampleMeshWithNormals (mesh, 0.05, 8, pcl_probcollision::io::kMaxMeshSamples, false);
  std::size_t shared = 0;
  for (const auto& p : other)
    for (const auto& q : without)
      shared += p.getVector3fMap () == q.getVector3fMap () ? 1 : 0;
  EXPECT_EQ (shared, 0u);  // another seed: every position new
}

// A triangle of no area (a polygon that repeats a vertex, split into a fan) holds no surface and
// draws nothing: the same surface gives the same samples (the probe of 2026-12-03: such
// triangles shifted the draws, and a box 5 mm into a table read collision 0.99 instead of
// contact 0.89).
TEST (MeshSampling, TrianglesWithoutAreaDrawNothing)
{
  pcl_probcollision::io::TriangleMesh mesh;
  mesh.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {1.0, 1.0, 0.0}};
  mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  pcl_probcollision::io::TriangleMesh padded = mesh;
  padded.triangles = {{0, 1, 2}, {2, 0, 0}, {1, 3, 2}, {1, 1, 3}, {0, 3, 0}};
  const auto plain = pcl_probcollision::io::sampleMeshWithNormals (mesh, 0.05, 7);
  const auto with_degenerate = pcl_probcollision::io::sampleMeshWithNormals (padded, 0.05, 7);
  ASSERT_EQ (plain.size (), with_degenerate.size ());
  for (std::size_t i = 0; i < plain.size (); ++i)
    EXPECT_EQ (plain[i].getVector3fMap (), with_degenerate[i].getVector3fMap ()) << i;
}
