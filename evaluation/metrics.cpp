// SPDX-License-Identifier: BSD-3-Clause
#include "metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace pcl_probcollision_eval
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();

void
requireSameSize (std::size_t a, std::size_t b, const char* what)
{
  if (a != b)
    throw std::invalid_argument (std::string (what) + ": inputs differ in size (" + std::to_string (a) +
                                 " and " + std::to_string (b) + ")");
}

bool
anyNaN (const std::vector<double>& values)
{
  return std::any_of (values.begin (), values.end (), [] (double v) { return std::isnan (v); });
}

/** \brief 1-based ranks of `values`, tied values sharing the mean of their ranks. */
std::vector<double>
midRanks (const std::vector<double>& values)
{
  std::vector<std::size_t> order (values.size ());
  std::iota (order.begin (), order.end (), std::size_t{0});
  std::sort (order.begin (), order.end (), [&] (std::size_t i, std::size_t j) { return values[i] < values[j]; });
  std::vector<double> rank (values.size ());
  for (std::size_t first = 0; first < order.size ();)
  {
    std::size_t last = first + 1;  // one past the tie group
    while (last < order.size () && values[order[last]] == values[order[first]])
      ++last;
    // Ranks first+1 .. last, their mean:
    const double mid = 0.5 * static_cast<double> (first + 1 + last);
    for (std::size_t k = first; k < last; ++k)
      rank[order[k]] = mid;
    first = last;
  }
  return rank;
}
} // namespace

double
rocAuc (const std::vector<double>& score, const std::vector<bool>& positive)
{
  requireSameSize (score.size (), positive.size (), "rocAuc");
  if (anyNaN (score))
    return kNaN;
  const auto n_pos = static_cast<double> (std::count (positive.begin (), positive.end (), true));
  const double n_neg = static_cast<double> (positive.size ()) - n_pos;
  if (n_pos == 0.0 || n_neg == 0.0)
    return kNaN;
  // Mann-Whitney U of the positives = (sum of their ranks) - n_pos (n_pos + 1) / 2; with
  // mid-ranks every tied positive-negative pair contributes exactly 1/2.
  const std::vector<double> rank = midRanks (score);
  double rank_sum = 0.0;
  for (std::size_t i = 0; i < rank.size (); ++i)
    if (positive[i])
      rank_sum += rank[i];
  const double u = rank_sum - 0.5 * n_pos * (n_pos + 1.0);
  return u / (n_pos * n_neg);
}

double
brierScore (const std::vector<double>& probability, const std::vector<bool>& outcome)
{
  requireSameSize (probability.size (), outcome.size (), "brierScore");
  if (probability.empty ())
    return kNaN;
  double sum = 0.0;
  for (std::size_t i = 0; i < probability.size (); ++i)
  {
    const double e = probability[i] - (outcome[i] ? 1.0 : 0.0);
    sum += e * e;
  }
  return sum / static_cast<double> (probability.size ());
}

std::vector<ReliabilityBin>
reliabilityBins (const std::vector<double>& probability, const std::vector<bool>& outcome, std::size_t bins)
{
  requireSameSize (probability.size (), outcome.size (), "reliabilityBins");
  if (bins == 0)
    throw std::invalid_argument ("reliabilityBins: bins must be positive");
  std::vector<ReliabilityBin> out (bins);
  std::vector<double> sum_p (bins, 0.0);
  std::vector<double> sum_o (bins, 0.0);
  const auto n_bins = static_cast<double> (bins);
  for (std::size_t i = 0; i < probability.size (); ++i)
  {
    if (std::isnan (probability[i]))
      continue;
    const double p = std::clamp (probability[i], 0.0, 1.0);
    // floor(p * bins), with p = 1 (and rounding just below it) kept in the last bin.
    const std::size_t b = std::min (static_cast<std::size_t> (p * n_bins), bins - 1);
    ++out[b].count;
    sum_p[b] += p;
    sum_o[b] += outcome[i] ? 1.0 : 0.0;
  }
  for (std::size_t b = 0; b < bins; ++b)
  {
    out[b].lo = static_cast<double> (b) / n_bins;
    out[b].hi = static_cast<double> (b + 1) / n_bins;
    const auto count = static_cast<double> (out[b].count);
    out[b].mean_predicted = out[b].count > 0 ? sum_p[b] / count : kNaN;
    out[b].observed = out[b].count > 0 ? sum_o[b] / count : kNaN;
  }
  return out;
}

double
percentile (std::vector<double> values, double percent)
{
  if (!(percent >= 0.0 && percent <= 100.0))
    throw std::invalid_argument ("percentile: percent must be in [0, 100]");
  if (values.empty () || anyNaN (values))
    return kNaN;
  std::sort (values.begin (), values.end ());
  const double h = static_cast<double> (values.size () - 1) * percent / 100.0;
  const auto lo = static_cast<std::size_t> (std::floor (h));
  const std::size_t hi = std::min (lo + 1, values.size () - 1);
  return values[lo] + (h - static_cast<double> (lo)) * (values[hi] - values[lo]);
}

TimeSummary
summarizeTimes (const std::vector<double>& times)
{
  TimeSummary s;
  s.median = percentile (times, 50.0);
  s.p90 = percentile (times, 90.0);
  s.p99 = percentile (times, 99.0);
  s.max = percentile (times, 100.0);
  return s;
}

