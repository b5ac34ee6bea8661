// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/point_types.h>

namespace pcl_probcollision
{
std::ostream&
operator<< (std::ostream& os, const Covariance& c)
{
  return os << "(" << c.xx << "," << c.xy << "," << c.xz << "; " << c.yy << "," << c.yz << "; "
            << c.zz << ")";
}
} // namespace pcl_probcollision
