// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Point-cloud input: PCD and face-less PLY files into PointXYZ (or PointNormal, with the file's
// normals), with every check a file of unknown origin needs (PCL 1.13's PCD reader crashes on a
// header without FIELDS). Shared by pcd_collision and the Python bindings. pcl/io/pcd_io.h and
// ply_io.h stay in cloud_input.cpp.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace pcl_probcollision
{
namespace io
{
/** \brief What storing a file's x y z in PCL's float points cost: the largest change of a finite
  * stored x, y or z by the conversion, and the largest |coordinate| (both 0 when the file stores
  * them as float32, which converts exactly). A float keeps 24 bits: a float64 cloud 10 km from
  * its origin is kept to about 0.5 mm, one in UTM coordinates (thousands of km) to metres. */
struct XyzRounding
{
  double largest_change = 0.0;
  double largest_magnitude = 0.0;
};

/** \brief Why the command lines cannot read path ("cannot read 'PATH': No such file or
  * directory", "is a directory", "not a regular file" or the system's reason), or empty when it
  * is a regular file they can open. PCL's readers are given regular files only: on a directory
  * PCDReader::readHeader never returns, and opening a FIFO blocks. */
std::string unreadableFile (const std::string& path);

/** \brief Loads any PCD with x y z fields into PointXYZ, keeping width/height (organization),
  * NaN points and the VIEWPOINT (sensor_origin_, sensor_orientation_); a .ply (extension
  * case-insensitive) goes through PCL's PLY reader, its camera element giving the viewpoint. x y z
  * of any numeric type are converted. False with a reason naming the file when the file is
  * unreadable, malformed or truncated, has no x y z, or has no points. rounding, when given,
  * gets what the conversion to float cost. */
bool loadCloud (const std::string& path, pcl::PointCloud<pcl::PointXYZ>& cloud, std::string& error,
                XyzRounding* rounding = nullptr);

/** \brief loadCloud (the same reader, checks and messages) with the file's normals: when the file
  * has all of normal_x normal_y normal_z (any numeric type, converted; a PLY's nx ny nz as PCL's
  * PLY reader names them), has_normals is true and each point gets its stored normal as it is (not
  * normalized); a NaN or zero one becomes NaN, a point without a normal, which the surface
  * model orients from its neighbours (buildCloudModel<PointNormal>); one with an infinite
  * component is refused, naming the file and the point. Without normal fields
  * has_normals is false and every normal is NaN. False with a reason naming the file and the
  * missing field when only some of the three are there (e.g. normal_x alone). Curvature is 0. */
bool loadCloudWithNormals (const std::string& path, pcl::PointCloud<pcl::PointNormal>& cloud, bool& has_normals,
                           std::string& error, XyzRounding* rounding = nullptr);

/** \brief One value of a PCLPointCloud2 field as double, whatever its numeric type (NaN for an
  * unknown type): the one reader of stored x y z (and normals) for clouds and meshes. */
double readField (const std::uint8_t* p, std::uint8_t datatype);

/** \brief A PLY header PCL's reader can take without failing an assertion: well-formed lines
  * (format, element, property with PLY types, comment, obj_info, end_header), no property twice
  * in an element, no list property in the vertex element, vertex colours as uchar red, green,
  * blue (and alpha) in that order, no element count beyond the file's bytes. False with the
  * file, the header line and the reason. PCL's reader aborted on each of these (found by
  * fuzzing); the cloud and the mesh readers check it first. counts, when given, gets the
  * vertex and face element counts (isFacelessPly) and the layout checkPlyValues walks. */
struct PlyCounts
{
  long long vertices = 0;  ///< entries of the element "vertex"
  long long faces = 0;     ///< entries of the element "face"
  /** \brief One property of an element: its PLY type, and for a list its count's type. */
  struct Property
  {
    std::string name;
    std::string type;
    std::string count_type;  ///< empty for a scalar property
  };
  struct Element
  {
    std::string name;
    long long count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;  ///< in the header's order, which is the data's
  bool ascii = false;             ///< format ascii 1.0
  std::size_t header_lines = 0;   ///< lines up to and including end_header
};
bool checkPlyHeader (const std::string& path, std::string& error, PlyCounts* counts = nullptr);

/** \brief For an ascii PLY whose header checkPlyHeader accepted into layout (a binary one passes
  * unread): every entry's line holds its element's values (a list's count and that many more),
  * each a number of its property's type (an integer type's an integer within its range; nan and
  * inf are numbers), else false with the file, the line and the value. PCL's reader takes a value
  * it cannot parse for NaN, so a point with `abc` was skipped as non-finite, and for an integer
  * property for 0 (a face's vertex index), and said nothing; a line short of a value failed as
  * "corrupt" without its line. Every entry is checked, its line counted from the file's start. */
bool checkPlyValues (const std::string& path, const PlyCounts& layout, std::string& error);

/** \brief True for a .ply file whose header declares vertices and no face: a point cloud, which
  * loadCloud reads. A PLY with faces is a mesh; an unreadable one is left to the mesh loader,
  * which reports it. Reads the header only. */
bool isFacelessPly (const std::string& path);

/** \brief isFacelessPly for a caller that must know the kind before loading: true with faceless
  * set when the file is not a .ply (faceless false: its extension says its kind) or its header
  * was read, false with the loaders' reason naming the file (unreadableFile, checkPlyHeader) when
  * a .ply cannot be read or its header is malformed, whose kind nothing tells. pcd_collision
  * asks it before judging options by the inputs' kinds: a missing or malformed .ply was called
  * "a mesh" by its extension. */
bool plyKind (const std::string& path, bool& faceless, std::string& error);
} // namespace io
} // namespace pcl_probcollision
