// SPDX-License-Identifier: BSD-3-Clause
#include "mesh_input.h"
#include "mesh_sampling.h"
#include "cloud_input.h"
#include "quiet_pcl_console.h"

#include <pcl/PolygonMesh.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_lib_io.h>

#include <vtkObject.h>
#include <vtkOutputWindow.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <exception>
#include <filesystem>
#include <iterator>
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


/** \brief An OBJ file's vertices ("v x y z [w]") and faces ("f" with "i", "i/j", "i//k" or
  * "i/j/k"; a negative index counts back from the last vertex read, as the format says), as
  * 0-based indices; every other statement (vt, vn, g, o, s, usemtl, comments) is skipped.
  * Written here because both readers at hand crash on malformed files: VTK's on a face "1/1/1"
  * without texture coordinates, PCL's on a vertex line with two numbers (found in review). On
  * the bundled gripper and FCL's piano and room it gives VTK's vertices (as float, as every
  * reader stores them) and faces, bit for bit. False with the file, line and reason. */
bool
readObj (const std::string& path, std::vector<std::array<double, 3>>& vertices, std::vector<std::vector<long long>>& faces,
         std::string& error)
{
  std::ifstream in (path, std::ios::binary);
  if (!in)
  {
    error = "'" + path + "' is not a readable obj mesh (cannot open it)";
    return false;
  }
  std::string line;
  std::size_t number = 0;
  auto fail = [&] (const std::string& why) {
    error = "'" + path + "' line " + std::to_string (number) + ": " + why;
    return false;
  };
  while (std::getline (in, line))
  {
    ++number;
    const char* p = line.c_str ();
    const char* end = p + line.size ();
    auto skipBlanks = [&] { while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p; };
    skipBlanks ();
    if (end - p < 2 || (p[1] != ' ' && p[1] != '\t') || (p[0] != 'v' && p[0] != 'f'))
      continue;  // not a vertex or a face (vt, vn, comments, groups, materials, blank lines)
    const char kind = p[0];
    p += 2;
    if (kind == 'v')
    {
      std::array<double, 3> v;
      for (int k = 0; k < 3; ++k)
      {
        skipBlanks ();
        if (p + 1 < end && *p == '+' && p[1] != '-')  // "+1.5": from_chars takes no plus sign
          ++p;
        float value = 0.0f;
        const auto [next, ec] = std::from_chars (p, end, value);
        if (ec != std::errc () || (next < end && *next != ' ' && *next != '\t' && *next != '\r'))
          return fail ("a vertex needs three numbers x y z");
        v[static_cast<std::size_t> (k)] = value;
        p = next;
      }
      vertices.push_back (v);
      continue;
    }
    std::vector<long long> face;
    for (skipBlanks (); p < end; skipBlanks ())
    {
      long long i = 0;
      const auto [next, ec] = std::from_chars (p, end, i);
      if (ec != std::errc () || i == 0)
        return fail ("a face's vertex index must be a non-zero integer");
      p = next;
      while (p < end && *p != ' ' && *p != '\t' && *p != '\r')  // "/j", "//k", "/j/k": not read
        ++p;
      face.push_back (i > 0 ? i - 1 : static_cast<long long> (vertices.size ()) + i);
    }
    faces.push_back (std::move (face));
  }
  if (vertices.empty ())
  {
    error = "'" + path + "' is not a readable obj mesh (no vertex)";
    return false;
  }
  return true;
}

/** \brief A legacy VTK file's POLYDATA points and polygons (ASCII or BINARY; the cell layout of
  * versions up to 4.2, "n size" then size integers, and of 5.x, OFFSETS and CONNECTIVITY), as
  * 0-based indices. Vertices, lines and triangle strips are read past and not kept (VTK's bridge
  * kept none either); reading stops at POINT_DATA, CELL_DATA or FIELD. Written here because
  * VTK's reader crashes on a truncated cell list (ASCII or binary; found in review). On the
  * gripper and FCL's room written by VTK's writer in both encodings and both layouts it gives
  * VTK's vertices and faces, bit for bit. False with the file and the reason. */
