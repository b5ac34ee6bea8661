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
/** \brief Whether strtod reads the whole word as a number (nan and inf included), and which.
  * strtod's hex forms ("0x10", "0x1p-3") are not numbers: PCL's reader reads them as 0. */
bool
wholeNumber (const std::string& word, double* value = nullptr)
{
  char* end = nullptr;
  const double v = std::strtod (word.c_str (), &end);
  if (value)
    *value = v;
  return !word.empty () && end == word.c_str () + word.size () && word.find_first_of ("xX") == std::string::npos;
}

/** \brief Whether a word of an ascii PCD line, read by strtod as value (erange: strtod's
  * ERANGE), keeps its value in the field as PCL's ascii reader reads it; if not, why ("is not an
  * integer within ..."). An integer field takes a whole number within its type's range (PCL read
  * "300" in a U 1 field as 44 and "1.5" in an I field as 1), a float one a number within its
  * range, nan and inf included (PCL read 1e39 in a float32 field as Inf: the point was dropped as
  * non-finite). */
bool
fieldValue (const char* word, std::size_t length, double value, bool erange, const pcl::PCLPointField& field,
            std::string& why)
{
  long long low = 0, high = 0;
  const char* type = nullptr;  // TYPE and SIZE
  switch (field.datatype)
  {
    case pcl::PCLPointField::INT8: low = -128; high = 127; type = "I SIZE 1"; break;
    case pcl::PCLPointField::UINT8: high = 255; type = "U SIZE 1"; break;
    case pcl::PCLPointField::INT16: low = -32768; high = 32767; type = "I SIZE 2"; break;
    case pcl::PCLPointField::UINT16: high = 65535; type = "U SIZE 2"; break;
    case pcl::PCLPointField::INT32: low = -2147483648LL; high = 2147483647LL; type = "I SIZE 4"; break;
    case pcl::PCLPointField::UINT32: high = 4294967295LL; type = "U SIZE 4"; break;
    case pcl::PCLPointField::INT64:
      low = std::numeric_limits<long long>::min ();
      high = std::numeric_limits<long long>::max ();
      type = "I SIZE 8";
      break;
    case pcl::PCLPointField::UINT64: type = "U SIZE 8"; break;
    case pcl::PCLPointField::FLOAT32:
      // From 2^128 - 2^103 on (FLT_MAX and half its last place) a number rounds to Inf as a float.
      if (!(std::isfinite (value) && std::abs (value) >= 0x1.ffffffp+127) && !(std::isinf (value) && erange))
        return true;
      why = "is beyond the float range of field '" + field.name + "' (TYPE F SIZE 4)";
      return false;
    case pcl::PCLPointField::FLOAT64:
      if (!(std::isinf (value) && erange))  // "inf" itself sets no ERANGE
        return true;
      why = "is beyond the double range of field '" + field.name + "' (TYPE F SIZE 8)";
      return false;
    default:
      return true;  // bool, or a type PCL's reader skips
  }
  char* end = nullptr;
  errno = 0;
  bool ok = false;
  if (field.datatype == pcl::PCLPointField::UINT64)
    ok = word[0] != '-' && (std::strtoull (word, &end, 10), end == word + length) && errno == 0;  // strtoull takes "-1"
  else
  {
    const long long v = std::strtoll (word, &end, 10);
    ok = end == word + length && errno == 0 && v >= low && v <= high;
  }
  if (!ok)
    why = "is not an integer within the range of field '" + field.name + "' (TYPE " + type + ": " +
          (field.datatype == pcl::PCLPointField::UINT64 ? std::string ("0 to 18446744073709551615")
                                                        : std::to_string (low) + " to " + std::to_string (high)) +
          ")";
  return ok;
}

/** \brief For a PCD with DATA ascii: every value of its first `points` data lines a number, as
  * strtod reads it whole (nan and inf included; hex forms not), and as many of them a line as the
  * fields' COUNTs, with or without those of padding fields "_" (PCL's writer leaves them out of an
  * ascii file, its reader skips their places), each a value its field keeps (fieldValue), the rest
  * of the file unread. PCL's reader reads a value that is not a number ("abc") as 0, one with
  * trailing garbage ("1.5x") as its numeric start, and a missing value as 0 (a short line became a
  * point at the origin), and says nothing. fields are the header's as PCL's readHeader read them. */
