// SPDX-License-Identifier: BSD-3-Clause
// The C++ side of bench_python.py (issue #18): builds the two models from PCL clouds and times
// collideBatch on the same poses, so that Python's figures have a C++ reference on the same cores.
// Usage: pcl_probcollision_bench_batch DIR THREADS REPEATS
//   DIR/a.f32, DIR/b.f32: N x 3 float32 points; DIR/poses.f64: M x 16 row-major T_a_b;
//   DIR/sigma.txt: the isotropic sigma of both clouds.
// Prints one JSON object: build times (median of 5, ms), the batch's best wall time over
// REPEATS (s), poses/s, and the sum of P (the same answers as Python's).
#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

using namespace pcl_probcollision;

namespace
{
template <typename T>
std::vector<T>
readAll (const std::string& path)
{
  std::ifstream f (path, std::ios::binary);
  std::vector<char> bytes ((std::istreambuf_iterator<char> (f)), std::istreambuf_iterator<char> ());
  std::vector<T> out (bytes.size () / sizeof (T));
  std::copy (bytes.begin (), bytes.begin () + static_cast<std::ptrdiff_t> (out.size () * sizeof (T)),
             reinterpret_cast<char*> (out.data ()));
  return out;
}

pcl::PointCloud<pcl::PointXYZ>
cloudOf (const std::vector<float>& xyz)
{
  pcl::PointCloud<pcl::PointXYZ> c;
  for (std::size_t i = 0; i + 2 < xyz.size (); i += 3)
    c.push_back (pcl::PointXYZ (xyz[i], xyz[i + 1], xyz[i + 2]));
  return c;
}

double
seconds (std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double> (std::chrono::steady_clock::now () - t0).count ();
}
} // namespace

int
main (int argc, char** argv)
{
  if (argc != 4)
  {
    std::fprintf (stderr, "usage: %s DIR THREADS REPEATS\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  const int threads = std::stoi (argv[2]);
  const int repeats = std::stoi (argv[3]);
  const auto a = cloudOf (readAll<float> (dir + "/a.f32"));
  const auto b = cloudOf (readAll<float> (dir + "/b.f32"));
  const auto raw = readAll<double> (dir + "/poses.f64");
  double sigma = 0.0;
  std::ifstream (dir + "/sigma.txt") >> sigma;
  CloudModelParams params;
  params.noise = SensorNoiseModel::isotropic (sigma);

  std::vector<double> build_ms;
  CloudModel::ConstPtr A, B;
  for (int i = 0; i < 5; ++i)
  {
    const auto t0 = std::chrono::steady_clock::now ();
    A = buildCloudModel (a, params);
    build_ms.push_back (seconds (t0) * 1e3);
    B = buildCloudModel (b, params);
  }
  std::sort (build_ms.begin (), build_ms.end ());

  std::vector<Eigen::Isometry3d> poses (raw.size () / 16);
  for (std::size_t k = 0; k < poses.size (); ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        poses[k].matrix () (i, j) = raw[k * 16 + static_cast<std::size_t> (i * 4 + j)];
  const CollisionRequest request;
  std::vector<CollisionResult> results;
  double best = 1e300;
  for (int r = 0; r < repeats; ++r)
  {
    const auto t0 = std::chrono::steady_clock::now ();
    collideBatch (*A, *B, poses, request, results, threads);
    best = std::min (best, seconds (t0));
  }
  double sum = 0.0;
  for (const auto& r : results)
    sum += r.probability;
  std::printf ("{\"points_a\":%zu,\"points_b\":%zu,\"build_a_ms\":%.3f,\"poses\":%zu,\"threads\":%d,"
               "\"batch_s\":%.6f,\"poses_per_s\":%.1f,\"sum_p\":%.17g}\n",
               A->size (), B->size (), build_ms[build_ms.size () / 2], poses.size (), threads, best,
               static_cast<double> (poses.size ()) / best, sum);
  return 0;
}
