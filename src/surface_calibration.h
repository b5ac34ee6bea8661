// SPDX-License-Identifier: BSD-3-Clause
// The surface layer's calibration maps (CollisionRequest::surface_calibrated). Private to the
// library (src/), used by src/collide.cpp.
#pragma once

namespace pcl_probcollision
{
namespace detail
{
/** \brief Which answer a calibration map was fitted for. */
enum class SurfaceCalibration
{
  SurfaceLayer,  ///< CollisionRequest::surface alone
  Pooled         ///< CollisionRequest::surface_pooled
};

/** \brief P through the calibration map fitted for `which` (docs/SURFACE.md, "Calibration"):
  * strictly increasing on the contact band [free_below, collision_above] of CollisionRequest's
  * defaults, onto itself, and the identity outside it. So the map keeps every ranking and, at
  * the default thresholds, every verdict; it moves P inside the band to the collision share
  * observed there. NaN stays NaN. */
double
calibratedSurfaceProbability (double p, SurfaceCalibration which);
} // namespace detail
} // namespace pcl_probcollision
