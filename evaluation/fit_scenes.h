// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// The scenes the surface layer's calibration maps are fitted on (src/surface_calibration.cpp,
// scripts/fit-surface-calibration.py): a furnished floor and an object made of boxes, drawn
// from a seed. They are W1's kind of scene (a piano-sized object among furniture, millimetres)
// but none of the scenes the evaluation reports (W1's piano and room, W2's primitives, W3's
// scans), so that the maps are never fitted on what docs/RESULTS.md measures.

#include "mesh_input.h"

#include <cstdint>

namespace pcl_probcollision_eval
{
/** \brief A robot mesh and an environment mesh, in millimetres, z up. */
struct FitScene
{
  pcl_probcollision::io::TriangleMesh robot, env;
};

/** \brief The scene of a seed (the same seed, the same scene), every part a closed box with
  * outward faces:
  *  - env: a floor slab about 6 x 6 m and 30 mm thick (top at z = 15 mm), two or three walls
  *    1 m tall and 20-40 mm thick along its edges, and 6-9 pieces of furniture on it (tables of
  *    a top and four legs, cabinets, low boxes, open shelves of two sides and three boards),
  *    each turned about z at random;
  *  - robot: a body 0.7-1.2 x 0.5-0.9 x 0.2-0.4 m on three or four legs, a lid 15-25 mm thick
  *    opened 15-50 degrees about one long edge of the body's top, and a block on one side. */
FitScene makeFitScene (std::uint64_t seed);
} // namespace pcl_probcollision_eval
