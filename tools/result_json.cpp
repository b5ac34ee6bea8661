// SPDX-License-Identifier: BSD-3-Clause
// pcd_collision's -json line (tools/result_json.h).
#include "result_json.h"

#include "json_writer.h"

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/version.h>

namespace pcd_collision
{
namespace
{
using pcl_probcollision::io::JsonWriter;

/** \brief The member "surface" of an input: null without a surface model. */
void
surfaceJson (JsonWriter& j, const std::optional<SurfaceFacts>& s)
{
  if (!s)
  {
    j.null ();
    return;
  }
  j.beginObject ();
  j.key ("orientation").string (s->orientation);
  j.key ("inside_known").boolean (s->inside_known);
  j.key ("hidden_from_viewpoint").number (s->hidden_from_viewpoint);
  j.key ("closed_share").number (s->closed_share);
  j.key ("solid_share").number (s->solid_share);
  j.endObject ();
}

void
inputJson (JsonWriter& j, const InputSummary& in)
{
  j.beginObject ();
  j.key ("path").string (in.path);
  if (!in.mesh)
  {
    j.key ("kind").string ("cloud");
    j.key ("points").unsignedInteger (in.points);
    j.key ("finite").unsignedInteger (in.finite);
    j.key ("width").unsignedInteger (in.width);
    j.key ("height").unsignedInteger (in.height);
  }
  else
  {
    j.key ("kind").string ("mesh");
    j.key ("vertices").unsignedInteger (in.vertices);
    j.key ("triangles").unsignedInteger (in.triangles);
    j.key ("points").unsignedInteger (in.points);
    j.key ("spacing").number (in.spacing);
    j.key ("spacing_source").string (in.spacing_source);
  }
  // Samples the default resolution merged into others (CloudModel::mergedSamples; the model has
  // points - merged_samples points); null when the input has no model.
  j.key ("merged_samples");
  if (in.merged_samples)
    j.unsignedInteger (*in.merged_samples);
  else
    j.null ();
  j.key ("surface");
  surfaceJson (j, in.surface);
  j.endObject ();
}

} // namespace

void
summarizeModel (const pcl_probcollision::CloudModel* model, InputSummary& summary)
{
  summary.merged_samples.reset ();
  summary.surface.reset ();
  if (!model)
    return;
  summary.merged_samples = model->mergedSamples ();
  if (model->surface ().empty ())
    return;
  const auto& s = model->surface ();
  summary.surface = SurfaceFacts{pcl_probcollision::orientationName (s.orientation ()), s.insideKnown (),
                                 s.hiddenFromViewpoint (), s.closedShare (), s.solidShare ()};
}

std::string
runMembersJson (const Options& o, const InputSummary& a, const InputSummary& b)
{
  const auto& rq = requestFor (o);
  JsonWriter j;
  j.beginObject ();
  j.key ("inputs").beginObject ();
  j.key ("a");
  inputJson (j, a);
  j.key ("b");
  inputJson (j, b);
  j.endObject ();
  j.key ("parameters").beginObject ();
  // "sensor" is the model of both inputs, null when they differ; a mesh gets no noise.
  j.key ("sensor");
  o.sensor_a == o.sensor_b ? j.string (o.sensor_a) : j.null ();
  j.key ("sensor_a");
  !a.mesh ? j.string (o.sensor_a) : j.null ();
  j.key ("sensor_b");
  !b.mesh ? j.string (o.sensor_b) : j.null ();
  j.key ("sigma_a");
  (o.sensor_a == "isotropic" && !a.mesh) ? j.number (o.sigma_a) : j.null ();
  j.key ("sigma_b");
  (o.sensor_b == "isotropic" && !b.mesh) ? j.number (o.sigma_b) : j.null ();
  j.key ("k").integer (o.k);
  j.key ("thresholds").numbers ({o.free_below, o.collision_above});
  j.key ("traversal").string (o.stochastic ? "stochastic" : "deterministic");
  j.key ("positions").string (o.measured ? "measured" : "projected");
  j.key ("seed").unsignedInteger (o.seed);
  j.key ("exhaustive").boolean (rq.exhaustive);
  j.key ("defer_kernel_fits").boolean (rq.defer_kernel_fits);
  j.key ("max_leaf_fits").unsignedInteger (rq.max_leaf_fits);
  j.key ("max_surface_pairs").unsignedInteger (rq.max_surface_pairs);
  j.key ("noise_resolution").number (modelParamsFor (o, true).noiseResolution ());
  j.key ("noise_resolution_gate").string (pcl_probcollision::CloudModelParams::resolutionGateName (o.noise_resolution_gate));
  j.key ("noise_stop").number (o.noise_stop);
  j.key ("surface").boolean (rq.surface);
  j.key ("surface_pooled").boolean (rq.surface_pooled);
  j.key ("surface_ladder").boolean (rq.surface_ladder);
  j.key ("surface_calibrated").boolean (rq.surface_calibrated);
  j.key ("distance").boolean (rq.distance);
  j.key ("closed_a").boolean (o.closed_a);
  j.key ("closed_b").boolean (o.closed_b);
  j.key ("orientation_a").string (pcl_probcollision::orientationName (o.orientation_a));
  j.key ("orientation_b").string (pcl_probcollision::orientationName (o.orientation_b));
  const pcl_probcollision::BVHParams hierarchy = modelParamsFor (o, true).hierarchy;
  j.key ("nmax").integer (hierarchy.n_max);
  j.key ("nmin").integer (hierarchy.n_min);
  j.key ("sigma_max").number (hierarchy.sigma_max);
  j.key ("epsilon").number (hierarchy.epsilon);
  j.key ("split").string (o.split);
  j.endObject ();
  j.endObject ();
  return j.objectMembers ();
}

std::string
resultJson (const Options& o, const InputSummary& a, const InputSummary& b, const pcl_probcollision::CollisionResult& r,
            const Pose& pose, long long pose_index, const std::optional<double>& write_ms, std::size_t points_written,
            const std::string* run_members)
{
  JsonWriter j;
  j.beginObject ();
  if (pose_index >= 0)
    j.key ("pose_index").integer (pose_index);
  j.key ("pose").numbers ({pose[0], pose[1], pose[2], pose[3], pose[4], pose[5]});
  j.key ("verdict").string (pcl_probcollision::verdictName (r.verdict));
  j.key ("probability").number (r.probability);
  // Whose answer P is (CollisionResult::answered_by): "separators", "surface" or "pooled"; with
  // -surface_ladder it varies from pose to pose.
  j.key ("answered_by").string (pcl_probcollision::answeredByName (r.answered_by));
  j.key ("signed_distance").number (r.signed_distance);
  j.key ("signed_distance_std").number (r.signed_distance_std);
  // Always a boolean (false without -surface): the surface layer's answer rests on surface the
  // samples do not show (CollisionResult::unobserved).
  j.key ("unobserved").boolean (r.unobserved);
  // Always a boolean (false without -distance): signed_distance is the nearest samples' distance,
  // nearest_points the two samples (A's, B's; null otherwise).
  j.key ("sample_distance").boolean (r.sample_distance);
  if (r.sample_distance)
  {
    j.key ("nearest_points").beginArray ();
    j.numbers ({r.nearest_point_a.x (), r.nearest_point_a.y (), r.nearest_point_a.z ()});
    j.numbers ({r.nearest_point_b.x (), r.nearest_point_b.y (), r.nearest_point_b.z ()});
    j.endArray ();
  }
  else
    j.key ("nearest_points").null ();
  j.key ("lower_bound").boolean (r.lower_bound);
  j.key ("budget_exhausted").boolean (r.budget_exhausted);
  // Always a boolean (false without -noise_resolution): the answer is the unmerged models',
  // asked again after the merged ones read contact leaning to collision (CollisionResult::full_resolution).
  j.key ("full_resolution").boolean (r.full_resolution);
  j.key ("no_leaf_tested").boolean (r.no_leaf_tested);
  j.key ("points_a").unsignedInteger (r.points_a);
  j.key ("points_b").unsignedInteger (r.points_b);
  j.key ("points_skipped_nonfinite").unsignedInteger (r.points_skipped_nonfinite);
  j.key ("leaf_pairs").unsignedInteger (r.leaf_pairs_tested);
  j.key ("bv_tests").unsignedInteger (r.bv_tests);
  j.key ("kernel_leaf_pairs").unsignedInteger (r.kernel_leaf_pairs);
  j.key ("degenerate_leaf_pairs").unsignedInteger (r.degenerate_leaf_pairs);
  j.key ("classifier_iterations").unsignedInteger (r.classifier_iterations);
  j.key ("build_ms").number (r.build_ms);
  j.key ("query_ms").number (r.query_ms);
  j.key ("witness");
  if (r.witness_side == 0)
    j.null ();
  else
  {
    j.beginObject ();
    j.key ("point").numbers ({r.witness_point.x (), r.witness_point.y (), r.witness_point.z ()});
    j.key ("side").string (r.witness_side > 0 ? "a" : "b");
    j.key ("index").integer (r.witness_index);
    j.key ("normal").numbers ({r.witness_normal.x (), r.witness_normal.y (), r.witness_normal.z ()});
    j.endObject ();
  }
  j.key ("timings_ms").beginObject ();
  j.key ("load_a").number (a.load_ms);
  j.key ("load_b").number (b.load_ms);
  j.key ("sample_meshes").number (a.sample_ms + b.sample_ms);
  j.key ("build").number (r.build_ms);
  j.key ("query").number (r.query_ms);
  if (write_ms)
    j.key ("write").number (*write_ms);
  j.endObject ();
  j.members (run_members ? *run_members : runMembersJson (o, a, b));
  if (o.output)
  {
    j.key ("output").beginObject ();
    j.key ("path").string (*o.output);
    j.key ("points").unsignedInteger (points_written);
    j.endObject ();
  }
  // Which release answered: a logged line stays traceable after an upgrade changed answers.
  j.key ("version").string (pcl_probcollision::libraryVersion ());
  j.endObject ();
  return j.text ();
}
} // namespace pcd_collision
