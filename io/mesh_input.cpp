// SPDX-License-Identifier: BSD-3-Clause
#include "mesh_input.h"

#include <pcl/PolygonMesh.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

#include <vtkObject.h>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace pcd_collision
{
void
setVtkMessages (bool enabled)
{
  vtkObject::SetGlobalWarningDisplay (enabled ? 1 : 0);
}

bool
loadTriangleMesh (const std::string& path, TriangleMesh& mesh, std::string& error)
{
  mesh = TriangleMesh ();
  std::string ext = path.substr (path.find_last_of ('.') == std::string::npos ? path.size ()
                                                                               : path.find_last_of ('.') + 1);
  std::transform (ext.begin (), ext.end (), ext.begin (),
                  [] (unsigned char c) { return static_cast<char> (std::tolower (c)); });

  pcl::PolygonMesh polygon_mesh;
  int vertices_read = 0;
  if (ext == "obj")
    vertices_read = pcl::io::loadPolygonFileOBJ (path, polygon_mesh);
  else if (ext == "ply")
    vertices_read = pcl::io::loadPolygonFilePLY (path, polygon_mesh);
  else if (ext == "stl")
    vertices_read = pcl::io::loadPolygonFileSTL (path, polygon_mesh);
  else if (ext == "vtk")
    vertices_read = pcl::io::loadPolygonFileVTK (path, polygon_mesh);
  else
  {
    error = "'" + path + "': unsupported mesh type (expected .ply, .obj, .stl or .vtk)";
    return false;
  }
  const std::size_t n = static_cast<std::size_t> (polygon_mesh.cloud.width) * polygon_mesh.cloud.height;
  if (vertices_read <= 0 || n == 0)
  {
    error = "'" + path + "' is not a readable " + ext + " mesh (no vertex read)";
    return false;
  }
  bool has_xyz = true;
  for (const char* name : {"x", "y", "z"})
    has_xyz = has_xyz && pcl::getFieldIndex (polygon_mesh.cloud, name) >= 0;
  if (!has_xyz)
  {
    error = "'" + path + "': mesh vertices have no x y z";
    return false;
  }
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2 (polygon_mesh.cloud, vertices);
  mesh.vertices.reserve (vertices.size ());
  for (const auto& p : vertices.points)
    mesh.vertices.push_back ({static_cast<double> (p.x), static_cast<double> (p.y), static_cast<double> (p.z)});

  auto finite = [&] (std::uint32_t i) {
    const auto& v = mesh.vertices[i];
    return std::isfinite (v[0]) && std::isfinite (v[1]) && std::isfinite (v[2]);
  };
  for (const pcl::Vertices& polygon : polygon_mesh.polygons)
  {
    const auto& idx = polygon.vertices;
    for (const std::uint32_t i : idx)
    {
      if (i >= mesh.vertices.size ())
      {
        error = "'" + path + "': a face refers to vertex " + std::to_string (i) + " of " +
                std::to_string (mesh.vertices.size ());
        return false;
      }
    }
    if (idx.size () < 3)
      continue;
    for (std::size_t j = 1; j + 1 < idx.size (); ++j)
    {
      if (!finite (idx[0]) || !finite (idx[j]) || !finite (idx[j + 1]))
        continue;
      mesh.triangles.push_back ({static_cast<int> (idx[0]), static_cast<int> (idx[j]), static_cast<int> (idx[j + 1])});
    }
  }
  if (mesh.triangles.empty ())
  {
    error = "'" + path + "' has no triangles (" + std::to_string (mesh.vertices.size ()) +
            " vertices; a mesh input needs faces)";
    return false;
  }
  return true;
}
} // namespace pcd_collision
