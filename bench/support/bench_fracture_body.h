/* The body the fracture benchmarks cut (bench_fracture, bench_fracture_blade), so that their
 * numbers compare. */
#ifndef PIOLA_BENCH_FRACTURE_BODY_H
#define PIOLA_BENCH_FRACTURE_BODY_H

#include "piola/world.h"

/* A world without gravity holding mesh as one neo-Hookean solid (E = 0.1 MPa, nu = 0.3,
 * shear and bulk viscosity 1 Pa s), stretched and sheared by a fixed initial matrix and
 * flying at `velocity` (m/s). Returns NULL (message printed) on failure. */
piola_world *bench_fracture_world(const piola_tet_mesh *mesh, piola_vec3 velocity);

/* Thread CPU time (s) per step of `steps` steps of dt; exits with the message on failure. */
double bench_fracture_time_steps(piola_world *w, int steps, double dt);

#endif
