// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pcl_probcollision/point_types.h>
#include <pcl_probcollision/sensor_noise.h>

#include <pcl/features/feature.h>

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

namespace pcl_probcollision
{
/** \brief Per-point covariance of a point cloud: the k-nearest-neighbour discretisation
  * covariance of Pauly, Mitra and Guibas (2004) plus a sensor noise model (METHOD.md 3).
  *
  * For each point x_i with neighbours N_i (its k nearest, itself excluded):
  * Psi_i = sum_j w_ij (x_j - x_i)(x_j - x_i)^T / sum_j w_ij, w_ij = exp(-|x_i - x_j|^2 / tau_i^2),
  * tau_i = tau r_i / sqrt(k), r_i the distance to the k-th neighbour. The output is
  * Psi_i + Sigma_i, with Sigma_i from the SensorNoiseModel (none by default).
  *
  * Defaults: k = 10, tau = 2 sqrt(k) (so tau_i = 2 r_i, the authors' reference code), the
  * discretisation term on, no sensor noise, surface projection on (it acts only with a sensor
  * noise model), Euclidean k-d tree search unless setSearchMethod()
  * gives another. The default search is the k-d tree of pcl::search::KdTree (FLANN, exact, the
  * same neighbours), queried for many points at once; a search set by setSearchMethod() is
  * asked one point at a time, as pcl::Feature does.
  *
  * \note Output is index-aligned with the input (or its indices); an organized input keeps its
  * width and height. A non-finite input point gets an all-NaN covariance and the output is then
  * not dense. Every finite point gets a finite, symmetric positive semi-definite covariance.
  * \note Degenerate neighbourhoods give well-defined results: fewer than k finite neighbours
  * use the ones there are (k' = finite points - 1); a point with no neighbour, or whose
  * neighbours all coincide with it (r_i = 0), gets Psi_i = 0; collinear or coplanar
  * neighbourhoods give a singular Psi_i (zero variance across the line or plane), which is the
  * exact answer for noise-free samples. Add a sensor noise model to regularise it.
  * \note Radius search is not supported (the method is defined on k neighbours): compute()
  * fails with a PCL_ERROR and an empty output when a radius is set.
  */
template <typename PointInT, typename PointOutT = Covariance>
class CovarianceEstimation : public pcl::Feature<PointInT, PointOutT>
{
public:
  /** \brief Shared pointer to an estimator. */
  using Ptr = pcl::shared_ptr<CovarianceEstimation<PointInT, PointOutT>>;
  /** \brief Shared pointer to a const estimator. */
  using ConstPtr = pcl::shared_ptr<const CovarianceEstimation<PointInT, PointOutT>>;
  /** \brief The output cloud: one PointOutT (a Covariance by default) per input point. */
  using PointCloudOut = typename pcl::Feature<PointInT, PointOutT>::PointCloudOut;

  CovarianceEstimation ()
  {
    this->feature_name_ = "CovarianceEstimation";
    this->k_ = 10;
  }

  /** \brief Number of nearest neighbours k >= 1 (default 10). Throws
    * pcl::BadArgumentException otherwise. */
  void setKSearch (int k);
  /** \brief The number of nearest neighbours k. */
  int getKSearch () const { return this->k_; }

  /** \brief Global kernel scale tau > 0 (tau_i = tau r_i / sqrt(k)); unset means 2 sqrt(k).
    * Throws pcl::BadArgumentException for a non-positive or non-finite value. */
  void setScale (double tau);
  /** \brief The scale in use: the one set, or 2 sqrt(k). */
  double getScale () const;

  /** \brief Whether Psi_i (the discretisation term) is added (default true). */
  void setUseDiscretization (bool use) { use_discretization_ = use; }
  /** \brief Whether the discretisation term is added. */
  bool getUseDiscretization () const { return use_discretization_; }

  /** \brief The sensor noise added to every point (default none). */
  void setSensorNoise (const SensorNoiseModel& model) { noise_ = model; }
  /** \brief The sensor noise model in use. */
  const SensorNoiseModel& getSensorNoise () const { return noise_; }

  /** \brief Sensor pose in the input cloud's frame for the depth models; unset means the
    * input's sensor_origin_ and sensor_orientation_. */
  void setSensorPose (const SensorPose& pose) { sensor_pose_ = pose; }
  /** \brief The sensor pose in use: the one set, else the input cloud's viewpoint fields
    * (SensorPose::fromViewpoint), else the default pose when there is no input. */
  SensorPose getSensorPose () const;

