// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// A minimal streaming JSON writer for one-line records (JSON Lines), as pcd_collision -json
// prints them. No dependency beyond the standard library.

#include <cstdint>
#include <initializer_list>
#include <string>

namespace pcl_probcollision::io
{
/** \brief Writes one JSON value, usually an object, into a string without whitespace. Commas are
  * placed by the writer; the caller only nests begin/end pairs correctly and calls key() before
  * each member of an object.
  *
  * Numbers are printed as the shortest text that reads back as the same double (std::to_chars); NaN and Inf, which JSON cannot hold, become null (the
  * library's "not computed"). Strings are escaped per RFC 8259 (quote, backslash, control
  * characters); well-formed UTF-8 is copied unchanged, and any other byte (a file name that is
  * not UTF-8) is written \udcXX, Python's surrogateescape: the text stays UTF-8, and
  * os.fsencode() of the string Python's json parses gives the bytes back.
  *
  * \code
  * JsonWriter j;
  * j.beginObject ().key ("p").number (0.5).key ("pose").numbers ({0, 0, 0.1}).endObject ();
  * j.text ();  // {"p":0.5,"pose":[0,0,0.1]}
  * \endcode
  */
class JsonWriter
{
public:
  JsonWriter& beginObject ();
  JsonWriter& endObject ();
  JsonWriter& beginArray ();
  JsonWriter& endArray ();
  /** \brief The name of the next member of the current object. */
  JsonWriter& key (const std::string& name);

  /** \brief A number, or null when it is not finite. */
  JsonWriter& number (double value);
  /** \brief An array of numbers, each as number() writes it. */
  JsonWriter& numbers (std::initializer_list<double> values);
  JsonWriter& integer (long long value);
  JsonWriter& unsignedInteger (std::uint64_t value);
  JsonWriter& boolean (bool value);
  JsonWriter& null ();
  JsonWriter& string (const std::string& value);

  /** \brief Pre-formatted members of the current object: objectMembers() of another writer,
    * written as they are (nothing when fragment is empty). Lets a caller format the members that
    * every line of a run repeats once. */
  JsonWriter& members (const std::string& fragment);
  /** \brief The members of the one object written so far, without its braces (for members());
    * empty when the text is not one object. */
  std::string objectMembers () const;

  /** \brief Everything written so far. */
  std::string text () const { return out_; }

private:
  /** \brief Writes the comma before a value, unless it follows a key or opens a container. */
  void beforeValue ();
  void quoted (const std::string& s);

  std::string out_;  // appended to: an ostringstream's put() and sentry were a third of -json's time
  bool need_comma_ = false;
  bool after_key_ = false;
};
} // namespace pcl_probcollision::io
