// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/covariance_estimation.h>
#include <pcl_probcollision/detail/huge_pages.h>
#include <pcl_probcollision/detail/parallel.h>

#include <pcl/common/point_tests.h>
#include <pcl/exceptions.h>
#include <pcl/search/search.h>

#include <Eigen/Eigenvalues>
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <system_error>
#include <thread>
#include <utility>

namespace pcl_probcollision
{
namespace detail
{
/** \brief Exact Euclidean k-d tree over the xyz of a cloud, with one k-NN call for many queries.
  *
  * It builds the tree pcl::search::KdTree builds (a FLANN single k-d tree, at most 15 points per
  * leaf, over the finite points in cloud order), so it returns the same neighbours, ties
  * included. Why not pcl::search::KdTree itself: its per-point query allocates and opens an
  * OpenMP region on every call, which costs about as much as the search itself for k = 10.
  * Concurrent const queries are safe, as with PCL's searches. */
template <typename PointT>
class BatchKdTree : public pcl::search::Search<PointT>
{
public:
  using PointCloudConstPtr = typename pcl::search::Search<PointT>::PointCloudConstPtr;
  using IndicesConstPtr = typename pcl::search::Search<PointT>::IndicesConstPtr;
  using pcl::search::Search<PointT>::nearestKSearch;
  using pcl::search::Search<PointT>::radiusSearch;

  BatchKdTree () : pcl::search::Search<PointT> ("BatchKdTree", false) {}

  void
  setInputCloud (const PointCloudConstPtr& cloud, const IndicesConstPtr& indices = IndicesConstPtr ()) override
  {
    pcl::search::Search<PointT>::setInputCloud (cloud, indices);
    xyz_.clear ();
    cloud_index_.clear ();
    tree_.reset ();
    if (!cloud)
      return;
    const std::size_t most = indices ? indices->size () : cloud->size ();
    detail::reserveHugePages (xyz_, 3 * most);
    detail::reserveHugePages (cloud_index_, most);
    const auto add = [this] (pcl::index_t i) {
      const PointT& p = (*this->input_)[i];
      if (!pcl::isXYZFinite (p))
        return;
      xyz_.insert (xyz_.end (), {p.x, p.y, p.z});
      cloud_index_.push_back (i);
    };
    if (indices)
      std::for_each (indices->begin (), indices->end (), add);
    else
      for (std::size_t i = 0; i < cloud->size (); ++i)
        add (static_cast<pcl::index_t> (i));
    if (cloud_index_.empty ())
      return;
    tree_ = std::make_unique<Tree> (flann::Matrix<float> (xyz_.data (), cloud_index_.size (), 3),
                                    flann::KDTreeSingleIndexParams (15));
    tree_->buildIndex ();
  }

  /** \brief Number of points in the tree (the finite ones). */
  std::size_t
  size () const
  {
    return cloud_index_.size ();
  }

  /** \brief The k <= size() nearest neighbours of each of n finite query points (x, y, z floats
    * each): row q of indices and sqr_distances (k entries) holds its neighbours by increasing
    * distance, as indices into the input cloud. */
  void
  nearestKSearch (const float* queries, std::size_t n, std::size_t k, std::size_t* indices, float* sqr_distances) const
  {
    if (n == 0 || k == 0)
      return;
    flann::Matrix<std::size_t> rows (indices, n, k);
    flann::Matrix<float> dists (sqr_distances, n, k);
    flann::SearchParams params (-1, 0.0f);  // exact, as PCL's
    params.cores = 1;
    tree_->knnSearch (flann::Matrix<float> (const_cast<float*> (queries), n, 3), rows, dists, k, params);
    for (std::size_t j = 0; j < n * k; ++j)
      indices[j] = static_cast<std::size_t> (cloud_index_[indices[j]]);
  }

