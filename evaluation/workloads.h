// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The evaluation's rows and the methods' runners: what evaluate_collision.cpp drives.

#include "baselines.h"

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/collision_request.h>

#include <cstdint>
#include <functional>
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
  bool near_contact = false;
  std::string method, setting;
  double score = 0.0;        ///< our P, or the baseline's 1/0 (nn: exp(-d / r))
  std::string verdict;       ///< free, contact or collision
  double query_us = 0.0;
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
};

/** \brief One configuration of our method in the sweep. */
struct OursSetting
{
  std::string name = "default";
  pcl_probcollision::CollisionRequest request;
  /** \brief How each cloud is modelled (the noise is set per workload). */
  pcl_probcollision::CloudModelParams model;
};

/** \brief The sweep: the library defaults first ("default"), the paper's measured-position
  * maximum ("max"), then one change at a time. full = false keeps default and max only. */
std::vector<OursSetting> oursSettings (bool full);

/** \brief A query's answer: score in [0, 1] and a verdict. */
struct Answer
{
  double score = 0.0;
  std::string verdict;
};
/** \brief One method on one cloud pair, prebuilt: answers a pose. */
using PoseQuery = std::function<Answer (const Eigen::Isometry3d& T)>;

/** \brief Our method on a cloud pair (robot = input A, env = target B), isotropic noise sigma
  * declared for both. Builds the hierarchies now (build row filled) and returns the query. */
PoseQuery buildOurs (const CloudXYZ::ConstPtr& robot, const CloudXYZ::ConstPtr& env, double sigma,
                     const OursSetting& setting, BuildRow& build,
                     std::function<void (std::size_t leaf_pairs, std::size_t kernel, double features)> on_query);

/** \brief W3: every SCENES.md query (data_dir/scenes/queries.csv) with our default and max
  * settings; right counts the default's answers that match the listed verdict (resting:
  * not free; lifted: free) out of total. */
void evaluateScenes (const std::string& data_dir, std::vector<QueryRow>& rows, int& right, int& total);

/** \brief The mesh sampled uniformly by area plus every vertex, aiming at `target` points in all
  * (pcl_probcollision::io::sampleMesh; deterministic for a seed). */
CloudXYZ::Ptr sampleCount (const TriangleMesh& mesh, std::size_t target, std::uint64_t seed);

/** \brief Gaussian noise of standard deviation sigma on every coordinate (deterministic). */
CloudXYZ::Ptr addNoise (const CloudXYZ& clean, double sigma, std::uint64_t seed);
} // namespace pcl_probcollision_eval
