// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer: arbitrary bytes -> io::loadTriangleMesh, the mesh reader of pcd_collision, the
// evaluation and Python's read_mesh. The first byte picks the format ('o' OBJ, 'p' PLY, 'v'
// legacy VTK; any other byte by its value modulo 3), the rest is the file. Any crash or sanitizer
// report aborts, and so does a broken contract: a refusal without a reason, or an accepted mesh
// without triangles or with an index outside its vertices. STL goes through VTK's reader and is
// not fuzzed here (docs/RELIABILITY.md).
#include "mesh_input.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#define FUZZ_REQUIRE(cond)                                                                          \
  do                                                                                                \
  {                                                                                                 \
    if (!(cond))                                                                                    \
    {                                                                                               \
      std::fprintf (stderr, "fuzz_mesh_file: contract broken: %s (line %d)\n", #cond, __LINE__); \
      std::abort ();                                                                                \
    }                                                                                               \
  } while (0)

extern "C" int
LLVMFuzzerTestOneInput (const std::uint8_t* data, std::size_t size)
{
  if (size == 0)
    return 0;
  static const char* const kByValue[] = {"obj", "ply", "vtk"};
  const char* ext = data[0] == 'o' ? "obj" : data[0] == 'p' ? "ply" : data[0] == 'v' ? "vtk" : kByValue[data[0] % 3];
  const std::string path = "/tmp/fuzz_mesh_file_" + std::to_string (::getpid ()) + "." + ext;
  {
    std::ofstream f (path, std::ios::binary | std::ios::trunc);
    f.write (reinterpret_cast<const char*> (data + 1), static_cast<std::streamsize> (size - 1));
  }
  pcl_probcollision::io::TriangleMesh mesh;
  std::string error;
  const bool ok = pcl_probcollision::io::loadTriangleMesh (path, mesh, error);
  std::remove (path.c_str ());
  if (!ok)
  {
    FUZZ_REQUIRE (!error.empty ());
    return 0;
  }
  FUZZ_REQUIRE (!mesh.triangles.empty ());
  for (const auto& t : mesh.triangles)
    for (const int i : t)
      FUZZ_REQUIRE (i >= 0 && static_cast<std::size_t> (i) < mesh.vertices.size ());
  return 0;
}