  int
  nearestKSearch (const PointT& point, int k, pcl::Indices& k_indices,
                  std::vector<float>& k_sqr_distances) const override
  {
    const std::size_t kk = std::min (static_cast<std::size_t> (std::max (k, 0)), size ());
    std::vector<std::size_t> rows (kk);
    k_sqr_distances.resize (kk);
    const float query[3] = {point.x, point.y, point.z};
    nearestKSearch (query, 1, kk, rows.data (), k_sqr_distances.data ());
    k_indices.assign (rows.begin (), rows.end ());
    return static_cast<int> (kk);
  }

  int
  radiusSearch (const PointT& point, double radius, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                unsigned int max_nn = 0) const override
  {
    k_indices.clear ();
    k_sqr_distances.clear ();
    if (!tree_)
      return 0;
    flann::SearchParams params (-1, 0.0f, this->sorted_results_);
    params.max_neighbors = max_nn > 0 && max_nn < size () ? static_cast<int> (max_nn) : -1;
    float query[3] = {point.x, point.y, point.z};
    std::vector<std::vector<std::size_t>> rows;
    std::vector<std::vector<float>> dists;
    tree_->radiusSearch (flann::Matrix<float> (query, 1, 3), rows, dists, static_cast<float> (radius * radius), params);
    for (const std::size_t row : rows[0])
      k_indices.push_back (cloud_index_[row]);
    k_sqr_distances = std::move (dists[0]);
    return static_cast<int> (k_indices.size ());
  }

private:
  using Tree = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  std::vector<float> xyz_;           ///< finite points, x y z each
  pcl::Indices cloud_index_;         ///< row of xyz_ -> index into the input cloud
  std::unique_ptr<Tree> tree_;
};

/** \brief Neighbours of a block of query points, kept between blocks to reuse the memory. The
  * neighbours of the block's query b are indices[offset[b] + j], j < found[b]. */
struct NeighbourBlock
{
  std::vector<std::size_t> indices;  ///< into the search surface
  std::vector<float> sqr_distances;
  std::vector<std::size_t> offset;   ///< per query
  std::vector<int> found;            ///< per query; 0 for a non-finite query
  std::vector<float> queries;        ///< x y z of the finite queries (batched search)
};

/** \brief The k nearest neighbours (into the search surface) of each input[queries[b]]. With
  * BatchKdTree one FLANN call serves them all; another search (setSearchMethod) is asked one
  * point at a time, as pcl::Feature does. */
template <typename PointT>
void
findNeighbours (const pcl::search::Search<PointT>& search, const pcl::PointCloud<PointT>& input,
                const pcl::Indices& queries, int k, NeighbourBlock& block)
{
  const std::size_t n = queries.size ();
  std::size_t kk = static_cast<std::size_t> (std::max (k, 0));
  const auto* batch = dynamic_cast<const BatchKdTree<PointT>*> (&search);
  if (batch)
    kk = std::min (kk, batch->size ());
  block.indices.resize (n * kk);
  block.sqr_distances.resize (n * kk);
  block.offset.assign (n, 0);
  block.found.assign (n, 0);
  block.queries.clear ();
  std::size_t packed = 0;  // rows used, one per finite query
  pcl::Indices nn_indices;
  std::vector<float> nn_sqr_dists;
  for (std::size_t b = 0; b < n; ++b)
  {
    const PointT& p = input[queries[b]];
    if (kk == 0 || !pcl::isXYZFinite (p))
      continue;
    block.offset[b] = packed * kk;
    ++packed;
    if (batch)
    {
      block.queries.insert (block.queries.end (), {p.x, p.y, p.z});
      block.found[b] = static_cast<int> (kk);
      continue;
    }
    const int found = search.nearestKSearch (input, queries[b], k, nn_indices, nn_sqr_dists);
    const std::size_t m = std::min ({static_cast<std::size_t> (std::max (found, 0)), kk, nn_indices.size (),
                                     nn_sqr_dists.size ()});
    std::copy_n (nn_indices.begin (), m, block.indices.begin () + block.offset[b]);
    std::copy_n (nn_sqr_dists.begin (), m, block.sqr_distances.begin () + block.offset[b]);
    block.found[b] = static_cast<int> (m);
  }
  if (batch)
    batch->nearestKSearch (block.queries.data (), packed, kk, block.indices.data (), block.sqr_distances.data ());
}

/** \brief v's 21 low bits spread three apart (bit i moves to bit 3 i), for a Morton code. */
inline std::uint64_t
spreadBits (std::uint64_t v)
{
  v &= 0x1fffffULL;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

/** \brief The positions 0 .. n-1 of indices, sorted along a Z-order (Morton) curve through their
  * points; non-finite points last. Why: consecutive queries then descend the same k-d tree
  * branches and read the same neighbours, which stay in the cache. On mesh samples stored in
  * random order this saved about 3 % of the estimation on 11,500 points and 5 to 15 % on
  * 100,000; the results do not depend on the order. */
template <typename PointT>
std::vector<std::size_t>
zOrder (const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices)
{
  Eigen::Array3d lo = Eigen::Array3d::Constant (std::numeric_limits<double>::infinity ()), hi = -lo;
  for (const pcl::index_t i : indices)
    if (pcl::isXYZFinite (cloud[i]))
    {
      const Eigen::Array3d p = cloud[i].getArray3fMap ().template cast<double> ();
      lo = lo.min (p);
      hi = hi.max (p);
    }
  constexpr double kCells = (1 << 21) - 1;
  const Eigen::Array3d scale = (hi > lo).select (kCells / (hi - lo), 0.0);
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed;
  resizeHugePages (keyed, indices.size ());
  for (std::size_t j = 0; j < indices.size (); ++j)
  {
    std::uint64_t key = std::numeric_limits<std::uint64_t>::max ();
    const PointT& p = cloud[indices[j]];
    if (pcl::isXYZFinite (p))
    {
      const Eigen::Array3d cell = ((p.getArray3fMap ().template cast<double> () - lo) * scale).min (kCells);
      const auto spread = [&cell] (int axis) { return spreadBits (static_cast<std::uint64_t> (cell (axis))); };
      key = spread (0) | spread (1) << 1 | spread (2) << 2;
    }
    keyed[j] = {key, j};
  }
  std::sort (keyed.begin (), keyed.end ());
  std::vector<std::size_t> order;
  resizeHugePages (order, keyed.size ());
  std::transform (keyed.begin (), keyed.end (), order.begin (), [] (const auto& e) { return e.second; });
  return order;
}

/** \brief The smallest eigenvalue of a symmetric 3x3 matrix and a unit eigenvector for it.
  *
  * Why not always Eigen's iterative solver: the closed form (computeDirect) is about three
  * times faster, and this solve runs once per point. The closed form is less accurate in two
  * cases, which go to the iterative solver: close smallest eigenvalues (its vector error grows
  * as 1/gap^2; at a gap of a tenth of the spread it is below 1e-14) and a smallest eigenvalue
  * far below the largest (a near-exact plane, line or k < 3, where either solver's value is
  * rounding noise of the largest). Otherwise the value is the vector's Rayleigh quotient, off by
  * a few ulp of the largest eigenvalue like the iterative solver's, so that the covariances of
  * both agree to better than 1e-12 (relative). */
inline void
smallestEigenpair (const Eigen::Matrix3d& m, double& value, Eigen::Vector3d& vector)
{
  constexpr double kMinGap = 0.1, kMinRatio = 1e-3;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect (m);
  const Eigen::Vector3d& lambda = eig.eigenvalues ();
  if (lambda (1) - lambda (0) >= kMinGap * (lambda (2) - lambda (0)) && lambda (0) >= kMinRatio * lambda (2) &&
      lambda (2) > 0.0)
  {
    vector = eig.eigenvectors ().col (0);
    value = vector.dot (m * vector);
    return;
  }
  eig.compute (m);
  vector = eig.eigenvectors ().col (0);
  value = eig.eigenvalues ()(0);
}
} // namespace detail

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::setKSearch (int k)
{
  if (k < 1)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CovarianceEstimation::setKSearch] k = " << k
                                                                                      << " must be >= 1");
  this->k_ = k;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::setNumberOfThreads (int threads)
{
  if (threads < 0)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CovarianceEstimation::setNumberOfThreads] threads = "
                             << threads << " must be >= 0 (0: one per hardware thread)");
  threads_ = threads;
}