bool
readVtkLegacy (const std::string& path, std::vector<std::array<double, 3>>& vertices,
               std::vector<std::vector<long long>>& faces, std::string& error)
{
  std::ifstream in (path, std::ios::binary);
  const std::string text ((std::istreambuf_iterator<char> (in)), std::istreambuf_iterator<char> ());
  std::size_t at = 0;
  auto fail = [&] (const std::string& why) {
    error = "'" + path + "' is not a readable vtk mesh (" + why + ")";
    return false;
  };
  auto line = [&] {
    const std::size_t end = std::min (text.find ('\n', at), text.size ());
    std::string l = text.substr (at, end - at);
    at = std::min (end + 1, text.size ());
    if (!l.empty () && l.back () == '\r')
      l.pop_back ();
    return l;
  };
  auto isBlank = [] (char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  auto token = [&] {
    while (at < text.size () && isBlank (text[at]))
      ++at;
    const std::size_t start = at;
    while (at < text.size () && !isBlank (text[at]))
      ++at;
    return text.substr (start, at - start);
  };
  if (line ().rfind ("# vtk DataFile Version", 0) != 0)
    return fail ("no '# vtk DataFile Version' line");
  line ();  // the title
  std::string encoding = line ();
  while (!encoding.empty () && isBlank (encoding.back ()))
    encoding.pop_back ();
  if (encoding != "ASCII" && encoding != "BINARY")
    return fail ("expected ASCII or BINARY on line 3");
  const bool binary = encoding == "BINARY";
  if (token () != "DATASET" || token () != "POLYDATA")
    return fail ("only DATASET POLYDATA is read as a mesh");

  // One value of a data type: ASCII as text, BINARY big-endian.
  auto value = [&] (const std::string& type, double& v) {
    if (!binary)
    {
      const std::string t = token ();
      if (t.empty ())
        return false;
      const char* first = t.data ();
      const char* last = first + t.size ();
      std::from_chars_result r;
      if (type == "float")
      {
        float f = 0.0f;
        r = std::from_chars (first, last, f);
        v = f;
      }
      else if (type == "double")
        r = std::from_chars (first, last, v);
      else
      {
        long long i = 0;
        r = std::from_chars (first, last, i);
        v = static_cast<double> (i);
      }
      return r.ec == std::errc () && r.ptr == last;
    }
    std::size_t size = 0;
    if (type == "char" || type == "unsigned_char")
      size = 1;
    else if (type == "short" || type == "unsigned_short")
      size = 2;
    else if (type == "int" || type == "unsigned_int" || type == "float" || type == "vtktypeint32")
      size = 4;
    else if (type == "long" || type == "unsigned_long" || type == "double" || type == "vtktypeint64")
      size = 8;
    if (size == 0 || text.size () - at < size)
      return false;
    unsigned char b[8];
    for (std::size_t k = 0; k < size; ++k)  // big-endian in the file
      b[k] = static_cast<unsigned char> (text[at + size - 1 - k]);
    at += size;
    const bool is_unsigned = type.rfind ("unsigned", 0) == 0;
    if (type == "float")
    {
      float f;
      std::memcpy (&f, b, 4);
      v = f;
    }
    else if (type == "double")
      std::memcpy (&v, b, 8);
    else
    {
      std::uint64_t u = 0;
      std::memcpy (&u, b, size);
      if (!is_unsigned && size < 8 && (u >> (8 * size - 1)) != 0)
        u |= ~std::uint64_t{0} << (8 * size);  // sign extension
      v = is_unsigned ? static_cast<double> (u) : static_cast<double> (static_cast<std::int64_t> (u));
    }
    return true;
  };
  // An offset, index or point count read as any type: refused unless a whole number a long long
  // holds (a double of 1e227 in a 5.x OFFSETS section was undefined behaviour to convert).
  auto integer = [&] (const std::string& type, long long& i) {
    double v = 0.0;
    if (!value (type, v) || !(std::fabs (v) <= 9.0e15) || v != std::floor (v))
      return false;
    i = static_cast<long long> (v);
    return true;
  };
  auto count = [&] (const std::string& t, long long& n) {
    const auto r = std::from_chars (t.data (), t.data () + t.size (), n);
    return r.ec == std::errc () && r.ptr == t.data () + t.size () && n >= 0;
  };
  bool points_read = false;
  for (std::string key = token (); !key.empty (); key = token ())
  {
    if (key == "POINT_DATA" || key == "CELL_DATA" || key == "FIELD")
      break;  // attributes: not read
    if (key == "METADATA")
    {
      // Ends at an empty line.
      line ();
      while (at < text.size () && !line ().empty ())
        ;
      continue;
    }
    long long n = 0, size = 0;
    if (key == "POINTS")
    {
      const bool counted = count (token (), n);
      const std::string type = token ();
      // Each value takes a byte at least: a count beyond the file is refused before any allocation.
      if (!counted || n <= 0 || type.empty () || static_cast<std::size_t> (n) > (text.size () - at) / 3)
        return fail ("a bad POINTS header");
      if (binary)
        line ();  // the header's end: the values start on the next line
      vertices.resize (static_cast<std::size_t> (n));
      for (auto& v : vertices)
        for (double& c : v)
          if (!value (type, c))
            return fail ("POINTS: truncated or not numbers");
      points_read = true;
      continue;
    }
    if (key != "VERTICES" && key != "LINES" && key != "POLYGONS" && key != "TRIANGLE_STRIPS")
      return fail ("unknown section '" + key + "'");
    if (!count (token (), n) || !count (token (), size) || static_cast<std::size_t> (n) > text.size () - at ||
        static_cast<std::size_t> (size) > text.size () - at)
      return fail (key + ": a bad header");
    if (binary)
      line ();
    std::vector<std::vector<long long>> cells;
    const std::size_t mark = at;
    if (token () == "OFFSETS")  // 5.x: n offsets, then size indices
    {
      const std::string offset_type = token ();
      if (binary)
        line ();
      std::vector<long long> offsets (static_cast<std::size_t> (n));
      for (auto& o : offsets)
        if (!integer (offset_type, o))
          return fail (key + ": truncated offsets, or one not a whole number");
      if (token () != "CONNECTIVITY")
        return fail (key + ": no CONNECTIVITY after its offsets");
      const std::string index_type = token ();
      if (binary)
        line ();
      std::vector<long long> connectivity (static_cast<std::size_t> (size));
      for (auto& c : connectivity)
        if (!integer (index_type, c))
          return fail (key + ": truncated connectivity, or an index not a whole number");
      for (std::size_t c = 0; c + 1 < offsets.size (); ++c)
      {
        if (offsets[c] < 0 || offsets[c] > offsets[c + 1] || offsets[c + 1] > size)
          return fail (key + ": offsets out of order or beyond the connectivity");
        cells.emplace_back (connectivity.begin () + offsets[c], connectivity.begin () + offsets[c + 1]);
      }
    }
    else  // up to 4.2: n cells in size integers, each its point count then its indices
    {
      at = mark;
      long long used = 0;
      for (long long c = 0; c < n; ++c)
      {
        long long points = 0;
        if (!integer ("int", points) || points < 0 || used + 1 + points > size)
          return fail (key + ": a cell's point count beyond the declared size, or truncated");
        used += 1 + points;
        cells.emplace_back (static_cast<std::size_t> (points));
        for (long long& i : cells.back ())
          if (!integer ("int", i))
            return fail (key + ": truncated");
      }
      if (used != size)
        return fail (key + ": its cells do not fill the declared size");
    }
    if (key == "POLYGONS")
      faces.insert (faces.end (), std::make_move_iterator (cells.begin ()), std::make_move_iterator (cells.end ()));
  }
  if (!points_read || vertices.empty ())
    return fail ("no vertex");
  return true;
}

/** \brief A binary STL is as long as its header says: 80 bytes, a little-endian uint32 triangle
  * count n, 50 bytes a triangle. VTK's reader reads what is there and says nothing: a cut file
  * lost its last triangles, a count of 1,000 over 12 triangles was taken, and trailing bytes were
  * read as a vertex. A file that begins with "solid" and whose first bytes are text is ASCII STL,
  * which VTK's reader checks itself (a binary file may begin with "solid" too: its size decides). */
bool
checkStlSize (const std::string& path, std::string& error)
{
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size (path, ec);
  if (ec)
    return true;  // left to the reader, which names the failure
  std::ifstream in (path, std::ios::binary);
  unsigned char head[84] = {};
  in.read (reinterpret_cast<char*> (head), sizeof head);
  const std::size_t got = static_cast<std::size_t> (in.gcount ());
  const std::uint32_t n = static_cast<std::uint32_t> (head[80]) | static_cast<std::uint32_t> (head[81]) << 8 |
                          static_cast<std::uint32_t> (head[82]) << 16 | static_cast<std::uint32_t> (head[83]) << 24;
  const std::uintmax_t expected = 84 + std::uintmax_t{50} * n;
  if (got == sizeof head && bytes == expected)
    return true;
  const bool text = got >= 5 && std::memcmp (head, "solid", 5) == 0 &&
                    std::all_of (head, head + got, [] (unsigned char c) { return c >= 32 || std::isspace (c); });
  if (text)
    return true;
  error = "'" + path + "' is not a readable stl mesh (" +
          (got < sizeof head ? std::string ("shorter than a binary STL's 84-byte header, and no ASCII 'solid'")
                             : "a binary STL of " + std::to_string (n) + " triangles by its header, " +
                                   std::to_string (expected) + " bytes, but the file has " + std::to_string (bytes) +
                                   ": truncated or corrupt") +
          ")";
  return false;
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
  if (ext != "obj" && ext != "ply" && ext != "stl" && ext != "vtk")
  {
    error = "'" + path + "': unsupported mesh type (expected .ply, .obj, .stl or .vtk)";
    return false;
  }

  // Faces as 0-based indices, signed: an index is named as the file counts it (OBJ from 1, the
  // others from 0), and one below zero as negative.
  std::vector<std::vector<long long>> faces;
  const bool one_based = ext == "obj";
  if (ext == "obj")
  {
    if (!readObj (path, mesh.vertices, faces, error))
      return false;
  }
  else if (ext == "vtk")
  {
    if (!readVtkLegacy (path, mesh.vertices, faces, error))
      return false;
  }
  else
  {
    // PLY goes through PCL's own reader, which reports a malformed file; VTK's crashed on some (a
    // PLY declaring faces and no vertex, a truncated one: segmentation faults and double frees,
    // found in review). On the FCL meshes written as ASCII and binary PLY both give the same
    // vertices and faces, bit for bit. STL has no reader besides VTK's.
    pcl::PolygonMesh polygon_mesh;
    bool read = false;
    try
    {
      if (ext == "ply")
      {
        PlyCounts layout;
        if (!checkPlyHeader (path, error, &layout) || !checkPlyValues (path, layout, error))
          return false;
        read = pcl::io::loadPLYFile (path, polygon_mesh) >= 0;
      }
      else
      {
        if (!checkStlSize (path, error))
          return false;
        read = pcl::io::loadPolygonFileSTL (path, polygon_mesh) > 0;
      }
    }
    catch (const std::exception& e)  // e.g. std::bad_alloc (a negative count did it before the header check)
    {
      error = "'" + path + "' is not a readable " + ext + " mesh (malformed: " + e.what () + ")";
      return false;
    }
    const pcl::PCLPointCloud2& cloud = polygon_mesh.cloud;
    const std::size_t n = static_cast<std::size_t> (cloud.width) * cloud.height;
    if (!read || n == 0 || cloud.data.size () < n * cloud.point_step)
    {
      error = "'" + path + "' is not a readable " + ext + " mesh (" + (read && n == 0 ? "no vertex" : "malformed or truncated") + ")";
      return false;
    }
    int xyz[3];
    for (int k = 0; k < 3; ++k)
    {
      xyz[k] = pcl::getFieldIndex (cloud, std::string (1, static_cast<char> ('x' + k)));
      if (xyz[k] < 0)
      {
        error = "'" + path + "': mesh vertices have no x y z";
        return false;
      }
    }
    // Any numeric type (a PLY may store double x y z; PCL's reader keeps the file's type).
    mesh.vertices.resize (n);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
      {
        const pcl::PCLPointField& f = cloud.fields[static_cast<std::size_t> (xyz[k])];
        mesh.vertices[i][static_cast<std::size_t> (k)] = readField (cloud.data.data () + i * cloud.point_step + f.offset, f.datatype);
      }
    // The readers hand indices over as unsigned 32-bit numbers: a negative one wraps.
    faces.reserve (polygon_mesh.polygons.size ());
    for (const auto& polygon : polygon_mesh.polygons)
    {
      faces.emplace_back ();
      for (const std::uint32_t i : polygon.vertices)
        faces.back ().push_back (static_cast<std::int32_t> (i));
    }
  }

  auto finite = [&] (long long i) {
    const auto& v = mesh.vertices[static_cast<std::size_t> (i)];
    return std::isfinite (v[0]) && std::isfinite (v[1]) && std::isfinite (v[2]);
  };
  const auto count = static_cast<long long> (mesh.vertices.size ());
  for (std::size_t face = 0; face < faces.size (); ++face)
  {
    const auto& idx = faces[face];
    for (const long long i : idx)
    {
      if (i < 0 || i >= count)
      {
        const std::string where = "'" + path + "': face " + std::to_string (face + 1);
        if (i < 0)
          error = where + (one_based ? " has a vertex index below 1" : " has a negative vertex index (" + std::to_string (i) + ")");
        else
          error = where + " refers to vertex " + std::to_string (one_based ? i + 1 : i) +
                  (one_based ? " (counting from 1, as OBJ does)" : " (counting from 0)") + " but the file has " +
                  std::to_string (count) + " vertices";
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
  // Triangles whose vertices are collinear or repeated bound nothing: sampled, such a mesh was its
  // vertices alone, read as a cloud without noise.
  if (!(meshArea (mesh) > 0.0))
  {
    error = "'" + path + "' has no triangle with an area (" + std::to_string (mesh.triangles.size ()) +
            " triangles, every one with collinear or repeated vertices; a mesh input needs faces)";
    return false;
  }
  return true;
}
} // namespace pcl_probcollision::io
