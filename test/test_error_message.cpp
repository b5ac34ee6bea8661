// SPDX-License-Identifier: BSD-3-Clause
// errorMessage() (error_message.h): a pcl::PCLException loses PCL's "function in /path/file @
// line : " preamble and keeps its description whole; any other exception keeps its what().
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/error_message.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

using pcl_probcollision::errorMessage;

namespace
{
/** \brief errorMessage() of what `thrower` throws, caught as std::exception; also returns its
  * what() in `what`. */
template <typename Thrower>
std::string
messageOf (Thrower thrower, std::string& what)
{
  try
  {
    thrower ();
  }
  catch (const std::exception& e)
  {
    what = e.what ();
    return errorMessage (e);
  }
  ADD_FAILURE () << "nothing was thrown";
  return {};
}

void
throwBadArgument ()
{
  PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::Test::method] k " << 0 << " must be >= 1");
}
} // namespace

TEST (ErrorMessage, StripsThePreambleOfPclThrowException)
{
  std::string what;
  const std::string message = messageOf (throwBadArgument, what);
  EXPECT_EQ (message, "[pcl_probcollision::Test::method] k 0 must be >= 1");
  // The preamble was there: the function, this file's path and a line number.
  EXPECT_NE (what.find (__FILE__), std::string::npos) << what;
  EXPECT_NE (what.find ("throwBadArgument"), std::string::npos) << what;
  EXPECT_NE (what.find (" @ "), std::string::npos) << what;
  EXPECT_EQ (message.find (__FILE__), std::string::npos) << message;
}

TEST (ErrorMessage, StripsThePreambleOfEveryPclExceptionType)
{
  std::string what;
  EXPECT_EQ (messageOf ([] { PCL_THROW_EXCEPTION (pcl::IOException, "cannot read 'a.pcd'"); }, what),
             "cannot read 'a.pcd'");
  EXPECT_EQ (messageOf ([] { PCL_THROW_EXCEPTION (pcl::InitFailedException, "no input"); }, what), "no input");
  EXPECT_EQ (messageOf ([] { PCL_THROW_EXCEPTION (pcl::PCLException, "plain"); }, what), "plain");
}

TEST (ErrorMessage, KeepsADescriptionThatLooksLikeAPreamble)
{
  // Only the leading preamble goes: the same words inside the description stay.
  const std::string description = "f in /tmp/x.cpp @ 3 : ratio 1 : 2 @ 4";
  std::string what;
  EXPECT_EQ (messageOf ([&] { PCL_THROW_EXCEPTION (pcl::BadArgumentException, description); }, what), description);
  EXPECT_EQ (what.size (), what.find (description) + description.size ()) << what;  // what() ends with it
  EXPECT_GT (what.size (), description.size ()) << what;
}

TEST (ErrorMessage, KeepsAnEmptyDescriptionEmpty)
{
  std::string what;
  EXPECT_EQ (messageOf ([] { PCL_THROW_EXCEPTION (pcl::BadArgumentException, ""); }, what), "");
  EXPECT_FALSE (what.empty ());
}

TEST (ErrorMessage, StripsTheShorterPreambleOfAPartlyFilledException)
{
  // PCLException's own arguments are optional: no function, no file, no line.
  EXPECT_EQ (errorMessage (pcl::PCLException ("bare")), "bare");
  EXPECT_EQ (std::string (pcl::PCLException ("bare").what ()), ": bare");
  // A file without a line, and a function without a file.
  EXPECT_EQ (errorMessage (pcl::IOException ("no line", "/src/file.cpp", "void f()", 0)), "no line");
  EXPECT_EQ (errorMessage (pcl::IOException ("no file", nullptr, "void f()", 12)), "no file");
}

TEST (ErrorMessage, LeavesOtherExceptionsUnchanged)
{
  // Even a what() shaped like PCL's preamble: only a pcl::PCLException has one to strip.
  const std::string text = "void f() in /src/file.cpp @ 12 : description";
  EXPECT_EQ (errorMessage (std::runtime_error (text)), text);
  EXPECT_EQ (errorMessage (std::invalid_argument ("bad -k")), "bad -k");
  EXPECT_EQ (errorMessage (std::runtime_error ("")), "");
  std::string what;
  EXPECT_EQ (messageOf ([] { throw std::out_of_range ("index 7"); }, what), "index 7");
  EXPECT_EQ (what, "index 7");
}

TEST (ErrorMessage, ALibraryExceptionReadsFromItsClassPrefix)
{
  pcl_probcollision::CollisionRequest request;
  request.free_below = 0.75;
  std::string what;
  const std::string message = messageOf ([&] { request.validate (); }, what);
  EXPECT_EQ (message.rfind ("[pcl_probcollision::CollisionRequest::validate] free_below 0.75", 0), 0u) << message;
  EXPECT_EQ (message.find (".cpp"), std::string::npos) << message;  // no build path
  EXPECT_NE (what.find (".cpp"), std::string::npos) << what;
}
