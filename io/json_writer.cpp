// SPDX-License-Identifier: BSD-3-Clause
#include "json_writer.h"

#include <cmath>
#include <cstdio>

namespace pcl_probcollision::io
{
void
JsonWriter::beforeValue ()
{
  if (!after_key_ && need_comma_)
    out_ << ',';
  after_key_ = false;
  need_comma_ = true;
}

JsonWriter&
JsonWriter::beginObject ()
{
  beforeValue ();
  out_ << '{';
  need_comma_ = false;
  return *this;
}

JsonWriter&
JsonWriter::endObject ()
{
  out_ << '}';
  need_comma_ = true;
  return *this;
}

JsonWriter&
JsonWriter::beginArray ()
{
  beforeValue ();
  out_ << '[';
  need_comma_ = false;
  return *this;
}

JsonWriter&
JsonWriter::endArray ()
{
  out_ << ']';
  need_comma_ = true;
  return *this;
}

JsonWriter&
JsonWriter::key (const std::string& name)
{
  if (need_comma_)
    out_ << ',';
  quoted (name);
  out_ << ':';
  need_comma_ = false;
  after_key_ = true;
  return *this;
}

JsonWriter&
JsonWriter::number (double value)
{
  beforeValue ();
  if (!std::isfinite (value))
    out_ << "null";
  else
  {
    char buf[32];
    std::snprintf (buf, sizeof (buf), "%.10g", value);
    out_ << buf;
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
  out_ << value;
  return *this;
}

JsonWriter&
JsonWriter::unsignedInteger (std::uint64_t value)
{
  beforeValue ();
  out_ << value;
  return *this;
}

JsonWriter&
JsonWriter::boolean (bool value)
{
  beforeValue ();
  out_ << (value ? "true" : "false");
  return *this;
}

JsonWriter&
JsonWriter::null ()
{
  beforeValue ();
  out_ << "null";
  return *this;
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
  out_ << '"';
  for (const char ch : s)
  {
    const auto c = static_cast<unsigned char> (ch);
    switch (c)
    {
      case '"': out_ << "\\\""; break;
      case '\\': out_ << "\\\\"; break;
      case '\n': out_ << "\\n"; break;
      case '\r': out_ << "\\r"; break;
      case '\t': out_ << "\\t"; break;
      default:
        if (c < 0x20 || c == 0x7f)
        {
          char buf[8];
          std::snprintf (buf, sizeof (buf), "\\u%04x", c);
          out_ << buf;
        }
        else
          out_ << ch;
    }
  }
  out_ << '"';
}
} // namespace pcl_probcollision::io
