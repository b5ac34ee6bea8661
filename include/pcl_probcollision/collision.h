// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/probabilistic_bvh.h>
#include <pcl_probcollision/robust_classifier.h>

#include <Eigen/Geometry>

namespace pcl_probcollision
{
/** \brief The core query: probability that the objects behind two prebuilt hierarchies
  * collide, with B placed in A's frame by T_a_b (METHOD.md 6-8).
  *
  * Traverses both hierarchies together (boxes of B mapped on the fly), fits the robust
  * separator on the union of each leaf pair reached and keeps the largest reach-weighted
  * per-point probability. Points of A have label +1.
  *
  * \param[in] a hierarchy of object A (its frame is the query frame)
  * \param[in] b hierarchy of object B
  * \param[in] T_a_b rigid transform mapping B-frame points into A's frame
  * \param[in] request what to compute (validated)
  * \param[out] result verdict, probability, witness in A's frame, counters; per-point
  *             probabilities (request.per_point) index-aligned with a.cloud() and b.cloud()
  * \param[in] classifier a prebuilt classifier with request.classifier's parameters to reuse
  *            its random-feature draw across queries (optional)
  * \return result.ok(); false with status and message for an empty hierarchy, a non-finite or
  *         non-rigid T_a_b, or invalid request parameters.
  * \note Thread safety: any number of calls may share the same hierarchies and classifier.
  */
bool collide (const ProbabilisticBVH& a, const ProbabilisticBVH& b, const Eigen::Isometry3d& T_a_b,
              const CollisionRequest& request, CollisionResult& result,
              const RobustClassifier* classifier = nullptr);

/** \brief The verdict of a probability under a request's thresholds (Unknown for NaN). */
Verdict verdictFor (double probability, const CollisionRequest& request);
} // namespace pcl_probcollision
