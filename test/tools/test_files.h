// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Small file helpers shared by the CLI tests.

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
} // namespace test_files
