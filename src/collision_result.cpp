// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision_result.h>

namespace pcl_probcollision
{
void
mapResultPoints (CollisionResult& result, const Eigen::Isometry3d& T)
{
  if (result.witness_side != 0)
  {
    result.witness_point = T * result.witness_point;
    result.witness_normal = T.linear () * result.witness_normal;
  }
  if (result.sample_distance)
  {
    result.nearest_point_a = T * result.nearest_point_a;
    result.nearest_point_b = T * result.nearest_point_b;
  }
}
} // namespace pcl_probcollision
