// SPDX-License-Identifier: BSD-3-Clause
// evaluate_collision: the evaluation suite of docs/RESULTS.md (issue 6). Every method answers
// the same queries; ground truth comes from FCL on the meshes (W1), closed forms (W2) or
// SCENES.md (W3). Writes queries.csv, builds.csv, summary.csv, reliability.csv, flips.csv and
// model_size.csv into the output directory; scripts/evaluate.sh renders the charts.
//
//   evaluate_collision --out DIR --data SHARED_DATA_DIR [--quick] [--seed N]

#include "baselines.h"
#include "ground_truth.h"
#include "mesh_sampling.h"
#include "metrics.h"
#include "primitives.h"
#include "workloads.h"

#include <pcl_probcollision/collision_request.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <tuple>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace pcl_probcollision_eval;
using Clock = std::chrono::steady_clock;

namespace
{
struct Options
{
  std::string out_dir, data_dir;
  bool quick = false;
  std::uint64_t seed = 1;
  std::size_t poses = 0;          ///< W1 uniform and near-contact poses each (0: 40 quick, 300 full)
  bool ours_only = false;         ///< skip the baselines, W2 and W3 (for quick studies)
};

double
microsecondsSince (Clock::time_point start)
{
  return std::chrono::duration<double, std::micro> (Clock::now () - start).count ();
}

double
millisecondsSince (Clock::time_point start)
{
  return microsecondsSince (start) / 1000.0;
}

void
progress (const std::string& text)
{
  std::cerr << "[evaluate] " << text << std::endl;
}

// ---------------------------------------------------------------------------------------------
// Collected results. A cell is (workload, noise level, method, setting).
using CellKey = std::tuple<std::string, double, std::string, std::string>;

struct Results
{
  std::vector<QueryRow> queries;
  std::vector<BuildRow> builds;
  // flips[cell] = per pose, per re-sample: is free / score.
  struct Flip
  {
    std::vector<std::vector<bool>> is_free;
    std::vector<std::vector<double>> scores;
  };
  std::map<CellKey, Flip> flips;
};

// Runs one prebuilt method over a pose list, appending rows.
// score (optional) replaces the answer's score, computed outside the timed call.
void
runQueries (Results& results, const QueryRow& prototype, const std::vector<PoseTruth>& poses,
            const std::vector<bool>& near, const PoseQuery& query,
            const std::function<double (const Eigen::Isometry3d&)>& score = nullptr)
{
  for (std::size_t i = 0; i < poses.size (); ++i)
  {
    QueryRow row = prototype;
    row.query = std::to_string (i);
    row.exact_distance = poses[i].signed_distance;
    row.exact_collision = poses[i].collision;
    row.near_contact = near[i];
    const auto start = Clock::now ();
    const Answer a = query (poses[i].T);
    row.query_us = microsecondsSince (start);
    row.score = score ? score (poses[i].T) : a.score;
    row.verdict = a.verdict;
    results.queries.push_back (row);
  }
}

Answer
yesNo (bool collision)
{
  return {collision ? 1.0 : 0.0, collision ? "collision" : "free"};
}

// ---------------------------------------------------------------------------------------------
// W1: the piano in the room.
struct PianoRoom
{
  TriangleMesh rob_mesh, env_mesh;
  std::unique_ptr<ExactMeshPair> exact;
  double diagonal = 0.0;
  CloudXYZ::Ptr rob_clean, env_clean;
  std::vector<PoseTruth> poses;
  std::vector<bool> near;
};

PianoRoom
loadPianoRoom (const Options& o)
{
  PianoRoom w;
  std::string error;
  const std::string dir = o.data_dir + "/meshes/";
  if (!pcl_probcollision::io::loadTriangleMesh (dir + "piano_room_rob.obj", w.rob_mesh, error) ||
      !pcl_probcollision::io::loadTriangleMesh (dir + "piano_room_env.obj", w.env_mesh, error))
    throw std::runtime_error (error);
  w.exact.reset (new ExactMeshPair (w.rob_mesh, w.env_mesh));
  w.diagonal = w.exact->robotDiagonal ();
  w.rob_clean = sampleCount (w.rob_mesh, o.quick ? 3000 : 10000, o.seed * 101 + 1);
  w.env_clean = sampleCount (w.env_mesh, o.quick ? 12000 : 50000, o.seed * 101 + 2);

  const std::size_t uniform = o.poses ? o.poses : o.quick ? 40 : 250, near = uniform;
  const auto start = Clock::now ();
  w.poses = uniformPoseTruths (*w.exact, uniform, o.seed * 101 + 3, 2);
  NearContactOptions nc;
  nc.band = 0.05 * w.diagonal;
  nc.threads = 2;
  const auto near_poses = nearContactPoses (*w.exact, near, o.seed * 101 + 4, nc);
  w.poses.insert (w.poses.end (), near_poses.begin (), near_poses.end ());
  for (const auto& p : w.poses)
    w.near.push_back (std::abs (p.signed_distance) <= nc.band);
  progress ("W1 ground truth: " + std::to_string (w.poses.size ()) + " poses in " +
            std::to_string (millisecondsSince (start) / 1000.0) + " s");
  return w;
}

void
evaluatePianoRoom (const Options& o, const PianoRoom& w, Results& results)
{
  const std::vector<double> noise_pcts = o.quick ? std::vector<double> {0.5} : std::vector<double> {0.25, 0.5, 1.0, 4.0};
  for (const double pct : noise_pcts)
  {
    const double sigma = pct / 100.0 * w.diagonal;
    const double sigma_eff = std::sqrt (2.0) * sigma;
    const std::uint64_t noise_seed = o.seed * 1000 + static_cast<std::uint64_t> (pct * 100);
    const CloudXYZ::ConstPtr rob = addNoise (*w.rob_clean, sigma, noise_seed);
    const CloudXYZ::ConstPtr env = addNoise (*w.env_clean, sigma, noise_seed + 1);
    QueryRow proto;
    proto.workload = "W1";
    proto.noise_pct = pct;
    proto.sigma_eff = sigma_eff;
    auto buildRow = [&] (const std::string& method, const std::string& setting) {
      BuildRow b;
      b.workload = "W1";
      b.noise_pct = pct;
      b.method = method;
      b.setting = setting;
      return b;
    };

    // Ours: the whole sweep at 0.5 %, default and max elsewhere.
    for (const OursSetting& s : oursSettings (!o.quick && pct == 0.5))
    {
      BuildRow b = buildRow ("ours", s.name);
      double leaf_pairs = 0, kernel = 0, features = 0, n = 0;
      const PoseQuery q = buildOurs (rob, env, sigma, s, b, [&] (std::size_t lp, std::size_t k, double f) {
        leaf_pairs += lp;
        kernel += k;
        features += f;
        n += 1;
      });
      proto.method = "ours";
      proto.setting = s.name;
      runQueries (results, proto, w.poses, w.near, q);
      b.leaf_pairs_mean = leaf_pairs / n;
      b.kernel_share = leaf_pairs > 0 ? kernel / leaf_pairs : 0.0;
      b.features_mean = features / n;
      results.builds.push_back (b);
      progress ("W1 " + std::to_string (pct) + "% ours/" + s.name + " done");
    }

    if (o.ours_only)
      continue;
    // FCL on the exact meshes: the ground truth itself, timed as the exact-data reference.
    {
      BuildRow b = buildRow ("fcl_mesh", "exact");
      const auto start = Clock::now ();
      ExactMeshPair meshes (w.rob_mesh, w.env_mesh);
      b.build_ms = millisecondsSince (start);
      b.memory_bytes = static_cast<double> (meshes.memoryBytes ());
      results.builds.push_back (b);
      proto.method = "fcl_mesh";
      proto.setting = "exact";
      runQueries (results, proto, w.poses, w.near, [&] (const Eigen::Isometry3d& T) { return yesNo (meshes.collide (T)); });
    }

    // Collision maps: the env cloud in an octomap at 1, 2 and 4 sigma, against the piano mesh;
    // at 2 sigma also the piano cloud's own octree.
    for (const int factor : {1, 2, 4})
    {
      const std::string name = "octomap_" + std::to_string (factor) + "x";
      BuildRow b = buildRow (name, "mesh");
      OctomapBaseline map;
      const auto start = Clock::now ();
      map.buildEnv (*env, factor * sigma);
      map.setRobotMesh (w.rob_mesh);
      b.build_ms = millisecondsSince (start);
      b.memory_bytes = static_cast<double> (map.envMemoryBytes ());
      results.builds.push_back (b);
      proto.method = name;
      proto.setting = "mesh";
      runQueries (results, proto, w.poses, w.near, [&] (const Eigen::Isometry3d& T) { return yesNo (map.collideMesh (T)); });
      if (factor == 2)
      {
        BuildRow c = buildRow (name, "cloud");
        const auto start2 = Clock::now ();
        map.buildRobotCloud (*rob);
        c.build_ms = b.build_ms + millisecondsSince (start2);
        c.memory_bytes = static_cast<double> (map.envMemoryBytes () + map.robotCloudMemoryBytes ());
        results.builds.push_back (c);
        proto.setting = "cloud";
        runQueries (results, proto, w.poses, w.near, [&] (const Eigen::Isometry3d& T) { return yesNo (map.collideCloud (T)); });
      }
    }

    // Nearest-neighbour threshold at r = 1, 2, 3 sigma_eff: the timed query is the early-exit
    // "any pair closer than r"; the score exp(-d / r), d the distance capped at the near-contact
    // band (beyond it every pose scores 0), ranks by distance and is computed untimed.
    {
      NearestNeighbourBaseline nn;
      const auto start = Clock::now ();
      nn.build (*env, *rob);
      const double build_ms = millisecondsSince (start);
      for (const int k : {1, 2, 3})
      {
        const std::string name = "nn_" + std::to_string (k) + "sigma";
        BuildRow b = buildRow (name, "kdtree");
        b.build_ms = build_ms;
        b.memory_bytes = static_cast<double> (nn.memoryBytes ());
        results.builds.push_back (b);
        const double r = k * sigma_eff;
        proto.method = name;
        proto.setting = "kdtree";
        runQueries (
          results, proto, w.poses, w.near,
          [&] (const Eigen::Isometry3d& T) { return yesNo (nn.within (T, r)); },
          [&] (const Eigen::Isometry3d& T) { return std::exp (-nn.minDistance (T, 0.05 * w.diagonal) / r); });
      }
    }

    // Reconstruct (greedy projection triangulation) then FCL.
    {
      BuildRow b = buildRow ("reconstruct", "gp3");
      ReconstructBaseline rec;
      const auto start = Clock::now ();
      rec.build (*rob, *env);
      b.build_ms = millisecondsSince (start);
      b.memory_bytes = static_cast<double> (rec.memoryBytes ());
      results.builds.push_back (b);
      proto.method = "reconstruct";
      proto.setting = "gp3";
      runQueries (results, proto, w.poses, w.near, [&] (const Eigen::Isometry3d& T) { return yesNo (rec.collide (T)); });
    }
    progress ("W1 " + std::to_string (pct) + "% baselines done");

    // Stability: near-contact poses with |d| < sigma_eff, the sensor noise re-sampled.
    std::vector<std::size_t> flip_poses;
    for (std::size_t i = 0; i < w.poses.size () && flip_poses.size () < (o.quick ? 10u : 50u); ++i)
      if (std::abs (w.poses[i].signed_distance) < sigma_eff)
        flip_poses.push_back (i);
    const int resamples = o.quick ? 5 : 20;
    auto record = [&] (const std::string& method, const std::string& setting, std::size_t k, const Answer& a) {
      auto& f = results.flips[{"W1", pct, method, setting}];
      f.is_free.resize (flip_poses.size ());
      f.scores.resize (flip_poses.size ());
      f.is_free[k].push_back (a.verdict == "free");
      f.scores[k].push_back (a.score);
    };
    for (int r = 0; r < resamples; ++r)
    {
      const std::uint64_t seed = noise_seed + 7919 * (r + 1);
      const CloudXYZ::ConstPtr rob_r = addNoise (*w.rob_clean, sigma, seed);
      const CloudXYZ::ConstPtr env_r = addNoise (*w.env_clean, sigma, seed + 1);
      for (const OursSetting& s : oursSettings (false))
      {
        BuildRow unused;
        const PoseQuery q = buildOurs (rob_r, env_r, sigma, s, unused, nullptr);
        for (std::size_t k = 0; k < flip_poses.size (); ++k)
          record ("ours", s.name, k, q (w.poses[flip_poses[k]].T));
      }
      for (const int factor : {1, 2, 4})
      {
        OctomapBaseline map;
        map.buildEnv (*env_r, factor * sigma);
        map.setRobotMesh (w.rob_mesh);
        for (std::size_t k = 0; k < flip_poses.size (); ++k)
          record ("octomap_" + std::to_string (factor) + "x", "mesh", k,
                  yesNo (map.collideMesh (w.poses[flip_poses[k]].T)));
      }
      NearestNeighbourBaseline nn;
      nn.build (*env_r, *rob_r);
      for (std::size_t k = 0; k < flip_poses.size (); ++k)
      {
        const double d = nn.minDistance (w.poses[flip_poses[k]].T, 0.05 * w.diagonal);
        for (const int m : {1, 2, 3})
          record ("nn_" + std::to_string (m) + "sigma", "kdtree", k,
                  Answer {std::exp (-d / (m * sigma_eff)), d < m * sigma_eff ? "collision" : "free"});
      }
    }
    progress ("W1 " + std::to_string (pct) + "% stability: " + std::to_string (flip_poses.size ()) + " poses x " +
              std::to_string (resamples) + " re-samples");
  }
}

// ---------------------------------------------------------------------------------------------
// W2: primitives with closed-form gaps. Ours (default, max) and the cloud-only baselines.
void
evaluatePrimitives (const Options& o, Results& results)
{
  const std::vector<double> scales = o.quick ? std::vector<double> {1.0} : std::vector<double> {1.0, 4.0};
  for (const double scale : scales)
  {
    const auto queries = makePrimitiveQueries (scale, o.seed, o.quick);
    for (const auto& pq : queries)
    {
      QueryRow proto;
      proto.workload = "W2";
      proto.noise_pct = scale;
      proto.sigma_eff = std::sqrt (2.0) * pq.sigma;
      proto.query = pq.name;
      proto.exact_distance = pq.exact_distance;
      proto.exact_collision = pq.exact_collision;
      proto.near_contact = std::abs (pq.exact_distance) <= 3.0 * proto.sigma_eff;
      const Eigen::Isometry3d I = Eigen::Isometry3d::Identity ();
      auto push = [&] (const std::string& method, const std::string& setting, const Answer& a, double us) {
        QueryRow row = proto;
        row.method = method;
        row.setting = setting;
        row.score = a.score;
        row.verdict = a.verdict;
        row.query_us = us;
        results.queries.push_back (row);
      };
      for (const OursSetting& s : oursSettings (false))
      {
        BuildRow unused;
        const PoseQuery q = buildOurs (pq.b, pq.a, pq.sigma, s, unused, nullptr);
        const auto start = Clock::now ();
        const Answer a = q (I);
        push ("ours", s.name, a, microsecondsSince (start));
      }
      NearestNeighbourBaseline nn;
      nn.build (*pq.a, *pq.b);
      auto start = Clock::now ();
      const double d = nn.minDistance (I);
      const double us = microsecondsSince (start);
      for (const int m : {1, 2, 3})
        push ("nn_" + std::to_string (m) + "sigma", "kdtree",
              Answer {std::exp (-d / (m * proto.sigma_eff)), d < m * proto.sigma_eff ? "collision" : "free"}, us);
      OctomapBaseline map;
      map.buildEnv (*pq.a, 2.0 * pq.sigma);
      map.buildRobotCloud (*pq.b);
      start = Clock::now ();
      const bool hit = map.collideCloud (I);
      push ("octomap_2x", "cloud", yesNo (hit), microsecondsSince (start));
    }
    progress ("W2 sigma scale " + std::to_string (scale) + ": " + std::to_string (queries.size ()) + " queries");
  }
}

// ---------------------------------------------------------------------------------------------
// Output.
std::string
fmt (double v)
{
  if (std::isnan (v))
    return "nan";
  std::ostringstream s;
  s.precision (6);
  s << v;
  return s.str ();
}

void
writeFile (const std::string& path, const std::string& text)
{
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f (tmp);
    f << text;
    if (!f)
      throw std::runtime_error ("cannot write " + tmp);
  }
  if (std::rename (tmp.c_str (), path.c_str ()) != 0)
    throw std::runtime_error ("cannot rename " + tmp + " to " + path);
}