bool
checkAsciiValues (const std::string& path, std::size_t points, const std::vector<pcl::PCLPointField>& fields,
                  std::string& error)
{
  std::size_t values = 0, values_unpadded = 0;
  for (const pcl::PCLPointField& f : fields)
  {
    values += std::max<std::size_t> (1, f.count);
    values_unpadded += f.name == "_" ? 0 : std::max<std::size_t> (1, f.count);
  }
  struct Word
  {
    std::size_t begin, end;  // in the line
    double value;
    bool erange;
  };
  std::vector<Word> words;
  std::ifstream in (path, std::ios::binary);
  std::string line, why;
  std::size_t line_number = 0;
  bool in_data = false;
  std::size_t read = 0;
  for (; read < points && std::getline (in, line);)
  {
    ++line_number;
    if (!in_data)
    {
      const std::size_t first = line.find_first_not_of (" \t\r");  // PCL reads a keyword after blanks
      in_data = first != std::string::npos && line.compare (first, 4, "DATA") == 0;
      continue;
    }
    const auto where = [&] (std::size_t k) {
      return "'" + path + "' line " + std::to_string (line_number) + ", value " + std::to_string (k + 1) + ": '" +
             line.substr (words[k].begin, words[k].end - words[k].begin) + "' ";
    };
    // The words between blanks, each read once (a blank after it made its end for strtod).
    words.clear ();
    line.push_back ('\0');
    for (std::size_t i = 0; i < line.size () - 1;)
    {
      if (std::isspace (static_cast<unsigned char> (line[i])))
      {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < line.size () - 1 && !std::isspace (static_cast<unsigned char> (line[j])))
        ++j;
      const char blank = line[j];
      line[j] = '\0';
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod (line.c_str () + i, &end);
      const bool number = end == line.c_str () + j && std::memchr (line.c_str () + i, 'x', j - i) == nullptr &&
                          std::memchr (line.c_str () + i, 'X', j - i) == nullptr;
      words.push_back ({i, j, v, errno == ERANGE});
      line[j] = blank;
      if (!number)  // as wholeNumber: strtod's hex forms are not numbers
      {
        error = where (words.size () - 1) + "is not a number";
        return false;
      }
      i = j;
    }
    const std::size_t column = words.size ();
    if (column > 0 && column != values && column != values_unpadded)
    {
      error = "'" + path + "' line " + std::to_string (line_number) + ": " + std::to_string (column) + " value" +
              (column == 1 ? "" : "s") + ", expected " + std::to_string (values_unpadded) +
              (values != values_unpadded ? " (or " + std::to_string (values) + " with its padding)" : std::string ()) +
              " (its header's FIELDS and COUNT)";
      return false;
    }
    // Each value against its field; a padding field's values, when the line has them, PCL skips.
    std::size_t k = 0;
    for (const pcl::PCLPointField& f : fields)
    {
      const bool padding = f.name == "_";
      if (padding && column != values)
        continue;
      for (std::size_t c = 0; c < std::max<std::size_t> (1, f.count) && k < column; ++c, ++k)
        if (!padding && !fieldValue (line.c_str () + words[k].begin, words[k].end - words[k].begin, words[k].value,
                                     words[k].erange, f, why))
        {
          error = where (k) + why;
          return false;
        }
    }
    read += column > 0 ? 1 : 0;  // PCL skips blank lines
  }
  if (in_data && read < points)  // PCL's reader: "could not be read", no line named
  {
    error = "'" + path + "' is truncated: it ends at line " + std::to_string (line_number) + ", after " +
            std::to_string (read) + " of the " + std::to_string (points) + " points its header announces";
    return false;
  }
  return true;
}

/** \brief A PCD header's VIEWPOINT line (its words after the keyword) holds seven finite
  * numbers within the float range (tx ty tz qw qx qy qz). PCL's reader stops at a value it cannot
  * read ("nan", "inf", "1e39") and leaves the sensor origin at 0 0 0 and the rest of the
  * quaternion uninitialised, without a word: the orientation toward the viewpoint and `-o`'s
  * header then rest on garbage; with fewer than seven it refuses the whole header, unexplained.
  * The quaternion must not be 0 0 0 0. */
