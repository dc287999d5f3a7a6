/* Blocks of tets and what the world dynamics tests measure on them (test_dynamics.c,
 * test_backward_euler.c, test_plasticity_world.c, test_stable_step.c,
 * test_energy_check.c, test_fracture*.c): the mesh, a world without gravity, a world
 * holding a deformed block, the momenta of solid 0, and the spinning, drifting start of the
 * free-flight tests. */
#ifndef PIOLA_TEST_BLOCK_SCENES_H
#define PIOLA_TEST_BLOCK_SCENES_H

#include "piola/mesh.h"
#include "piola/world.h"

/* The box [0,a]x[0,b]x[0,c] (m) of nx*ny*nz cubes, 6 tets each (piola_tet_mesh_box_grid). */
piola_tet_mesh block_mesh(int nx, int ny, int nz, double a, double b, double c);
void block_mesh_free(piola_tet_mesh *m);

/* A world without gravity, its default settings otherwise, whose steps are at most max_dt (s). */
piola_world *weightless_world(double max_dt);

/* A world without gravity (max_dt 1 s, the given cfl; cg_max_iterations > 0 replaces the
 * default) holding one solid: n x n x n cubes of edge 0.1 m (E = 10 kPa, nu = 0.3,
 * 1000 kg/m^3, both viscosities `viscosity` in Pa s), its free nodes deformed by initial
 * about the rest centroid. */
piola_world *deformed_block_world(piola_material_model model, int n, piola_mat3 initial,
                                  double viscosity, double cfl, int32_t cg_max_iterations);
/* The same with the material's inversion mode and threshold set (the other is the model's
 * default where mode is PIOLA_INVERSION_MODEL_DEFAULT or threshold 0). */
piola_world *deformed_block_world_inverting(piola_material_model model, piola_inversion_mode mode,
                                            double threshold, int n, piola_mat3 initial,
                                            double viscosity, double cfl,
                                            int32_t cg_max_iterations);

/* Linear momentum p (kg m/s), angular momentum l about the origin (kg m^2/s) and, when
 * kinetic is not NULL, the kinetic energy (J) of solid 0. */
void solid_momenta(const piola_world *w, double p[3], double l[3], double *kinetic);

/* Gives solid 0 (a block(3, 2, 2, 0.3, 0.2, 0.2) or so) a spin of 3 rad/s about the
 * vertical through (0.15, 0.1), a drift of (0.5, -0.2) m/s and the vertical velocity
 * vz + vz_per_y (y - 0.1) (m/s). */
void spin_block(piola_world *w, double vz, double vz_per_y);

#endif
