// SPDX-License-Identifier: BSD-3-Clause
// calibration_drift: how the pair probability of two parallel noisy patches moves with the number
// of points, for measured positions (the paper's maximum) and projected ones (the default).
// Patches of n x n points, spacing 1 cm, sigma 2 mm on every axis, gaps -1 to 6 sigma, mean of 8
// noise draws. Writes CSV (gap_sigma,points_per_side,measured,projected) to stdout.
#include <pcl_probcollision/probabilistic_collision.h>

#include <pcl_probcollision/normal_distribution.h>

#include <cstdio>
#include <random>

using namespace pcl_probcollision;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace
{
Cloud::Ptr
patch (int n, double spacing, double z, double sigma, std::mt19937_64& rng)
{
  auto normal = [&] () { return detail::standardNormal (rng); };  // portable: same numbers everywhere
  Cloud::Ptr c (new Cloud);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      c->push_back (pcl::PointXYZ (static_cast<float> (i * spacing + sigma * normal ()),
                                   static_cast<float> (j * spacing + sigma * normal ()),
                                   static_cast<float> (z + sigma * normal ())));
  return c;
}
} // namespace

int
main ()
{
  const double sigma = 0.002, spacing = 0.01;
  const int draws = 8;
  std::printf ("gap_sigma,points_per_side,measured,projected\n");
  for (const double gap : {-1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 6.0})
    for (const int n : {5, 10, 20, 40})
    {
      double sum[2] = {0.0, 0.0};
      for (int d = 0; d < draws; ++d)
        for (int projected = 0; projected < 2; ++projected)
        {
          std::mt19937_64 rng (static_cast<std::uint64_t> (d + 1));
          ProbabilisticCollision<pcl::PointXYZ> pc;
          pc.setInputCloud (patch (n, spacing, 0.0, sigma, rng));
          pc.setTargetCloud (patch (n, spacing, -gap * sigma, sigma, rng));
          pc.setInputNoise (SensorNoiseModel::isotropic (sigma));
          pc.setTargetNoise (SensorNoiseModel::isotropic (sigma));
          pc.setSurfaceProjection (projected == 1);
          CollisionRequest request;
          request.exhaustive = true;  // the maximum itself, not an early-stop lower bound
          pc.setRequest (request);
          CollisionResult r;
          if (!pc.compute (r))
          {
            std::fprintf (stderr, "calibration_drift: %s\n", r.message.c_str ());
            return 1;
          }
          sum[projected] += r.probability;
        }
      std::printf ("%g,%d,%.4f,%.4f\n", gap, n * n, sum[0] / draws, sum[1] / draws);
    }
  return 0;
}
