// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/detail/parallel.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <optional>
#include <vector>

namespace pcl_probcollision
{
namespace
{
/** \brief Whether collide() would get as far as classifying, i.e. need a classifier. */
bool
needsClassifier (const CollisionRequest& request)
{
  try
  {
    request.validate ();
  }
  catch (const pcl::PCLException&)
  {
    return false;  // collide() reports it on every pose, as a single query would
  }
  return true;
}
} // namespace

bool
collideBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
              const CollisionRequest& request, std::vector<CollisionResult>& results, int threads,
              const RobustClassifier* classifier)
{
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::collideBatch] threads = " << threads
                             << " must be >= 0 (0: one per hardware thread)");
  const std::size_t count = T_a_b.size ();
  results.assign (count, CollisionResult ());
  if (count == 0)
    return true;

  // Drawing the random features is costly: one classifier for every pose. collide() would draw
  // the same one (its parameters and seed are the request's), so results do not change.
  std::optional<RobustClassifier> shared;
  if (!classifier && needsClassifier (request))
    classifier = &shared.emplace (request.classifier);

  // Poses are independent and their results stored by index: which thread answers a pose, and
  // when, changes nothing. Poses are handed out one at a time since their costs differ widely
  // (a free pose prunes at the roots, a contact fits hundreds of leaf pairs); a failure rethrows
  // the earliest pose's.
  detail::parallelFor (count, detail::threadCount (threads), [&] (std::size_t i, std::size_t) {
    collide (a, b, T_a_b[i], request, results[i], classifier);
  });
  return std::all_of (results.begin (), results.end (), [] (const CollisionResult& r) { return r.ok (); });
}
} // namespace pcl_probcollision
