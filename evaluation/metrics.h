// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Metrics of the evaluation suite (issue #6): ranking (ROC AUC), calibration (Brier score,
// reliability diagram), speed (percentiles), stability (verdict flip rate) and the
// speed-versus-accuracy Pareto front.
//
// Conventions shared by every function here:
//  - paired inputs (scores and outcomes, x and y) must have equal sizes, otherwise
//    std::invalid_argument is thrown;
//  - a NaN input makes the result NaN (a missing answer must not silently improve a metric),
//    except where a function's brief says otherwise;
//  - an undefined result (empty input, a class with no members) is NaN.

#include <cstddef>
#include <vector>

namespace pcl_probcollision_eval
{
/** \brief ROC area under the curve of `score` for predicting `positive` (higher score = more
  * likely positive): the Mann-Whitney probability that a random positive outscores a random
  * negative, ties counting 1/2. Computed from mid-ranks in O(n log n). NaN when either class is
  * empty or a score is NaN. */
double rocAuc (const std::vector<double>& score, const std::vector<bool>& positive);

/** \brief Brier score: mean of (probability - outcome)^2 with outcome 1 for true, 0 for false.
  * 0 is perfect, 0.25 is the constant 1/2 forecast. NaN when empty. */
double brierScore (const std::vector<double>& probability, const std::vector<bool>& outcome);

/** \brief One bin of a reliability diagram. */
struct ReliabilityBin
{
  double lo = 0.0;                ///< lower edge (inclusive)
  double hi = 0.0;                ///< upper edge (exclusive, except 1 in the last bin)
  double mean_predicted = 0.0;    ///< mean probability in the bin; NaN when count is 0
  double observed = 0.0;          ///< share of true outcomes in the bin; NaN when count is 0
  std::size_t count = 0;          ///< predictions in the bin
};

/** \brief Reliability diagram: `bins` equal bins on [0, 1] (bin i is [i/bins, (i+1)/bins),
  * the last one closed). Probabilities outside [0, 1] are clamped into the end bins; a NaN
  * probability goes in no bin, so the counts then sum to less than the input size.
  * Always returns `bins` entries. Throws std::invalid_argument when bins is 0. */
std::vector<ReliabilityBin> reliabilityBins (const std::vector<double>& probability,
                                             const std::vector<bool>& outcome, std::size_t bins = 10);

/** \brief The `percent` percentile (0..100) with linear interpolation between closest ranks:
  * on the sorted values x_0 <= ... <= x_{n-1}, rank h = (n - 1) percent / 100 and the result is
  * x_floor(h) + (h - floor(h)) (x_ceil(h) - x_floor(h)) (R type 7, NumPy's default). So 0 gives
  * the minimum, 50 the usual median, 100 the maximum. NaN when empty. Throws
  * std::invalid_argument when percent is outside [0, 100]. */
double percentile (std::vector<double> values, double percent);

/** \brief Summary of a set of query times (any unit; the result is in the same unit). */
struct TimeSummary
{
  double median = 0.0;
  double p90 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
};

/** \brief median / p90 / p99 / max of `times` by percentile(). All NaN when empty. */
TimeSummary summarizeTimes (const std::vector<double>& times);

/** \brief Mean and sample standard deviation. */
struct MeanStd
{
  double mean = 0.0;
  double std = 0.0;  ///< with the n - 1 denominator; 0 for a single value
};

/** \brief Mean and sample standard deviation; both NaN when empty. */
MeanStd meanStd (const std::vector<double>& values);

/** \brief Verdict flip rate under noise re-sampling. `is_free[pose][resample]` is true when the
  * method said "free" for that re-sampling of that pose. Per pose, the flip share is the
  * fraction of re-samples whose free / not-free verdict differs from the pose's majority
  * verdict, i.e. min(k, n - k) / n with k free verdicts out of n (a tie gives 1/2 whichever
  * side is called the majority); the result is its mean over the poses that have at least one
  * re-sample. 0 means perfectly stable, 1/2 is the worst possible. NaN when no pose has any. */
double flipRate (const std::vector<std::vector<bool>>& is_free);

/** \brief Any-flip rate under re-scans (issue #16): per pose, 1 when its free / not-free
  * verdicts are not all the same across the draws, else 0; the mean over the poses with at least
  * two draws. Stricter than flipRate(): one dissenting draw out of n flips the pose. NaN when no
  * pose has two draws. */
double anyFlipRate (const std::vector<std::vector<bool>>& is_free);

/** \brief Hidden collisions: among the answers that said "free", those whose pose collides. */
struct HiddenCollisions
{
  std::size_t free_answers = 0;  ///< answers "free"
  std::size_t hidden = 0;        ///< of which collide
  double rate = 0.0;             ///< hidden / free_answers; NaN when there is no free answer
};

/** \brief Counts hidden collisions over paired answers (answered_free[i], collides[i]). */
HiddenCollisions hiddenCollisions (const std::vector<bool>& answered_free, const std::vector<bool>& collides);

/** \brief Tolerance of the reliability check of issue #16 for a bin: the larger of `floor`
  * (0.1) and k (2) binomial standard errors sqrt(p (1 - p) / n) at p = the bin's mean predicted
  * probability. NaN when count is 0 or mean_predicted is NaN. */
double reliabilityTolerance (double mean_predicted, std::size_t count, double floor = 0.1, double k = 2.0);

/** \brief The check itself: |observed - mean_predicted| <= reliabilityTolerance(); false for
  * an empty bin. Which bins are judged (issue #16: those holding at least 30) is the caller's. */
bool reliabilityBinWithin (const ReliabilityBin& bin, double floor = 0.1, double k = 2.0);

/** \brief Error of a signed-distance estimate against the truth. */
struct DistanceErrors
{
  std::size_t count = 0;           ///< pairs with a finite estimate (the median skips the others)
  std::size_t total = 0;           ///< all pairs
  double median_abs_error = 0.0;   ///< median |estimate - truth| / scale; NaN when count is 0
  /** \brief Share of all pairs with |estimate - truth| <= k std: a pair without an estimate, or
    * with a NaN std, is not covered (an answer without an interval covers nothing); NaN when no
    * pair has an estimate (not measured). */
  double coverage = 0.0;
};

/** \brief Errors of `estimate` (NaN = not computed: skipped by the median, uncovered) with standard deviations `std`
  * against `truth`, in units of `scale` (per pair, e.g. sigma_eff); coverage of the +-k std
  * interval. Throws std::invalid_argument when the sizes differ. */
DistanceErrors signedDistanceErrors (const std::vector<double>& estimate, const std::vector<double>& std,
                                     const std::vector<double>& truth, const std::vector<double>& scale,
                                     double k = 2.0);

/** \brief Mean over groups of the sample standard deviation within each group (groups with
  * fewer than two values are skipped): e.g. the spread of our probability over the noise
  * re-samples of one pose, averaged over poses. NaN when no group has two values. */
double meanGroupStd (const std::vector<std::vector<double>>& groups);

/** \brief Pareto front for "x lower is better, y higher is better" (x = query time,
  * y = accuracy): flag i is true when no other point is at least as good in both and strictly
  * better in one. Equal points are all on the front. A point with a NaN coordinate is never on
  * the front and dominates nothing. */
std::vector<bool> paretoFront (const std::vector<double>& x, const std::vector<double>& y);
} // namespace pcl_probcollision_eval
