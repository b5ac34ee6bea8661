// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The evaluation's rows and the methods' runners: what evaluate_collision.cpp drives.

#include "baselines.h"

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision_request.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace pcl_probcollision_eval
{
/** \brief One query answered by one method (a row of queries.csv). */
struct QueryRow
{
  std::string workload;      ///< W1, W2 or W3
  double noise_pct = 0.0;    ///< W1: noise as % of the piano diagonal; W2: sigma scale; W3: 0
  double sigma_eff = 0.0;    ///< sqrt(sigma_a^2 + sigma_b^2), the scale "easy" is measured in
  std::string query;
  double exact_distance = 0.0;
  bool exact_collision = false;
  bool near_contact = false; ///< W1: |d| <= 5 % of the diagonal; W2: |d| <= 3 sigma_eff; W3: in-contact
  bool near_sigma = false;   ///< |d| <= 2.8 sigma_eff (issue #16's near band in noise units; not W3)
  std::string pose_set;      ///< W1: uniform, near_pct (+-5 % targets) or near_sigma (+-2.8 sigma_eff targets)
  std::string method, setting;
  double score = 0.0;        ///< our P, or the baseline's 1/0 (nn: exp(-d / r))
  std::string verdict;       ///< free, contact or collision
  double query_us = 0.0;
  /** \brief Ours: CollisionResult::signed_distance and its std (NaN when not computed). */
  double signed_distance = std::numeric_limits<double>::quiet_NaN ();
  double signed_distance_std = std::numeric_limits<double>::quiet_NaN ();
  /** \brief Ours: CollisionResult::answered_by's name (the ladder's rung); empty for baselines. */
  std::string answered_by;
};

/** \brief Build cost and model size of one method on one workload cell. */
struct BuildRow
{
  std::string workload, method, setting;
  double noise_pct = 0.0;
  double build_ms = 0.0;
  double memory_bytes = 0.0;
  // Our model size (0 for the baselines).
  double nodes = 0.0, leaf_pairs_mean = 0.0, kernel_share = 0.0, features_mean = 0.0;
  double points = 0.0;  ///< model points of both clouds (fewer than samples when merged)
};

/** \brief One configuration of our method in the sweep. */
struct OursSetting
{
  std::string name = "default";
  pcl_probcollision::CollisionRequest request;
  /** \brief How each cloud is modelled (the noise is set per workload). */
  pcl_probcollision::CloudModelParams model;
};

/** \brief The sweep: the library defaults first ("default"), the separators alone without the
  * surface layer ("classifier": CollisionRequest::surface and CloudModelParams::surface false),
  * the surface layer on ("surface": both true), the paper's model ("max": measured positions,
  * separators alone), then one change at a time from the defaults. One of classifier and
  * surface answers as default does (the surface layer is off by default while experimental).
  * "pooled" is the surface layer pooled with the separators (CollisionRequest::surface_pooled),
  * "ladder" the separators first and the surface layer where they leave the answer open
  * (CollisionRequest::surface_ladder), "surface-k20" the surface layer on models of 20
  * neighbours (CloudModelParams::k). max is unmerged whatever the default resolution. full =
  * false keeps default, classifier, surface, pooled, ladder, surface-k20 and max. Each c of
  * merge adds "merge<c>"
  * and "surface-merge<c>": classifier and surface with CloudModelParams::noise_resolution = c;
  * each c of gate "gate<c>" and "surface-gate<c>", the same merge gated by the local spacing
  * (ResolutionGate::WhereNoiseExceedsSpacing); each c of cloud_merge "cloudmerge<c>" and
  * "surface-cloudmerge<c>", the same merge of a whole cloud where it is sampled finer than its
  * noise (ResolutionGate::WholeCloud); each c of stop "stop<c>" and "surface-stop<c>",
  * the hierarchy not split within the noise (BVHParams::noise_stop = c). Each n of cap adds
  * "cap<n>": classifier with CollisionRequest::max_leaf_fits = n (issue #17 item 2), and
  * "ladder-cap<n>": ladder with CollisionRequest::max_surface_pairs = n. W2 adds
  * "surface-closed" itself (CloudModelParams::closed_objects on its solids, Solids). */
std::vector<OursSetting> oursSettings (bool full, const std::vector<double>& merge = {},
                                       const std::vector<double>& gate = {}, const std::vector<double>& stop = {},
                                       const std::vector<double>& cap = {},
                                       const std::vector<double>& cloud_merge = {});

/** \brief evaluate_collision --surface-calibrated: the settings with the surface layer answer
  * with its calibration maps (CollisionRequest::surface_calibrated, off by default). */
void calibratedSurface (std::vector<OursSetting>& settings);

/** \brief A query's answer: score in [0, 1] and a verdict; ours also the signed distance and
  * its std (NaN when not computed, e.g. before the surface layer or with surface off) and the
  * request's surface switch. */
struct Answer
{
  double score = 0.0;
  std::string verdict;
  double signed_distance = std::numeric_limits<double>::quiet_NaN ();
  double signed_distance_std = std::numeric_limits<double>::quiet_NaN ();
  bool surface = false;
  std::string answered_by {};  ///< ours: answeredByName (); empty for baselines
};
/** \brief One method on one cloud pair, prebuilt: answers a pose. */
using PoseQuery = std::function<Answer (const Eigen::Isometry3d& T)>;

/** \brief Our two cloud models (robot = input A, env = target B). */
struct OursModels
{
  pcl_probcollision::CloudModel::ConstPtr robot, env;
};

/** \brief Per point of a sampled cloud, the outward normal of the mesh face it came from
  * (index-aligned with the cloud; noise moves points, not their order). */
using Outward = std::vector<Eigen::Vector3f>;

/** \brief Which side each point was seen from, for both clouds: what a registered multi-view
  * scan knows (each point's sensor). The evaluation emulates it with the mesh faces' sides;
  * only the sign is used (orientedScan). */
struct ScanSides
{
  const Outward* robot = nullptr;
  const Outward* env = nullptr;
};

/** \brief Which clouds are closed solids seen from outside: a setting's
  * CloudModelParams::closed_objects applies only to those (W2 declares what a user knows of its
  * shapes: not the floor patch, nor the room the cube is inside of). */
struct Solids
{
  bool robot = true;
  bool env = true;
};

/** \brief A noisy cloud as a scan with oriented normals: each normal is the plane fitted to the
  * point's k nearest noisy neighbours (the library's own estimate), turned to the side the
  * point was seen from. Only the side comes from the mesh, never the direction. */
pcl::PointCloud<pcl::PointNormal>::Ptr orientedScan (const CloudXYZ& noisy, const Outward& outward, int k);

/** \brief Builds both cloud models with isotropic noise sigma declared for both; fills the
  * build row's time, memory and node count. With sides, each cloud is built from its
  * orientedScan (normals estimated before the timed build, as a scan would bring them). */
OursModels buildOursModels (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma,
                            const pcl_probcollision::CloudModelParams& model, BuildRow& build,
                            const ScanSides& sides = ScanSides (), const Solids& solids = Solids ());

/** \brief The query of one request on prebuilt models (several requests may share them). */
PoseQuery oursQuery (const OursModels& models, const pcl_probcollision::CollisionRequest& request,
                     std::function<void (std::size_t leaf_pairs, std::size_t kernel, double features)> on_query);

/** \brief Our method on a cloud pair (robot = input A, env = target B), isotropic noise sigma
  * declared for both. Builds the hierarchies now (build row filled) and returns the query. */
PoseQuery buildOurs (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma,
                     const OursSetting& setting, BuildRow& build,
                     std::function<void (std::size_t leaf_pairs, std::size_t kernel, double features)> on_query,
                     const ScanSides& sides = ScanSides (), const Solids& solids = Solids ());

/** \brief W3: every SCENES.md query (data_dir/scenes/queries.csv) with every setting of
  * oursSettings (false, {}, {}, {}, {}, cloud_merge); right counts the default's answers that match
  * the listed verdict (resting: not free; lifted: free) out of total. */
void evaluateScenes (const std::string& data_dir, const std::vector<double>& cloud_merge, std::vector<QueryRow>& rows,
                     int& right, int& total);

/** \brief The mesh sampled uniformly by area plus every vertex, aiming at `target` points in all
  * (pcl_probcollision::io::sampleMesh; deterministic for a seed); without `vertices`, by area
  * alone (every position new for a new seed: the re-scans). With outward, also each sample's
  * face normal (the same points). */
CloudXYZ::Ptr sampleCount (const TriangleMesh& mesh, std::size_t target, std::uint64_t seed, Outward* outward = nullptr,
                           bool vertices = true);

/** \brief Gaussian noise of standard deviation sigma on every coordinate (deterministic). */
CloudXYZ::Ptr addNoise (const CloudXYZ& clean, double sigma, std::uint64_t seed);
} // namespace pcl_probcollision_eval