  /** \brief After compute(): r_i, the distance of each output point to its k-th neighbour
    * (NaN for non-finite points, 0 without neighbours), index-aligned with the output. The
    * hierarchy uses r_i^2 as the surface area a point stands for. */
  const std::vector<float>& getNeighbourRadii () const { return radii_; }
  /** \brief After compute(): the squared distance of each output point to its nearest
    * neighbour (in the search surface) at a positive distance, as the neighbour search returned
    * it (coincident points are skipped); 0 when the search covered every finite point of the
    * surface and found none; NaN when it is not known (a non-finite point, or all k + 1 found
    * coincident while more points exist). What io::medianSpacing() measures, without a second
    * search (CloudModel::medianNeighbourSpacing). */
  const std::vector<float>& getNearestSquaredDistances () const { return nearest_sqr_; }
  /** \brief After compute(): true when some finite point of the input has another at exactly
    * its position (x y z equal) among its neighbours, with the input as its own search surface.
    * buildCloudModel() then models each position once (CloudModel::coincidentSamples()). */
  bool hasCoincidentPoints () const { return coincident_; }
  /** \brief After compute(): the median, over up to kScatterRatioPoints of the output points
    * (evenly strided), of the ratio of the middle to the largest eigenvalue of the scatter of
    * each point and its k nearest neighbours (unweighted, about their mean). About 0.6 on a
    * surface scan (0.59-0.69 on the scans of ../shared/data), near 0 where the samples lie along
    * lines: 0.03 on a LiDAR's rings, whose neighbours all lie on their own ring. NaN when no
    * point had two neighbours. */
  double getNeighbourScatterRatio () const { return scatter_ratio_; }
  /** \brief Output points getNeighbourScatterRatio() reads at most (about). */
  static constexpr std::size_t kScatterRatioPoints = 1000;

  /** \brief Locally denoised positions (default on, as CloudModelParams::surface_projection,
    * chosen by the evaluation; needs a sensor noise model: without one nothing moves).
    *
    * A measured point carries its full sensor noise across the surface, and the maximum of
    * many such points near contact drifts toward 1 (docs/RESULTS.md). With projection on,
    * each point moves toward the plane fitted to its weighted neighbours (itself excluded):
    * x'_i = x_i - alpha_i n_i n_i^T (x_i - c_i), with c_i their weighted centroid, n_i the
    * plane's normal and alpha_i = min(1, 2 s_i^2 / lambda_i), lambda_i the neighbours' scatter
    * across the plane and s_i^2 the sensor's variance along n_i: 1 on a flat noisy patch
    * (noise explains the scatter), small at edges and corners, which stay near where they were
    * measured. The discretisation term is taken about x'_i and kept along n_i only (a sample
    * sliding along its own surface does not move the surface), and the covariance's extent
    * along n_i is scaled by (1 - alpha)^2 + alpha^2 / k_eff, the variance of the shrunk
    * position, k_eff = (sum w)^2 / sum w^2 the neighbours' effective number. Without a sensor
    * noise model nothing changes. getSurfaceDisplacements() returns x'_i - x_i. */
  void setSurfaceProjection (bool project) { project_ = project; }
  /** \brief Whether surface projection is on. */
  bool getSurfaceProjection () const { return project_; }
  /** \brief After compute() with projection on: x'_i - x_i per output point (zero when
    * projection is off or moved nothing, NaN for non-finite points); empty otherwise. Kept as
    * a displacement so that points far from the origin keep their double precision. */
  const std::vector<Eigen::Vector3d>& getSurfaceDisplacements () const { return displacements_; }