MeanStd
meanStd (const std::vector<double>& values)
{
  if (values.empty ())
    return {kNaN, kNaN};
  const auto n = static_cast<double> (values.size ());
  const double mean = std::accumulate (values.begin (), values.end (), 0.0) / n;
  if (values.size () == 1)
    return {mean, std::isnan (mean) ? kNaN : 0.0};
  // Two passes: the centred sum is accurate where sum(x^2) - n mean^2 would cancel.
  double ss = 0.0;
  for (double v : values)
    ss += (v - mean) * (v - mean);
  return {mean, std::sqrt (ss / (n - 1.0))};
}

double
flipRate (const std::vector<std::vector<bool>>& is_free)
{
  double sum = 0.0;
  std::size_t poses = 0;
  for (const std::vector<bool>& verdicts : is_free)
  {
    if (verdicts.empty ())
      continue;
    const auto n = static_cast<double> (verdicts.size ());
    const auto k = static_cast<double> (std::count (verdicts.begin (), verdicts.end (), true));
    sum += std::min (k, n - k) / n;
    ++poses;
  }
  return poses > 0 ? sum / static_cast<double> (poses) : kNaN;
}

double
anyFlipRate (const std::vector<std::vector<bool>>& is_free)
{
  double sum = 0.0;
  std::size_t poses = 0;
  for (const std::vector<bool>& verdicts : is_free)
  {
    if (verdicts.size () < 2)
      continue;
    const bool all_same = std::all_of (verdicts.begin (), verdicts.end (), [&] (bool v) { return v == verdicts.front (); });
    sum += all_same ? 0.0 : 1.0;
    ++poses;
  }
  return poses > 0 ? sum / static_cast<double> (poses) : kNaN;
}

HiddenCollisions
hiddenCollisions (const std::vector<bool>& answered_free, const std::vector<bool>& collides)
{
  requireSameSize (answered_free.size (), collides.size (), "hiddenCollisions");
  HiddenCollisions h;
  for (std::size_t i = 0; i < answered_free.size (); ++i)
    if (answered_free[i])
    {
      ++h.free_answers;
      h.hidden += collides[i] ? 1 : 0;
    }
  h.rate = h.free_answers > 0 ? static_cast<double> (h.hidden) / static_cast<double> (h.free_answers) : kNaN;
  return h;
}

double
reliabilityTolerance (double mean_predicted, std::size_t count, double floor, double k)
{
  if (count == 0 || std::isnan (mean_predicted))
    return kNaN;
  const double p = std::clamp (mean_predicted, 0.0, 1.0);
  return std::max (floor, k * std::sqrt (p * (1.0 - p) / static_cast<double> (count)));
}

bool
reliabilityBinWithin (const ReliabilityBin& bin, double floor, double k)
{
  const double tolerance = reliabilityTolerance (bin.mean_predicted, bin.count, floor, k);
  return !std::isnan (tolerance) && !std::isnan (bin.observed) &&
         std::abs (bin.observed - bin.mean_predicted) <= tolerance;
}

DistanceErrors
signedDistanceErrors (const std::vector<double>& estimate, const std::vector<double>& std,
                      const std::vector<double>& truth, const std::vector<double>& scale, double k)
{
  requireSameSize (estimate.size (), std.size (), "signedDistanceErrors");
  requireSameSize (estimate.size (), truth.size (), "signedDistanceErrors");
  requireSameSize (estimate.size (), scale.size (), "signedDistanceErrors");
  DistanceErrors out;
  std::vector<double> errors;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < estimate.size (); ++i)
  {
    if (!std::isfinite (estimate[i]))
      continue;
    const double e = std::abs (estimate[i] - truth[i]);
    errors.push_back (e / scale[i]);
    covered += (std::isfinite (std[i]) && e <= k * std[i]) ? 1 : 0;
  }
  out.count = errors.size ();
  out.total = estimate.size ();
  out.median_abs_error = percentile (errors, 50.0);
  // Over all pairs: a pose answered without a distance (the ladder's separators) covers nothing
  // (found in review: counted over the poses with one, the ladder's 0.45-0.60 read 0.87-0.94).
  out.coverage = out.count > 0 ? static_cast<double> (covered) / static_cast<double> (out.total) : kNaN;
  return out;
}

double
meanGroupStd (const std::vector<std::vector<double>>& groups)
{
  double sum = 0.0;
  std::size_t used = 0;
  for (const std::vector<double>& g : groups)
  {
    if (g.size () < 2)
      continue;
    sum += meanStd (g).std;
    ++used;
  }
  return used > 0 ? sum / static_cast<double> (used) : kNaN;
}

std::vector<bool>
paretoFront (const std::vector<double>& x, const std::vector<double>& y)
{
  requireSameSize (x.size (), y.size (), "paretoFront");
  const auto valid = [&] (std::size_t i) { return !std::isnan (x[i]) && !std::isnan (y[i]); };
  const auto dominates = [&] (std::size_t j, std::size_t i) {
    return x[j] <= x[i] && y[j] >= y[i] && (x[j] < x[i] || y[j] > y[i]);
  };
  // O(n^2): a chart has tens of points.
  std::vector<bool> front (x.size (), false);
  for (std::size_t i = 0; i < x.size (); ++i)
  {
    if (!valid (i))
      continue;
    bool dominated = false;
    for (std::size_t j = 0; j < x.size () && !dominated; ++j)
      dominated = j != i && valid (j) && dominates (j, i);
    front[i] = !dominated;
  }
  return front;
}
} // namespace pcl_probcollision_eval
