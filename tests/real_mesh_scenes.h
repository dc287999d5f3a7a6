/* Real meshes of ../shared/data as the scramble tests use them (test_never_blow_up.c,
 * test_scrambles_every_model.c, test_scrambles_slivers.c, test_scrambles_stable_neohookean.c,
 * test_recent_bounds.c, test_failed_step_velocity.c): a mesh moved and scaled to a given
 * bounding-box diagonal, one material for every model at the same rest shear modulus, the
 * finiteness and energy of a solid's state, a scrambled solid's world, and one scramble run. */
#ifndef PIOLA_TEST_REAL_MESH_SCENES_H
#define PIOLA_TEST_REAL_MESH_SCENES_H

#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/world.h"

/* The mesh at `relative` (under ../shared/data) as its file has it; free it with
 * piola_tet_mesh_free. Fails the test when it cannot be read. */
piola_tet_mesh real_mesh_read(const char *relative);

/* The mesh at `relative` (under ../shared/data), its bounding box centred at the origin and
 * scaled to the diagonal `diagonal` (m). Fails the test when it cannot be read. */
piola_tet_mesh real_mesh_scaled(const char *relative, double diagonal);

/* The diagonal of the mesh's bounding box (m). */
double real_mesh_diagonal(const piola_tet_mesh *mesh);

/* E (Pa) and nu for every model: the models with their own parameters get the same shear
 * modulus mu = E / (2 (1 + nu)) (Ogden's default terms scaled, Mooney-Rivlin with
 * C10 = 3 C01, HGO's matrix), so that what is predicted from E holds for them too. */
piola_material_def real_mesh_material_def(piola_material_model model, double youngs,
                                          double poisson);

/* Whether every position and velocity of solid 0 is finite. */
int real_mesh_solid_finite(const piola_world *w);

/* Kinetic plus elastic energy of solid 0 (J). */
double real_mesh_total_energy(const piola_world *w);

/* What a scramble scene sets; the rest is shared (real_mesh_scramble_world). */
typedef struct real_mesh_scramble {
  piola_material_def material;
  double viscosity;                 /* shear and bulk viscosity, Pa s */
  double radius;                    /* scramble radius, m */
  piola_integrator_type integrator; /* an implicit one takes one step per 1/30 s frame */
  const double *fibers;             /* 3 per tet (HGO, muscle), or NULL */
  const piola_mat3 *start_matrix;   /* initial.matrix (a collapse), or NULL: the identity */
} real_mesh_scramble;

/* A world with no gravity and one solid: `mesh` at 1000 kg/m^3 as `scene` sets it. NULL, with
 * piola_last_error() saying why, when the world refuses the solid. */
piola_world *real_mesh_scramble_world(const piola_tet_mesh *mesh, const real_mesh_scramble *scene);

/* One scramble run of the issue 21 done-when (test_scrambles_every_model.c,
 * test_scrambles_slivers.c, test_scrambles_stable_neohookean.c): `mesh` (as real_mesh_scaled
 * gives it, named `name` in messages), E = 20 kPa, nu = 0.3, 1000 kg/m^3, shear and bulk
 * viscosity 1000 Pa s, no gravity, the model's default inversion, scrambled by `radius` (m),
 * `fibers` (3 per tet, HGO only, may be NULL), run for `seconds` with piola's explicit integrator
 * in 20 frames. Fails the test unless every frame succeeds with a finite state and the total
 * energy never rises above 1.05 times the start's (nothing adds work; 5% for the LINEAR
 * extension's work without a potential, docs/time-stepping.md "What is not physics").
 * PIOLA_TEST_VERBOSE prints steps and CPU time. */
void real_mesh_scramble_run(const piola_tet_mesh *mesh, const char *name,
                            piola_material_model model, double radius, double seconds,
                            const double *fibers);

/* real_mesh_scramble_run for each of `count` models (no fibres) on the mesh at `relative`
 * scaled to `diagonal` (m), scrambled by `radius` (m), for 2 s scaled by PIOLA_TEST_SCALE (at
 * least 0.02 s); PIOLA_TEST_MODEL (a model's name) selects one. */
void real_mesh_scramble_models(const char *relative, double diagonal,
                               const piola_material_model *models, int count, double radius);

#endif