bool
checkViewpoint (const std::string& path, std::size_t line_number, const std::vector<std::string>& words,
                std::string& error)
{
  double rotation_norm = 0.0;  // |qw| + |qx| + |qy| + |qz|, as read
  for (std::size_t column = 1; column < words.size (); ++column)
  {
    double value = 0.0;
    const std::string& word = words[column];
    if (!wholeNumber (word, &value) || !std::isfinite (value) || std::isinf (std::strtof (word.c_str (), nullptr)))
    {
      error = "'" + path + "' line " + std::to_string (line_number) + ": VIEWPOINT value " + std::to_string (column) +
              " '" + word + "' is not a finite number (VIEWPOINT tx ty tz qw qx qy qz)";
      return false;
    }
    if (column >= 4)
      rotation_norm += std::abs (value);
  }
  if (words.size () != 8)
  {
    error = "'" + path + "' line " + std::to_string (line_number) + ": VIEWPOINT has " + std::to_string (words.size () - 1) +
            " values, expected 7 (tx ty tz qw qx qy qz)";
    return false;
  }
  // A quaternion of zeros is no rotation; PCL would hand it on and the viewpoint's axis
  // would be a guess. An unrotated sensor is 1 0 0 0.
  if (rotation_norm == 0.0)
  {
    error = "'" + path + "' line " + std::to_string (line_number) +
            ": VIEWPOINT quaternion qw qx qy qz is 0 0 0 0, which is no rotation (an unrotated sensor is 1 0 0 0)";
    return false;
  }
  return true;
}

/** \brief a x b, or the largest std::uint64_t where that overflows (a size no file reaches). */
std::uint64_t
product (std::uint64_t a, std::uint64_t b)
{
  return b != 0 && a > std::numeric_limits<std::uint64_t>::max () / b ? std::numeric_limits<std::uint64_t>::max ()
                                                                         : a * b;
}

/** \brief Whether word is a whole number (digits only) of at most max, and which. */
bool
headerNumber (const std::string& word, std::uint64_t max, std::uint64_t& value)
{
  if (word.empty () || word.find_first_not_of ("0123456789") != std::string::npos)
    return false;
  errno = 0;
  value = std::strtoull (word.c_str (), nullptr, 10);
  return errno == 0 && value <= max;
}

/** \brief A PCD header, read as PCL's readHeader reads it (a line's keyword by its start, '#'
  * comments and empty lines skipped, the header ending at its DATA line), checked before that
  * reader sees it: readHeader sets aside POINTS x the point's bytes when it reads POINTS, before
  * anything refuses the file (a 187-byte binary PCD claiming 1,000,000,000 points took 12 GB and
  * 52 s to be refused; POINTS -5, or a negative SIZE or COUNT, ended in a bad_alloc or
  * "vector::_M_default_append" naming no file). Refused, naming the file and the line: WIDTH,
  * HEIGHT, POINTS, SIZE or COUNT values that are not whole numbers; POINTS other than WIDTH x
  * HEIGHT; a DATA type other than ascii, binary or binary_compressed (PCL read "binaryX" as binary
  * and any other word as ascii); a VIEWPOINT it cannot read (checkViewpoint); a header without a
  * DATA line (PCL read its lines as points at the origin); and points the data after the header
  * cannot hold: binary, POINTS x the point's bytes; ascii, a character a value, and no more than
  * 8 bytes set aside a character (a value of a known type takes 8 bytes at most, and a separator
  * besides its character); binary_compressed, the two little-endian uint32 after the header: the
  * compressed size, which the file must hold, and the uncompressed one, which must be POINTS x
  * the point's bytes and within what LZF unpacks from the compressed (at most 264 bytes from 3).
  * Reads the header and, for binary_compressed, 8 bytes more. */
