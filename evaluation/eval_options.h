// SPDX-License-Identifier: BSD-3-Clause
// The evaluation tools' option values (evaluate_collision's options, dump_primitive's, and
// bench_performance's BENCH_PERFORMANCE_NOISE): one reader per rule, each value read whole by the
// command-line tool's parsers (tools/cli_options.h: "5x", "2.5" and "-1" are not whole numbers,
// "1O", "nan" and hex floats not numbers), each refusal a std::invalid_argument naming the option
// and the value. Before 2026-12-04 evaluate_collision read these with std::stoull / std::stod
// (truncating "5x" to 5, wrapping "-1", "stoull" as the only message) and bench_performance and
// dump_primitive each kept a reader of their own.
#pragma once

#include <cli_options.h>

#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pcl_probcollision_eval
{
namespace options
{
/** \brief The items of a comma-separated value. An empty value or item is refused: an unset shell
  * variable (`--noise "$LEVELS"`) read as "the default" or "none" without a word. `name` is what
  * the message names ("option --only"). */
inline std::vector<std::string>
items (const std::string& name, const std::string& text)
{
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true)
  {
    const std::size_t comma = text.find (',', start);
    out.push_back (text.substr (start, comma == std::string::npos ? std::string::npos : comma - start));
    if (out.back ().empty ())
      throw std::invalid_argument (name + ": '" + text + "' has an empty item (a comma-separated list of one or more)");
    if (comma == std::string::npos)
      return out;
    start = comma + 1;
  }
}

/** \brief A whole number from 0 to max, decimal digits only. */
inline std::uint64_t
wholeNumber (const std::string& name, const std::string& text, std::uint64_t max = std::numeric_limits<std::uint64_t>::max ())
{
  std::uint64_t v = 0;
  if (!pcd_collision::parseUint64 (text, v) || v > max)
    throw std::invalid_argument (name + ": '" + text + "' is not a whole number from 0 to " + std::to_string (max));
  return v;
}

/** \brief A finite number at least `min`, or strictly above it with `above`. */
inline double
number (const std::string& name, const std::string& text, double min, bool above)
{
  double v = 0.0;
  if (!pcd_collision::parseDouble (text, v))
    throw std::invalid_argument (name + ": '" + text + "' is not a finite number");
  if (above ? !(v > min) : !(v >= min))
  {
    std::ostringstream what;
    what << name << ": " << text << " must be " << (above ? "above " : "at least ") << min;
    throw std::invalid_argument (what.str ());
  }
  return v;
}

/** \brief Comma-separated numbers, each as `number` takes it. */
inline std::vector<double>
numbers (const std::string& name, const std::string& text, double min, bool above)
{
  std::vector<double> out;
  for (const std::string& item : items (name, text))
    out.push_back (number (name, item, min, above));
  return out;
}
} // namespace options
} // namespace pcl_probcollision_eval
