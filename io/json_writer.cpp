// SPDX-License-Identifier: BSD-3-Clause
#include "json_writer.h"

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

namespace pcl_probcollision::io
{
namespace
{
/** \brief Length of the well-formed UTF-8 sequence starting at s[i] (a lead byte >= 0x80), or 0
  * when there is none: a stray continuation byte, a sequence cut short, an overlong form, a
  * surrogate or a code point above U+10FFFF (the Unicode standard's table 3-7). */
std::size_t
utf8SequenceLength (const std::string& s, std::size_t i)
{
  const auto byte = [&s] (std::size_t k) { return static_cast<unsigned char> (s[k]); };
  const unsigned char c = byte (i);
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xbf;  // the range of the second byte
  if (c >= 0xc2 && c <= 0xdf)
    length = 2;
  else if (c >= 0xe0 && c <= 0xef)
  {
    length = 3;
    low = c == 0xe0 ? 0xa0 : 0x80;
    high = c == 0xed ? 0x9f : 0xbf;
  }
  else if (c >= 0xf0 && c <= 0xf4)
  {
    length = 4;
    low = c == 0xf0 ? 0x90 : 0x80;
    high = c == 0xf4 ? 0x8f : 0xbf;
  }
  else
    return 0;
  if (i + length > s.size () || byte (i + 1) < low || byte (i + 1) > high)
    return 0;
  for (std::size_t k = 2; k < length; ++k)
    if (byte (i + k) < 0x80 || byte (i + k) > 0xbf)
      return 0;
  return length;
}
} // namespace

void
JsonWriter::beforeValue ()
{
  if (!after_key_ && need_comma_)
    out_ += ',';
  after_key_ = false;
  need_comma_ = true;
}

JsonWriter&
JsonWriter::beginObject ()
{
  beforeValue ();
  out_ += '{';
  need_comma_ = false;
  return *this;
}

JsonWriter&
JsonWriter::endObject ()
{
  out_ += '}';
  need_comma_ = true;
  return *this;
}

JsonWriter&
JsonWriter::beginArray ()
{
  beforeValue ();
  out_ += '[';
  need_comma_ = false;
  return *this;
}

JsonWriter&
JsonWriter::endArray ()
{
  out_ += ']';
  need_comma_ = true;
  return *this;
}

JsonWriter&
JsonWriter::key (const std::string& name)
{
  if (need_comma_)
    out_ += ',';
  quoted (name);
  out_ += ':';
  need_comma_ = false;
  after_key_ = true;
  return *this;
}

JsonWriter&
JsonWriter::number (double value)
{
  beforeValue ();
  if (!std::isfinite (value))
    out_ += "null";
  else
  {
    // The shortest text that reads back as the same double (std::to_chars without a precision):
    // bit-exact through any JSON parser, and several times faster than printf.
    char buf[32];
    const auto end = std::to_chars (buf, buf + sizeof (buf), value).ptr;
    out_.append (buf, end);
  }
  return *this;
}

JsonWriter&
JsonWriter::numbers (std::initializer_list<double> values)
{
  beginArray ();
  for (const double v : values)
    number (v);
  return endArray ();
}

JsonWriter&
JsonWriter::integer (long long value)
{
  beforeValue ();
  out_ += std::to_string (value);
  return *this;
}

JsonWriter&
JsonWriter::unsignedInteger (std::uint64_t value)
{
  beforeValue ();
  out_ += std::to_string (value);
  return *this;
}

JsonWriter&
JsonWriter::boolean (bool value)
{
  beforeValue ();
  out_ += (value ? "true" : "false");
  return *this;
}

JsonWriter&
JsonWriter::null ()
{
  beforeValue ();
  out_ += "null";
  return *this;
}

JsonWriter&
JsonWriter::members (const std::string& fragment)
{
  if (fragment.empty ())
    return *this;
  if (need_comma_)
    out_ += ',';
  out_ += fragment;
  need_comma_ = true;
  after_key_ = false;
  return *this;
}

std::string
JsonWriter::objectMembers () const
{
  if (out_.size () < 2 || out_.front () != '{' || out_.back () != '}')
    return std::string ();
  return out_.substr (1, out_.size () - 2);
}

JsonWriter&
JsonWriter::string (const std::string& value)
{
  beforeValue ();
  quoted (value);
  return *this;
}

void
JsonWriter::quoted (const std::string& s)
{
  out_ += '"';
  const std::size_t n = s.size ();
  const auto plain = [] (unsigned char c) { return c >= 0x20 && c < 0x7f && c != '"' && c != '\\'; };
  for (std::size_t i = 0; i < n;)
  {
    // Plain ASCII in one append (a member's name is all plain).
    std::size_t run = i;
    while (run < n && plain (static_cast<unsigned char> (s[run])))
      ++run;
    out_.append (s.data () + i, run - i);
    i = run;
    if (i == n)
      break;
    const auto c = static_cast<unsigned char> (s[i]);
    if (c >= 0x80)
    {
      // JSON text must be UTF-8 (RFC 8259, 8.1); a byte outside a well-formed sequence is
      // kept recoverable as surrogateescape's \udcXX.
      const std::size_t length = utf8SequenceLength (s, i);
      if (length == 0)
      {
        char buf[8];
        std::snprintf (buf, sizeof (buf), "\\udc%02x", c);
        out_ += buf;
        ++i;
      }
      else
      {
        out_.append (s.data () + i, length);
        i += length;
      }
      continue;
    }
    switch (c)
    {
      case '"': out_ += "\\\""; break;
      case '\\': out_ += "\\\\"; break;
      case '\n': out_ += "\\n"; break;
      case '\r': out_ += "\\r"; break;
      case '\t': out_ += "\\t"; break;
      default:
        if (c < 0x20 || c == 0x7f)
        {
          char buf[8];
          std::snprintf (buf, sizeof (buf), "\\u%04x", c);
          out_ += buf;
        }
        else
          out_ += static_cast<char> (c);
    }
    ++i;
  }
  out_ += '"';
}
} // namespace pcl_probcollision::io
