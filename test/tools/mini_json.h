// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// A strict, minimal JSON reader for the CLI tests (RFC 8259 values; no extensions: NaN,
// Infinity, trailing commas and comments are rejected). Throws std::runtime_error.

#include <cctype>
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mini_json
{
struct Value
{
  enum class Type
  {
    Null,
    Bool,
    Number,
    String,
    Array,
    Object
  };
  Type type = Type::Null;
  bool boolean = false;
  double number = 0.0;
  std::string text;     ///< the string, or the number's literal text
  std::vector<Value> array;
  std::map<std::string, Value> object;

  bool has (const std::string& key) const { return type == Type::Object && object.count (key) > 0; }
  const Value& operator[] (const std::string& key) const
  {
    const auto it = object.find (key);
    if (type != Type::Object || it == object.end ())
      throw std::runtime_error ("no key '" + key + "'");
    return it->second;
  }
  const Value& operator[] (std::size_t i) const
  {
    if (type != Type::Array || i >= array.size ())
      throw std::runtime_error ("no element " + std::to_string (i));
    return array[i];
  }
  /** \brief A number literal without fraction or exponent. */
  bool isInteger () const
  {
    return type == Type::Number && text.find_first_of (".eE") == std::string::npos;
  }
};

class Parser
{
public:
  explicit Parser (const std::string& s) : s_ (s) {}
  Value parse ()
  {
    Value v = value ();
    ws ();
    if (i_ != s_.size ())
      fail ("trailing characters");
    return v;
  }

private:
  [[noreturn]] void fail (const std::string& why) const
  {
    throw std::runtime_error ("JSON error at " + std::to_string (i_) + ": " + why);
  }
  void ws ()
  {
    while (i_ < s_.size () && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r'))
      ++i_;
  }
  bool literal (const char* word)
  {
    const std::string w (word);
    if (s_.compare (i_, w.size (), w) == 0)
    {
      i_ += w.size ();
      return true;
    }
    return false;
  }
  std::string string ()
  {
    if (s_[i_] != '"')
      fail ("expected string");
    ++i_;
    std::string out;
    while (true)
    {
      if (i_ >= s_.size ())
        fail ("unterminated string");
      const char c = s_[i_++];
      if (c == '"')
        return out;
      if (static_cast<unsigned char> (c) < 0x20)
        fail ("control character in string");
      if (c != '\\')
      {
        out.push_back (c);
        continue;
      }
      if (i_ >= s_.size ())
        fail ("bad escape");
      const char e = s_[i_++];
      switch (e)
      {
        case '"': out.push_back ('"'); break;
        case '\\': out.push_back ('\\'); break;
        case '/': out.push_back ('/'); break;
        case 'b': out.push_back ('\b'); break;
        case 'f': out.push_back ('\f'); break;
        case 'n': out.push_back ('\n'); break;
        case 'r': out.push_back ('\r'); break;
        case 't': out.push_back ('\t'); break;
        case 'u':
        {
          if (i_ + 4 > s_.size ())
            fail ("bad \\u escape");
          const unsigned long cp = std::strtoul (s_.substr (i_, 4).c_str (), nullptr, 16);
          i_ += 4;
          out.push_back (cp < 0x80 ? static_cast<char> (cp) : '?');
          break;
        }
        default: fail ("bad escape");
      }
    }
  }
  Value value ()
  {
    ws ();
    if (i_ >= s_.size ())
      fail ("unexpected end");
    Value v;
    const char c = s_[i_];
    if (c == '{')
    {
      v.type = Value::Type::Object;
      ++i_;
      ws ();
      if (s_[i_] == '}')
      {
        ++i_;
        return v;
      }
      while (true)
      {
        ws ();
        const std::string k = string ();
        ws ();
        if (s_[i_] != ':')
          fail ("expected ':'");
        ++i_;
        if (v.object.count (k))
          fail ("duplicate key " + k);
        v.object[k] = value ();
        ws ();
        if (s_[i_] == ',')
        {
          ++i_;
          continue;
        }
        if (s_[i_] == '}')
        {
          ++i_;
          return v;
        }
        fail ("expected ',' or '}'");
      }
    }
    if (c == '[')
    {
      v.type = Value::Type::Array;
      ++i_;
      ws ();
      if (s_[i_] == ']')
      {
        ++i_;
        return v;
      }
      while (true)
      {
        v.array.push_back (value ());
        ws ();
        if (s_[i_] == ',')
        {
          ++i_;
          continue;
        }
        if (s_[i_] == ']')
        {
          ++i_;
          return v;
        }
        fail ("expected ',' or ']'");
      }
    }
    if (c == '"')
    {
      v.type = Value::Type::String;
      v.text = string ();
      return v;
    }
    if (literal ("true"))
    {
      v.type = Value::Type::Bool;
      v.boolean = true;
      return v;
    }
    if (literal ("false"))
    {
      v.type = Value::Type::Bool;
      return v;
    }
    if (literal ("null"))
      return v;
    // number: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
    const std::size_t start = i_;
    if (s_[i_] == '-')
      ++i_;
    auto digits = [&] () {
      const std::size_t d = i_;
      while (i_ < s_.size () && std::isdigit (static_cast<unsigned char> (s_[i_])))
        ++i_;
      return i_ - d;
    };
    if (i_ < s_.size () && s_[i_] == '0')
      ++i_;
    else if (digits () == 0)
      fail ("bad value");
    if (i_ < s_.size () && s_[i_] == '.')
    {
      ++i_;
      if (digits () == 0)
        fail ("bad fraction");
    }
    if (i_ < s_.size () && (s_[i_] == 'e' || s_[i_] == 'E'))
    {
      ++i_;
      if (i_ < s_.size () && (s_[i_] == '+' || s_[i_] == '-'))
        ++i_;
      if (digits () == 0)
        fail ("bad exponent");
    }
    v.type = Value::Type::Number;
    v.text = s_.substr (start, i_ - start);
    v.number = std::strtod (v.text.c_str (), nullptr);
    return v;
  }

  const std::string& s_;
  std::size_t i_ = 0;
};

inline Value
parse (const std::string& s)
{
  return Parser (s).parse ();
}
} // namespace mini_json
