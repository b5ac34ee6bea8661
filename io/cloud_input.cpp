// SPDX-License-Identifier: BSD-3-Clause
#include "cloud_input.h"

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace pcl_probcollision
{
namespace io
{
namespace
{
/** \brief One field value as double, whatever its PCD type. */
double
readField (const std::uint8_t* p, std::uint8_t datatype)
{
  switch (datatype)
  {
    case pcl::PCLPointField::INT8: { std::int8_t v; std::memcpy (&v, p, 1); return v; }
    case pcl::PCLPointField::UINT8: { std::uint8_t v; std::memcpy (&v, p, 1); return v; }
    case pcl::PCLPointField::INT16: { std::int16_t v; std::memcpy (&v, p, 2); return v; }
    case pcl::PCLPointField::UINT16: { std::uint16_t v; std::memcpy (&v, p, 2); return v; }
    case pcl::PCLPointField::INT32: { std::int32_t v; std::memcpy (&v, p, 4); return v; }
    case pcl::PCLPointField::UINT32: { std::uint32_t v; std::memcpy (&v, p, 4); return v; }
    case pcl::PCLPointField::FLOAT32: { float v; std::memcpy (&v, p, 4); return v; }
    case pcl::PCLPointField::FLOAT64: { double v; std::memcpy (&v, p, 8); return v; }
    default: return std::numeric_limits<double>::quiet_NaN ();
  }
}

std::size_t
fieldSize (std::uint8_t datatype)
{
  switch (datatype)
  {
    case pcl::PCLPointField::INT8: case pcl::PCLPointField::UINT8: return 1;
    case pcl::PCLPointField::INT16: case pcl::PCLPointField::UINT16: return 2;
    case pcl::PCLPointField::INT32: case pcl::PCLPointField::UINT32: case pcl::PCLPointField::FLOAT32: return 4;
    case pcl::PCLPointField::FLOAT64: return 8;
    default: return 0;
  }
}
bool
isPly (const std::string& path)
{
  std::string ext = std::filesystem::path (path).extension ().string ();
  std::transform (ext.begin (), ext.end (), ext.begin (), [] (unsigned char c) { return static_cast<char> (std::tolower (c)); });
  return ext == ".ply";
}
} // namespace

bool
isFacelessPly (const std::string& path)
{
  if (!isPly (path))
    return false;
  std::ifstream in (path, std::ios::binary);
  std::string line;
  bool vertices = false;
  // A header has a few dozen lines; the bound stops at a binary file that only starts with "ply".
  for (int n = 0; n < 10000 && std::getline (in, line); ++n)
  {
    if (!line.empty () && line.back () == '\r')
      line.pop_back ();
    if (n == 0 && line != "ply")
      return false;
    if (line == "end_header")
      return vertices;
    std::istringstream words (line);
    std::string keyword, element;
    long long count = 0;
    if (words >> keyword >> element >> count && keyword == "element")
    {
      if (element == "face" && count > 0)
        return false;
      vertices = vertices || (element == "vertex" && count > 0);
    }
  }
  return false;  // no end_header: not a PLY header the tool understands
}

bool
loadCloud (const std::string& path, pcl::PointCloud<pcl::PointXYZ>& cloud, std::string& error)
{
  cloud.clear ();
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero ();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity ();
  const bool ply = isPly (path);
  const char* format = ply ? "PLY" : "PCD";
  if (ply)
  {
    pcl::PLYReader reader;
    int version = 0;
    if (reader.read (path, blob, origin, orientation, version) < 0)
    {
      error = "'" + path + "' is truncated or corrupt (PLY data could not be read)";
      return false;
    }
  }
  else
  {
    pcl::PCDReader reader;
    int version = 0, data_type = 0;
    unsigned int data_idx = 0;
    if (reader.readHeader (path, blob, origin, orientation, version, data_type, data_idx) < 0)
    {
      error = "'" + path + "' is not a PCD file (malformed or missing header)";
      return false;
    }
    if (blob.fields.empty ())
    {
      error = "'" + path + "' is not a PCD file (no FIELDS in its header)";
      return false;
    }
  }
  if (static_cast<std::size_t> (blob.width) * blob.height == 0)
  {
    error = "'" + path + "' has no points (empty cloud)";
    return false;
  }
  // x y z are checked on the PCD header, before the (possibly large) data are read.
  int idx[3];
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
  {
    idx[i] = pcl::getFieldIndex (blob, names[i]);
    if (idx[i] < 0)
    {
      error = "'" + path + "' has no '" + names[i] + "' field (a " + format + " input needs x y z)";
      return false;
    }
    if (fieldSize (blob.fields[idx[i]].datatype) == 0)
    {
      error = "'" + path + "': field '" + names[i] + "' has an unknown type";
      return false;
    }
  }
  if (!ply)
  {
    pcl::PCDReader reader;
    int version = 0;
    if (reader.read (path, blob, origin, orientation, version) < 0)
    {
      error = "'" + path + "' is truncated or corrupt (PCD data could not be read)";
      return false;
    }
  }
  const std::size_t n = static_cast<std::size_t> (blob.width) * blob.height;
  if (n == 0)
  {
    error = "'" + path + "' has no points";
    return false;
  }
  if (blob.data.size () < n * blob.point_step)
  {
    error = "'" + path + "' is truncated (fewer data bytes than its header announces)";
    return false;
  }
  bool all_float = true;
  for (int i = 0; i < 3; ++i)
    all_float = all_float && blob.fields[idx[i]].datatype == pcl::PCLPointField::FLOAT32;
  if (all_float)
    pcl::fromPCLPointCloud2 (blob, cloud);
  else
  {
    cloud.resize (n);
    for (std::size_t j = 0; j < n; ++j)
    {
      const std::uint8_t* row = blob.data.data () + j * blob.point_step;
      cloud[j].x = static_cast<float> (readField (row + blob.fields[idx[0]].offset, blob.fields[idx[0]].datatype));
      cloud[j].y = static_cast<float> (readField (row + blob.fields[idx[1]].offset, blob.fields[idx[1]].datatype));
      cloud[j].z = static_cast<float> (readField (row + blob.fields[idx[2]].offset, blob.fields[idx[2]].datatype));
    }
    cloud.width = blob.width;
    cloud.height = blob.height;
    cloud.is_dense = false;
  }
  cloud.header = pcl::PCLHeader ();
  cloud.sensor_origin_ = origin;
  cloud.sensor_orientation_ = orientation;
  bool dense = true;
  for (const auto& p : cloud.points)
    dense = dense && std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z);
  cloud.is_dense = dense;
  return true;
}
} // namespace io
} // namespace pcl_probcollision
