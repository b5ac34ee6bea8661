// SPDX-License-Identifier: BSD-3-Clause
// A consumer of the installed package: estimates covariances of a small grid through the
// compiled instantiation and checks the result, so a broken export fails here.
#include <pcl_probcollision/covariance_estimation.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdio>

int
main ()
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud (new pcl::PointCloud<pcl::PointXYZ>);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i)
      cloud->push_back (pcl::PointXYZ (0.01f * i, 0.01f * j, 0.0f));
  pcl_probcollision::CovarianceEstimation<pcl::PointXYZ> estimation;
  estimation.setInputCloud (cloud);
  estimation.setSensorNoise (pcl_probcollision::SensorNoiseModel::isotropic (0.001));
  pcl::PointCloud<pcl_probcollision::Covariance> covariances;
  estimation.compute (covariances);
  if (covariances.size () != cloud->size () || !covariances[12].isFinite () || covariances[12].zz < 0.9e-6f)
  {
    std::fprintf (stderr, "downstream: unexpected covariance output\n");
    return 1;
  }
  std::printf ("downstream: %zu covariances, centre zz = %g\n", covariances.size (), covariances[12].zz);
  return 0;
}