bool
isEasy (const QueryRow& r)
{
  return std::abs (r.exact_distance) > 3.0 * r.sigma_eff;
}

// Easy queries: free must read free, collision must read collision (contact is wrong both ways).
bool
easyCorrect (const QueryRow& r)
{
  return r.exact_collision ? r.verdict == "collision" : r.verdict == "free";
}

void
writeOutputs (const Options& o, const Results& results)
{
  std::ostringstream q;
  q << "workload,noise_pct,sigma_eff,query,exact_distance,exact_collision,near_contact,easy,method,setting,score,"
       "verdict,query_us\n";
  for (const auto& r : results.queries)
    q << r.workload << ',' << fmt (r.noise_pct) << ',' << fmt (r.sigma_eff) << ',' << r.query << ','
      << fmt (r.exact_distance) << ',' << r.exact_collision << ',' << r.near_contact << ',' << isEasy (r) << ','
      << r.method << ',' << r.setting << ',' << fmt (r.score) << ',' << r.verdict << ',' << fmt (r.query_us) << '\n';
  writeFile (o.out_dir + "/queries.csv", q.str ());

  // Group rows per (workload, noise, method, setting), in first-seen order.
  using Key = CellKey;
  std::vector<Key> order;
  std::map<Key, std::vector<const QueryRow*>> groups;
  for (const auto& r : results.queries)
  {
    const Key k {r.workload, r.noise_pct, r.method, r.setting};
    if (!groups.count (k))
      order.push_back (k);
    groups[k].push_back (&r);
  }
  std::map<Key, const BuildRow*> builds;
  for (const auto& b : results.builds)
    builds[{b.workload, b.noise_pct, b.method, b.setting}] = &b;

  struct Summary
  {
    Key key;
    std::size_t queries = 0, easy = 0;
    double easy_accuracy = NAN, auc = NAN, brier = NAN, flip = NAN, p_std = NAN;
    TimeSummary t;
    double build_ms = NAN, memory = NAN;
  };
  std::vector<Summary> summaries;
  std::ostringstream rel;
  rel << "workload,noise_pct,method,setting,bin_lo,bin_hi,mean_predicted,observed,count\n";
  for (const Key& k : order)
  {
    const auto& rows = groups[k];
    Summary s;
    s.key = k;
    s.queries = rows.size ();
    std::vector<double> scores, times, near_scores;
    std::vector<bool> outcomes, near_outcomes;
    std::size_t right = 0;
    for (const QueryRow* r : rows)
    {
      scores.push_back (r->score);
      outcomes.push_back (r->exact_collision);
      times.push_back (r->query_us);
      if (isEasy (*r))
      {
        ++s.easy;
        right += easyCorrect (*r) ? 1 : 0;
      }
      if (r->near_contact)
      {
        near_scores.push_back (r->score);
        near_outcomes.push_back (r->exact_collision);
      }
    }
    s.easy_accuracy = s.easy ? static_cast<double> (right) / s.easy : NAN;
    s.auc = rocAuc (scores, outcomes);
    // W3's "in-contact" queries have no exact outcome (resting objects touch): no Brier there.
    if (std::get<2> (k) == "ours" && std::get<0> (k) != "W3" && !near_scores.empty ())
    {
      s.brier = brierScore (near_scores, near_outcomes);
      for (const auto& bin : reliabilityBins (near_scores, near_outcomes, 10))
        rel << std::get<0> (k) << ',' << fmt (std::get<1> (k)) << ',' << std::get<2> (k) << ',' << std::get<3> (k)
            << ',' << fmt (bin.lo) << ',' << fmt (bin.hi) << ',' << fmt (bin.mean_predicted) << ','
            << fmt (bin.observed) << ',' << bin.count << '\n';
    }
    s.t = summarizeTimes (times);
    if (builds.count (k))
    {
      s.build_ms = builds[k]->build_ms;
      s.memory = builds[k]->memory_bytes;
    }
    const auto f = results.flips.find (k);
    if (f != results.flips.end ())
    {
      s.flip = flipRate (f->second.is_free);
      s.p_std = std::get<2> (k) == "ours" ? meanGroupStd (f->second.scores) : NAN;
    }
    summaries.push_back (s);
  }
  // Pareto front per workload and noise level: median time against ROC AUC (chart 1).
  std::vector<bool> pareto (summaries.size (), false);
  {
    std::map<std::pair<std::string, double>, std::vector<std::size_t>> cells;
    for (std::size_t i = 0; i < summaries.size (); ++i)
      cells[{std::get<0> (summaries[i].key), std::get<1> (summaries[i].key)}].push_back (i);
    for (const auto& cell : cells)
    {
      std::vector<double> x, y;
      for (const std::size_t i : cell.second)
      {
        x.push_back (summaries[i].t.median);
        y.push_back (summaries[i].auc);
      }
      const auto front = paretoFront (x, y);
      for (std::size_t j = 0; j < cell.second.size (); ++j)
        pareto[cell.second[j]] = front[j];
    }
  }
  std::ostringstream sum;
  sum << "workload,noise_pct,method,setting,queries,easy_queries,easy_accuracy,auc,brier_near,flip_rate,p_std,"
         "median_us,p90_us,max_us,build_ms,memory_bytes,pareto\n";
  std::ostringstream flips;
  flips << "workload,noise_pct,method,setting,flip_rate,p_std\n";
  for (std::size_t i = 0; i < summaries.size (); ++i)
  {
    const Summary& s = summaries[i];
    sum << std::get<0> (s.key) << ',' << fmt (std::get<1> (s.key)) << ',' << std::get<2> (s.key) << ','
        << std::get<3> (s.key) << ',' << s.queries << ',' << s.easy << ',' << fmt (s.easy_accuracy) << ','
        << fmt (s.auc) << ',' << fmt (s.brier) << ',' << fmt (s.flip) << ',' << fmt (s.p_std) << ','
        << fmt (s.t.median) << ',' << fmt (s.t.p90) << ',' << fmt (s.t.max) << ',' << fmt (s.build_ms) << ','
        << fmt (s.memory) << ',' << pareto[i] << '\n';
    if (!std::isnan (s.flip))
      flips << std::get<0> (s.key) << ',' << fmt (std::get<1> (s.key)) << ',' << std::get<2> (s.key) << ','
            << std::get<3> (s.key) << ',' << fmt (s.flip) << ',' << fmt (s.p_std) << '\n';
  }
  writeFile (o.out_dir + "/summary.csv", sum.str ());
  writeFile (o.out_dir + "/reliability.csv", rel.str ());
  writeFile (o.out_dir + "/flips.csv", flips.str ());

  std::ostringstream model;
  model << "workload,noise_pct,setting,nodes,leaf_pairs_mean,kernel_share,features_mean,easy_accuracy,auc\n";
  for (const auto& b : results.builds)
  {
    if (b.method != "ours")
      continue;
    for (const Summary& s : summaries)
      if (s.key == Key {b.workload, b.noise_pct, b.method, b.setting})
        model << b.workload << ',' << fmt (b.noise_pct) << ',' << b.setting << ',' << fmt (b.nodes) << ','
              << fmt (b.leaf_pairs_mean) << ',' << fmt (b.kernel_share) << ',' << fmt (b.features_mean) << ','
              << fmt (s.easy_accuracy) << ',' << fmt (s.auc) << '\n';
  }
  writeFile (o.out_dir + "/model_size.csv", model.str ());
}