  /** \brief Also record, for the surface model (CloudModel), each point's unoriented normal
    * and its neighbours (default off: costs one eigen solve a point and k indices a point). */
  void setComputeSurface (bool compute) { compute_surface_ = compute; }
  /** \brief Whether normals and neighbours are recorded for the surface model. */
  bool getComputeSurface () const { return compute_surface_; }
  /** \brief With setComputeSurface(true), whether to fit each point's normal (default on). Off
    * when the caller has a normal for every point: the neighbours are still recorded, without
    * the eigen solve a point, and getNormals() stays empty. */
  void setComputeNormals (bool compute) { compute_normals_ = compute; }
  /** \brief Whether each point's normal is fitted (with setComputeSurface(true)). */
  bool getComputeNormals () const { return compute_normals_; }
  /** \brief After compute() with setComputeSurface(true) (and setComputeNormals, the default):
    * the unit normal of the plane fitted
    * to each output point's neighbours (the weakest direction of its discretisation spread),
    * unoriented; zero where it is undetermined (fewer than two neighbours, all coincident),
    * NaN for non-finite points. Empty otherwise. */
  const std::vector<Eigen::Vector3f>& getNormals () const { return normals_; }
  /** \brief After compute() with setComputeSurface(true): getKSearch() input-cloud indices per
    * output point (row-major, -1 where fewer neighbours exist), the point itself excluded. */
  const std::vector<int>& getNeighbours () const { return neighbours_; }

  /** \brief Threads of compute(): 0 = one per hardware thread; default 1, as for
    * pcl::NormalEstimation. The output is the same for any count. Used only with the default
    * search (no setSearchMethod), whose concurrent queries are known to be safe. Throws
    * pcl::BadArgumentException for a negative count. */
  void setNumberOfThreads (int threads);
  /** \brief The thread count as set (0 = one per hardware thread). */
  int getNumberOfThreads () const { return threads_; }

  /** \brief pcl::Feature::compute(), with the output sized beside the k-d tree's build where
    * compute() runs on threads (its first writes are page faults: about 0.3 s of serial work at
    * 5,000,000 points in this project's VMs). Through a pcl::Feature reference the base's
    * compute() gives the same output. */
  void compute (PointCloudOut& output);

protected:
  /** \brief pcl::Feature::initCompute() after this class's checks: fails with a PCL_ERROR for a
    * radius search, k < 1 or a sensor pose the noise model cannot use; defaults the search to
    * a k-d tree (Euclidean, also for organized clouds). */
  bool initCompute () override;
  /** \brief Computes the covariance of every input point (or indexed point) into output,
    * and the per-point outputs the settings ask for. */
  void computeFeature (PointCloudOut& output) override;

private:
  /** \brief The surface projection of one point (see setSurfaceProjection), from its
    * neighbours' weighted mean offset and second moment about it: the displacement, the
    * discretisation term about the moved point, the local normal and the variance share kept
    * along it. False (nothing moves) without sensor variance along the normal. */
  static bool projectOntoSurface (const Eigen::Vector3d& mean_offset, const Eigen::Matrix3d& second_moment,
                                  double k_eff, const Eigen::Matrix3d& sensor_cov, Eigen::Vector3d& displacement,
                                  Eigen::Matrix3d& psi, Eigen::Vector3d& normal, double& shrink);

  std::optional<double> tau_;
  bool use_discretization_ = true;
  SensorNoiseModel noise_;
  std::optional<SensorPose> sensor_pose_;
  std::vector<float> radii_;
  std::vector<float> nearest_sqr_;
  bool coincident_ = false;
  double scatter_ratio_ = std::numeric_limits<double>::quiet_NaN ();
  bool project_ = true;  // CloudModelParams::surface_projection; test_cloud_model checks they agree
  std::vector<Eigen::Vector3d> displacements_;
  bool compute_surface_ = false;
  bool compute_normals_ = true;
  std::vector<Eigen::Vector3f> normals_;
  std::vector<int> neighbours_;
  int threads_ = 1;
  /** \brief The threads compute() runs on (see setNumberOfThreads). */
  std::size_t threadCount () const;
  /** \brief The visiting order, when initCompute computed it beside the k-d tree's build. */
  std::vector<std::size_t> order_;
  /** \brief Sizes the per-point outputs (radii_, nearest_sqr_, displacements_, normals_,
    * neighbours_, as the settings ask) for n points, each "not computed" (NaN, -1). */
  void resetOutputs (std::size_t n);
  /** \brief True when initCompute reset the outputs beside the k-d tree's build. */
  bool outputs_ready_ = false;
  /** \brief compute()'s output while it runs, for initCompute to size. */
  PointCloudOut* output_ = nullptr;
};
} // namespace pcl_probcollision

#ifdef PCL_NO_PRECOMPILE
#include <pcl_probcollision/impl/covariance_estimation.hpp>
#endif
