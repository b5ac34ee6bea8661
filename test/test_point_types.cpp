// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/point_types.h>

#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <unistd.h>

using pcl_probcollision::Covariance;

TEST (Covariance, MatrixRoundTripKeepsSymmetricEntries)
{
  Eigen::Matrix3d m;
  m << 4, 1, 2, 1, 5, 3, 2, 3, 6;
  const Covariance c (m);
  EXPECT_TRUE (c.matrix ().isApprox (m));
  EXPECT_TRUE (c.isFinite ());
  EXPECT_FALSE (Covariance::nan ().isFinite ());
}

TEST (Covariance, RegisteredFieldsAreTheSixUpperTriangleEntries)
{
  std::vector<pcl::PCLPointField> fields;
  pcl::getFields<Covariance> (fields);
  ASSERT_EQ (fields.size (), 6u);
  const char* names[] = {"cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"};
  for (std::size_t i = 0; i < 6; ++i)
  {
    EXPECT_EQ (fields[i].name, names[i]);
    EXPECT_EQ (fields[i].datatype, pcl::PCLPointField::FLOAT32);
  }
}

class CovariancePcd : public ::testing::TestWithParam<bool>
{};

TEST_P (CovariancePcd, SaveLoadRoundTripsIncludingNaN)
{
  pcl::PointCloud<Covariance> cloud;
  cloud.width = 3;
  cloud.height = 2;
  cloud.resize (6);
  for (std::size_t i = 0; i < cloud.size (); ++i)
  {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity () * (1e-6 * (i + 1));
    m (0, 1) = m (1, 0) = -2.5e-7 * i;
    m (1, 2) = m (2, 1) = 3.25e-8 * i;
    cloud[i] = Covariance (m);
  }
  cloud[4] = Covariance::nan ();
  cloud.is_dense = false;

  char path[] = "/tmp/pcl_probcollision_cov_XXXXXX";
  const int fd = mkstemp (path);
  ASSERT_GE (fd, 0);
  close (fd);
  const std::string file = std::string (path) + ".pcd";
  std::rename (path, file.c_str ());
  ASSERT_EQ (pcl::io::savePCDFile (file, cloud, /*binary=*/GetParam ()), 0);

  pcl::PointCloud<Covariance> loaded;
  ASSERT_EQ (pcl::io::loadPCDFile (file, loaded), 0);
  std::remove (file.c_str ());
  ASSERT_EQ (loaded.size (), cloud.size ());
  EXPECT_EQ (loaded.width, 3u);
  EXPECT_EQ (loaded.height, 2u);
  for (std::size_t i = 0; i < cloud.size (); ++i)
  {
    if (i == 4)
    {
      EXPECT_FALSE (loaded[i].isFinite ());
      continue;
    }
    // ASCII PCD prints 8 significant digits; binary is exact.
    const double tol = GetParam () ? 0.0 : 1e-7 * cloud[i].matrix ().norm ();
    EXPECT_TRUE ((loaded[i].matrix () - cloud[i].matrix ()).cwiseAbs ().maxCoeff () <= tol) << i;
  }
}

INSTANTIATE_TEST_SUITE_P (AsciiAndBinary, CovariancePcd, ::testing::Values (false, true));
