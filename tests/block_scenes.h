/* Blocks of tets and what the world dynamics tests measure on them (test_dynamics.c,
 * test_backward_euler.c, test_plasticity_world.c): the mesh, the momenta of solid 0, and
 * the spinning, drifting start of the free-flight tests. */
#ifndef PIOLA_TEST_BLOCK_SCENES_H
#define PIOLA_TEST_BLOCK_SCENES_H

#include "piola/mesh.h"
#include "piola/world.h"

/* The box [0,a]x[0,b]x[0,c] (m) of nx*ny*nz cubes, 6 tets each (piola_tet_mesh_box_grid). */
piola_tet_mesh block_mesh(int nx, int ny, int nz, double a, double b, double c);
void block_mesh_free(piola_tet_mesh *m);

/* Linear momentum p (kg m/s), angular momentum l about the origin (kg m^2/s) and, when
 * kinetic is not NULL, the kinetic energy (J) of solid 0. */
void solid_momenta(const piola_world *w, double p[3], double l[3], double *kinetic);

/* Gives solid 0 (a block(3, 2, 2, 0.3, 0.2, 0.2) or so) a spin of 3 rad/s about the
 * vertical through (0.15, 0.1), a drift of (0.5, -0.2) m/s and the vertical velocity
 * vz + vz_per_y (y - 0.1) (m/s). */
void spin_block(piola_world *w, double vz, double vz_per_y);

#endif
