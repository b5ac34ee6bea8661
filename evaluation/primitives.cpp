// SPDX-License-Identifier: BSD-3-Clause
#include "primitives.h"

#include <pcl_probcollision/normal_distribution.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>

namespace pcl_probcollision_eval
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxExpectedPoints = 2.0e7;

using pcl_probcollision::detail::uniformUnit;

/** \brief SplitMix64 finaliser: spreads nearby seeds (0, 1, 2, ...) over the whole 64 bits. */
std::uint64_t
mix (std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::uint64_t
deriveSeed (std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0)
{
  return mix (mix (mix (seed) ^ a) ^ b);
}

/** \brief Collects surface points and adds the noise. Positions and noise use separate
  * engines so that sigma = 0 reproduces the noisy sample's positions exactly. */
class NoisySampler
{
public:
  NoisySampler (double spacing, double sigma, std::uint64_t seed, double area)
    : spacing_ (spacing), sigma_ (sigma), position_rng_ (deriveSeed (seed, 1)), noise_rng_ (deriveSeed (seed, 2)),
      cloud_ (new PrimitiveCloud)
  {
    if (!(spacing > 0.0) || !std::isfinite (spacing))
      throw std::invalid_argument ("sampleSurface: spacing must be positive and finite");
    if (!(sigma >= 0.0) || !std::isfinite (sigma))
      throw std::invalid_argument ("sampleSurface: sigma must be non-negative and finite");
    if (!(area > 0.0) || !std::isfinite (area))
      throw std::invalid_argument ("sampleSurface: degenerate shape");
    const double expected = area / (spacing * spacing);
    if (expected > kMaxExpectedPoints)
      throw std::invalid_argument ("sampleSurface: more than 20 million points expected; increase the spacing");
    cloud_->reserve (static_cast<std::size_t> (expected * 1.05) + 16);
  }

  double spacing () const { return spacing_; }

  /** \brief Uniform in [0, 1) from the position stream. */
  double uniform () { return uniformUnit (position_rng_); }

  void
  emit (const Eigen::Vector3d& p)
  {
    Eigen::Vector3d q = p;
    if (sigma_ > 0.0)
      q += sigma_ * Eigen::Vector3d (gaussian (), gaussian (), gaussian ());
    cloud_->push_back (pcl::PointXYZ (static_cast<float> (q.x ()), static_cast<float> (q.y ()), static_cast<float> (q.z ())));
  }

  PrimitiveCloud::Ptr
  finish ()
  {
    cloud_->width = static_cast<std::uint32_t> (cloud_->size ());
    cloud_->height = 1;
    cloud_->is_dense = true;
    return cloud_;
  }

private:
  /** \brief Standard normal by Box-Muller, the second value of each pair kept for the next call. */
  double
  gaussian ()
  {
    if (has_spare_)
    {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt (-2.0 * std::log (1.0 - uniformUnit (noise_rng_)));  // 1 - u > 0
    const double angle = 2.0 * kPi * uniformUnit (noise_rng_);
    spare_ = radius * std::sin (angle);
    has_spare_ = true;
    return radius * std::cos (angle);
  }

  double spacing_;
  double sigma_;
  std::mt19937_64 position_rng_;
  std::mt19937_64 noise_rng_;
  bool has_spare_ = false;
  double spare_ = 0.0;
  PrimitiveCloud::Ptr cloud_;
};

/** \brief Maps rectangle coordinates to a surface point. Lambdas passed as one must declare
  * `-> Eigen::Vector3d`: a deduced Eigen expression type would outlive its temporaries. */
using SurfaceMap = std::function<Eigen::Vector3d (double u, double v)>;

/** \brief Jittered grid on [0, width) x [0, height) with square cells of side `spacing`
  * anchored at the origin: one uniform point per cell, dropped when it falls outside the
  * rectangle or `keep` rejects it. Every location thus has the same density 1 / spacing^2,
  * border cells included; `map` must be area-preserving (an isometry here). */
void
sampleRectangle (NoisySampler& sampler, double width, double height, const SurfaceMap& map,
                 const std::function<bool (double, double)>& keep = nullptr)
{
  const double s = sampler.spacing ();
  const auto nu = static_cast<long> (std::ceil (width / s));
  const auto nv = static_cast<long> (std::ceil (height / s));
  for (long i = 0; i < nu; ++i)
    for (long j = 0; j < nv; ++j)
    {
      const double u = (static_cast<double> (i) + sampler.uniform ()) * s;
      const double v = (static_cast<double> (j) + sampler.uniform ()) * s;
      if (u < width && v < height && (!keep || keep (u, v)))
        sampler.emit (map (u, v));
    }
}

/** \brief Horizontal disk: the jittered grid over its bounding square, clipped to the disk. */
void
sampleDisk (NoisySampler& sampler, const Eigen::Vector3d& center, double radius)
{
  const double d = 2.0 * radius;
  sampleRectangle (
      sampler, d, d, [&] (double u, double v) -> Eigen::Vector3d { return center + Eigen::Vector3d (u - radius, v - radius, 0.0); },
      [&] (double u, double v) { return (u - radius) * (u - radius) + (v - radius) * (v - radius) <= radius * radius; });
}

/** \brief Polar cap area of a sphere between the pole and polar angle theta. */
double
capArea (double radius, double theta)
{
  return 2.0 * kPi * radius * radius * (1.0 - std::cos (theta));
}

void
checkFinite (const Eigen::Vector3d& v, const char* what)
{
  if (!v.allFinite ())
    throw std::invalid_argument (std::string ("sampleSurface: non-finite ") + what);
}
} // namespace

double
surfaceArea (const Sphere& s)
{
  return 4.0 * kPi * s.radius * s.radius;
}

double
surfaceArea (const Box& b)
{
  const Eigen::Vector3d e = 2.0 * b.half_extents;
  return 2.0 * (e.x () * e.y () + e.y () * e.z () + e.z () * e.x ());
}

double
surfaceArea (const Cylinder& c)
{
  return 2.0 * kPi * c.radius * (c.height + c.radius);
}

double
surfaceArea (const PlanePatch& p)
{
  return 4.0 * p.half_size * p.half_size;
}

PrimitiveCloud::Ptr
sampleSurface (const Sphere& s, double spacing, double sigma, std::uint64_t seed)
{
  checkFinite (s.center, "centre");
  NoisySampler sampler (spacing, sigma, seed, s.radius > 0.0 ? surfaceArea (s) : 0.0);
  // Bands about one spacing wide in polar angle; a band's cell count is the difference of the
  // rounded cumulative cap areas, so the total is exactly round(area / spacing^2) and every
  // band's density is within rounding of 1 / spacing^2. Within a band, z uniform is uniform by
  // area (Archimedes), and a random phase keeps the bands' cell borders from lining up.
  const double cell = spacing * spacing;
  const long bands = std::max (1l, std::lround (kPi * s.radius / spacing));
  long cells_before = 0;
  for (long k = 0; k < bands; ++k)
  {
    const double theta_hi = kPi * static_cast<double> (k + 1) / static_cast<double> (bands);
    const long cells_through = std::lround (capArea (s.radius, theta_hi) / cell);
    const long n = cells_through - cells_before;
    cells_before = cells_through;
    const double z_top = s.radius * std::cos (kPi * static_cast<double> (k) / static_cast<double> (bands));
    const double z_bottom = s.radius * std::cos (theta_hi);
    const double phase = 2.0 * kPi * sampler.uniform ();
    for (long j = 0; j < n; ++j)
    {
      const double phi = phase + 2.0 * kPi * (static_cast<double> (j) + sampler.uniform ()) / static_cast<double> (n);
      const double z = z_bottom + (z_top - z_bottom) * sampler.uniform ();
      const double rho = std::sqrt (std::max (0.0, s.radius * s.radius - z * z));
      sampler.emit (s.center + Eigen::Vector3d (rho * std::cos (phi), rho * std::sin (phi), z));
    }
  }
  return sampler.finish ();
}

PrimitiveCloud::Ptr
sampleSurface (const Box& b, double spacing, double sigma, std::uint64_t seed)
{
  checkFinite (b.center, "centre");
  const bool valid = (b.half_extents.array () > 0.0).all () && b.half_extents.allFinite ();
  NoisySampler sampler (spacing, sigma, seed, valid ? surfaceArea (b) : 0.0);
  for (int axis = 0; axis < 3; ++axis)
  {
    const int k1 = (axis + 1) % 3;
    const int k2 = (axis + 2) % 3;
    const Eigen::Vector3d e1 = Eigen::Vector3d::Unit (k1);
    const Eigen::Vector3d e2 = Eigen::Vector3d::Unit (k2);
    const double h1 = b.half_extents[k1];
    const double h2 = b.half_extents[k2];
    for (double side : {-1.0, 1.0})
    {
      const Eigen::Vector3d face_center = b.center + side * b.half_extents[axis] * Eigen::Vector3d::Unit (axis);
      sampleRectangle (sampler, 2.0 * h1, 2.0 * h2,
                       [&] (double u, double v) -> Eigen::Vector3d { return face_center + (u - h1) * e1 + (v - h2) * e2; });
    }
  }
  return sampler.finish ();
}

PrimitiveCloud::Ptr
sampleSurface (const Cylinder& c, double spacing, double sigma, std::uint64_t seed)
{
  checkFinite (c.base_center, "base centre");
  const bool valid = c.radius > 0.0 && c.height > 0.0;
  NoisySampler sampler (spacing, sigma, seed, valid ? surfaceArea (c) : 0.0);
  // The side unrolls isometrically onto a 2 pi r x h rectangle.
  sampleRectangle (sampler, 2.0 * kPi * c.radius, c.height, [&] (double u, double v) -> Eigen::Vector3d {
    const double phi = u / c.radius;
    return c.base_center + Eigen::Vector3d (c.radius * std::cos (phi), c.radius * std::sin (phi), v);
  });
  sampleDisk (sampler, c.base_center, c.radius);
  sampleDisk (sampler, c.base_center + Eigen::Vector3d (0.0, 0.0, c.height), c.radius);
  return sampler.finish ();
}

PrimitiveCloud::Ptr
sampleSurface (const PlanePatch& p, double spacing, double sigma, std::uint64_t seed)
{
  checkFinite (p.center, "centre");
  NoisySampler sampler (spacing, sigma, seed, p.half_size > 0.0 ? surfaceArea (p) : 0.0);
  const double h = p.half_size;
  sampleRectangle (sampler, 2.0 * h, 2.0 * h,
                   [&] (double u, double v) -> Eigen::Vector3d { return p.center + Eigen::Vector3d (u - h, v - h, 0.0); });
  return sampler.finish ();
}

double
signedDistance (const Sphere& a, const Sphere& b)
{
  return (a.center - b.center).norm () - a.radius - b.radius;
}

double
signedDistance (const Box& a, const Box& b)
{
  // Per axis: gap > 0 when the projections are apart, otherwise -gap is their overlap.
  const Eigen::Vector3d gap =
      (a.center - b.center).cwiseAbs () - (a.half_extents + b.half_extents);
  if ((gap.array () > 0.0).any ())
    return gap.cwiseMax (0.0).norm ();
  return gap.maxCoeff ();  // minus the smallest overlap
}

double
signedDistance (const Sphere& s, const Box& b)
{
  // Per axis: > 0 outside the slab of the box, otherwise minus the depth inside it.
  const Eigen::Vector3d outside = (s.center - b.center).cwiseAbs () - b.half_extents;
  if ((outside.array () > 0.0).any ())
    return outside.cwiseMax (0.0).norm () - s.radius;
  return outside.maxCoeff () - s.radius;  // -(depth to the nearest face) - radius
}

double
signedDistance (const Sphere& s, const PlanePatch& p)
{
  return s.center.z () - p.center.z () - s.radius;
}

double
signedDistance (const Cylinder& c, const PlanePatch& p)
{
  return c.base_center.z () - p.center.z ();
}

double
clearanceInside (const Box& room, const Box& object)
{
  // Per axis: the clearance to the nearer of the two walls (< 0: protrusion through it).
  const Eigen::Vector3d clearance =
      room.half_extents - (object.center - room.center).cwiseAbs () - object.half_extents;
  if ((clearance.array () < 0.0).any ())
    return -(-clearance).cwiseMax (0.0).norm ();
  return clearance.minCoeff ();
}

std::vector<double>
primitiveGapsInSigma (bool quick)
{
  if (quick)
    return {-5.0, -0.5, 0.5, 4.0, 8.0};
  return {-5.0, -4.0, -3.0, -2.0, -1.0, -0.5, -0.2, 0.0, 0.2, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0};
}

namespace
{
constexpr double kDefaultSpacing = 0.003;
constexpr double kSparseSpacing = 0.012;
constexpr double kDenseSpacing = 0.001;
constexpr double kTouchingTolerance = 1e-12;  // m

/** \brief A sampled object: its cloud and spacing. */
struct Sampled
{
  PrimitiveCloud::Ptr cloud;
  double spacing = 0.0;
};

/** \brief Samples a shape with the workload's noise setting. */
class WorkloadSampler
{
public:
  WorkloadSampler (double sigma, bool noise_free) : sigma_ (noise_free ? 0.0 : sigma) {}

  template <typename Shape>
  Sampled
  operator() (const Shape& shape, double spacing, std::uint64_t seed) const
  {
    return {sampleSurface (shape, spacing, sigma_, seed), spacing};
  }

private:
  double sigma_;
};

/** \brief A placed object for one gap: its cloud and the closed-form signed distance. */
struct Placement
{
  Sampled b;
  double exact_distance = 0.0;
};

using FixedObject = std::function<Sampled (const WorkloadSampler&, std::uint64_t seed)>;

/** \brief A scenario: the fixed object and how to place the other at a target gap (m). */
struct Scenario
{
  std::string name;
  FixedObject fixed;
  std::function<Placement (const WorkloadSampler&, double gap, std::uint64_t seed)> place;
  /** \brief The fixed object is a solid seen from outside (PrimitiveQuery::solid_a): not the
    * floor patch (an open sheet) nor the room (the cube is inside it). */
  bool fixed_solid = true;
};

/** \brief A scenario's fixed object: `shape` sampled at `spacing`. */
template <typename Shape>
FixedObject
fixedObject (const Shape& shape, double spacing)
{
  return [shape, spacing] (const WorkloadSampler& sample, std::uint64_t seed) { return sample (shape, spacing, seed); };
}

// Shapes shared by several scenarios.
const Box kBigBox{Eigen::Vector3d::Zero (), Eigen::Vector3d (0.10, 0.08, 0.06)};
const PlanePatch kFloor{Eigen::Vector3d::Zero (), 0.2};
const Box kPlate{Eigen::Vector3d::Zero (), Eigen::Vector3d (0.1, 0.1, 0.001)};  // 2 mm thick

std::vector<Scenario>
makeScenarios (bool quick)
{
  std::vector<Scenario> out;
  const Sphere big_sphere{Eigen::Vector3d::Zero (), 0.08};
  out.push_back ({"sphere_sphere",
                  fixedObject (big_sphere, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Eigen::Vector3d dir = Eigen::Vector3d (2.0, 1.0, 2.0) / 3.0;
                    const Sphere s{(0.08 + 0.05 + gap) * dir, 0.05};
                    return Placement{sample (s, kDefaultSpacing, seed), signedDistance (big_sphere, s)};
                  }});
  out.push_back ({"sphere_plane",
                  fixedObject (kFloor, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Sphere s{Eigen::Vector3d (0.03, -0.02, 0.06 + gap), 0.06};
                    return Placement{sample (s, kDefaultSpacing, seed), signedDistance (s, kFloor)};
                  }, false});
  out.push_back ({"box_box_face",
                  fixedObject (kBigBox, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Box b{Eigen::Vector3d (0.10 + 0.04 + gap, 0.02, -0.01), Eigen::Vector3d (0.04, 0.05, 0.03)};
                    return Placement{sample (b, kDefaultSpacing, seed), signedDistance (kBigBox, b)};
                  }});
  out.push_back ({"box_box_edge",
                  fixedObject (kBigBox, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    // Apart: along (0.6, 0.8) in x-y, so the vertical edges are closest. Overlapping:
                    // equally deep in x and y, so the depth is the gap's size either way.
                    const Eigen::Vector2d offset = gap >= 0.0 ? Eigen::Vector2d (0.6 * gap, 0.8 * gap) : Eigen::Vector2d (gap, gap);
                    const Box b{Eigen::Vector3d (0.10 + 0.04 + offset.x (), 0.08 + 0.04 + offset.y (), 0.01),
                                Eigen::Vector3d (0.04, 0.04, 0.04)};
                    return Placement{sample (b, kDefaultSpacing, seed), signedDistance (kBigBox, b)};
                  }});
  out.push_back ({"cylinder_plane",
                  fixedObject (kFloor, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Cylinder c{Eigen::Vector3d (-0.02, 0.03, gap), 0.05, 0.15};
                    return Placement{sample (c, kDefaultSpacing, seed), signedDistance (c, kFloor)};
                  }, false});
  out.push_back ({"plate_sphere",
                  fixedObject (kPlate, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Sphere s{Eigen::Vector3d (0.01, 0.02, 0.001 + 0.05 + gap), 0.05};
                    return Placement{sample (s, kDefaultSpacing, seed), signedDistance (s, kPlate)};
                  }});
  out.push_back ({"plate_box",
                  fixedObject (kPlate, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Box b{Eigen::Vector3d (-0.02, 0.01, 0.001 + 0.03 + gap), Eigen::Vector3d (0.03, 0.03, 0.03)};
                    return Placement{sample (b, kDefaultSpacing, seed), signedDistance (kPlate, b)};
                  }});
  out.push_back ({"plate_edge_sphere",
                  fixedObject (kPlate, kDefaultSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Sphere s{Eigen::Vector3d (0.1 + 0.05 + gap, 0.01, 0.0), 0.05};
                    return Placement{sample (s, kDefaultSpacing, seed), signedDistance (s, kPlate)};
                  }});
  const Box room{Eigen::Vector3d (0.0, 0.0, 1.5), Eigen::Vector3d (2.0, 2.0, 1.5)};
  const double room_spacing = quick ? 0.04 : 0.02;
  out.push_back ({"room_cube",
                  fixedObject (room, room_spacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Box cube{Eigen::Vector3d (2.0 - 0.025 - gap, 0.4, 1.1), Eigen::Vector3d::Constant (0.025)};
                    return Placement{sample (cube, kDefaultSpacing, seed), clearanceInside (room, cube)};
                  }, false});
  const Sphere sparse_sphere{Eigen::Vector3d::Zero (), 0.1};
  out.push_back ({"sphere_sphere_sparse",
                  fixedObject (sparse_sphere, kSparseSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Eigen::Vector3d dir = Eigen::Vector3d (1.0, 2.0, 2.0) / 3.0;
                    const Sphere s{(0.2 + gap) * dir, 0.1};
                    return Placement{sample (s, kSparseSpacing, seed), signedDistance (sparse_sphere, s)};
                  }});
  const Box dense_cube{Eigen::Vector3d::Zero (), Eigen::Vector3d::Constant (0.03)};
  out.push_back ({"sphere_box_dense",
                  fixedObject (dense_cube, kDenseSpacing),
                  [=] (const WorkloadSampler& sample, double gap, std::uint64_t seed) {
                    const Sphere s{Eigen::Vector3d (0.03 + 0.03 + gap, 0.005, -0.004), 0.03};
                    return Placement{sample (s, kDenseSpacing, seed), signedDistance (s, dense_cube)};
                  }});
  return out;
}

std::string
gapLabel (double gap_in_sigma)
{
  std::ostringstream label;
  label << gap_in_sigma << 's';  // default stream format: "-0.5s", "0s", "8s"
  return label.str ();
}
} // namespace

std::vector<PrimitiveQuery>
makePrimitiveQueries (const PrimitiveWorkloadOptions& options)
{
  if (!(options.sigma_scale > 0.0 && options.sigma_scale <= 8.0))
    throw std::invalid_argument ("makePrimitiveQueries: sigma_scale must be in (0, 8]");
  const double sigma = kPrimitiveBaseSigma * options.sigma_scale;
  const WorkloadSampler sample (sigma, options.noise_free);
  const std::vector<double> gaps = primitiveGapsInSigma (options.quick);
  const std::vector<Scenario> scenarios = makeScenarios (options.quick);

  std::vector<PrimitiveQuery> out;
  out.reserve (scenarios.size () * gaps.size ());
  for (std::size_t si = 0; si < scenarios.size (); ++si)
  {
    const Scenario& scenario = scenarios[si];
    const Sampled fixed = scenario.fixed (sample, deriveSeed (options.seed, si, 0));
    for (std::size_t gi = 0; gi < gaps.size (); ++gi)
    {
      const Placement placed = scenario.place (sample, gaps[gi] * sigma, deriveSeed (options.seed, si, gi + 1));
      PrimitiveQuery q;
      q.name = scenario.name + "/" + gapLabel (gaps[gi]);
      q.scenario = scenario.name;
      q.a = fixed.cloud;
      q.b = placed.b.cloud;
      q.sigma = sigma;
      q.spacing_a = fixed.spacing;
      q.spacing_b = placed.b.spacing;
      q.solid_a = scenario.fixed_solid;
      // Rounding must not turn a nominal gap of 0 (resting contact) into a 1e-17 m gap.
      q.exact_distance = std::abs (placed.exact_distance) < kTouchingTolerance ? 0.0 : placed.exact_distance;
      q.exact_collision = q.exact_distance <= 0.0;
      out.push_back (std::move (q));
    }
  }
  return out;
}

std::vector<PrimitiveQuery>
makePrimitiveQueries (double sigma_scale, std::uint64_t seed, bool quick)
{
  PrimitiveWorkloadOptions options;
  options.sigma_scale = sigma_scale;
  options.seed = seed;
  options.quick = quick;
  return makePrimitiveQueries (options);
}
} // namespace pcl_probcollision_eval
