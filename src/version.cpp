// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/version.h>

const char*
pcl_probcollision::libraryVersion ()
{
  return PCL_PROBCOLLISION_VERSION_STRING;
}
