// SPDX-License-Identifier: BSD-3-Clause
// The normalised two-class problem shared by the linear and the RFF rung (METHOD.md 4, 5.1,
// 5.3): points in the unit cube, covariances times S^2, labels, class-balanced weights, and
// the margin loss. Internal: not API.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace pcl_probcollision
{
namespace detail
{
/** \brief eps_s of METHOD.md 5.3: s_i = sqrt(w^T Sigma_i w + eps_s^2). */
constexpr double kSigmaFloor = 1e-12;
/** \brief eta_b of METHOD.md 5.3: a ridge eta_b b^2 / 2 on the bias, so that H is never singular. */
constexpr double kBiasRidge = 1e-10;

/** \brief The loss l(v) of METHOD.md 5.3 and its first two derivatives. */
struct MarginLoss
{
  bool huber = false;   ///< false: squared hinge max(0, v)^2 / 2; true: Huberised hinge
  double width = 0.01;  ///< h of the Huberised hinge

  double value (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return 0.5 * v * v;
    return v <= width ? v * v / (2.0 * width) : v - 0.5 * width;
  }
  double first (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return v;
    return v <= width ? v / width : 1.0;
  }
  /** \brief The generalised second derivative ([v > 0] for the squared hinge). */
  double second (double v) const
  {
    if (v <= 0.0)
      return 0.0;
    if (!huber)
      return 1.0;
    return v <= width ? 1.0 / width : 0.0;
  }
  /** \brief sum_i weight_i l(v_i), vectorised. */
  template <typename Derived>
  double weightedSum (const Eigen::ArrayBase<Derived>& v, const Eigen::ArrayXd& weight) const
  {
    if (!huber)
      return 0.5 * (weight * v.max (0.0).square ()).sum ();
    // l = min(m, h)^2 / (2h) + (m - min(m, h)) with m = max(v, 0)
    const Eigen::ArrayXd m = v.max (0.0);
    return (weight * (m.min (width).square () / (2.0 * width) + (m - m.min (width)))).sum ();
  }
};

/** \brief The normalised problem, structure of arrays, points of A (label +1) first.
  *
  * Its columns are views of one buffer that resize() keeps when a problem is smaller than an
  * earlier one, so that a problem reused from leaf pair to leaf pair allocates nothing (eleven
  * arrays a fit otherwise). Each column starts on Eigen's largest alignment, as an
  * Eigen::ArrayXd does, so that every expression and reduction over it is evaluated as over an
  * ArrayXd (the same packets, the same order of sums). */
struct SeparatorProblem
{
  /** \brief A column: n values, aligned as an Eigen::ArrayXd. */
  using Column = Eigen::Map<Eigen::ArrayXd, Eigen::AlignedMax>;

  Eigen::Index n = 0;    ///< number of points
  Eigen::Index n_a = 0;  ///< points 0 .. n_a - 1 belong to A
  Column x {nullptr, 0}, y {nullptr, 0}, z {nullptr, 0};  ///< unit-cube means
  Column sxx {nullptr, 0}, sxy {nullptr, 0}, sxz {nullptr, 0};  ///< unit-cube covariances S Sigma_i S^T
  Column syy {nullptr, 0}, syz {nullptr, 0}, szz {nullptr, 0};
  Column label {nullptr, 0};   ///< c_i = +1 (A) or -1 (B)
  Column weight {nullptr, 0};  ///< C_i = C n / (2 n_{c_i})

  SeparatorProblem () = default;
  SeparatorProblem (const SeparatorProblem& other) : n (other.n), n_a (other.n_a), storage_ (other.storage_) { seat (); }
  SeparatorProblem&
  operator= (const SeparatorProblem& other)
  {
    if (this != &other)
    {
      n = other.n;
      n_a = other.n_a;
      storage_ = other.storage_;
      seat ();
    }
    return *this;
  }

  /** \brief Sets n and points every column at count values (their contents undefined), reusing
    * the buffer when it is large enough. */
  void
  resize (Eigen::Index count)
  {
    n = count;
    const std::size_t need = static_cast<std::size_t> (kColumns * stride (count));
    if (storage_.size () < need)
      storage_.resize (need);
    seat ();
  }
  /** \brief Frees the buffer (n becomes 0) when it holds more than keep doubles. */
  void
  releaseAbove (std::size_t keep)
  {
    if (storage_.capacity () <= keep)
      return;
    decltype (storage_) ().swap (storage_);
    n = n_a = 0;
    seat ();
  }

  Eigen::Vector3d point (Eigen::Index i) const { return Eigen::Vector3d (x (i), y (i), z (i)); }
  Eigen::Matrix3d covariance (Eigen::Index i) const
  {
    Eigen::Matrix3d m;
    m << sxx (i), sxy (i), sxz (i), sxy (i), syy (i), syz (i), sxz (i), syz (i), szz (i);
    return m;
  }
  /** \brief g^T Sigma_i g, clamped at 0 (covariances are PSD up to rounding). */
  double quadratic (Eigen::Index i, const Eigen::Vector3d& g) const
  {
    const double q = g (0) * g (0) * sxx (i) + g (1) * g (1) * syy (i) + g (2) * g (2) * szz (i) +
                     2.0 * (g (0) * g (1) * sxy (i) + g (0) * g (2) * sxz (i) + g (1) * g (2) * syz (i));
    return std::max (q, 0.0);
  }

private:
  static constexpr Eigen::Index kColumns = 11;
  /** \brief Doubles from one column's start to the next: count rounded up to whole
    * alignment units. */
  static Eigen::Index
  stride (Eigen::Index count)
  {
    constexpr Eigen::Index unit = std::max<Eigen::Index> (1, EIGEN_MAX_ALIGN_BYTES / static_cast<Eigen::Index> (sizeof (double)));
    return (count + unit - 1) / unit * unit;
  }
  void
  seat ()
  {
    Column* columns[kColumns] = {&x, &y, &z, &sxx, &sxy, &sxz, &syy, &syz, &szz, &label, &weight};
    const Eigen::Index s = stride (n);
    for (Eigen::Index k = 0; k < kColumns; ++k)
      new (columns[k]) Column (n > 0 ? storage_.data () + k * s : nullptr, n);
  }
  std::vector<double, Eigen::aligned_allocator<double>> storage_;
};

/** \brief How one solve went. */
struct SolverReport
{
  int iterations = 0;
  bool converged = false;
  double objective = std::numeric_limits<double>::quiet_NaN ();
};
} // namespace detail
} // namespace pcl_probcollision
