// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <exception>
#include <string>

namespace pcl_probcollision
{
/** \brief The text of an exception as a user should read it.
  *
  * PCL_THROW_EXCEPTION makes what() "function in /source/path/file.cpp @ line : description";
  * the build machine's paths mean nothing to a user and leak into logs, so for a
  * pcl::PCLException this returns the description alone (our descriptions name the class and
  * method themselves, "[pcl_probcollision::Class::method] ..."). Any other exception gives its
  * what() unchanged. Every message the library puts in a result, and every one the tools print,
  * goes through here.
  */
std::string errorMessage (const std::exception& e);
} // namespace pcl_probcollision
