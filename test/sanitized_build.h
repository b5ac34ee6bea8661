// SPDX-License-Identifier: BSD-3-Clause
// PCL_PC_SANITIZED is defined in AddressSanitizer and ThreadSanitizer builds (scripts/
// ci-reliability.sh), where tests run smaller workloads of the same contracts: instrumented code
// is 10-50x slower. g++ defines __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__; clang 14 defines
// neither and answers __has_feature instead, so both are asked.
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PCL_PC_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define PCL_PC_SANITIZED 1
#endif
#endif
