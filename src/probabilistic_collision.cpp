// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/probabilistic_collision.h>
#include <pcl_probcollision/impl/probabilistic_collision.hpp>

#include <pcl/impl/instantiate.hpp>

#ifndef PCL_NO_PRECOMPILE
PCL_INSTANTIATE (ProbabilisticCollision, PCL_PROBCOLLISION_POINT_TYPES)
#endif
