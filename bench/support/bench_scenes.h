/* Benchmark scenes shared by several programs. */
#ifndef PIOLA_BENCH_SCENES_H
#define PIOLA_BENCH_SCENES_H

#include "piola/world.h"

/* The full-step scene of issue 3: mesh (e.g. torus-easy.veg) as a neo-Hookean solid
 * (E = 100 kPa, nu = 0.4), slightly scrambled, falling at 1 m/s onto a plane (friction 0.5)
 * through its lowest point, with shear and bulk viscosities chosen so that the two damping
 * solves of a step of 1e-4 s take about 20 CG iterations together. max_dt = 1e-4 s with the
 * CFL bound off, so every step has that size. cg_tolerance <= 0 keeps the default.
 * Returns NULL (message printed) on failure. */
piola_world *bench_torus_step_world(const piola_tet_mesh *mesh, double cg_tolerance);

#endif
