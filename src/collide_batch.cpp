// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

namespace pcl_probcollision
{
namespace
{
/** \brief Threads to run: the caller's count (0: the machine's), at least one, at most one per pose. */
std::size_t
workerCount (int threads, std::size_t poses)
{
  const std::size_t wanted = threads > 0 ? static_cast<std::size_t> (threads)
                                         : std::max (1u, std::thread::hardware_concurrency ());
  return std::min (wanted, poses);
}

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
  // (a free pose prunes at the roots, a contact fits hundreds of leaf pairs).
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max ();
  std::atomic<std::size_t> next (0);
  const std::size_t workers = workerCount (threads, count);
  std::vector<std::exception_ptr> errors (workers);
  std::vector<std::size_t> error_pose (workers, kNone);
  auto work = [&] (std::size_t worker) {
    std::size_t i = kNone;
    try
    {
      while ((i = next.fetch_add (1, std::memory_order_relaxed)) < count)
        collide (a, b, T_a_b[i], request, results[i], classifier);
    }
    catch (...)
    {
      // Escaping a std::thread would terminate the program: keep it for the caller and stop
      // handing out poses, the batch is lost anyway.
      errors[worker] = std::current_exception ();
      error_pose[worker] = i;
      next.store (count, std::memory_order_relaxed);
    }
  };

  // The calling thread is worker 0, so one thread costs no thread start.
  std::vector<std::thread> pool;
  pool.reserve (workers - 1);
  for (std::size_t w = 1; w < workers; ++w)
  {
    try
    {
      pool.emplace_back (work, w);
    }
    catch (const std::system_error&)
    {
      break;  // no more threads available: the ones running take the remaining poses
    }
  }
  work (0);
  for (std::thread& t : pool)
    t.join ();

  // Several workers may have failed: rethrow the failure of the earliest pose.
  std::size_t first = kNone;
  for (std::size_t w = 0; w < workers; ++w)
    if (errors[w] && (first == kNone || error_pose[w] < error_pose[first]))
      first = w;
  if (first != kNone)
    std::rethrow_exception (errors[first]);
  return std::all_of (results.begin (), results.end (), [] (const CollisionResult& r) { return r.ok (); });
}
} // namespace pcl_probcollision
