// SPDX-License-Identifier: BSD-3-Clause
#include "mesh_input.h"
#include "quiet_pcl_console.h"

#include <pcl/PolygonMesh.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

#include <vtkObject.h>
#include <vtkOutputWindow.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>

namespace pcl_probcollision::io
{
namespace
{
std::once_flag g_vtk_messages_set;
std::atomic<bool> g_vtk_messages{false};

void
applyVtkMessages (bool enabled)
{
  g_vtk_messages = enabled;
  // The warning/error macros check the global flag; the output window covers direct calls.
  vtkObject::SetGlobalWarningDisplay (enabled ? 1 : 0);
  vtkOutputWindow::GetInstance ()->SetDisplayMode (enabled ? vtkOutputWindow::DEFAULT : vtkOutputWindow::NEVER);
}

} // namespace

bool
readerMessagesShown ()
{
  return g_vtk_messages;
}

void
setVtkMessages (bool enabled)
{
  std::call_once (g_vtk_messages_set, [] {});  // an explicit choice: the loader keeps it
  applyVtkMessages (enabled);
}

bool
loadTriangleMesh (const std::string& path, TriangleMesh& mesh, std::string& error)
{
  // VTK is silent unless a caller asked otherwise first: the reason returned in `error` is the
  // one report of a bad file, in every program that loads meshes.
  std::call_once (g_vtk_messages_set, [] { applyVtkMessages (false); });
  const QuietPclConsole quiet;
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
  // The readers give 0-based indices (OBJ's 1-based ones converted) as unsigned: an index is
  // named as the file counts it, and one below zero as negative.
  const bool one_based = ext == "obj";
  for (std::size_t face = 0; face < polygon_mesh.polygons.size (); ++face)
  {
    const auto& idx = polygon_mesh.polygons[face].vertices;
    for (const std::uint32_t i : idx)
    {
      if (i >= mesh.vertices.size ())
      {
        const std::string where = "'" + path + "': face " + std::to_string (face + 1);
        const auto as_signed = static_cast<std::int32_t> (i);
        if (as_signed < 0)
          error = where + (one_based ? " has a vertex index below 1 (relative, negative OBJ indices are not read)"
                                     : " has a negative vertex index (" + std::to_string (as_signed) + ")");
        else
          error = where + " refers to vertex " + std::to_string (one_based ? std::uint64_t{i} + 1 : std::uint64_t{i}) +
                  (one_based ? " (counting from 1, as OBJ does)" : " (counting from 0)") + " but the file has " +
                  std::to_string (mesh.vertices.size ()) + " vertices";
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
} // namespace pcl_probcollision::io
