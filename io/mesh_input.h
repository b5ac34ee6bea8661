// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Triangle-mesh input, shared by pcd_collision, the benchmarks and the evaluation. PLY goes through
// PCL's own reader, OBJ and legacy VTK through readers of our own (VTK's crash on malformed files),
// STL through PCL's VTK bridge (pcl/io/vtk_lib_io.h), kept in mesh_input.cpp alone because its
// headers are heavy.

#include <array>
#include <string>
#include <vector>

namespace pcl_probcollision::io
{
struct TriangleMesh
{
  std::vector<std::array<double, 3>> vertices;
  /** \brief Vertex indices; polygons with more than three vertices are fan-triangulated. */
  std::vector<std::array<int, 3>> triangles;
};

/** \brief Loads a .ply, .obj, .stl or .vtk mesh (extension case-insensitive). False with a
  * reason in error (naming the file) when the file cannot be read, is malformed or truncated, has
  * no vertex, no triangle or no triangle with an area, or refers to a missing vertex. Vertex coordinates of any numeric type
  * are converted. Triangles with a non-finite vertex are dropped.
  *
  * The readers print nothing: the first call silences VTK's warnings and output window for the
  * whole process (unless setVtkMessages() chose first), and PCL's console during the read. */
bool loadTriangleMesh (const std::string& path, TriangleMesh& mesh, std::string& error);

/** \brief Shows (true) or silences (false, the default) the messages of VTK and of PCL's
  * readers (its VTK bridge, its PCD and PLY readers behind loadCloud), process-wide, for every
  * later load (pcd_collision -v shows them). */
void setVtkMessages (bool enabled);
} // namespace pcl_probcollision::io
