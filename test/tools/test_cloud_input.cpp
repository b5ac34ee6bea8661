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
#include <initializer_list>
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

/** \brief Lines 1-5 of a float x y z PCD header (WIDTH is line 6, HEIGHT 7, VIEWPOINT 8, POINTS 9,
  * DATA 10 with pcd ()). */
const std::string kXyzFields = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

std::string
pcd (const std::string& width, const std::string& points, const std::string& data_type, const std::string& fields = kXyzFields)
{
  return fields + "WIDTH " + width + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + points + "\nDATA " + data_type + "\n";
}

/** \brief loadCloud's error for path, empty when it loads. */
std::string
loadError (const std::string& path)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::string error;
  return loadCloud (path, cloud, error) ? std::string () : error;
}

/** \brief The bytes of the floats, as a binary PCD stores them (x86-64: little-endian). */
template <typename T>
std::string
bytesOf (std::initializer_list<T> values)
{
  std::string out;
  for (const T v : values)
    out.append (reinterpret_cast<const char*> (&v), sizeof (v));
  return out;
}

/** \brief raw as LZF literal runs (a control byte of length - 1, then up to 32 bytes), which PCL's
  * lzfDecompress reads, after the two uint32 sizes of a binary_compressed PCD. */
std::string
lzfLiterals (const std::string& raw, std::uint32_t compressed_size = 0, std::uint32_t uncompressed_size = 0)
{
  std::string runs;
  for (std::size_t i = 0; i < raw.size (); i += 32)
  {
    const std::string run = raw.substr (i, 32);
    runs += static_cast<char> (run.size () - 1) + run;
  }
  const std::uint32_t sizes[2] = {compressed_size ? compressed_size : static_cast<std::uint32_t> (runs.size ()),
                                  uncompressed_size ? uncompressed_size : static_cast<std::uint32_t> (raw.size ())};
  return std::string (reinterpret_cast<const char*> (sizes), sizeof (sizes)) + runs;
}
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

