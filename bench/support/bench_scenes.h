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

/* A file of ../shared/data (path relative to it) centred and scaled to a bounding-box diagonal
 * of `diagonal` m (by way of recovery_read_unit_mesh's unit mesh). Returns 0 on success (else
 * the message is piola_last_error()). */
int bench_read_mesh_with_diagonal(const char *relative, double diagonal, piola_tet_mesh *mesh);

/* The body of tests/test_scrambles_every_model.c as the scramble benchmarks build it: `mesh`
 * as `model` with its default parameters, E = 20 kPa, nu = 0.3, 1000 kg/m^3, shear and bulk
 * viscosity 1000 Pa s, scrambled within `radius` m. */
piola_solid_def bench_scramble_solid_def(const piola_tet_mesh *mesh, piola_material_model model,
                                         double radius);

#endif
