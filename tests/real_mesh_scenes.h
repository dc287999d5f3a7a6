/* Real meshes of ../shared/data as the issue 21 acceptance tests use them
 * (test_never_blow_up.c, test_scrambles_every_model.c): a mesh moved and scaled to a given
 * bounding-box diagonal, one material for every model at the same rest shear modulus, and the
 * finiteness of a solid's state. */
#ifndef PIOLA_TEST_REAL_MESH_SCENES_H
#define PIOLA_TEST_REAL_MESH_SCENES_H

#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/world.h"

/* The mesh at `relative` (under ../shared/data), its bounding box centred at the origin and
 * scaled to the diagonal `diagonal` (m). Fails the test when it cannot be read. */
piola_tet_mesh real_mesh_scaled(const char *relative, double diagonal);

/* E (Pa) and nu for every model: the models with their own parameters get the same shear
 * modulus mu = E / (2 (1 + nu)) (Ogden's default terms scaled, Mooney-Rivlin with
 * C10 = 3 C01, HGO's matrix), so that what is predicted from E holds for them too. */
piola_material_def real_mesh_material_def(piola_material_model model, double youngs, double poisson);

/* Whether every position and velocity of solid 0 is finite. */
int real_mesh_solid_finite(const piola_world *w);

#endif
