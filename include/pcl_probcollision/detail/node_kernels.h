// SPDX-License-Identifier: BSD-3-Clause
// The per-point passes of a hierarchy node's build (METHOD.md 8.1-8.4): projections on the box
// axes with their standard deviations, then each point's outside probability. Defined in
// src/detail/node_kernels.cpp, compiled per instruction set (target_clones) without FMA
// contraction, so that every clone computes the same bits as the scalar code did: the model
// is the same on any x86-64 machine.
// Internal: not API.
#pragma once

#include <pcl_probcollision/detail/leakage.h>
#include <pcl_probcollision/uncertain_points.h>

#include <Eigen/Core>

#include <cstddef>

namespace pcl_probcollision
{
namespace detail
{
/** \brief What nodeProjections() finds besides the per-point arrays: per box axis the inflated
  * extents lo/hi (min of q - k_sigma s, max of q + k_sigma s), the largest deviation and the
  * range of the projections. */
struct NodeExtents
{
  double lo[3], hi[3], s_max[3], q_min[3], q_max[3];
};

/** \brief The projection pass of points[0..m) of a node with centre mean and box axes a_k =
  * axes.col(k) (METHOD.md 8.1, 8.3): qk[i] = a_k^T (x_i - mean) and sk[i] = sqrt(max(0, a_k^T
  * Sigma_i a_k)) (arrays of m, overlapping nothing), and their extremes. means holds the x, y, z
  * of each point in turn (a std::vector<Eigen::Vector3d>'s data). */
void nodeProjections (std::size_t m, const int* points, const double* means,
                      const PackedCovariance* covariances, const Eigen::Vector3d& mean,
                      const Eigen::Matrix3d& axes, double k_sigma, double* q0, double* q1, double* q2,
                      double* s0, double* s1, double* s2, NodeExtents& out);

/** \brief out[i] = P_x of point i of a node (METHOD.md 8.4) from nodeProjections()'s arrays qk and
  * sk, for the box [lo, hi] in box coordinates: per axis the outside probability Phi(-z_lo) +
  * Phi(-z_hi) with the tabulated tail (normalTailTabulated()), z the distances to the two faces
  * in the point's deviations, combined by bound. MinSlab (the maximum) leaves out the axes that
  * cannot attain it: with d_k = min(z_lo, z_hi) (the point is inside its box), axis k's outside
  * probability lies in [Phi(-d_k), 2 Phi(-d_k)], and Phi(-d - 1) < Phi(-d) / 2 for d >= 0, so
  * an axis with d_k >= min_j d_j + 1 is strictly below the maximum. */
void nodeOutside (std::size_t m, const double* q0, const double* q1, const double* q2, const double* s0,
                  const double* s1, const double* s2, const double* lo, const double* hi, LeakageBound bound,
                  double* out);
} // namespace detail
} // namespace pcl_probcollision
