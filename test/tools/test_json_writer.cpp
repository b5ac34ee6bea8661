// SPDX-License-Identifier: BSD-3-Clause
// The JSON writer of io/ on its own: the exact bytes, which pcd_collision -json promises to keep.

#include "json_writer.h"
#include "mini_json.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

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

TEST (JsonWriter, NumbersHaveTenSignificantDigitsAndNeverNanOrInf)
{
  JsonWriter j;
  j.numbers ({0.0, 1.0, -0.5, 0.1, 1.0 / 3.0, 123456789012.0, 1e-7, 0.003670914317123,
              std::numeric_limits<double>::quiet_NaN (), std::numeric_limits<double>::infinity (),
              -std::numeric_limits<double>::infinity ()});
  EXPECT_EQ (j.text (), "[0,1,-0.5,0.1,0.3333333333,1.23456789e+11,1e-07,0.003670914317,null,null,null]");
  EXPECT_NO_THROW (mini_json::parse (j.text ()));
}

TEST (JsonWriter, StringsAreEscaped)
{
  JsonWriter j;
  j.beginObject ().key ("q\"k").string ("a\"b\\c\nd\re\tf\x01g\x7fh/\xc3\xa9").endObject ();
  EXPECT_EQ (j.text (), "{\"q\\\"k\":\"a\\\"b\\\\c\\nd\\re\\tf\\u0001g\\u007fh/\xc3\xa9\"}");
  const mini_json::Value v = mini_json::parse (j.text ());
  EXPECT_EQ (v["q\"k"].text, "a\"b\\c\nd\re\tf\x01g\x7fh/\xc3\xa9");
}
