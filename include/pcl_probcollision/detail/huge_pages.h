// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pcl_probcollision
{
namespace detail
{
/** \brief Arrays at least this large are offered to transparent huge pages: one 2 MiB page (a
  * range holds a whole aligned one from 2 MiB on, always from 4 MiB on). */
constexpr std::size_t kHugePageMinBytes = std::size_t{2} << 20;

/** \brief Asks the kernel to back [data, data + bytes) with transparent huge pages
  * (madvise(MADV_HUGEPAGE) on the whole 2 MiB pages inside it; Linux only, a hint that may be
  * ignored, nothing below kHugePageMinBytes). Call it before the array's first write: every
  * first touch of a 4 KiB page is a page fault, and in this project's virtual machines a fault
  * costs about 11 us against 0.2 us a 4 KiB share of a huge page (docs/PERFORMANCE.md: the
  * 5,000,000-point run went from 14.3-17.0 s to 11.0-12.2 s on such a VM). A system whose THP
  * setting is "always" needs none of this; "madvise" (this project's VMs) does; "never" ignores
  * it. */
inline void
adviseHugePages (const void* data, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (!data || bytes < kHugePageMinBytes)
    return;
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t> (data) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t> (data) + bytes) & ~(kHuge - 1);
  if (end > begin)
    madvise (reinterpret_cast<void*> (begin), end - begin, MADV_HUGEPAGE);  // a hint: failure changes nothing
#else
  (void) data;
  (void) bytes;
#endif
}

/** \brief v.reserve(n), newly reserved memory offered to huge pages (adviseHugePages) before
  * anything is written to it; nothing when v holds n already. For the large arrays of a build:
  * then resize() or assign(). */
template <typename Vector>
void
reserveHugePages (Vector& v, std::size_t n)
{
  if (v.capacity () >= n)
    return;
  v.reserve (n);
  adviseHugePages (v.data (), v.capacity () * sizeof (typename Vector::value_type));
}

/** \brief v.resize(n) on memory offered to huge pages (reserveHugePages). */
template <typename Vector>
void
resizeHugePages (Vector& v, std::size_t n)
{
  reserveHugePages (v, n);
  v.resize (n);
}

/** \brief v.shrink_to_fit(), the exact copy on memory offered to huge pages (reserveHugePages). */
template <typename Vector>
void
shrinkHugePages (Vector& v)
{
  if (v.capacity () == v.size ())
    return;
  Vector exact;
  reserveHugePages (exact, v.size ());
  exact.assign (v.begin (), v.end ());
  v.swap (exact);
}

/** \brief v.assign(n, value) on memory offered to huge pages (reserveHugePages). */
template <typename Vector>
void
assignHugePages (Vector& v, std::size_t n, const typename Vector::value_type& value)
{
  reserveHugePages (v, n);
  v.assign (n, value);
}
} // namespace detail
} // namespace pcl_probcollision
