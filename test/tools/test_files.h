// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Small file helpers shared by the CLI tests.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace test_files
{
inline std::string
readFile (const std::filesystem::path& p)
{
  std::ifstream f (p, std::ios::binary);
  return std::string (std::istreambuf_iterator<char> (f), std::istreambuf_iterator<char> ());
}

inline void
writeFile (const std::filesystem::path& p, const std::string& text)
{
  std::ofstream f (p, std::ios::binary);
  f << text;
}

inline std::vector<std::string>
lines (const std::string& text)
{
  std::vector<std::string> out;
  std::istringstream in (text);
  std::string l;
  while (std::getline (in, l))
    out.push_back (l);
  return out;
}
#ifdef TEST_WORK_DIR
/** \brief An empty directory for the running test: TEST_WORK_DIR/<prefix><test name>. */
inline std::filesystem::path
freshTestDir (const std::string& prefix)
{
  const std::filesystem::path dir =
    std::filesystem::path (TEST_WORK_DIR) / (prefix + ::testing::UnitTest::GetInstance ()->current_test_info ()->name ());
  std::filesystem::remove_all (dir);
  std::filesystem::create_directories (dir);
  return dir;
}
#endif
} // namespace test_files
