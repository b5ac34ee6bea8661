// SPDX-License-Identifier: BSD-3-Clause
// The JSON writer of io/ on its own: the exact bytes, which pcd_collision -json promises to keep.

#include "json_writer.h"
#include "mini_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>

using pcl_probcollision::io::JsonWriter;

TEST (JsonWriter, CommasAndNesting)
{
  JsonWriter j;
  j.beginObject ();
  j.key ("a").integer (-3);
  j.key ("empty_object").beginObject ().endObject ();
  j.key ("empty_array").beginArray ().endArray ();
  j.key ("nested").beginObject ().key ("x").beginArray ().boolean (true).null ().boolean (false).endArray ();
  j.key ("y").string ("z").endObject ();
  j.key ("objects").beginArray ().beginObject ().endObject ().beginObject ().key ("k").integer (1).endObject ().endArray ();
  j.key ("last").unsignedInteger (std::numeric_limits<std::uint64_t>::max ());
  j.endObject ();
  EXPECT_EQ (j.text (), "{\"a\":-3,\"empty_object\":{},\"empty_array\":[],\"nested\":{\"x\":[true,null,false],"
                        "\"y\":\"z\"},\"objects\":[{},{\"k\":1}],\"last\":18446744073709551615}");
  EXPECT_NO_THROW (mini_json::parse (j.text ()));
}

// The shortest text that reads back as the same double: a -json line's P and distances compare
// bit for bit with the library's (they had 10 significant digits).
TEST (JsonWriter, NumbersReadBackExactlyAndAreNeverNanOrInf)
{
  JsonWriter j;
  j.numbers ({0.0, 1.0, -0.5, 0.1, 1.0 / 3.0, 123456789012.0, 1e-7, 0.003670914317123, 0.1 + 0.2,
              std::numeric_limits<double>::quiet_NaN (), std::numeric_limits<double>::infinity (),
              -std::numeric_limits<double>::infinity ()});
  EXPECT_EQ (j.text (), "[0,1,-0.5,0.1,0.3333333333333333,123456789012,1e-07,0.003670914317123,0.30000000000000004,"
                        "null,null,null]");
  EXPECT_NO_THROW (mini_json::parse (j.text ()));

  std::mt19937_64 draw (7);
  std::uniform_real_distribution<double> uniform (-1.0, 1.0);
  for (int i = 0; i < 1000; ++i)
  {
    const double value = uniform (draw) * std::pow (10.0, static_cast<int> (draw () % 40) - 20);
    JsonWriter one;
    one.number (value);
    EXPECT_EQ (std::strtod (one.text ().c_str (), nullptr), value) << one.text ();
  }
}

// Members formatted once and repeated, as pcd_collision -json writes the inputs and parameters of
// every line of a run: the same bytes as written in place.
TEST (JsonWriter, PreformattedMembersAreTheSameBytes)
{
  JsonWriter part;
  part.beginObject ().key ("inputs").beginObject ().key ("a").string ("x.pcd").endObject ();
  part.key ("k").integer (10).endObject ();
  const std::string members = part.objectMembers ();
  EXPECT_EQ (members, "\"inputs\":{\"a\":\"x.pcd\"},\"k\":10");

  JsonWriter in_place, reused;
  in_place.beginObject ().key ("p").number (0.5);
  in_place.key ("inputs").beginObject ().key ("a").string ("x.pcd").endObject ().key ("k").integer (10);
  in_place.key ("version").string ("1").endObject ();
  reused.beginObject ().key ("p").number (0.5).members (members).key ("version").string ("1").endObject ();
  EXPECT_EQ (reused.text (), in_place.text ());
  JsonWriter first;
  first.beginObject ().members (members).members ("").endObject ();
  EXPECT_EQ (first.text (), "{" + members + "}");
  EXPECT_NO_THROW (mini_json::parse (first.text ()));
  JsonWriter array;
  array.beginArray ().endArray ();
  EXPECT_EQ (array.objectMembers (), "");
}

TEST (JsonWriter, StringsAreEscaped)
{
  JsonWriter j;
  j.beginObject ().key ("q\"k").string ("a\"b\\c\nd\re\tf\x01g\x7fh/\xc3\xa9").endObject ();
  EXPECT_EQ (j.text (), "{\"q\\\"k\":\"a\\\"b\\\\c\\nd\\re\\tf\\u0001g\\u007fh/\xc3\xa9\"}");
  const mini_json::Value v = mini_json::parse (j.text ());
  EXPECT_EQ (v["q\"k"].text, "a\"b\\c\nd\re\tf\x01g\x7fh/\xc3\xa9");
}

// A file name need not be UTF-8, but JSON text must be (a byte 0xff made Python's json.loads fail
// on the whole line). Well-formed sequences are copied; each other byte becomes \udcXX.
TEST (JsonWriter, BytesThatAreNotUtf8BecomeSurrogateEscapes)
{
  const std::string valid = "\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80 \xf4\x8f\xbf\xbf";  // U+00E9, U+20AC, U+1F600, U+10FFFF
  JsonWriter ok;
  ok.string (valid);
  EXPECT_EQ (ok.text (), "\"" + valid + "\"");
  const struct
  {
    std::string bytes, json;
  } cases[] = {
      {"x\xff.pcd", "\"x\\udcff.pcd\""},                 // never a UTF-8 byte
      {"\x80", "\"\\udc80\""},                            // a stray continuation byte
      {"\xc0\xaf", "\"\\udcc0\\udcaf\""},                 // an overlong '/'
      {"\xe2\x82", "\"\\udce2\\udc82\""},                 // cut short
      {"\xe2\x82.", "\"\\udce2\\udc82.\""},               // cut short before ASCII
      {"\xed\xa0\x80", "\"\\udced\\udca0\\udc80\""},      // an encoded surrogate
      {"\xf4\x90\x80\x80", "\"\\udcf4\\udc90\\udc80\\udc80\""},  // above U+10FFFF
      {"\xe9t\xc3\xa9", "\"\\udce9t\xc3\xa9\""},              // Latin-1 beside UTF-8
  };
  for (const auto& c : cases)
  {
    JsonWriter j;
    j.string (c.bytes);
    EXPECT_EQ (j.text (), c.json) << c.bytes;
  }
}
