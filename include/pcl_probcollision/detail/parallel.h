// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <limits>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief The most threads a `threads` setting starts: per-worker scratch is allocated up front,
  * and a count like INT_MAX asked for gigabytes of it (found in review). The answers do not
  * depend on the count, so the cap changes nothing but the speed of an absurd request. */
constexpr int kMaxThreads = 1024;

/** \brief Why a thread count is refused, empty when it lies in [0, kMaxThreads]: the one rule
  * pcd_collision's -threads and the Python bindings' `threads` refuse by, in words that follow
  * the option's name. The library itself throws for a negative count only and starts at most
  * kMaxThreads: a count above it asked for threads it never started (Python's
  * collide_batch(threads=10**6) read as 1,024, found by a probe). */
inline std::string
threadsRangeError (int threads)
{
  if (threads >= 0 && threads <= kMaxThreads)
    return {};
  return "must be in [0, " + std::to_string (kMaxThreads) + "] (0: one per hardware thread)";
}

/** \brief The number of threads a `threads` setting asks for: itself when > 0 (at most
  * kMaxThreads), else one per hardware thread (at least one). The one reading of the library's
  * "0 = every core". */
inline std::size_t
threadCount (int threads)
{
  return threads > 0 ? static_cast<std::size_t> (std::min (threads, kMaxThreads))
                     : std::max (1u, std::thread::hardware_concurrency ());
}

/** \brief Runs task(i, worker) for every i in [0, count) on at most `workers` threads, the
  * calling one included (worker 0), so one worker starts no thread. Items are handed out one at
  * a time in increasing order, since their costs may differ widely; a task may use per-worker
  * scratch indexed by `worker` (< workers). Callers keep results deterministic by writing each
  * item's result to its own slot. When tasks throw, the remaining items are abandoned and the
  * exception of the lowest failing item is rethrown. When no more threads can be started the
  * running ones take the remaining items. */
template <typename Task>
void
parallelFor (std::size_t count, std::size_t workers, Task&& task)
{
  workers = std::max<std::size_t> (1, std::min (workers, count));
  if (count == 0)
    return;
  if (workers == 1)
  {
    for (std::size_t i = 0; i < count; ++i)
      task (i, std::size_t{0});
    return;
  }
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max ();
  std::atomic<std::size_t> next (0);
  std::vector<std::exception_ptr> errors (workers);
  std::vector<std::size_t> error_item (workers, kNone);
  auto work = [&] (std::size_t worker) {
    std::size_t i = kNone;
    try
    {
      while ((i = next.fetch_add (1, std::memory_order_relaxed)) < count)
        task (i, worker);
    }
    catch (...)
    {
      // Escaping a std::thread would terminate the program: keep it for the caller.
      errors[worker] = std::current_exception ();
      error_item[worker] = i;
      next.store (count, std::memory_order_relaxed);
    }
  };
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
      break;
    }
  }
  work (0);
  for (std::thread& t : pool)
    t.join ();
  std::size_t first = kNone;
  for (std::size_t w = 0; w < workers; ++w)
    if (errors[w] && (first == kNone || error_item[w] < error_item[first]))
      first = w;
  if (first != kNone)
    std::rethrow_exception (errors[first]);
}

/** \brief The range size for parallelChunks() over `count` cheap items on `workers`: about four
  * ranges a worker, so that a cloud of 50,000 points is not one range on one thread (a fixed
  * 65,536 left the second thread idle there), but at least 4,096 items (a range must outweigh a
  * hand-out) and at most 65,536. */
inline std::size_t
cheapChunk (std::size_t count, std::size_t workers)
{
  const std::size_t ranges = 4 * std::max<std::size_t> (workers, 1);
  return std::min<std::size_t> (65536, std::max<std::size_t> (4096, (count + ranges - 1) / ranges));
}

/** \brief task(c, begin, end) for the consecutive ranges [begin, end) of `chunk` items (the last
  * one shorter) that cover [0, count), c the range's number, on parallelFor's workers: for loops
  * over many cheap items, where one item is not worth handing out alone. */
template <typename Task>
void
parallelChunks (std::size_t count, std::size_t chunk, std::size_t workers, Task&& task)
{
  parallelFor ((count + chunk - 1) / chunk, workers, [&] (std::size_t c, std::size_t) {
    task (c, c * chunk, std::min (count, (c + 1) * chunk));
  });
}
} // namespace detail
} // namespace pcl_probcollision
