/* Cloth scenes shared by the contact tests (test_contact_shells.c, test_collision_step.c):
 * a flat sheet, the cloth material they use, and a solid block thrown into a free cloth. */
#ifndef PIOLA_TEST_CLOTH_SCENES_H
#define PIOLA_TEST_CLOTH_SCENES_H

#include "piola/mesh.h"
#include "piola/world_shells.h"

/* A square sheet of size (m) with cells x cells cells at height z (m), moved by shift (m)
 * along x and shift / 2 along y. */
piola_tri_mesh cloth_sheet(double size, int cells, double z, double shift);

/* A light cloth (0.5 mm thick, E = 50 kPa, small bending) on mesh, with self_collision on or
 * off at collision thickness h (m). */
piola_shell_def cloth_shell_def(const piola_tri_mesh *mesh, int self_collision, double h);

/* A 6 x 6 x 3 cm soft block at z in [0.01, 0.04] m thrown up at speed (m/s) into a free
 * 12 x 12 cm cloth at rest at z = 0.05 m, no gravity, collision thickness h (m). With
 * collision_interval 0 (after every step) every step is judged, otherwise every interval end:
 * no intersecting triangles (exact referee), total linear momentum kept to 1e-10, some
 * contact (impacts too at speed >= 10 m/s), and a real two-way exchange of momentum. */
void block_hits_free_cloth(double speed, double h, double collision_interval);

#endif
