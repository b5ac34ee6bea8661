// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/robust_classifier.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <functional>
#include <vector>

namespace pcl_probcollision
{
/** \brief The core query: probability that the objects behind two models collide, with B
  * placed in A's frame by T_a_b (METHOD.md 6-8).
  *
  * Traverses both hierarchies together (boxes of B mapped on the fly), fits the robust
  * separator on the union of each leaf pair reached and keeps the largest reach-weighted
  * per-point probability. Points of A have label +1. The pose is composed with the two models'
  * local origins in double, so models far from the origin lose no precision (CloudModel).
  *
  * \param[in] a model of object A (its frame is the query frame)
  * \param[in] b model of object B
  * \param[in] T_a_b rigid transform mapping B-frame points into A's frame; a rotation whose
  *            digits were rounded (R^T R within 1e-2 of the identity,
  *            detail::kRoundedRotationTolerance) is taken to its nearest rotation
  *            (detail::rigidPose), an exact one (within 1e-6) is used as given
  * \param[in] request what to compute (validated)
  * \param[out] result verdict, probability, witness (in the query frame, here A's: see
  *             CollisionResult::witness_point), counters; per-point probabilities
  *             (request.per_point) index-aligned with the clouds the models were built from;
  *             message holds the models' warnings (CloudModel::warning()) on success
  * \param[in] classifier a prebuilt classifier with request.classifier's parameters to reuse
  *            its random-feature draw across queries (optional)
  * \return result.ok(); false with status and message for a non-finite or non-rigid T_a_b,
  *         invalid request parameters, or a classifier built with other parameters than
  *         request.classifier (InvalidInput).
  * \note Thread safety: any number of calls may share the same models and classifier.
  */
bool collide (const CloudModel& a, const CloudModel& b, const Eigen::Isometry3d& T_a_b,
              const CollisionRequest& request, CollisionResult& result,
              const RobustClassifier* classifier = nullptr);

/** \brief collide() for many poses of B, spread over several threads (issue #8).
  *
  * Each pose is an independent query on the shared models and classifier; results are
  * stored by pose index, so they do not depend on the thread count or on scheduling.
  *
  * \param[in] a model of object A (its frame is the query frame)
  * \param[in] b model of object B
  * \param[in] T_a_b rigid transforms mapping B-frame points into A's frame, one per query
  * \param[in] request what to compute (invalid: every pose fails as in collide())
  * \param[out] results resized to T_a_b.size(); results[i] is what
  *             collide (a, b, T_a_b[i], request, results[i], classifier) gives (timings aside)
  * \param[in] threads worker threads: 0 = std::thread::hardware_concurrency() (at least 1),
  *            never more than poses; negative throws pcl::BadArgumentException
  * \param[in] classifier as for collide(); without one, a single classifier with
  *            request.classifier's parameters is drawn and shared by all poses
  * \return true when every pose succeeded; a failing pose has its own status and message and
  *         the others are still answered.
  * \throws pcl::BadArgumentException for threads < 0. An exception escaping collide() in a
  *         worker (std::bad_alloc) stops the batch and is rethrown here after every worker
  *         has stopped (the earliest pose's); results are then incomplete.
  */
bool collideBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
                   const CollisionRequest& request, std::vector<CollisionResult>& results, int threads = 0,
                   const RobustClassifier* classifier = nullptr);

/** \brief collideBatch() that hands each result over while the later poses are answered:
  * ready (i) is called once for every pose, in pose order, as soon as results[i] and every
  * result before it are final.
  *
  * The answers are those of the other overload, whatever the thread count. Calls of ready never
  * overlap; they are made on the batch's threads (the calling one included), so a slow ready
  * holds up one worker, and it may move from or clear results[i] (a caller that prints or stores
  * each answer then keeps none of them). A worker does not start a pose 64 times the thread count
  * or more past the first one not yet handed over, so a slow pose holds back a bounded number of
  * finished results. With an empty ready this is the other overload.
  * \return true when every pose succeeded (counted before ready sees each result)
  * \throws pcl::BadArgumentException for threads < 0. An exception from ready stops the batch:
  *         no later pose is handed over, and it is rethrown here once every worker has stopped
  *         (an exception escaping collide() likewise). */
bool collideBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
                   const CollisionRequest& request, std::vector<CollisionResult>& results, int threads,
                   const RobustClassifier* classifier, const std::function<void (std::size_t)>& ready);

/** \brief The verdict of a probability under a request's thresholds (Unknown for NaN, "not
  * computed"): the one rule every verdict, label and colour of the library and its tools derives
  * from.
  * \throws pcl::BadArgumentException for thresholds validate() refuses (validateThresholds()),
  *         and for a probability outside [0, 1] (infinite ones included), naming it. */
Verdict verdictFor (double probability, const CollisionRequest& request);
} // namespace pcl_probcollision
