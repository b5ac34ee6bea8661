// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>

#include <pcl/exceptions.h>

#include <cmath>
#include <string>

namespace pcl_probcollision
{
void
CollisionRequest::validateThresholds () const
{
  const std::string why = thresholdsError ();
  if (!why.empty ())
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, "[pcl_probcollision::CollisionRequest::validate] " << why);
}

void
CollisionRequest::validate () const
{
  const char* where = "[pcl_probcollision::CollisionRequest::validate] ";
  validateThresholds ();
  if (!(rho_min >= 0.0 && rho_min <= 1.0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, where << "rho_min " << rho_min << " outside [0, 1]");
  if (!(expanded_k_sigma >= 0.0 && std::isfinite (expanded_k_sigma)))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         where << "expanded_k_sigma " << expanded_k_sigma << " must be finite and >= 0");
  if (traversal != TraversalMode::ExpectedWeight && traversal != TraversalMode::Stochastic &&
      traversal != TraversalMode::ExpandedBV)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException, where << "traversal mode " << static_cast<int> (traversal) << " is unknown");
  // Each of these changes how the surface layer's answer is used: without it they would change
  // nothing, and the answer would be the separators' under a request that names the surface.
  if (!surface && (surface_pooled || surface_ladder || surface_calibrated || max_surface_pairs > 0))
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         where << (surface_pooled    ? "surface_pooled"
                                   : surface_ladder  ? "surface_ladder"
                                   : surface_calibrated ? "surface_calibrated"
                                                        : "max_surface_pairs")
                               << " needs surface: set surface too (pcd_collision's -surface_pooled and "
                                  "-surface_ladder imply -surface)");
  if (surface_pooled && surface_ladder)
    PCL_THROW_EXCEPTION (pcl::BadArgumentException,
                         where << "surface_pooled and surface_ladder exclude each other: pick one way to combine the "
                                  "surface layer with the separators");
  classifier.validate ();
}

bool
CollisionRequest::operator== (const CollisionRequest& o) const
{
  return free_below == o.free_below && collision_above == o.collision_above && exhaustive == o.exhaustive &&
         per_point == o.per_point && enable_timings == o.enable_timings && traversal == o.traversal &&
         rho_min == o.rho_min && seed == o.seed && expanded_k_sigma == o.expanded_k_sigma && classifier == o.classifier &&
         defer_kernel_fits == o.defer_kernel_fits && max_leaf_fits == o.max_leaf_fits &&
         max_surface_pairs == o.max_surface_pairs && surface == o.surface &&
         surface_pooled == o.surface_pooled &&
         surface_ladder == o.surface_ladder && surface_calibrated == o.surface_calibrated && distance == o.distance;
}

const char*
verdictName (Verdict verdict)
{
  switch (verdict)
  {
    case Verdict::Free: return "free";
    case Verdict::InContact: return "contact";
    case Verdict::InCollision: return "collision";
    case Verdict::Unknown: break;
  }
  return "unknown";
}

const char*
answeredByName (AnsweredBy answered_by)
{
  switch (answered_by)
  {
    case AnsweredBy::Separators: return "separators";
    case AnsweredBy::SurfaceLayer: return "surface";
    case AnsweredBy::Pooled: return "pooled";
    case AnsweredBy::Unknown: break;
  }
  return "unknown";
}
} // namespace pcl_probcollision
