// SPDX-License-Identifier: BSD-3-Clause
// detail/parallel.h: the work loop of every threaded part (batch queries, the build).
#include <pcl_probcollision/detail/parallel.h>

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

using pcl_probcollision::detail::cheapChunk;
using pcl_probcollision::detail::parallelFor;
using pcl_probcollision::detail::threadCount;

TEST (Parallel, ThreadCountReadsZeroAsEveryCore)
{
  EXPECT_GE (threadCount (0), 1u);
  EXPECT_EQ (threadCount (1), 1u);
  EXPECT_EQ (threadCount (3), 3u);
  EXPECT_EQ (threadCount (1024), 1024u);
  EXPECT_EQ (threadCount (2147483647), 1024u);  // capped: per-worker scratch is allocated up front
}

TEST (Parallel, CheapChunksGiveEveryWorkerRangesWithinBounds)
{
  // 50,000 points on two threads: eight ranges, not one (it was one range of 65,536).
  EXPECT_EQ (cheapChunk (50000, 2), 6250u);
  EXPECT_EQ (cheapChunk (1000, 2), 4096u);          // at least 4,096 items a range
  EXPECT_EQ (cheapChunk (5000000, 2), 65536u);      // at most 65,536
  EXPECT_EQ (cheapChunk (50000, 0), cheapChunk (50000, 1));  // no worker reads as one
}

TEST (Parallel, EveryItemRunsOnceOnAWorkerInRange)
{
  for (const std::size_t workers : {1u, 2u, 3u, 16u})
    for (const std::size_t count : {0u, 1u, 5u, 1000u})
    {
      std::vector<std::atomic<int>> runs (count);
      std::atomic<bool> worker_in_range (true);
      parallelFor (count, workers, [&] (std::size_t i, std::size_t w) {
        ++runs[i];
        if (w >= workers || w >= count)
          worker_in_range = false;
      });
      for (std::size_t i = 0; i < count; ++i)
        EXPECT_EQ (runs[i].load (), 1) << workers << " workers, item " << i;
      EXPECT_TRUE (worker_in_range.load ());
    }
}

TEST (Parallel, TheLowestFailingItemsExceptionIsRethrown)
{
  for (const std::size_t workers : {1u, 2u, 4u})
  {
    try
    {
      parallelFor (200, workers, [] (std::size_t i, std::size_t) {
        if (i == 37 || i == 150)
          throw std::runtime_error ("item " + std::to_string (i));
      });
      FAIL () << "no exception with " << workers << " workers";
    }
    catch (const std::runtime_error& e)
    {
      EXPECT_EQ (std::string (e.what ()), "item 37") << workers << " workers";
    }
  }
}
