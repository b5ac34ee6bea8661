// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/detail/parallel.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <vector>

namespace pcl_probcollision
{
namespace
{
/** \brief Poses a worker may answer ahead of the first one not yet handed over, per worker: a
  * slow pose then holds back at most this many finished results (each may carry per-point
  * arrays), while the others keep every thread busy. pcd_collision answered chunks of this many
  * poses a thread before answers were streamed. */
constexpr std::size_t kStreamWindowPerWorker = 64;

/** \brief The classifier a batch shares among its threads: the last one drawn, kept for the
  * next batch with the same parameters (the same parameters and seed draw the same features, so
  * answers do not change). A draw costs about 35 us, more than a batch of a few poses far from
  * contact: a batch of one pose took 37 us from Python against 1.8 us for collide(), whose
  * thread keeps its own (a probe, 2026-12-06). Batches running at once share it; it is never
  * changed once drawn. */
std::shared_ptr<const RobustClassifier>
batchClassifier (const ClassifierParams& params)
{
  static std::mutex mutex;
  static std::shared_ptr<const RobustClassifier> last;
  const std::lock_guard<std::mutex> lock (mutex);
  if (!last || last->getParams () != params)
    last = std::make_shared<const RobustClassifier> (params);
  return last;
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

/** \brief Hands items finished in any order over to `ready` in index order. done (i) marks item i
  * finished; the thread that finds the next items in order finished calls ready for them, one call
  * at a time and outside the lock, so that the other workers keep finishing items meanwhile.
  * waitForRoom (i) holds a worker about to start item i while i lies `window` or more items past
  * the next one to hand over. stop () ends the handing over: waits return false at once. An
  * exception from ready stops it too and leaves done () to its caller. */
class InOrderHandover
{
public:
  InOrderHandover (std::size_t count, std::size_t window, const std::function<void (std::size_t)>& ready)
    : done_ (count, 0), window_ (window), ready_ (ready)
  {}

  bool
  waitForRoom (std::size_t i)
  {
    std::unique_lock<std::mutex> lock (mutex_);
    room_.wait (lock, [&] { return stopped_ || i < next_ + window_; });
    return !stopped_;
  }

  void
  done (std::size_t i)
  {
    std::unique_lock<std::mutex> lock (mutex_);
    done_[i] = 1;
    if (handing_ || stopped_)
      return;  // the thread handing over meets item i in its turn
    handing_ = true;
    while (!stopped_ && next_ < done_.size () && done_[next_])
    {
      const std::size_t item = next_;
      lock.unlock ();
      try
      {
        ready_ (item);
      }
      catch (...)
      {
        lock.lock ();
        handing_ = false;
        stopped_ = true;
        room_.notify_all ();
        throw;
      }
      lock.lock ();
      ++next_;
      room_.notify_all ();
    }
    handing_ = false;
  }

  void
  stop ()
  {
    const std::lock_guard<std::mutex> lock (mutex_);
    stopped_ = true;
    room_.notify_all ();
  }

private:
  std::mutex mutex_;
  std::condition_variable room_;
  std::vector<char> done_;
  std::size_t next_ = 0;  ///< the first item not yet handed over
  std::size_t window_;
  bool handing_ = false;  ///< a thread is handing items over
  bool stopped_ = false;
  const std::function<void (std::size_t)>& ready_;
};

/** \brief Both collideBatch() overloads: the plain batch without ready, the streamed one with it. */
bool
runBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
          const CollisionRequest& request, std::vector<CollisionResult>& results, int threads,
          const RobustClassifier* classifier, const std::function<void (std::size_t)>* ready)
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
  std::shared_ptr<const RobustClassifier> shared;
  if (!classifier && needsClassifier (request))
    classifier = (shared = batchClassifier (request.classifier)).get ();

  // Poses are independent and their results stored by index: which thread answers a pose, and
  // when, changes nothing. Poses are handed out one at a time since their costs differ widely
  // (a free pose prunes at the roots, a contact fits hundreds of leaf pairs); a failure rethrows
  // the earliest pose's.
  const std::size_t workers = std::min (count, detail::threadCount (threads));
  if (!ready)
  {
    detail::parallelFor (count, workers, [&] (std::size_t i, std::size_t) {
      collide (a, b, T_a_b[i], request, results[i], classifier);
    });
    return std::all_of (results.begin (), results.end (), [] (const CollisionResult& r) { return r.ok (); });
  }
  InOrderHandover handover (count, kStreamWindowPerWorker * workers, *ready);
  std::atomic<std::size_t> failed (0);  // ready may clear a result before the end
  detail::parallelFor (count, workers, [&] (std::size_t i, std::size_t) {
    try
    {
      if (!handover.waitForRoom (i))
        return;
      if (!collide (a, b, T_a_b[i], request, results[i], classifier))
        failed.fetch_add (1, std::memory_order_relaxed);
      handover.done (i);
    }
    catch (...)
    {
      handover.stop ();  // no worker may wait for this pose
      throw;
    }
  });
  return failed.load () == 0;
}
} // namespace

bool
collideBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
              const CollisionRequest& request, std::vector<CollisionResult>& results, int threads,
              const RobustClassifier* classifier)
{
  return runBatch (a, b, T_a_b, request, results, threads, classifier, nullptr);
}

bool
collideBatch (const CloudModel& a, const CloudModel& b, const std::vector<Eigen::Isometry3d>& T_a_b,
              const CollisionRequest& request, std::vector<CollisionResult>& results, int threads,
              const RobustClassifier* classifier, const std::function<void (std::size_t)>& ready)
{
  return runBatch (a, b, T_a_b, request, results, threads, classifier, ready ? &ready : nullptr);
}
} // namespace pcl_probcollision
