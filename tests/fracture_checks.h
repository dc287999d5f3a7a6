/* What the fracture tests measure on a cut solid (test_fracture*.c): its fragment
 * surfaces' enclosed volumes and closure, its material per fragment and its mass, and a
 * checkpoint round trip between two worlds. */
#ifndef PIOLA_TEST_FRACTURE_CHECKS_H
#define PIOLA_TEST_FRACTURE_CHECKS_H

#include <stdint.h>

#include "piola/world.h"
#include "piola/world_fracture.h"

/* Adds `mesh` as solid 0's default model, E = 20 kPa, nu = 0.3, shear and bulk viscosity
 * `viscosity` Pa s. */
void fracture_add_solid(piola_world *w, const piola_tet_mesh *mesh, double viscosity);
/* The spinning, stretched bar of the free-flight tests: `mesh` (a box grid) undamped in a
 * world of steps <= 5e-4 s, each rest point p at (stretch p0 + 0.1 p1, 0.9 p1, p2 + 0.05 p0)
 * with velocity (0.5 - 3 (p1 - y_centre), -0.2 + 3 (p0 - 0.15), 0.1 + p1) m/s. */
piola_world *fracture_spinning_bar(const piola_tet_mesh *mesh, double stretch, double y_centre);
/* Gives solid 0 of w the default fracture definition with the `count` scripted cuts `cuts`. */
void fracture_set_cuts(piola_world *w, const piola_fracture_cut *cuts, int32_t count);
/* The bounding box of `mesh`'s vertices (m). */
void fracture_mesh_bounds(const piola_tet_mesh *mesh, double lo[3], double hi[3]);
/* Volume enclosed by the triangles [first, end) of s (m^3, divergence theorem). */
double fracture_enclosed_volume(const piola_fracture_surface *s, int32_t first, int32_t end);
/* Directed edges of the triangles [first, end) of s that are not one of exactly two
 * triangles on their edge, running it opposite ways (0: closed, consistently oriented and
 * every edge shared by exactly two triangles, as docs/fracture.md promises). */
int32_t fracture_unpaired_edges(const piola_fracture_surface *s, int32_t first, int32_t end);
/* The area (m^2) of solid 0's cross-section at the rest plane x = x0 (on no vertex), at the
 * current positions: per tet the polygon where that plane meets it, mapped by the tet's
 * deformation. Only for a solid not cut yet (its tets are the rest mesh's). */
double fracture_rest_section_area(const piola_world *w, double x0);
/* Sum of the lumped masses of solid 0 (kg). */
double fracture_total_mass(const piola_world *w);
/* Per fragment of solid 0: its material volume, the sum of fraction x rest volume of its
 * copies (m^3; calloc'ed, the caller frees). */
double *fracture_material_volumes(const piola_world *w);
/* Writes a's checkpoint (frame `frame`, the key of b's scene without a scene file) to path
 * and reads it into b, which must accept it and take that frame. */
void fracture_checkpoint_round_trip(const piola_world *a, piola_world *b, const char *path, int32_t frame);
/* fracture_checkpoint_round_trip through a fresh file in the temporary folder ($TMPDIR, else
 * /tmp), removed afterwards. */
void fracture_checkpoint_round_trip_via_temp_file(const piola_world *a, piola_world *b,
                                                  int32_t frame);
/* Solid 0 of a and b is in the same state, bit for bit: mesh, positions, velocities,
 * masses, fractions, fragments, cut tets and time. */
void fracture_same_state(const piola_world *a, const piola_world *b);
/* Original tets of solid 0 with more than two copies: cut twice or more. */
int32_t fracture_recut_tets(const piola_world *w);

#endif