template <typename PointInT, typename PointOutT>
std::size_t
CovarianceEstimation<PointInT, PointOutT>::threadCount () const
{
  // Threads only with BatchKdTree, whose concurrent queries are known to be safe.
  const bool batch_search = dynamic_cast<const detail::BatchKdTree<PointInT>*> (this->tree_.get ()) != nullptr;
  return batch_search ? detail::threadCount (threads_) : 1;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::setScale (double tau)
{
  if (!(std::isfinite (tau) && tau > 0.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         "[pcl_probcollision::CovarianceEstimation::setScale] tau = " << tau
                                                                                      << " must be finite and > 0");
  tau_ = tau;
}

template <typename PointInT, typename PointOutT>
double
CovarianceEstimation<PointInT, PointOutT>::getScale () const
{
  return tau_ ? *tau_ : 2.0 * std::sqrt (static_cast<double> (this->k_));
}

template <typename PointInT, typename PointOutT>
SensorPose
CovarianceEstimation<PointInT, PointOutT>::getSensorPose () const
{
  if (sensor_pose_)
    return *sensor_pose_;
  if (this->input_)
    return SensorPose::fromViewpoint (this->input_->sensor_origin_, this->input_->sensor_orientation_);
  return SensorPose ();
}

template <typename PointInT, typename PointOutT>
bool
CovarianceEstimation<PointInT, PointOutT>::initCompute ()
{
  radii_.clear ();
  nearest_sqr_.clear ();
  displacements_.clear ();
  coincident_ = false;
  scatter_ratio_ = std::numeric_limits<double>::quiet_NaN ();
  if (this->search_radius_ != 0.0)
  {
    PCL_ERROR ("[pcl_probcollision::%s::initCompute] radius search (%g) is not supported: the "
               "covariance is defined on the k nearest neighbours; call setRadiusSearch (0).\n",
               this->getClassName ().c_str (), this->search_radius_);
    return false;
  }
  if (this->k_ < 1)
  {
    PCL_ERROR ("[pcl_probcollision::%s::initCompute] k = %d must be >= 1.\n",
               this->getClassName ().c_str (), this->k_);
    return false;
  }
  // A depth noise model measures depth from the sensor: without a finite origin every covariance
  // would come out NaN (SensorNoiseModel::sensorPoseError, buildCloudModel's rule too).
  if (noise_.usesSensorPose ())
  {
    const std::string why = noise_.sensorPoseError (getSensorPose ());
    if (!why.empty ())
    {
      PCL_ERROR ("[pcl_probcollision::%s::initCompute] %s (%s).\n", this->getClassName ().c_str (), why.c_str (),
                 sensor_pose_ ? "setSensorPose" : "the input cloud's sensor_origin_");
      return false;
    }
  }
  // pcl::Feature would pick OrganizedNeighbor (a projective, camera-model search) for organized
  // clouds; Pauly et al. define the neighbourhood in Euclidean space. BatchKdTree is the k-d
  // tree of pcl::search::KdTree, queried a block of points at a time.
  if (!this->tree_)
    this->tree_.reset (new detail::BatchKdTree<PointInT> ());
  // With threads, the visiting order (zOrder, a sort) is computed while the base class builds
  // the k-d tree: both are serial and take about as long (5,000,000 points: 0.45 and 0.9 s).
  // The per-point outputs are then sized there too: their first writes are page faults, 0.2-0.3
  // s of serial work at 5,000,000 points in this project's VMs (detail/huge_pages.h).
  order_.clear ();
  outputs_ready_ = false;
  std::thread side;
  if (threadCount () > 1 && pcl::PCLBase<PointInT>::initCompute ())
  {
    // A failure here only means computeFeature does it itself.
    const auto order = [this] {
      try
      {
        order_ = detail::zOrder (*this->input_, *this->indices_);
      }
      catch (const std::exception&)
      {
        order_.clear ();
      }
      try
      {
        const std::size_t n = this->indices_->size ();
        resetOutputs (n);
        // pcl::Feature::compute() sizes its output only where it has another size.
        if (output_ && output_->size () != n)
        {
          detail::reserveHugePages (output_->points, n);
          output_->resize (n);
        }
        outputs_ready_ = true;
      }
      catch (const std::exception&)
      {
        outputs_ready_ = false;
      }
    };
    try
    {
      side = std::thread (order);
    }
    catch (const std::system_error&)
    {
    }
  }
  const bool ok = pcl::Feature<PointInT, PointOutT>::initCompute ();
  if (side.joinable ())
    side.join ();
  return ok;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::compute (PointCloudOut& output)
{
  output_ = &output;
  try
  {
    pcl::Feature<PointInT, PointOutT>::compute (output);
  }
  catch (...)
  {
    output_ = nullptr;
    throw;
  }
  output_ = nullptr;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::resetOutputs (std::size_t n)
{
  detail::assignHugePages (radii_, n, std::numeric_limits<float>::quiet_NaN ());
  detail::assignHugePages (nearest_sqr_, n, std::numeric_limits<float>::quiet_NaN ());
  normals_.clear ();
  neighbours_.clear ();
  displacements_.clear ();
  if (compute_surface_)
  {
    if (compute_normals_)
      detail::assignHugePages (normals_, n, Eigen::Vector3f::Constant (std::numeric_limits<float>::quiet_NaN ()));
    detail::assignHugePages (neighbours_, n * static_cast<std::size_t> (this->k_), -1);
  }
  if (project_)
    detail::assignHugePages (displacements_, n, Eigen::Vector3d::Constant (std::numeric_limits<double>::quiet_NaN ()));
}

template <typename PointInT, typename PointOutT>
bool
CovarianceEstimation<PointInT, PointOutT>::projectOntoSurface (const Eigen::Vector3d& mean_offset,
                                                             const Eigen::Matrix3d& second_moment, double k_eff,
                                                             const Eigen::Matrix3d& sensor_cov,
                                                             Eigen::Vector3d& displacement, Eigen::Matrix3d& psi,
                                                             Eigen::Vector3d& normal, double& shrink)
{
  // Neighbours whose scatter's middle eigenvalue is at most this share of the two larger ones'
  // sum lie on a line, to rounding (exactly collinear samples give 0; a noisy row of samples
  // about (noise / extent)^2, far above it, and is projected as before).
  constexpr double kCollinearNeighbours = 1e-9;
  // Scatter of the neighbours (the point itself excluded, so that its own error does not pull
  // the plane) about their weighted centroid; its weakest direction is the local normal.
  const Eigen::Matrix3d scatter = second_moment - mean_offset * mean_offset.transpose ();
  const Eigen::Matrix3d sym = 0.5 * (scatter + scatter.transpose ());
  Eigen::Vector3d n;
  double lambda;
  detail::smallestEigenpair (sym, lambda, n);
  // Neighbours on one line (two of them, in a three-point cloud; a straight row of samples) fix
  // no plane: its normal is then any direction across the line, and the projection would slide
  // the point along its own surface onto the line (a three-point cloud's witness was reported
  // 0.15 away from every sample). The middle eigenvalue, from the trace and the sum of the
  // principal 2 x 2 minors once the smallest is known, says whether they do.
  const double rest = sym.trace () - lambda;  // the two larger eigenvalues' sum
  const double minors = sym (0, 0) * sym (1, 1) - sym (0, 1) * sym (0, 1) + sym (0, 0) * sym (2, 2) -
                        sym (0, 2) * sym (0, 2) + sym (1, 1) * sym (2, 2) - sym (1, 2) * sym (1, 2);
  const double product = minors - lambda * rest;  // theirs
  const double middle = 0.5 * (rest - std::sqrt (std::max (0.0, rest * rest - 4.0 * product)));
  if (!(middle > kCollinearNeighbours * rest))
    return false;
  lambda = std::max (lambda, 0.0);
  const double s2 = n.dot (sensor_cov * n);
  if (!(s2 > 0.0) || !(k_eff > 1.0))
    return false;
  // The sensor explains the scatter across the plane on a flat patch (alpha = 1; a factor 2
  // absorbs the sampling spread of lambda over about ten neighbours); at an edge or corner
  // the scatter is geometry, and the point keeps most of its measured position.
  constexpr double kTolerance = 2.0;
  const double alpha = lambda > kTolerance * s2 ? kTolerance * s2 / lambda : 1.0;
  // x_i sits at the origin of the moments, so the centroid is at mean_offset.
  displacement = alpha * n * n.dot (mean_offset);
  // The discretisation term about the new position, sum w (d - delta)(d - delta)^T / sum w,
  // along the normal only: sliding a sample along its own surface does not move the surface,
  // and a tangential spread of the sample spacing, seen by a leaf separator that is tilted
  // against the surface, read as a crossing (docs/RESULTS.md).
  const Eigen::Matrix3d about_moved = second_moment - mean_offset * displacement.transpose () -
                                      displacement * mean_offset.transpose () + displacement * displacement.transpose ();
  psi = n.dot (about_moved * n) * n * n.transpose ();
  // Variance of the shrunk position along n, as a share of the measured point's: the measured
  // part weighs (1 - alpha), the plane's offset (error s2 / k_eff, independent of x_i) alpha.
  shrink = (1.0 - alpha) * (1.0 - alpha) + alpha * alpha / k_eff;
  normal = n;
  return true;
}

template <typename PointInT, typename PointOutT>
void
CovarianceEstimation<PointInT, PointOutT>::computeFeature (PointCloudOut& output)
{
  const auto& input = *this->input_;
  const auto& surface = *this->surface_;
  const auto& indices = *this->indices_;
  const bool same_cloud = this->input_ == this->surface_;
  const SensorPose sensor = getSensorPose ();
  const double tau = getScale ();

  std::size_t finite_surface = 0;
  for (const auto& p : surface.points)
    finite_surface += pcl::isXYZFinite (p) ? 1 : 0;

  if (!outputs_ready_)
    resetOutputs (indices.size ());
  outputs_ready_ = false;
  const bool fit_normals = compute_surface_ && compute_normals_;
  // Ask one more than k: the query itself comes back when it is part of the surface.
  const int k_ask = static_cast<int> (std::min<std::size_t> (this->k_ + 1, finite_surface));
  // Neighbours are searched a block of points at a time: one FLANN call per block, and the
  // buffers stay small enough for the cache.
  constexpr std::size_t kBlockSize = 256;
  // Points are visited along a Z-order curve (see zOrder), a block at a time; each fills only its
  // own output slot, so blocks may run on several threads with the same result.
  const std::vector<std::size_t> order = order_.size () == indices.size () ? std::move (order_) : detail::zOrder (input, indices);
  order_.clear ();
  const std::size_t blocks = (order.size () + kBlockSize - 1) / kBlockSize;
  const std::size_t workers = threadCount ();
  struct Scratch
  {
    detail::NeighbourBlock block;
    pcl::Indices block_queries, nn_indices;
  };
  std::vector<Scratch> scratch (std::min (workers, std::max<std::size_t> (blocks, 1)));
  std::vector<char> block_dense (blocks, 1);
  std::vector<char> block_coincident (blocks, 0);  // hasCoincidentPoints()
  // getNeighbourScatterRatio(): every ratio_stride-th output point, whatever the threads.
  const std::size_t ratio_stride = std::max<std::size_t> (1, order.size () / kScatterRatioPoints);
  std::vector<float> scatter_ratios ((order.size () + ratio_stride - 1) / ratio_stride, std::numeric_limits<float>::quiet_NaN ());

  detail::parallelFor (blocks, workers, [&] (std::size_t blk, std::size_t worker) {
    Scratch& s = scratch[worker];
    detail::NeighbourBlock& block = s.block;
    pcl::Indices& nn_indices = s.nn_indices;
    nn_indices.resize (static_cast<std::size_t> (this->k_));
    const std::size_t o_begin = blk * kBlockSize, o_end = std::min (order.size (), o_begin + kBlockSize);
    s.block_queries.clear ();
    for (std::size_t q = o_begin; q < o_end; ++q)
      s.block_queries.push_back (indices[order[q]]);
    detail::findNeighbours (*this->tree_, input, s.block_queries, k_ask, block);
    for (std::size_t o = o_begin; o < o_end; ++o)
    {
      const std::size_t b = o - o_begin;
      const std::size_t out = order[o];
      const int index = indices[out];
      const PointInT& query = input[index];
      if (!pcl::isXYZFinite (query))
      {
        output[out] = PointOutT (Covariance::nan ());
        block_dense[blk] = 0;
        continue;
      }
      const Eigen::Vector3d xi = query.getVector3fMap ().template cast<double> ();

      // Keep at most k neighbours other than the query point itself.
      const std::size_t* row = block.indices.data () + block.offset[b];
      const float* row_sqr_dists = block.sqr_distances.data () + block.offset[b];
      std::size_t kept = 0;
      double r = 0.0;
      for (int j = 0; j < block.found[b] && kept < static_cast<std::size_t> (this->k_); ++j)
      {
        const auto neighbour = static_cast<pcl::index_t> (row[j]);
        if (same_cloud && neighbour == index)
          continue;
        if (!pcl::isXYZFinite (surface[neighbour]))
          continue;
        nn_indices[kept] = neighbour;
        ++kept;
        r = std::max (r, std::sqrt (static_cast<double> (row_sqr_dists[j])));
      }
      radii_[out] = static_cast<float> (r);
      // The nearest neighbour at a positive distance (the row is sorted; the point itself and
      // its duplicates come back at 0): getNearestSquaredDistances().
      const std::size_t found = static_cast<std::size_t> (std::max (block.found[b], 0));
      const float* positive = std::find_if (row_sqr_dists, row_sqr_dists + found, [] (float v) { return v > 0.f; });
      // The point itself and another at its very position: both at distance 0.
      if (same_cloud && positive - row_sqr_dists >= 2)
        block_coincident[blk] = 1;
      if (positive != row_sqr_dists + found)
        nearest_sqr_[out] = *positive;
      else if (found >= finite_surface)
        nearest_sqr_[out] = 0.0f;
      if (compute_surface_)
        std::copy (nn_indices.begin (), nn_indices.begin () + static_cast<std::ptrdiff_t> (kept),
                   neighbours_.begin () + static_cast<std::ptrdiff_t> (out * static_cast<std::size_t> (this->k_)));

      if (out % ratio_stride == 0 && kept >= 2)
      {
        // The point and its neighbours, unweighted, about their mean.
        Eigen::Vector3d mean = Eigen::Vector3d::Zero ();
        for (std::size_t j = 0; j < kept; ++j)
          mean += surface[nn_indices[j]].getVector3fMap ().template cast<double> () - xi;
        mean /= static_cast<double> (kept + 1);
        Eigen::Matrix3d scatter = mean * mean.transpose ();
        for (std::size_t j = 0; j < kept; ++j)
        {
          const Eigen::Vector3d d = surface[nn_indices[j]].getVector3fMap ().template cast<double> () - xi - mean;
          scatter.noalias () += d * d.transpose ();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        const Eigen::Vector3d l = solver.computeDirect (scatter, Eigen::EigenvaluesOnly).eigenvalues ();
        if (l[2] > 0.0)
          scatter_ratios[out / ratio_stride] = static_cast<float> (std::max (0.0, l[1]) / l[2]);
      }

      Eigen::Matrix3d psi = Eigen::Matrix3d::Zero ();
      // Weighted mean offset of the neighbours and their effective number (surface projection).
      Eigen::Vector3d first = Eigen::Vector3d::Zero ();
      double k_eff = 0.0, weight_sq_sum = 0.0;
      if (kept > 0 && r > 0.0)
      {
        const double tau_i = tau * r / std::sqrt (static_cast<double> (kept));
        const double inv_tau2 = 1.0 / (tau_i * tau_i);
        double weight_sum = 0.0;
        for (std::size_t j = 0; j < kept; ++j)
        {
          // Differences in double: exact for float inputs even far from the origin.
          const Eigen::Vector3d d = surface[nn_indices[j]].getVector3fMap ().template cast<double> () - xi;
          const double w = std::exp (-d.squaredNorm () * inv_tau2);
          psi.noalias () += w * d * d.transpose ();
          first += w * d;
          weight_sum += w;
          weight_sq_sum += w * w;
        }
        if (weight_sum > 0.0)
        {
          psi /= weight_sum;
          first /= weight_sum;
          k_eff = weight_sum * weight_sum / weight_sq_sum;
        }
      }

      if (fit_normals)
      {
        Eigen::Vector3d n = Eigen::Vector3d::Zero ();
        double lambda0 = 0.0;
        if (kept >= 2 && psi.trace () > 0.0)
          detail::smallestEigenpair (psi, lambda0, n);
        normals_[out] = n.cast<float> ();
      }
      Eigen::Matrix3d total = use_discretization_ ? psi : Eigen::Matrix3d::Zero ();
      if (noise_.type () != SensorNoiseModel::Type::None)
      {
        Eigen::Vector3d normal = Eigen::Vector3d::Zero ();
        if (noise_.usesNormal () && kept >= 2 && psi.trace () > 0.0)
        {
          const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig (psi);
          normal = eig.eigenvectors ().col (0);
        }
        const Eigen::Matrix3d sensor_cov = noise_.covariance (xi, normal, sensor);
        Eigen::Vector3d delta, n;
        Eigen::Matrix3d psi_moved;
        double shrink = 1.0;
        if (project_ && kept >= 2 && projectOntoSurface (first, psi, k_eff, sensor_cov, delta, psi_moved, n, shrink))
        {
          displacements_[out] = delta;
          total = (use_discretization_ ? psi_moved : Eigen::Matrix3d::Zero ()) + sensor_cov;
          const Eigen::Matrix3d A = Eigen::Matrix3d::Identity () - (1.0 - std::sqrt (shrink)) * n * n.transpose ();
          total = A * total * A.transpose ();
        }
        else
          total += sensor_cov;
      }
      if (project_ && !displacements_[out].allFinite ())
        displacements_[out].setZero ();
      total = 0.5 * (total + total.transpose ());
      output[out] = PointOutT (Covariance (total));
    }
  });
  output.is_dense = std::all_of (block_dense.begin (), block_dense.end (), [] (char d) { return d != 0; });
  coincident_ = std::any_of (block_coincident.begin (), block_coincident.end (), [] (char c) { return c != 0; });
  scatter_ratios.erase (std::remove_if (scatter_ratios.begin (), scatter_ratios.end (), [] (float v) { return std::isnan (v); }),
                        scatter_ratios.end ());
  if (!scatter_ratios.empty ())
  {
    std::nth_element (scatter_ratios.begin (), scatter_ratios.begin () + static_cast<std::ptrdiff_t> (scatter_ratios.size () / 2),
                      scatter_ratios.end ());
    scatter_ratio_ = scatter_ratios[scatter_ratios.size () / 2];
  }
}
} // namespace pcl_probcollision

#define PCL_INSTANTIATE_CovarianceEstimation(T) \
  template class PCL_EXPORTS pcl_probcollision::CovarianceEstimation<T, pcl_probcollision::Covariance>;
