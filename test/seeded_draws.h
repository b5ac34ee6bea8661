// SPDX-License-Identifier: BSD-3-Clause
// Seeded random scenes that are the same with every compiler.
//
// Never draw several numbers inside one call, as in Eigen::Vector3d (u (rng), u (rng), u (rng)):
// the order in which function arguments are evaluated is unspecified in C++ (g++ evaluates them
// right to left, clang left to right), so the "seeded" scene silently depends on the compiler.
// That is how two tests passed with g++ and failed under clang's sanitizer build
// (docs/RELIABILITY.md). Draw into named locals, one statement each, or use draw3().
#pragma once

#include <Eigen/Core>

namespace pcl_probcollision_test
{
/** \brief Three draws of dist, in the order x, y, z. */
template <typename Distribution, typename Engine>
Eigen::Vector3d
draw3 (Distribution& dist, Engine& rng)
{
  const double x = dist (rng);
  const double y = dist (rng);
  const double z = dist (rng);
  return Eigen::Vector3d (x, y, z);
}
} // namespace pcl_probcollision_test