bool
checkPcdHeader (const std::string& path, std::string& error)
{
  std::error_code size_error;
  const std::uint64_t file_size = std::filesystem::file_size (path, size_error);
  if (size_error)
    return true;  // unreadableFile let it through: PCL's reader reports it
  std::ifstream in (path, std::ios::binary);
  std::vector<std::string> names;
  std::vector<std::uint64_t> sizes, counts;  // per field, as FIELDS defaults them (4, 1)
  std::uint64_t point_step = 0, width = 0, height = 0, points = 0, set_aside = 0;
  bool has_width = false, has_height = false, has_points = false;
  std::size_t points_line = 0;
  std::string line;
  std::vector<std::string> w;
  for (std::size_t number = 1; std::getline (in, line); ++number)
  {
    if (line.empty ())
      continue;
    w.clear ();
    std::istringstream split (line);
    for (std::string word; split >> word;)
      w.push_back (word);
    if (w.empty ())
      break;  // blanks: no keyword, the end of PCL's header
    const std::string& key = w[0];
    const auto is = [&key] (const char* keyword) { return key.compare (0, std::strlen (keyword), keyword) == 0; };
    const std::string where = "'" + path + "' line " + std::to_string (number) + ": ";
    if (key[0] == '#' || is ("VERSION") || is ("TYPE"))
      continue;
    if (is ("FIELDS") || is ("COLUMNS"))
    {
      names.assign (w.begin () + 1, w.end ());
      sizes.assign (names.size (), 4);
      counts.assign (names.size (), 1);
      point_step = 4 * names.size ();
      continue;
    }
    if (is ("SIZE") || is ("COUNT"))
    {
      const bool size = is ("SIZE");
      for (std::size_t k = 1; k < w.size (); ++k)
      {
        std::uint64_t v = 0;
        if (!headerNumber (w[k], std::numeric_limits<int>::max (), v))  // PCL reads an int
        {
          error = where + (size ? "SIZE" : "COUNT") + " value " + std::to_string (k) + " '" + w[k] +
                  "' is not a whole number >= 0";
          return false;
        }
        if (k - 1 < names.size ())
          (size ? sizes : counts)[k - 1] = v;
      }
      // PCL's point bytes: the SIZEs summed, then at COUNT each SIZE x COUNT.
      point_step = 0;
      for (std::size_t i = 0; i < names.size (); ++i)
        point_step += sizes[i] * (size ? 1 : counts[i]);
      continue;
    }
    if (is ("WIDTH") || is ("HEIGHT") || is ("POINTS"))
    {
      const bool point_count = is ("POINTS");
      const std::string value = w.size () > 1 ? w[1] : std::string ();
      std::uint64_t v = 0;
      if (!headerNumber (value, point_count ? std::numeric_limits<std::uint64_t>::max () : 4294967295u, v))
      {
        error = where + (point_count ? "POINTS" : is ("WIDTH") ? "WIDTH" : "HEIGHT") + " '" + value +
                "' is not a whole number " + (point_count ? ">= 0" : "from 0 to 4294967295");
        return false;
      }
      if (point_count)
      {
        has_points = true;
        points = v;
        points_line = number;
        set_aside = std::max (set_aside, product (points, point_step));
      }
      else if (is ("WIDTH"))
      {
        has_width = true;
        width = v;
      }
      else
      {
        has_height = true;
        height = v;
      }
      continue;
    }
    if (is ("VIEWPOINT"))
    {
      if (!checkViewpoint (path, number, w, error))
        return false;
      continue;
    }
    if (!is ("DATA"))
    {
      error = "'" + path + "' is not a PCD file (line " + std::to_string (number) +
              ", before any DATA line, is not a PCD header line)";
      return false;
    }
    const std::string type = w.size () > 1 ? w[1] : std::string ();
    if (type != "ascii" && type != "binary" && type != "binary_compressed")
    {
      error = where + "DATA '" + type + "' is not ascii, binary or binary_compressed";
      return false;
    }
    // PCL takes HEIGHT 1 when it is not given (and WIDTH = POINTS when neither is); HEIGHT
    // without WIDTH it refuses itself.
    const std::uint64_t rows = has_height ? height : 1;
    if (has_points && has_width && product (width, rows) != points)
    {
      error = "'" + path + "' line " + std::to_string (points_line) + ": POINTS " + std::to_string (points) +
              " is not WIDTH x HEIGHT, " + std::to_string (width) + " x " + std::to_string (rows) + " = " +
              std::to_string (product (width, rows));
      return false;
    }
    const std::streamoff at = in.tellg ();  // -1 at the end of the file
    const std::uint64_t bytes = at < 0 ? 0 : file_size - static_cast<std::uint64_t> (at);
    const std::uint64_t data = product (points, point_step);
    set_aside = std::max (set_aside, data);
    const std::string announces = "'" + path + "' is truncated or corrupt: its header announces " + std::to_string (points) +
                                  " points (" + std::to_string (set_aside) + " bytes)";
    if (type == "binary" && set_aside > bytes)
    {
      error = announces + " but " + std::to_string (bytes) + " bytes follow it";
      return false;
    }
    if (type == "ascii")
    {
      std::uint64_t values = 0;  // at least, a line (padding fields' values may be left out)
      for (std::size_t i = 0; i < names.size (); ++i)
        values += names[i] == "_" ? 0 : counts[i];
      // A value takes a character at least, and a separator this bound leaves out: a file a line
      // or so short is left to checkAsciiValues, which names the line.
      const std::uint64_t least = product (points, std::max<std::uint64_t> (values, 1));
      if (least > bytes)
      {
        error = "'" + path + "' is truncated or corrupt: its header announces " + std::to_string (points) +
                " points of " + std::to_string (values) + " values (at least " + std::to_string (least) +
                " bytes as ascii) but " + std::to_string (bytes) + " bytes follow it";
        return false;
      }
      if (set_aside > product (bytes, 8))
      {
        error = announces + " but " + std::to_string (bytes) + " bytes of ascii follow it (8 bytes a character at most)";
        return false;
      }
    }
    if (type == "binary_compressed")
    {
      unsigned char sizes_read[8] = {};
      if (bytes < 8 || !in.read (reinterpret_cast<char*> (sizes_read), 8))
      {
        error = announces + " but its binary_compressed data end before their sizes (" + std::to_string (bytes) +
                " bytes follow it)";
        return false;
      }
      const auto le32 = [&sizes_read] (int at) {
        return std::uint64_t{sizes_read[at]} | std::uint64_t{sizes_read[at + 1]} << 8 |
               std::uint64_t{sizes_read[at + 2]} << 16 | std::uint64_t{sizes_read[at + 3]} << 24;
      };
      const std::uint64_t compressed = le32 (0), uncompressed = le32 (4);
      if (uncompressed != data)
      {
        error = "'" + path + "' is truncated or corrupt: its header announces " + std::to_string (points) + " points (" +
                std::to_string (data) + " bytes) but its binary_compressed data unpack to " +
                std::to_string (uncompressed) + " bytes";
        return false;
      }
      if (compressed > bytes - 8)
      {
        error = "'" + path + "' is truncated or corrupt: its binary_compressed data announce " +
                std::to_string (compressed) + " compressed bytes but " + std::to_string (bytes - 8) + " bytes follow";
        return false;
      }
      if (set_aside > product (compressed, 88))
      {
        error = announces + " but " + std::to_string (compressed) +
                " bytes of binary_compressed data unpack to at most 88 times as many (LZF)";
        return false;
      }
    }
    return true;
  }
  error = "'" + path + "' is not a PCD file (its header has no DATA line)";
  return false;
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
    // Checked before PCL's readHeader, which sets aside memory for the points its header claims.
    if (!checkPcdHeader (path, error))
      return false;
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
    if (data_type == 0 && !checkAsciiValues (path, static_cast<std::size_t> (blob.width) * blob.height, blob.fields, error))
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
  * kept. rounding, when given, gets what the conversion to float cost. False, the cloud cleared,
  * with the file and the point when a finite coordinate is beyond the float range (a float64
  * 2e299 became Inf, and the point was skipped as non-finite without a word). */
template <typename PointT>
bool
copyXyz (const CloudFile& file, const std::string& path, pcl::PointCloud<PointT>& cloud, XyzRounding* rounding,
         std::string& error)
{
  // From here a double rounds to Inf as a float: FLT_MAX and half its last place.
  constexpr double kFloatOverflow = 0x1.ffffffp+127;
  pcl_probcollision::detail::reserveHugePages (cloud.points, file.size);
  cloud.resize (file.size);
  XyzRounding cost;
  for (std::size_t j = 0; j < file.size; ++j)
    for (int i = 0; i < 3; ++i)
    {
      const double stored = file.value (j, file.xyz[i]);
      if (std::abs (stored) >= kFloatOverflow && std::isfinite (stored))
      {
        std::ostringstream s;
        s.precision (9);  // enough to tell it from FLT_MAX (3.40282347e+38)
        s << "'" << path << "': point " << j << "'s " << "xyz"[i] << " = " << stored
          << " is beyond the float range of the points PCL holds";
        error = s.str ();
        cloud.clear ();
        return false;
      }
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
  return true;
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
  else if (!copyXyz (file, path, cloud, rounding, error))
    return false;
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
  if (!copyXyz (file, path, cloud, xyzAreFloat (file) ? nullptr : rounding, error))
    return false;
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
    if (!n.allFinite () || (n.array () == 0.0f).all ())  // exactly 0: Eigen's isZero () took any length under 1e-5 for none
      n.setConstant (nan);
    cloud[j].getNormalVector3fMap () = n;
    cloud[j].curvature = 0.0f;
  }
  finishCloud (file, cloud);
  return true;
}
} // namespace io
} // namespace pcl_probcollision
