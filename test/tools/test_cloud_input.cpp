// SPDX-License-Identifier: BSD-3-Clause
// Point-cloud input of io/ on its own: loadCloudWithNormals (a cloud file's stored normals) next
// to loadCloud, the reader pcd_collision and the Python bindings share.

#include "cloud_input.h"
#include "test_files.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>

namespace fs = std::filesystem;
using pcl_probcollision::io::loadCloud;
using pcl_probcollision::io::loadCloudWithNormals;
using test_files::writeFile;

namespace
{
class CloudInput : public ::testing::Test
{
protected:
  void SetUp () override { dir_ = test_files::freshTestDir ("cloud_input_"); }
  std::string path (const char* name) const { return (dir_ / name).string (); }
  fs::path dir_;
};

const std::string kHeaderTail = "WIDTH 4\nHEIGHT 1\nVIEWPOINT 0.5 0 1 1 0 0 0\nPOINTS 4\nDATA ascii\n";
} // namespace

// x y z as doubles, normals as floats with an unrelated field between them; a zero and a NaN
// normal come back NaN (no direction), the others as stored (not normalized).
TEST_F (CloudInput, PcdNormalsAreLoadedWithTheirValues)
{
  writeFile (dir_ / "n.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity normal_x normal_y normal_z\n"
                             "SIZE 8 8 8 4 4 4 4\nTYPE F F F F F F F\nCOUNT 1 1 1 1 1 1 1\n" + kHeaderTail +
                             "0.1 0.2 0.3 7 0 0 2\n"
                             "0.4 0.5 0.6 7 0.6 -0.8 0\n"
                             "0.7 0.8 0.9 7 0 0 0\n"
                             "1 1.1 1.2 7 nan 0 1\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  std::string error;
  ASSERT_TRUE (loadCloudWithNormals (path ("n.pcd"), cloud, has_normals, error)) << error;
  EXPECT_TRUE (has_normals);
  ASSERT_EQ (cloud.size (), 4u);
  EXPECT_EQ (cloud.width, 4u);
  EXPECT_EQ (cloud.height, 1u);
  EXPECT_FLOAT_EQ (cloud[1].x, 0.4f);
  EXPECT_FLOAT_EQ (cloud[1].y, 0.5f);
  EXPECT_FLOAT_EQ (cloud[1].z, 0.6f);
  EXPECT_FLOAT_EQ (cloud[0].normal_x, 0.0f);
  EXPECT_FLOAT_EQ (cloud[0].normal_y, 0.0f);
  EXPECT_FLOAT_EQ (cloud[0].normal_z, 2.0f);
  EXPECT_FLOAT_EQ (cloud[1].normal_x, 0.6f);
  EXPECT_FLOAT_EQ (cloud[1].normal_y, -0.8f);
  EXPECT_FLOAT_EQ (cloud[1].normal_z, 0.0f);
  for (int i : {2, 3})
  {
    EXPECT_TRUE (std::isnan (cloud[i].normal_x)) << i;
    EXPECT_TRUE (std::isnan (cloud[i].normal_y)) << i;
    EXPECT_TRUE (std::isnan (cloud[i].normal_z)) << i;
    EXPECT_TRUE (std::isfinite (cloud[i].x)) << i;  // the point itself stays
  }
  EXPECT_FLOAT_EQ (cloud.sensor_origin_.x (), 0.5f);
  EXPECT_FLOAT_EQ (cloud.sensor_origin_.z (), 1.0f);
  EXPECT_TRUE (cloud.is_dense);

  // The same file through loadCloud: the same points.
  pcl::PointCloud<pcl::PointXYZ> xyz;
  ASSERT_TRUE (loadCloud (path ("n.pcd"), xyz, error)) << error;
  ASSERT_EQ (xyz.size (), 4u);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_EQ (xyz[i].getVector3fMap (), cloud[i].getVector3fMap ()) << i;
}

// An infinite normal component is a broken normal, not a missing one: refused naming the file
// and the point (it became NaN, "no normal", without a word), in ascii and binary files alike.
TEST_F (CloudInput, AnInfiniteNormalIsRefusedNamingThePoint)
{
  const std::string header = "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
                             "TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\n";
  writeFile (dir_ / "a.pcd", header + kHeaderTail + "0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 -inf 1\n3 0 0 0 0 1\n");
  std::string data;
  for (int i = 0; i < 4; ++i)
  {
    const float p[6] = {1.0f * i, 0.0f, 0.0f, i == 1 ? std::numeric_limits<float>::infinity () : 0.0f, 0.0f, 1.0f};
    data.append (reinterpret_cast<const char*> (p), sizeof (p));
  }
  writeFile (dir_ / "b.pcd", header + "WIDTH 4\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA binary\n" + data);
  for (const auto& [name, point] : {std::pair<const char*, int> {"a.pcd", 2}, {"b.pcd", 1}})
  {
    pcl::PointCloud<pcl::PointNormal> cloud;
    bool has_normals = false;
    std::string error;
    EXPECT_FALSE (loadCloudWithNormals (path (name), cloud, has_normals, error)) << name;
    EXPECT_NE (error.find (path (name) + "': point " + std::to_string (point) + " has a normal with an infinite component"),
               std::string::npos)
        << error;
    // Without normals (no -surface) the file's normals are not read, and it loads.
    pcl::PointCloud<pcl::PointXYZ> xyz;
    EXPECT_TRUE (loadCloud (path (name), xyz, error)) << error;
  }
}

// Integer normal fields are converted like x y z of any type; a binary file reads the same.
TEST_F (CloudInput, BinaryPcdWithIntegerNormals)
{
  std::string data;
  for (int i = 0; i < 4; ++i)
  {
    const float p[3] = {0.25f * i, 0.0f, 1.0f};
    const std::int8_t n[3] = {0, static_cast<std::int8_t> (i - 2), 1};
    data.append (reinterpret_cast<const char*> (p), sizeof (p));
    data.append (reinterpret_cast<const char*> (n), sizeof (n));
  }
  writeFile (dir_ / "b.pcd", "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 1 1 1\n"
                             "TYPE F F F I I I\nCOUNT 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\n"
                             "POINTS 4\nDATA binary\n" + data);
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  std::string error;
  ASSERT_TRUE (loadCloudWithNormals (path ("b.pcd"), cloud, has_normals, error)) << error;
  EXPECT_TRUE (has_normals);
  ASSERT_EQ (cloud.size (), 4u);
  EXPECT_EQ (cloud.width, 2u);
  EXPECT_EQ (cloud.height, 2u);
  for (int i = 0; i < 4; ++i)
  {
    EXPECT_FLOAT_EQ (cloud[i].x, 0.25f * i) << i;
    EXPECT_FLOAT_EQ (cloud[i].normal_y, static_cast<float> (i - 2)) << i;
    EXPECT_FLOAT_EQ (cloud[i].normal_z, 1.0f) << i;
  }
}

// A file without normal fields: loaded, has_normals false, every normal NaN.
TEST_F (CloudInput, PcdWithoutNormalsGivesNanNormals)
{
  writeFile (dir_ / "p.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n" + kHeaderTail +
                             "0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = true;
  std::string error;
  ASSERT_TRUE (loadCloudWithNormals (path ("p.pcd"), cloud, has_normals, error)) << error;
  EXPECT_FALSE (has_normals);
  ASSERT_EQ (cloud.size (), 4u);
  for (const auto& p : cloud.points)
    EXPECT_TRUE (std::isnan (p.normal_x) && std::isnan (p.normal_y) && std::isnan (p.normal_z));
  EXPECT_FLOAT_EQ (cloud[3].z, 1.0f);
}

// Only some of the normal fields: an error naming the file and the missing field. loadCloud,
// which reads no normals, still takes the file.
TEST_F (CloudInput, PartialNormalFieldsAreRejected)
{
  writeFile (dir_ / "nx.pcd", "VERSION 0.7\nFIELDS x y z normal_x\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n" +
                                  kHeaderTail + "0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n");
  writeFile (dir_ / "nxz.pcd", "VERSION 0.7\nFIELDS x y z normal_x normal_z\nSIZE 4 4 4 4 4\nTYPE F F F F F\n"
                                   "COUNT 1 1 1 1 1\n" + kHeaderTail + "0 0 0 1 0\n1 0 0 1 0\n0 1 0 1 0\n0 0 1 1 0\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = true;
  std::string error;
  EXPECT_FALSE (loadCloudWithNormals (path ("nx.pcd"), cloud, has_normals, error));
  EXPECT_FALSE (has_normals);
  EXPECT_NE (error.find ("nx.pcd"), std::string::npos) << error;
  EXPECT_NE (error.find ("'normal_y'"), std::string::npos) << error;
  EXPECT_TRUE (cloud.empty ());
  error.clear ();
  EXPECT_FALSE (loadCloudWithNormals (path ("nxz.pcd"), cloud, has_normals, error));
  EXPECT_NE (error.find ("nxz.pcd"), std::string::npos) << error;
  EXPECT_NE (error.find ("'normal_y'"), std::string::npos) << error;
  EXPECT_EQ (error.find ("'normal_z'"), std::string::npos) << error;  // present: not the one named missing

  pcl::PointCloud<pcl::PointXYZ> xyz;
  error.clear ();
  EXPECT_TRUE (loadCloud (path ("nx.pcd"), xyz, error)) << error;
  EXPECT_EQ (xyz.size (), 4u);
}

// The reader's other checks hold with normals too: a file without x y z is refused by name.
TEST_F (CloudInput, NormalsWithoutXyzAreRejected)
{
  writeFile (dir_ / "noxyz.pcd", "VERSION 0.7\nFIELDS normal_x normal_y normal_z\nSIZE 4 4 4\nTYPE F F F\n"
                                     "COUNT 1 1 1\n" + kHeaderTail + "0 0 1\n0 0 1\n0 0 1\n0 0 1\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  std::string error;
  EXPECT_FALSE (loadCloudWithNormals (path ("noxyz.pcd"), cloud, has_normals, error));
  EXPECT_NE (error.find ("noxyz.pcd"), std::string::npos) << error;
  EXPECT_NE (error.find ("'x'"), std::string::npos) << error;
}

// Only regular files reach PCL's readers: on a directory PCDReader::readHeader never returned
// (found in review through Python's read_cloud); a missing file names itself too.
TEST_F (CloudInput, DirectoriesAndMissingFilesAreRejectedBeforeReading)
{
  fs::create_directories (dir_ / "cloud.pcd");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::PointCloud<pcl::PointNormal> with_normals;
  bool has_normals = false;
  std::string error;
  EXPECT_FALSE (loadCloud (path ("cloud.pcd"), cloud, error));
  EXPECT_NE (error.find ("is a directory"), std::string::npos) << error;
  error.clear ();
  EXPECT_FALSE (loadCloudWithNormals (path ("cloud.pcd"), with_normals, has_normals, error));
  EXPECT_NE (error.find ("is a directory"), std::string::npos) << error;
  error.clear ();
  EXPECT_FALSE (loadCloud (path ("missing.pcd"), cloud, error));
  EXPECT_NE (error.find ("missing.pcd"), std::string::npos) << error;
  EXPECT_NE (error.find ("No such file"), std::string::npos) << error;
}

// A face-less PLY: nx ny nz (the usual PLY names, which PCL's reader maps to normal_x ...) and
// normal_x normal_y normal_z both give the normals; ascii and binary.
TEST_F (CloudInput, PlyNormals)
{
  const std::string rows = "0 0 0 0 0 1\n0.1 0 0 0 1 0\n0 0.1 0 0 0 0\n";
  writeFile (dir_ / "nxyz.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                                "end_header\n" + rows);
  writeFile (dir_ / "long.PLY", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                                "property double z\nproperty double normal_x\nproperty double normal_y\n"
                                "property double normal_z\nend_header\n" + rows);
  std::string binary;
  for (const float v : {0.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.1f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.1f, 0.f, 0.f, 0.f, 0.f})
    binary.append (reinterpret_cast<const char*> (&v), sizeof (v));  // x86-64: little-endian
  writeFile (dir_ / "bin.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
                               "property float nz\nend_header\n" + binary);
  for (const char* name : {"nxyz.ply", "long.PLY", "bin.ply"})
  {
    SCOPED_TRACE (name);
    pcl::PointCloud<pcl::PointNormal> cloud;
    bool has_normals = false;
    std::string error;
    ASSERT_TRUE (loadCloudWithNormals (path (name), cloud, has_normals, error)) << error;
    EXPECT_TRUE (has_normals);
    ASSERT_EQ (cloud.size (), 3u);
    EXPECT_FLOAT_EQ (cloud[1].x, 0.1f);
    EXPECT_FLOAT_EQ (cloud[0].normal_z, 1.0f);
    EXPECT_FLOAT_EQ (cloud[1].normal_y, 1.0f);
    EXPECT_FLOAT_EQ (cloud[1].normal_z, 0.0f);
    EXPECT_TRUE (std::isnan (cloud[2].normal_x));  // a zero normal: none
  }
  // A PLY with nx alone: refused like a PCD.
  writeFile (dir_ / "partial.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                   "property float z\nproperty float nx\nend_header\n0 0 0 1\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  std::string error;
  EXPECT_FALSE (loadCloudWithNormals (path ("partial.ply"), cloud, has_normals, error));
  EXPECT_NE (error.find ("partial.ply"), std::string::npos) << error;
  EXPECT_NE (error.find ("'normal_y'"), std::string::npos) << error;
}

// What holding x y z in float costs: reported for a float64 file (the largest change and the
// largest |coordinate|, NaN points left out), nothing for a float32 one, by both loaders.
TEST_F (CloudInput, TheRoundingOfDoubleCoordinatesIsReported)
{
  // 10 km out a float keeps steps of 2^-10 (about 1 mm): 10000.0003 is kept as 10000.0
  // (a change of 0.0003), 10000.0007 as 10000.0009765625 (a change of 0.0002765625).
  writeFile (dir_ / "far.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n" +
                                   kHeaderTail +
                                   "10000.0003 0 1\n"
                                   "10000.0007 0 1\n"
                                   "-20000.5 0.25 1\n"
                                   "nan nan nan\n");
  writeFile (dir_ / "near.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n" +
                                    kHeaderTail + "10000.0003 0 1\n0 0 1\n1 0 1\n0 1 1\n");
  std::string error;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl_probcollision::io::XyzRounding rounding;
  ASSERT_TRUE (loadCloud (path ("far.pcd"), cloud, error, &rounding)) << error;
  EXPECT_NEAR (rounding.largest_change, 0.0003, 1e-9);
  EXPECT_EQ (rounding.largest_magnitude, 20000.5);
  EXPECT_EQ (cloud[0].x, 10000.0f);
  pcl::PointCloud<pcl::PointNormal> with_normals;
  bool has_normals = true;
  pcl_probcollision::io::XyzRounding same;
  ASSERT_TRUE (loadCloudWithNormals (path ("far.pcd"), with_normals, has_normals, error, &same)) << error;
  EXPECT_EQ (same.largest_change, rounding.largest_change);
  EXPECT_EQ (same.largest_magnitude, rounding.largest_magnitude);
  // Stored as float32: rounded when written, nothing to report (and a stale value is cleared).
  ASSERT_TRUE (loadCloud (path ("near.pcd"), cloud, error, &rounding)) << error;
  EXPECT_EQ (rounding.largest_change, 0.0);
  EXPECT_EQ (rounding.largest_magnitude, 0.0);
  ASSERT_TRUE (loadCloudWithNormals (path ("near.pcd"), with_normals, has_normals, error, &same)) << error;
  EXPECT_EQ (same.largest_change, 0.0);
}
