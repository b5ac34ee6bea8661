// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// Workload W2 of the evaluation suite (issue #6): primitives with analytic answers. Noisy
// surface samples of spheres, axis-aligned boxes, axis-aligned capped cylinders and square
// plane patches, and query scenarios whose signed distance is known in closed form.
//
// Units are metres, z is up, and every shape and cloud is in one world frame (pose identity).
// Signed distance follows one convention throughout: positive = the gap between the two solids,
// negative = penetration depth (the length of the shortest translation that separates them).

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace pcl_probcollision_eval
{
using PrimitiveCloud = pcl::PointCloud<pcl::PointXYZ>;

/** \brief Sphere. */
struct Sphere
{
  Eigen::Vector3d center = Eigen::Vector3d::Zero ();
  double radius = 0.0;
};

/** \brief Axis-aligned box: center +/- half_extents. */
struct Box
{
  Eigen::Vector3d center = Eigen::Vector3d::Zero ();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero ();
};

/** \brief Capped cylinder with its axis along +z, from base_center up to base_center + height z. */
struct Cylinder
{
  Eigen::Vector3d base_center = Eigen::Vector3d::Zero ();
  double radius = 0.0;
  double height = 0.0;
};

/** \brief Horizontal square plane patch (normal +z): center +/- half_size in x and y. In the
  * distance functions it stands for the boundary of the solid half-space below it, which is
  * exact while the other object's footprint stays within the patch. */
struct PlanePatch
{
  Eigen::Vector3d center = Eigen::Vector3d::Zero ();
  double half_size = 0.0;
};

/** \brief Surface areas (the cylinder's includes both caps; the patch is one-sided). */
double surfaceArea (const Sphere& s);
double surfaceArea (const Box& b);
double surfaceArea (const Cylinder& c);
double surfaceArea (const PlanePatch& p);

/** \brief Noisy surface sample, uniform by area with one point per spacing^2 of area on average.
  *
  * Stratified (jittered) sampling: the surface is cut, through an area-preserving
  * parametrisation, into cells of area spacing^2 (rectangles and the cylinder's side into a
  * spacing grid clipped at the border, caps into a grid clipped to the disk, the sphere into
  * polar bands one spacing wide) and each cell gets one uniform point. Unlike independent
  * draws this leaves no large holes, so the spacing is the sampling resolution. The count is
  * round(area / spacing^2) for the sphere and within a few percent of it otherwise.
  *
  * Each point then gets independent Gaussian noise of standard deviation sigma on every axis.
  * Positions and noise come from two separate streams, so sigma = 0 gives exactly the
  * noise-free positions of the noisy sample with the same seed. Deterministic for a seed and
  * independent of the standard library (std::mt19937_64 raw bits, own transforms).
  * Throws std::invalid_argument for a non-positive spacing, a negative sigma, a degenerate
  * shape, or more than 20 million expected points. */
PrimitiveCloud::Ptr sampleSurface (const Sphere& s, double spacing, double sigma, std::uint64_t seed);
PrimitiveCloud::Ptr sampleSurface (const Box& b, double spacing, double sigma, std::uint64_t seed);
PrimitiveCloud::Ptr sampleSurface (const Cylinder& c, double spacing, double sigma, std::uint64_t seed);
PrimitiveCloud::Ptr sampleSurface (const PlanePatch& p, double spacing, double sigma, std::uint64_t seed);

/** \brief Sphere-sphere: |c_a - c_b| - r_a - r_b (exact for solids, containment included). */
double signedDistance (const Sphere& a, const Sphere& b);

/** \brief Box-box (both axis-aligned): the Euclidean norm of the per-axis gaps when separated,
  * minus the smallest per-axis overlap when overlapping (the Minkowski difference is a box). */
double signedDistance (const Box& a, const Box& b);

/** \brief Sphere-box: distance from the centre to the box minus the radius; with the centre
  * inside the box, -(radius + distance from the centre to the nearest face). */
double signedDistance (const Sphere& s, const Box& b);

/** \brief Sphere against the half-space below the patch: centre height above it minus radius. */
double signedDistance (const Sphere& s, const PlanePatch& p);

/** \brief Cylinder against the half-space below the patch: bottom height above the patch. */
double signedDistance (const Cylinder& c, const PlanePatch& p);

/** \brief Box `object` inside a hollow `room` whose walls are solid beyond its faces: the
  * smallest wall clearance when the object is wholly inside, otherwise minus the norm of its
  * per-axis protrusions through the walls. */
double clearanceInside (const Box& room, const Box& object);

/** \brief One query of workload W2: two clouds with an exact answer. */
struct PrimitiveQuery
{
  std::string name;          ///< "<scenario>/<gap in sigma>s", e.g. "plate_sphere/-0.5s"; the same for every seed
  std::string scenario;      ///< e.g. "plate_sphere"
  PrimitiveCloud::Ptr a;     ///< the fixed object; one cloud shared by all queries of a scenario
  PrimitiveCloud::Ptr b;     ///< the placed object, sampled anew for each query
  double sigma = 0.0;        ///< per-axis noise standard deviation of both clouds (m)
  double spacing_a = 0.0;    ///< sampling spacing of a (m)
  double spacing_b = 0.0;    ///< sampling spacing of b (m)
  double exact_distance = 0.0;  ///< closed-form signed distance (m): > 0 gap, < 0 penetration depth
  bool exact_collision = false; ///< exact_distance <= 0 (touching counts; |d| < 1e-12 m reads as 0)
  /** \brief a is a closed solid seen from outside (every placed object b is): what a user would
    * declare with CloudModelParams::closed_objects; false for the floor patch and the room. */
  bool solid_a = true;
};

/** \brief Options of makePrimitiveQueries(). */
struct PrimitiveWorkloadOptions
{
  double sigma_scale = 1.0;  ///< noise sigma = kPrimitiveBaseSigma * sigma_scale, in (0, 8]
  std::uint64_t seed = 1;    ///< drives sample positions and noise only, never the geometry
  bool quick = false;        ///< fewer gaps per scenario and a coarser room
  bool noise_free = false;   ///< sample exactly on the surfaces (sigma still sets the gaps): for checks
};

/** \brief Noise standard deviation at sigma_scale 1 (m). */
constexpr double kPrimitiveBaseSigma = 0.001;

/** \brief The nominal gaps of each scenario, in units of sigma, from -5 to +8: near-contact
  * ones (|gap| < 1), easy ones (|gap| > 3) and, in the full set, 0 (resting contact).
  * Full: -5 -4 -3 -2 -1 -0.5 -0.2 0 0.2 0.5 1 2 3 4 6 8; quick: -5 -0.5 0.5 4 8. */
std::vector<double> primitiveGapsInSigma (bool quick);

/** \brief The W2 query set: every scenario at every gap of primitiveGapsInSigma(), with
  * sigma = kPrimitiveBaseSigma * sigma_scale and each gap = its multiple of sigma, so the
  * normalised distance is the same at every noise level. Scenarios (default spacing 3 mm):
  *  - sphere_sphere: r 8 cm and r 5 cm along a diagonal;
  *  - sphere_plane: r 6 cm over a 40 cm patch;
  *  - box_box_face, box_box_edge: 20x16x12 cm box against a smaller box, face to face and
  *    along a vertical edge (a separated edge pair is apart along x and y);
  *  - cylinder_plane: r 5 cm, 15 cm tall, standing on (gap 0), above, or sunk into the patch;
  *  - plate_sphere, plate_box, plate_edge_sphere: a 20x20 cm plate 2 mm thick (all six faces
  *    sampled, so both sides) against a r 5 cm sphere or a 6 cm cube from above, and a sphere
  *    against its 2 mm rim;
  *  - room_cube: a 5 cm cube inside a 4x4x3 m room near a wall (room spacing 2 cm, 4 cm quick);
  *  - sphere_sphere_sparse: two r 10 cm spheres at 12 mm spacing (more than the noise);
  *  - sphere_box_dense: r 3 cm sphere against a 6 cm cube at 1 mm spacing.
  * Queries with the same name describe the same geometry for every seed, so calling again
  * with another seed re-samples the sensor noise of the same poses. Throws
  * std::invalid_argument when sigma_scale is outside (0, 8] (at 8 the deepest penetration,
  * 4 cm, still leaves each placed object crossing the other surface). */
std::vector<PrimitiveQuery> makePrimitiveQueries (const PrimitiveWorkloadOptions& options);

/** \brief makePrimitiveQueries() with the given scale, seed and mode, noise on. */
std::vector<PrimitiveQuery> makePrimitiveQueries (double sigma_scale, std::uint64_t seed, bool quick);
} // namespace pcl_probcollision_eval