// Only an exactly zero normal is none: a short one is a direction (Eigen's isZero () read any
// normal under 1e-5 long as none, and -surface propagated such a cloud; a probe's finding).
TEST_F (CloudInput, AShortNormalIsKept)
{
  writeFile (dir_ / "short.pcd", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity normal_x normal_y normal_z\n"
                                 "SIZE 8 8 8 4 4 4 4\nTYPE F F F F F F F\nCOUNT 1 1 1 1 1 1 1\n" + kHeaderTail +
                                 "0.1 0.2 0.3 7 0 0 1e-20\n"
                                 "0.4 0.5 0.6 7 0 1e-6 0\n"
                                 "0.7 0.8 0.9 7 0 0 0\n"
                                 "1 1.1 1.2 7 0 0 -0\n");
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  std::string error;
  ASSERT_TRUE (loadCloudWithNormals (path ("short.pcd"), cloud, has_normals, error)) << error;
  ASSERT_EQ (cloud.size (), 4u);
  EXPECT_FLOAT_EQ (cloud[0].normal_z, 1e-20f);
  EXPECT_FLOAT_EQ (cloud[1].normal_y, 1e-6f);
  for (int i : {2, 3})
    EXPECT_TRUE (std::isnan (cloud[i].normal_x)) << i;
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

// A header's point count is checked against the bytes after it before PCL's reader sets aside
// memory for the points it claims: a 187-byte binary PCD claiming 1,000,000,000 points took 12 GB
// and 52 s before it was refused. Each encoding has its bound; what PCL wrote still loads.
TEST_F (CloudInput, PointsTheDataCannotHoldAreRefusedBeforeReading)
{
  const std::string three = bytesOf<float> ({0, 0, 0, 1, 0, 0, 2, 0, 0});
  writeFile (dir_ / "claim.pcd", "# .PCD v0.7\n" + pcd ("1000000000", "1000000000", "binary") + three);
  ASSERT_EQ (fs::file_size (dir_ / "claim.pcd"), 187u);
  EXPECT_EQ (loadError (path ("claim.pcd")), "'" + path ("claim.pcd") +
                                                 "' is truncated or corrupt: its header announces 1000000000 points "
                                                 "(12000000000 bytes) but 36 bytes follow it");
  writeFile (dir_ / "short.pcd", pcd ("4", "4", "binary") + three);
  EXPECT_EQ (loadError (path ("short.pcd")),
             "'" + path ("short.pcd") + "' is truncated or corrupt: its header announces 4 points (48 bytes) but 36 bytes follow it");
  // ascii: a value takes a character at least; a file a line or so short is named where it ends
  // (PCL's reader: "could not be read").
  writeFile (dir_ / "claim_ascii.pcd", pcd ("1000000", "1000000", "ascii") + "0 0 0\n1 0 0\n2 0 0\n");
  EXPECT_EQ (loadError (path ("claim_ascii.pcd")), "'" + path ("claim_ascii.pcd") +
                                                       "' is truncated or corrupt: its header announces 1000000 points of 3 "
                                                       "values (at least 3000000 bytes as ascii) but 18 bytes follow it");
  writeFile (dir_ / "lines_short.pcd", pcd ("5", "5", "ascii") + "0 0 0\n1 0 0\n\n2 0 0\n");
  EXPECT_EQ (loadError (path ("lines_short.pcd")),
             "'" + path ("lines_short.pcd") + "' is truncated: it ends at line 14, after 3 of the 5 points its header announces");
  // binary_compressed: the sizes after the header (x x x y y y z z z, packed as LZF literals).
  const std::string fields = bytesOf<float> ({0, 1, 2, 0, 0, 0, 0, 0, 0});
  writeFile (dir_ / "packed.pcd", pcd ("3", "3", "binary_compressed") + lzfLiterals (fields));
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::string error;
  ASSERT_TRUE (loadCloud (path ("packed.pcd"), cloud, error)) << error;
  ASSERT_EQ (cloud.size (), 3u);
  EXPECT_EQ (cloud[2].x, 2.0f);
  writeFile (dir_ / "unpacked_size.pcd", pcd ("3", "3", "binary_compressed") + lzfLiterals (fields, 0, 4000000000u));
  EXPECT_EQ (loadError (path ("unpacked_size.pcd")),
             "'" + path ("unpacked_size.pcd") +
                 "' is truncated or corrupt: its header announces 3 points (36 bytes) but its binary_compressed data unpack "
                 "to 4000000000 bytes");
  writeFile (dir_ / "packed_size.pcd", pcd ("3", "3", "binary_compressed") + lzfLiterals (fields, 1000));
  EXPECT_EQ (loadError (path ("packed_size.pcd")), "'" + path ("packed_size.pcd") +
                                                       "' is truncated or corrupt: its binary_compressed data announce 1000 "
                                                       "compressed bytes but 38 bytes follow");
  // LZF unpacks at most 264 bytes from 3: 357913941 points (4294967292 bytes) need more than 38.
  writeFile (dir_ / "packed_claim.pcd", pcd ("357913941", "357913941", "binary_compressed") +
                                            lzfLiterals (fields, 0, 4294967292u));
  EXPECT_NE (loadError (path ("packed_claim.pcd")).find ("' is truncated or corrupt: its header announces 357913941 points "
                                                         "(4294967292 bytes) but 38 bytes of binary_compressed data unpack to "
                                                         "at most 88 times as many (LZF)"),
             std::string::npos)
      << loadError (path ("packed_claim.pcd"));
}

// The header's numbers and DATA type as PCL's reader takes them: POINTS -5 ended in
// "vector::_M_default_append" (no file named), a negative COUNT in a bad_alloc, POINTS other than
// WIDTH x HEIGHT in "malformed or missing header", "binaryX" was read as binary and "foo" as
// ascii, a header without DATA as points at the origin; a short VIEWPOINT got the generic message
// and a quaternion of zeros was taken for no rotation.
TEST_F (CloudInput, PcdHeaderNumbersAndDataTypeAreChecked)
{
  const std::string data = "0 0 0\n1 0 0\n2 0 0\n";
  const struct
  {
    const char* name;
    std::string text;
    std::string message;  // after "'PATH'"
  } cases[] = {
      {"points.pcd", pcd ("3", "-5", "ascii") + data, " line 9: POINTS '-5' is not a whole number >= 0"},
      {"width.pcd", pcd ("3.0", "3", "ascii") + data, " line 6: WIDTH '3.0' is not a whole number from 0 to 4294967295"},
      {"wide.pcd", pcd ("4294967296", "3", "ascii") + data,
       " line 6: WIDTH '4294967296' is not a whole number from 0 to 4294967295"},
      {"count.pcd", pcd ("3", "3", "ascii", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 -3\n") + data,
       " line 5: COUNT value 3 '-3' is not a whole number >= 0"},
      {"product.pcd", pcd ("3", "5", "ascii") + data, " line 9: POINTS 5 is not WIDTH x HEIGHT, 3 x 1 = 3"},
      {"binary_x.pcd", pcd ("3", "3", "binaryX") + bytesOf<float> ({0, 0, 0, 1, 0, 0, 2, 0, 0}),
       " line 10: DATA 'binaryX' is not ascii, binary or binary_compressed"},
      {"foo.pcd", pcd ("3", "3", "foo") + data, " line 10: DATA 'foo' is not ascii, binary or binary_compressed"},
      {"no_data.pcd", kXyzFields + "WIDTH 4\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\n",
       " is not a PCD file (its header has no DATA line)"},
      {"viewpoint.pcd", kXyzFields + "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 1\nPOINTS 3\nDATA ascii\n" + data,
       " line 8: VIEWPOINT has 3 values, expected 7 (tx ty tz qw qx qy qz)"},
      {"no_rotation.pcd", kXyzFields + "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 1 0 -0 0.0 0e5\nPOINTS 3\nDATA ascii\n" + data,
       " line 8: VIEWPOINT quaternion qw qx qy qz is 0 0 0 0, which is no rotation (an unrotated sensor is 1 0 0 0)"},
  };
  for (const auto& c : cases)
  {
    writeFile (dir_ / c.name, c.text);
    EXPECT_EQ (loadError (path (c.name)), "'" + path (c.name) + "'" + c.message);
  }
  // A header as PCL writes it (and one with only POINTS, which PCL takes for WIDTH) loads.
  writeFile (dir_ / "fine.pcd", pcd ("3", "3", "ascii") + data);
  writeFile (dir_ / "old.pcd", kXyzFields + "POINTS 3\nDATA ascii\n" + data);
  writeFile (dir_ / "half_turn.pcd", kXyzFields + "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 0 1 0 0\nPOINTS 3\nDATA ascii\n" + data);
  EXPECT_EQ (loadError (path ("half_turn.pcd")), "");
  EXPECT_EQ (loadError (path ("fine.pcd")), "");
  EXPECT_EQ (loadError (path ("old.pcd")), "");
}

// strtod's hex forms are no numbers to PCL's reader, which reads them as 0: refused in the data
// and in the VIEWPOINT, as in a PLY.
TEST_F (CloudInput, HexValuesAreNotNumbers)
{
  for (const char* word : {"0x10", "0x1p-3", "0X.8"})
  {
    writeFile (dir_ / "hex.pcd", pcd ("3", "3", "ascii") + "0 0 0\n1 " + word + " 0\n2 0 0\n");
    EXPECT_EQ (loadError (path ("hex.pcd")), "'" + path ("hex.pcd") + "' line 12, value 2: '" + word + "' is not a number");
  }
  writeFile (dir_ / "hex_view.pcd", kXyzFields + "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0x10 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 0\n");
  EXPECT_EQ (loadError (path ("hex_view.pcd")), "'" + path ("hex_view.pcd") +
                                                    "' line 8: VIEWPOINT value 1 '0x10' is not a finite number (VIEWPOINT "
                                                    "tx ty tz qw qx qy qz)");
}

// An ascii value must be one its field keeps: PCL read "300" in a U 1 field as 44, "1.5" in an I
// field as 1, and 1e39 in a float32 one as Inf (the point dropped as non-finite), without a word.
// nan and inf stay numbers in a float field; padding values ("_") PCL skips are not checked.
TEST_F (CloudInput, AsciiValuesMustFitTheirFieldTypes)
{
  const std::string fields = "VERSION 0.7\nFIELDS x y z label _ id\nSIZE 4 4 8 1 1 2\nTYPE F F F U U I\nCOUNT 1 1 1 1 2 1\n";
  const struct
  {
    const char* line;
    std::string message;  // empty: it loads
  } cases[] = {
      {"0 0 0 255 0 0 -32768", ""},
      {"nan inf -inf 0 9999 -1.5 32767", ""},
      {"3.4e38 -3.4e38 1e-300 0 0 0 0", ""},
      {"0 0 0 300 0 0 0", "value 4: '300' is not an integer within the range of field 'label' (TYPE U SIZE 1: 0 to 255)"},
      {"0 0 0 -1 0 0 0", "value 4: '-1' is not an integer within the range of field 'label' (TYPE U SIZE 1: 0 to 255)"},
      {"0 0 0 1 0 0 1.5", "value 7: '1.5' is not an integer within the range of field 'id' (TYPE I SIZE 2: -32768 to 32767)"},
      {"0 0 0 1 0 0 nan", "value 7: 'nan' is not an integer within the range of field 'id' (TYPE I SIZE 2: -32768 to 32767)"},
      {"0 1e39 0 1 0 0 0", "value 2: '1e39' is beyond the float range of field 'y' (TYPE F SIZE 4)"},
      {"0 0 1e400 1 0 0 0", "value 3: '1e400' is beyond the double range of field 'z' (TYPE F SIZE 8)"},
  };
  for (const auto& c : cases)
  {
    SCOPED_TRACE (c.line);
    writeFile (dir_ / "typed.pcd", pcd ("2", "2", "ascii", fields) + "1 2 3 4 5 6 7\n" + c.line + "\n");
    EXPECT_EQ (loadError (path ("typed.pcd")), c.message.empty () ? "" : "'" + path ("typed.pcd") + "' line 12, " + c.message);
  }
}

// A finite stored coordinate that a float cannot hold (a float64 2e299) became Inf and the point
// was skipped as non-finite without a word: refused by both loaders, naming the point.
TEST_F (CloudInput, CoordinatesBeyondTheFloatRangeAreRefused)
{
  const std::string fields = "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n";
  writeFile (dir_ / "far.pcd", pcd ("2", "2", "binary", fields) + bytesOf<double> ({0, 0, 0, 1, 2e299, 3}));
  writeFile (dir_ / "far_ascii.pcd", pcd ("2", "2", "ascii", fields) + "0 0 0\n-3.5e38 0 0\n");
  for (const auto& [name, what] : {std::pair<const char*, const char*> {"far.pcd", "point 1's y = 2e+299"},
                                   {"far_ascii.pcd", "point 1's x = -3.5e+38"}})
  {
    const std::string expected = "'" + path (name) + "': " + what + " is beyond the float range of the points PCL holds";
    EXPECT_EQ (loadError (path (name)), expected);
    pcl::PointCloud<pcl::PointNormal> cloud;
    bool has_normals = true;
    std::string error;
    EXPECT_FALSE (loadCloudWithNormals (path (name), cloud, has_normals, error));
    EXPECT_EQ (error, expected);
    EXPECT_TRUE (cloud.empty ());
  }
  // FLT_MAX itself, and a stored Inf or NaN (a point without coordinates), load.
  writeFile (dir_ / "edge.pcd", pcd ("2", "2", "ascii", fields) + "3.4028234663852886e38 0 0\ninf nan 0\n");
  EXPECT_EQ (loadError (path ("edge.pcd")), "");
}