Options
parse (int argc, char** argv)
{
  Options o;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&] () -> std::string {
      if (i + 1 >= argc)
        throw std::invalid_argument ("option " + a + " needs a value");
      return argv[++i];
    };
    if (a == "--out")
      o.out_dir = value ();
    else if (a == "--data")
      o.data_dir = value ();
    else if (a == "--quick")
      o.quick = true;
    else if (a == "--seed")
      o.seed = std::stoull (value ());
    else if (a == "--poses")
      o.poses = std::stoull (value ());
    else if (a == "--ours-only")
      o.ours_only = true;
    else
      throw std::invalid_argument ("unknown option " + a +
                                   " (usage: evaluate_collision --out DIR --data DIR [--quick] [--seed N] [--poses N] [--ours-only])");
  }
  if (o.out_dir.empty () || o.data_dir.empty ())
    throw std::invalid_argument ("--out and --data are required");
  return o;
}
} // namespace

int
main (int argc, char** argv)
{
  try
  {
    const Options o = parse (argc, argv);
    const auto start = Clock::now ();
    Results results;
    int scenes_right = 0, scenes_total = 0;
    if (!o.ours_only)
    {
      evaluateScenes (o.data_dir, results.queries, scenes_right, scenes_total);
      progress ("W3 scenes: " + std::to_string (scenes_right) + " / " + std::to_string (scenes_total) +
                " answered as SCENES.md lists (default setting)");
      evaluatePrimitives (o, results);
    }
    const PianoRoom w = loadPianoRoom (o);
    evaluatePianoRoom (o, w, results);
    writeOutputs (o, results);
    progress ("done in " + std::to_string (millisecondsSince (start) / 1000.0) + " s; W3 " +
              std::to_string (scenes_right) + "/" + std::to_string (scenes_total));
    return scenes_right == scenes_total ? 0 : 3;
  }
  catch (const std::exception& e)
  {
    std::cerr << "evaluate_collision: " << e.what () << std::endl;
    return 2;
  }
}
