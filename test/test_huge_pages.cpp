// SPDX-License-Identifier: BSD-3-Clause
// detail/huge_pages.h: the large arrays of a build offered to transparent huge pages.
#include <pcl_probcollision/detail/huge_pages.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <vector>

using namespace pcl_probcollision::detail;

TEST (HugePages, TheHelpersDoWhatTheVectorOperationsDo)
{
  const std::size_t n = (kHugePageMinBytes / sizeof (double)) * 3;  // large enough to be advised
  std::vector<double> a;
  assignHugePages (a, n, 2.5);
  ASSERT_EQ (a.size (), n);
  EXPECT_EQ (a.front (), 2.5);
  EXPECT_EQ (a.back (), 2.5);
  std::vector<int> r;
  resizeHugePages (r, 10);  // small: a plain resize
  EXPECT_EQ (r, std::vector<int> (10, 0));
  // A reservation already large enough is left alone (no reallocation, the data stays put).
  const double* before = a.data ();
  reserveHugePages (a, n / 2);
  EXPECT_EQ (a.data (), before);
  // shrinkHugePages: an exact copy, the same contents.
  std::vector<int> s;
  s.reserve (1000);
  s.assign ({3, 1, 4, 1, 5});
  shrinkHugePages (s);
  EXPECT_EQ (s, (std::vector<int> {3, 1, 4, 1, 5}));
  EXPECT_EQ (s.capacity (), s.size ());
}

#if defined(__linux__)
namespace
{
/** The VmFlags of the mapping of /proc/self/smaps that holds address, empty if none does. */
std::string
vmFlagsAt (const void* address)
{
  const auto at = reinterpret_cast<std::uintptr_t> (address);
  std::ifstream smaps ("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline (smaps, line))
  {
    unsigned long long lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head (line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-')
      inside = lo <= at && at < hi;
    else if (inside && line.rfind ("VmFlags:", 0) == 0)
      return line;
  }
  return {};
}
} // namespace

TEST (HugePages, ALargeReservationIsAdvisedWhereTheKernelHasThem)
{
  std::vector<double> v;
  reserveHugePages (v, (std::size_t{16} << 20) / sizeof (double));  // 16 MiB
  // An address in the middle lies in a whole aligned 2 MiB page of the range.
  const std::string flags = vmFlagsAt (v.data () + v.capacity () / 2);
  ASSERT_FALSE (flags.empty ()) << "no mapping holds the vector's memory";
  struct stat st {};
  const bool kernel_has_thp = stat ("/sys/kernel/mm/transparent_hugepage/enabled", &st) == 0;
  // "hg": MADV_HUGEPAGE; a kernel without transparent huge pages refuses the advice.
  EXPECT_EQ (flags.find (" hg") != std::string::npos, kernel_has_thp) << flags;
}
#endif
