// SPDX-License-Identifier: BSD-3-Clause
#include <gtest/gtest.h>
// Filled in by the component that lands next.
TEST (Placeholder, BuildsAndLinks) { EXPECT_EQ (1 + 1, 2); }
