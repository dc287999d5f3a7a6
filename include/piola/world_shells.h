/* piola: thin shells and cloth in a world (see piola/world.h and piola/shell_body.h).
 *
 * A shell is stepped by the same Newmark scheme as a solid (docs/time-stepping.md): its
 * in-plane and bending forces are the explicit elastic force, its in-plane and bending
 * damping join the implicit damping solves, it collides with the world's obstacles and
 * follows the same constraints. After each step's force update, plastic flow (in-plane and
 * bending) runs for the step's dt. Shells have their own index space (0 .. shell_count - 1).
 *
 * One-way coupling with solids (paper section 9, the cape on the Buddha): with
 * collide_with_solids, after the obstacles each free node of the shell is also pushed out of
 * the solids' moving boundary surfaces: the closest point p on the current boundary
 * triangles (face, edge or vertex) decides inside or outside by the side of that triangle's
 * outward normal; a node inside moves to p, its normal velocity becomes at least the
 * surface's (interpolated from the solid's nodal velocities), and friction acts as for
 * obstacles. The normal used is the direction between the node and p, whichever way points
 * outward. Only the part of a node's path within the longest boundary edge of the surface
 * is searched, so a node that got deeper than that is not found. The solids do not feel the
 * shell.
 *
 * Two-way contact (self_collision): the shell's own triangles, edges and vertices join the
 * world's collision surface (world_contact.c), with its thickness as the repulsion distance
 * and its lumped masses, so it collides with itself, with other shells and with the solids
 * that have self_collision too, and the impulses act on both sides. Against such a solid the
 * one-way coupling above is skipped, so the two never act on the same pair.
 *
 *   piola_shell_def def = piola_default_shell_def();
 *   def.mesh = &cloth;                 // rest shape in world space, m
 *   def.bending.stiffness = 1e-4;      // N m
 *   piola_world_add_shell(world, &def, NULL); */
#ifndef PIOLA_WORLD_SHELLS_H
#define PIOLA_WORLD_SHELLS_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/shell_body.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_shell_def {
  const char *name;               /* copied; NULL gives "shell<i>" */
  const piola_tri_mesh *mesh;     /* rest shape in world space (m), copied. Required */
  piola_material_def material;    /* in-plane material (membrane version, see shell_body.h).
                                     Default piola_default_material_def() */
  double thickness;               /* m, > 0. Default 1e-3 */
  double density;                 /* kg/m^3, > 0. Default 1000 */
  piola_shell_bending_def bending;       /* default: no bending */
  piola_shell_plasticity_def plasticity; /* default: no plasticity */
  bool use_reference_normals;     /* rest normals as the reference (shell_body.h). Default false */
  piola_track stiffness_scale;    /* dimensionless, >= 0: in-plane and bending. Default 1 */
  piola_track shear_viscosity;    /* Pa s, >= 0: in-plane beta. Default 0 */
  piola_track bulk_viscosity;     /* Pa s, >= 0: in-plane alpha. Default 0 */
  piola_vec3 velocity;            /* m/s, initial velocity of every free node. Default 0 */
  const piola_constraint_def *constraints; /* constraint_count constraints, copied */
  int32_t constraint_count;
  bool collide_with_solids;       /* one-way coupling to the solids' surfaces. Default false */
  double solid_friction;          /* Coulomb mu against the solids, >= 0. Default 0.3 */
  /* Two-way contact through the collision module (BFA02, docs/contact.md): the shell's
   * triangles join the world's collision surface, so the shell collides with itself, with
   * other shells and with solids that have self_collision enabled, and impulses act on both
   * sides. Default: off */
  piola_self_collision_def self_collision;
} piola_shell_def;

PIOLA_API piola_shell_def piola_default_shell_def(void);

/* Adds a shell at the world's current time; index (may be NULL) receives its index. */
PIOLA_API piola_status piola_world_add_shell(piola_world *world, const piola_shell_def *def,
                                             int32_t *index);

PIOLA_API int32_t piola_world_shell_count(const piola_world *world);
PIOLA_API const char *piola_world_shell_name(const piola_world *world, int32_t shell);
PIOLA_API const piola_shell_body *piola_world_shell_body(const piola_world *world, int32_t shell);
PIOLA_API const double *piola_world_shell_positions(const piola_world *world, int32_t shell);  /* m */
PIOLA_API const double *piola_world_shell_velocities(const piola_world *world, int32_t shell); /* m/s */
/* Vertex flags: 0 free, 1 fixed, 2 driven. */
PIOLA_API const uint8_t *piola_world_shell_constraint_flags(const piola_world *world, int32_t shell);

typedef struct piola_world_shell_stats {
  double kinetic_energy;   /* J */
  double membrane_energy;  /* J, at the last force update */
  double bending_energy;   /* J */
  int32_t inverted_count;  /* triangles opposing their reference normal */
  int32_t degenerate_count;
} piola_world_shell_stats;

PIOLA_API piola_world_shell_stats piola_world_shell_get_stats(const piola_world *world, int32_t shell);

#ifdef __cplusplus
}
#endif

#endif
