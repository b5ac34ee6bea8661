// SPDX-License-Identifier: BSD-3-Clause
#include "cloud_input.h"
#include "quiet_pcl_console.h"

#include <pcl_probcollision/detail/huge_pages.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <new>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace pcl_probcollision
{
namespace io
{
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

namespace
{
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
/** \brief Whether strtod reads the whole word as a number (nan and inf included), and which. */
bool
wholeNumber (const std::string& word, double* value = nullptr)
{
  char* end = nullptr;
  const double v = std::strtod (word.c_str (), &end);
  if (value)
    *value = v;
  return !word.empty () && end == word.c_str () + word.size ();
}

/** \brief For a PCD with DATA ascii: every value of its first `points` data lines a number, as
  * strtod reads it whole (nan and inf included), and `values` of them a line (the header's
  * COUNTs summed), or `values_unpadded` (those of padding fields "_" left out: PCL's writer
  * leaves them out of an ascii file, its reader skips their places), the rest of the file unread. PCL's reader reads a value that is not a number
  * ("abc") as 0, one with trailing garbage ("1.5x") as its numeric start, and a missing value as
  * 0 (a short line became a point at the origin), and says nothing. */
bool
checkAsciiValues (const std::string& path, std::size_t points, std::size_t values, std::size_t values_unpadded,
                  std::string& error)
{
  std::ifstream in (path, std::ios::binary);
  std::string line;
  std::size_t line_number = 0;
  bool in_data = false;
  for (std::size_t read = 0; read < points && std::getline (in, line);)
  {
    ++line_number;
    if (!in_data)
    {
      in_data = line.compare (0, 4, "DATA") == 0;
      continue;
    }
    std::istringstream words (line);
    std::string word;
    bool any = false;
    std::size_t column = 0;
    while (words >> word)
    {
      ++column;
      any = true;
      if (!wholeNumber (word))
      {
        error = "'" + path + "' line " + std::to_string (line_number) + ", value " + std::to_string (column) + ": '" +
                word + "' is not a number";
        return false;
      }
    }
    if (any && column != values && column != values_unpadded)
    {
      error = "'" + path + "' line " + std::to_string (line_number) + ": " + std::to_string (column) + " value" +
              (column == 1 ? "" : "s") + ", expected " + std::to_string (values_unpadded) +
              (values != values_unpadded ? " (or " + std::to_string (values) + " with its padding)" : std::string ()) +
              " (its header's FIELDS and COUNT)";
      return false;
    }
    read += any ? 1 : 0;  // PCL skips blank lines
  }
  return true;
}

/** \brief A PCD header's VIEWPOINT line, if any, holds seven finite numbers (tx ty tz qw qx qy
  * qz). PCL's reader stops at a value it cannot read ("nan", "inf") and leaves the sensor origin
  * at 0 0 0 and the rest of the quaternion uninitialised, without a word: the orientation
  * toward the viewpoint and `-o`'s header then rest on garbage. */
bool
checkViewpoint (const std::string& path, std::string& error)
{
  std::ifstream in (path, std::ios::binary);
  std::string line;
  for (std::size_t line_number = 1; std::getline (in, line) && line.compare (0, 4, "DATA") != 0; ++line_number)
  {
    if (line.compare (0, 9, "VIEWPOINT") != 0)
      continue;
    std::istringstream words (line.substr (9));
    std::string word;
    std::size_t column = 0;
    while (words >> word)
    {
      ++column;
      double value = 0.0;
      if (!wholeNumber (word, &value) || !std::isfinite (value))
      {
        error = "'" + path + "' line " + std::to_string (line_number) + ": VIEWPOINT value " + std::to_string (column) +
                " '" + word + "' is not a finite number (VIEWPOINT tx ty tz qw qx qy qz)";
        return false;
      }
    }
    if (column != 7)
    {
      error = "'" + path + "' line " + std::to_string (line_number) + ": VIEWPOINT has " + std::to_string (column) +
              " values, expected 7 (tx ty tz qw qx qy qz)";
      return false;
    }
  }
  return true;
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
checkPlyHeader (const std::string& path, std::string& error, PlyCounts* counts)
{
  std::ifstream in (path, std::ios::binary);
  in.seekg (0, std::ios::end);
  const auto file_size = static_cast<long long> (in.tellg ());
  in.seekg (0);
  auto fail = [&] (std::size_t line, const std::string& why) {
    error = "'" + path + "' is not a readable PLY file (header line " + std::to_string (line) + ": " + why + ")";
    return false;
  };
  static const std::set<std::string> kTypes = {"char",  "uchar",  "short",  "ushort",  "int",     "uint",   "float",
                                               "double", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                                               "float32", "float64"};
  std::string line, element;
  long long element_count = 0;
  std::set<std::string> names;             // the current element's properties
  std::vector<std::string> colours;        // the vertex element's colour properties, in order
  std::size_t number = 0;
  // A header has a few dozen lines; the bound stops at a binary file that only starts with "ply".
  while (number < 10000 && std::getline (in, line))
  {
    ++number;
    if (!line.empty () && line.back () == '\r')
      line.pop_back ();
    std::istringstream words (line);
    std::vector<std::string> w;
    for (std::string word; words >> word;)
      w.push_back (word);
    if (number == 1)
    {
      if (line != "ply")
        return fail (number, "the first line is not 'ply'");
      continue;
    }
    if (w.empty ())
      return fail (number, "an empty line");
    if (line[0] == ' ' || line[0] == '\t')  // PCL's reader asserts on " obj_info" (found by fuzzing)
      return fail (number, "a line starting with a blank");
    for (const char c : line)
      if (!(c == '\t' || (c >= ' ' && c <= '~')))
        return fail (number, "a character that is not printable ASCII");
    const std::string& key = w[0];
    if (key == "comment" || key == "obj_info")
      continue;
    if (key == "format")
    {
      if (w.size () != 3 || (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian") ||
          w[2] != "1.0")
        return fail (number, "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (counts)
        counts->ascii = w[1] == "ascii";
      continue;
    }
    // An element of entries without properties takes no bytes: PCL's reader then steps through
    // any count, 6 billion in a fuzzed file (a spin).
    if ((key == "element" || key == "end_header") && !element.empty () && element_count > 0 && names.empty ())
      return fail (number, "element '" + element + "' has entries but no property");
    if (key == "element")
    {
      if (w.size () != 3 || !(std::istringstream (w[2]) >> element_count) || element_count < 0 ||
          std::to_string (element_count) != w[2])
        return fail (number, "expected 'element NAME COUNT' with a count >= 0");
      // Each entry takes a byte at least: a count beyond the file is refused before any allocation.
      if (element_count > file_size)
        return fail (number, "element '" + w[1] + "' declares " + w[2] + " entries, more than the file's bytes");
      element = w[1];
      names.clear ();
      if (counts && element == "vertex")
        counts->vertices = element_count;
      if (counts && element == "face")
        counts->faces = element_count;
      if (counts)
        counts->elements.push_back ({element, element_count, {}});
      continue;
    }
    if (key == "property")
    {
      if (element.empty ())
        return fail (number, "a property before any element");
      const bool list = w.size () == 5 && w[1] == "list";
      if (!(list && kTypes.count (w[2]) && kTypes.count (w[3])) && !(w.size () == 3 && kTypes.count (w[1])))
        return fail (number, "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME' with PLY types");
      const std::string& name = w.back ();
      if (!names.insert (name).second)
        return fail (number, "property '" + name + "' given twice in element '" + element + "'");
      if (counts)
        counts->elements.back ().properties.push_back ({name, list ? w[3] : w[1], list ? w[2] : std::string ()});
      // PCL's reader sizes a vertex list by the first vertex and writes later, longer ones past
      // its buffer (an assertion, an abort); and it packs red, green and blue into one field
      // by their order: other orders or a missing one write past it (found by fuzzing).
      if (element == "vertex" && list)
        return fail (number, "a list property in the vertex element ('" + name + "') is not read");
      // PCL's reader takes a face's vertex indices as int or uint only, and their count as uchar,
      // int or uint: other indices (uchar, short, ...) and ushort counts left every face out
      // without a word (the mesh read "no triangles"), char and short counts failed as
      // "malformed or truncated".
      if (element == "face" && list && (name == "vertex_indices" || name == "vertex_index"))
      {
        const auto one_of = [] (const std::string& type, std::initializer_list<const char*> types) {
          return std::find (types.begin (), types.end (), type) != types.end ();
        };
        if (!one_of (w[3], {"int", "uint", "int32", "uint32"}))
          return fail (number, "the face list '" + name + "' has " + w[3] +
                                 " indices; PCL's PLY reader reads int or uint indices only");
        if (!one_of (w[2], {"uchar", "uint8", "int", "int32", "uint", "uint32"}))
          return fail (number, "the face list '" + name + "' has " + w[2] +
                                 " counts; PCL's PLY reader reads uchar, int or uint counts only");
      }
      if (element == "vertex")
        for (const std::string prefix : {"", "diffuse_"})
          for (const char* c : {"red", "green", "blue", "alpha"})
            if (name == prefix + c)
            {
              if (w[1] != "uchar" && w[1] != "uint8")
                return fail (number, "colour property '" + name + "' must be uchar");
              colours.push_back (c);
            }
      continue;
    }
    if (key == "end_header")
    {
      if (!colours.empty () && colours != std::vector<std::string>{"red", "green", "blue"} &&
          colours != std::vector<std::string>{"red", "green", "blue", "alpha"})
        return fail (number, "vertex colours must be red, green, blue (and alpha), in that order");
      if (counts)
        counts->header_lines = number;
      return true;
    }
    return fail (number, "unknown keyword '" + key + "'");
  }
  error = "'" + path + "' is not a readable PLY file (no end_header)";
  return false;
}

namespace
{
/** \brief The range of a PLY integer type (false for a floating-point one). */
bool
plyIntegerRange (const std::string& type, long long& low, long long& high)
{
  static const struct
  {
    const char* names[2];
    long long low, high;
  } kIntegers[] = {{{"char", "int8"}, -128, 127},          {{"uchar", "uint8"}, 0, 255},
                   {{"short", "int16"}, -32768, 32767},    {{"ushort", "uint16"}, 0, 65535},
                   {{"int", "int32"}, -2147483648LL, 2147483647LL}, {{"uint", "uint32"}, 0, 4294967295LL}};
  for (const auto& t : kIntegers)
    if (type == t.names[0] || type == t.names[1])
    {
      low = t.low;
      high = t.high;
      return true;
    }
  return false;
}

/** \brief Whether word is a value of a PLY property of type `type` as checkPlyValues wants it:
  * an integer within the type's range, or a decimal number (nan and inf included; strtod's hex
  * floats are not, PCL's reader takes them for NaN). */
bool
isPlyValue (const std::string& word, const std::string& type)
{
  const char* begin = word.c_str ();
  char* end = nullptr;
  long long low = 0, high = 0;
  if (plyIntegerRange (type, low, high))
  {
    errno = 0;
    const long long v = std::strtoll (begin, &end, 10);
    return !word.empty () && end == begin + word.size () && errno == 0 && v >= low && v <= high;
  }
  std::strtod (begin, &end);
  return !word.empty () && end == begin + word.size () && word.find_first_of ("xX") == std::string::npos;
}
} // namespace

bool
checkPlyValues (const std::string& path, const PlyCounts& layout, std::string& error)
{
  if (!layout.ascii)
    return true;
  std::ifstream in (path, std::ios::binary);
  std::string line;
  std::size_t line_number = 0;
  while (line_number < layout.header_lines && std::getline (in, line))
    ++line_number;
  std::vector<std::string> words;
  for (const PlyCounts::Element& element : layout.elements)
    for (long long entry = 0; entry < element.count; ++entry)
    {
      if (!std::getline (in, line))
      {
        error = "'" + path + "' is truncated: it ends at line " + std::to_string (line_number) + ", within the " +
                std::to_string (element.count) + " entries of element '" + element.name + "' its header declares";
        return false;
      }
      ++line_number;
      // PCL's reader takes one line an entry, its values between blanks (a CR ending included).
      words.clear ();
      std::istringstream split (line);
      for (std::string word; split >> word;)
        words.push_back (word);
      const std::string where = "'" + path + "' line " + std::to_string (line_number);
      auto refuse = [&] (std::size_t index, const std::string& type, const std::string& property) {
        long long low = 0, high = 0;
        error = where + ", value " + std::to_string (index + 1) + ": '" + words[index] + "' is not " +
                (plyIntegerRange (type, low, high) ? "an integer within the range of " + type + " (property '" + property + "')"
                                                   : std::string ("a number"));
        return false;
      };
      // The values the header asks for, in order: one a scalar property, a list's count and as
      // many values after it.
      std::size_t next = 0;  // the next word's index
      bool listed = false;   // the element has a list: its line's length depends on the counts
      bool short_line = false;
      for (const PlyCounts::Property& property : element.properties)
      {
        long long n = 1;
        if (!property.count_type.empty ())
        {
          listed = true;
          if (next >= words.size ())
          {
            short_line = true;
            break;
          }
          if (!isPlyValue (words[next], property.count_type) || (n = std::strtoll (words[next].c_str (), nullptr, 10)) < 0)
            return refuse (next, property.count_type, property.name);
          ++next;
        }
        for (long long k = 0; k < n && !short_line; ++k, ++next)
        {
          if (next >= words.size ())
            short_line = true;
          else if (!isPlyValue (words[next], property.type))
            return refuse (next, property.type, property.name);
        }
        if (short_line)
          break;
      }
      if (short_line || next < words.size ())
      {
        const std::string values = std::to_string (words.size ()) + " value" + (words.size () == 1 ? "" : "s");
        error = where + ": " + values + ", " +
                (!listed ? "expected " + std::to_string (element.properties.size ())
                         : short_line ? std::string ("too few") : "expected " + std::to_string (next)) +
                " (its header's properties of element '" + element.name + "'" +
                (listed ? ", a list's count and as many values" : "") + ")";
        return false;
      }
    }
  return true;
}

bool
isFacelessPly (const std::string& path)
{
  bool faceless = false;
  std::string unused;
  // An unreadable header is left to the mesh loader, which reports it (the same check, the same words).
  return plyKind (path, faceless, unused) && faceless;
}

bool
plyKind (const std::string& path, bool& faceless, std::string& error)
{
  faceless = false;
  if (!isPly (path))
    return true;
  error = unreadableFile (path);
  PlyCounts counts;
  if (!error.empty () || !checkPlyHeader (path, error, &counts))
    return false;
  faceless = counts.vertices > 0 && counts.faces == 0;
  return true;
}

namespace
{
/** \brief A cloud file read into PCL's generic form, its fields located and checked: the one
  * owner of the parsing behind loadCloud and loadCloudWithNormals. */
struct CloudFile
{
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero ();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity ();
  int xyz[3] = {-1, -1, -1};
  int normal[3] = {-1, -1, -1};  ///< normal_x normal_y normal_z; -1 when the file has none
  std::size_t size = 0;

  double value (std::size_t point, int field) const
  {
    const pcl::PCLPointField& f = blob.fields[static_cast<std::size_t> (field)];
    return readField (blob.data.data () + point * blob.point_step + f.offset, f.datatype);
  }
};

/** \brief Checks a field of the header: present with a known type, one value per point, and
  * named once (a negative index is absent). PCL's reader matches a coordinate with COUNT 2 or
  * more to no point field and leaves it 0 in every point, and a name given twice reads its first
  * field, both without a word. */
bool
checkField (const CloudFile& file, int index, const std::string& path, const char* name, std::string& error)
{
  const pcl::PCLPointField& field = file.blob.fields[static_cast<std::size_t> (index)];
  if (fieldSize (field.datatype) == 0)
  {
    error = "'" + path + "': field '" + name + "' has an unknown type";
    return false;
  }
  if (field.count > 1)
  {
    error = "'" + path + "': field '" + name + "' has COUNT " + std::to_string (field.count) +
            " (a coordinate or normal component needs COUNT 1)";
    return false;
  }
  const auto same = std::count_if (file.blob.fields.begin (), file.blob.fields.end (),
                                   [&] (const pcl::PCLPointField& f) { return f.name == name; });
  if (same > 1)
  {
    error = "'" + path + "': field '" + name + "' appears " + std::to_string (same) + " times in its FIELDS";
    return false;
  }
  return true;
}

} // namespace

std::string
unreadableFile (const std::string& path)
{
  std::error_code ec;
  const auto status = std::filesystem::status (path, ec);
  if (ec || !std::filesystem::exists (status))
    return "cannot read '" + path + "': No such file or directory";
  if (!std::filesystem::is_regular_file (status))
    return "cannot read '" + path + "': " +
           (std::filesystem::is_directory (status) ? std::string ("is a directory") : std::string ("not a regular file"));
  std::FILE* f = std::fopen (path.c_str (), "rb");
  if (!f)
    return "cannot read '" + path + "': " + std::strerror (errno);
  std::fclose (f);
  return {};
}

namespace
{
/** \brief Reads the file (PCD, or PLY by its extension) with every check; with want_normals,
  * also locates normal_x normal_y normal_z, all three or none (a partial set is an error naming
  * the missing field). */
bool
readCloudFile (const std::string& path, bool want_normals, CloudFile& file, std::string& error)
{
  const QuietPclConsole quiet;  // the error returned is the one report (pcd_collision -v shows PCL's)
  pcl::PCLPointCloud2& blob = file.blob;
  error = unreadableFile (path);
  if (!error.empty ())
    return false;
  const bool ply = isPly (path);
  const char* format = ply ? "PLY" : "PCD";
  if (ply)
  {
    PlyCounts layout;
    if (!checkPlyHeader (path, error, &layout) || !checkPlyValues (path, layout, error))
      return false;
    pcl::PLYReader reader;
    int version = 0;
    if (reader.read (path, blob, file.origin, file.orientation, version) < 0)
    {
      error = "'" + path + "' is truncated or corrupt (PLY data could not be read)";
      return false;
    }
  }
  else
  {
    // readHeader() sizes blob.data for the points (and read() reuses it): on memory offered to
    // huge pages, the file's size being the binary data's (a 5,000,000-point floor: 15,000
    // faults at about 11 us fewer, detail/huge_pages.h). Other encodings may outgrow it. Only a
    // hint: a file too large to reserve for is left to PCL's reader, as before.
    std::error_code size_error;
    const std::uintmax_t bytes = std::filesystem::file_size (path, size_error);
    if (!size_error)
    {
      try
      {
        pcl_probcollision::detail::reserveHugePages (blob.data, static_cast<std::size_t> (bytes));
      }
      catch (const std::bad_alloc&)
      {
      }
    }
    pcl::PCDReader reader;
    int version = 0, data_type = 0;
    unsigned int data_idx = 0;
    if (reader.readHeader (path, blob, file.origin, file.orientation, version, data_type, data_idx) < 0)
    {
      error = "'" + path + "' is not a PCD file (malformed or missing header)";
      return false;
    }
    if (blob.fields.empty ())
    {
      error = "'" + path + "' is not a PCD file (no FIELDS in its header)";
      return false;
    }
    if (!checkViewpoint (path, error))
      return false;
    std::size_t values = 0, padding = 0;
    for (const pcl::PCLPointField& f : blob.fields)
      (f.name == "_" ? padding : values) += std::max<std::size_t> (1, f.count);
    if (data_type == 0 &&
        !checkAsciiValues (path, static_cast<std::size_t> (blob.width) * blob.height, values + padding, values, error))
      return false;
  }
  if (static_cast<std::size_t> (blob.width) * blob.height == 0)
  {
    error = "'" + path + "' has no points (empty cloud)";
    return false;
  }
  // The fields are checked on the PCD header, before the (possibly large) data are read.
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
  {
    file.xyz[i] = pcl::getFieldIndex (blob, names[i]);
    if (file.xyz[i] < 0)
    {
      error = "'" + path + "' has no '" + names[i] + "' field (a " + format + " input needs x y z)";
      return false;
    }
    if (!checkField (file, file.xyz[i], path, names[i], error))
      return false;
  }
  if (want_normals)
  {
    const char* normal_names[3] = {"normal_x", "normal_y", "normal_z"};
    int present = 0;
    for (int i = 0; i < 3; ++i)
    {
      file.normal[i] = pcl::getFieldIndex (blob, normal_names[i]);
      present += file.normal[i] >= 0 ? 1 : 0;
    }
    std::string given;
    for (int i = 0; i < 3; ++i)
      if (file.normal[i] >= 0)
        given += std::string (given.empty () ? "" : " ") + normal_names[i];
    for (int i = 0; i < 3 && present > 0; ++i)
    {
      if (file.normal[i] < 0)
      {
        error = "'" + path + "' has no '" + normal_names[i] + "' field but has " + given +
                " (normals need normal_x normal_y normal_z)";
        return false;
      }
      if (!checkField (file, file.normal[i], path, normal_names[i], error))
        return false;
    }
  }
  if (!ply)
  {
    pcl::PCDReader reader;
    int version = 0;
    if (reader.read (path, blob, file.origin, file.orientation, version) < 0)
    {
      error = "'" + path + "' is truncated or corrupt (PCD data could not be read)";
      return false;
    }
  }
  file.size = static_cast<std::size_t> (blob.width) * blob.height;
  if (file.size == 0)
  {
    error = "'" + path + "' has no points";
    return false;
  }
  if (blob.data.size () < file.size * blob.point_step)
  {
    error = "'" + path + "' is truncated (fewer data bytes than its header announces)";
    return false;
  }
  return true;
}

/** \brief x y z of every point, converted from whatever numeric type the file has; organization
  * kept. rounding, when given, gets what the conversion to float cost. */
template <typename PointT>
void
copyXyz (const CloudFile& file, pcl::PointCloud<PointT>& cloud, XyzRounding* rounding)
{
  pcl_probcollision::detail::reserveHugePages (cloud.points, file.size);
  cloud.resize (file.size);
  XyzRounding cost;
  for (std::size_t j = 0; j < file.size; ++j)
    for (int i = 0; i < 3; ++i)
    {
      const double stored = file.value (j, file.xyz[i]);
      const float kept = static_cast<float> (stored);
      cloud[j].data[i] = kept;
      if (std::isfinite (stored))
      {
        cost.largest_change = std::max (cost.largest_change, std::abs (stored - static_cast<double> (kept)));
        cost.largest_magnitude = std::max (cost.largest_magnitude, std::abs (stored));
      }
    }
  cloud.width = file.blob.width;
  cloud.height = file.blob.height;
  if (rounding)
    *rounding = cost;
}

/** \brief Whether the file stores x y z as float32, which PCL's points hold exactly. */
bool
xyzAreFloat (const CloudFile& file)
{
  bool all_float = true;
  for (int i = 0; i < 3; ++i)
    all_float = all_float && file.blob.fields[static_cast<std::size_t> (file.xyz[i])].datatype == pcl::PCLPointField::FLOAT32;
  return all_float;
}

/** \brief The viewpoint, a fresh header and is_dense (every x y z finite). */
template <typename PointT>
void
finishCloud (const CloudFile& file, pcl::PointCloud<PointT>& cloud)
{
  cloud.header = pcl::PCLHeader ();
  cloud.sensor_origin_ = file.origin;
  cloud.sensor_orientation_ = file.orientation;
  bool dense = true;
  for (const auto& p : cloud.points)
    dense = dense && std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z);
  cloud.is_dense = dense;
}
} // namespace

bool
loadCloud (const std::string& path, pcl::PointCloud<pcl::PointXYZ>& cloud, std::string& error, XyzRounding* rounding)
{
  cloud.clear ();
  if (rounding)
    *rounding = XyzRounding ();
  CloudFile file;
  if (!readCloudFile (path, false, file, error))
    return false;
  // fromPCLPointCloud2 resizes the cloud to width x height.
  pcl_probcollision::detail::reserveHugePages (cloud.points, std::size_t{file.blob.width} * file.blob.height);
  if (xyzAreFloat (file))
    pcl::fromPCLPointCloud2 (file.blob, cloud);
  else
    copyXyz (file, cloud, rounding);
  finishCloud (file, cloud);
  return true;
}

bool
loadCloudWithNormals (const std::string& path, pcl::PointCloud<pcl::PointNormal>& cloud, bool& has_normals,
                      std::string& error, XyzRounding* rounding)
{
  cloud.clear ();
  has_normals = false;
  if (rounding)
    *rounding = XyzRounding ();
  CloudFile file;
  if (!readCloudFile (path, true, file, error))
    return false;
  copyXyz (file, cloud, xyzAreFloat (file) ? nullptr : rounding);
  has_normals = file.normal[0] >= 0;
  const float nan = std::numeric_limits<float>::quiet_NaN ();
  for (std::size_t j = 0; j < file.size; ++j)
  {
    Eigen::Vector3f n (nan, nan, nan);
    if (has_normals)
      for (int i = 0; i < 3; ++i)
        n[i] = static_cast<float> (file.value (j, file.normal[i]));
    // An infinite component is a broken normal, not a missing one (as buildCloudModel rules).
    if (std::isinf (n[0]) || std::isinf (n[1]) || std::isinf (n[2]))
    {
      std::ostringstream s;
      s << "'" << path << "': point " << j << " has a normal with an infinite component (" << n[0] << ", " << n[1]
        << ", " << n[2] << "); NaN or 0 marks a point without one";
      error = s.str ();
      return false;
    }
    // No usable direction (non-finite or zero): NaN, which the surface model orients from the
    // point's neighbours.
    if (!n.allFinite () || n.isZero ())
      n.setConstant (nan);
    cloud[j].getNormalVector3fMap () = n;
    cloud[j].curvature = 0.0f;
  }
  finishCloud (file, cloud);
  return true;
}
} // namespace io
} // namespace pcl_probcollision
