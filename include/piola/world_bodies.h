/* piola: the bodies of a world, whatever their kind (see piola/world.h).
 *
 * Every deformable thing a world steps is a body: a tetrahedral solid
 * (piola_world_add_solid) or a thin shell (piola_world_add_shell). These functions read any
 * of them through one id, so a caller that only needs nodes, names and energies does not
 * care which kind it holds. The kind-specific functions (piola_world_solid_*,
 * piola_world_shell_*) keep working on their own index spaces.
 *
 * Ids. A piola_body_id names one body for the life of the world. It is not a position: the
 * world keeps its bodies in step order (every solid before every shell, each kind in the
 * order it was added), so adding a solid after a shell moves the shells one place on, but
 * their ids do not change. An id packs a slot and a generation; an id that names no body
 * (0, PIOLA_NO_BODY, or one made up) is refused by every function below: they return
 * PIOLA_BODY_NONE, -1, NULL, zeros or PIOLA_ERROR_INVALID_ARGUMENT, never another body.
 *
 *   for (int32_t i = 0; i < piola_world_body_count(world); ++i) {
 *     piola_body_id id = piola_world_body_at(world, i);
 *     piola_body_stats st = piola_world_body_stats(world, id);
 *     printf("%s: %d nodes, %g J\n", piola_world_body_name(world, id),
 *            piola_world_body_node_count(world, id), st.kinetic_energy + st.elastic_energy);
 *   } */
#ifndef PIOLA_WORLD_BODIES_H
#define PIOLA_WORLD_BODIES_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_body_kind {
  PIOLA_BODY_NONE = -1, /* the answer for an id that names no body */
  PIOLA_BODY_SOLID = 0, /* a tetrahedral elastic solid (piola_world_add_solid) */
  PIOLA_BODY_SHELL = 1, /* a thin shell or cloth (piola_world_add_shell) */
} piola_body_kind;

/* Number of body kinds (PIOLA_BODY_SOLID .. PIOLA_BODY_KIND_COUNT - 1). */
#define PIOLA_BODY_KIND_COUNT 2

/* A body's id: slot in the low 32 bits, generation (>= 1) in the high 32 bits. */
typedef uint64_t piola_body_id;
#define PIOLA_NO_BODY ((piola_body_id)0)

/* Bodies of every kind in the world. */
PIOLA_API int32_t piola_world_body_count(const piola_world *world);
/* The id of the body at position (0 .. body_count - 1) of the step order: the solids in the
 * order they were added, then the shells. PIOLA_NO_BODY when out of range. */
PIOLA_API piola_body_id piola_world_body_at(const piola_world *world, int32_t position);
/* The id of solid or shell number index, as piola_world_add_solid / piola_world_add_shell
 * returned it. PIOLA_NO_BODY when there is none. */
PIOLA_API piola_body_id piola_world_body_of(const piola_world *world, piola_body_kind kind,
                                            int32_t index);

PIOLA_API piola_body_kind piola_world_body_kind(const piola_world *world, piola_body_id body);
/* The body's index among the bodies of its kind (the solid or shell index), or -1. */
PIOLA_API int32_t piola_world_body_index(const piola_world *world, piola_body_id body);
PIOLA_API const char *piola_world_body_name(const piola_world *world, piola_body_id body);
/* Nodes (vertices) of the body, or -1. */
PIOLA_API int32_t piola_world_body_node_count(const piola_world *world, piola_body_id body);
/* Elements of the body: tets of a solid, triangles of a shell; -1 for no body. */
PIOLA_API int32_t piola_world_body_element_count(const piola_world *world, piola_body_id body);

/* Per-node data, 3 per node for vectors; pointers stay valid until the next step or
 * set_state. */
PIOLA_API const double *piola_world_body_positions(const piola_world *world, piola_body_id body);  /* m */
PIOLA_API const double *piola_world_body_velocities(const piola_world *world, piola_body_id body); /* m/s */
PIOLA_API const double *piola_world_body_masses(const piola_world *world, piola_body_id body);     /* kg, lumped */
/* Node flags: 0 free, 1 fixed, 2 driven. */
PIOLA_API const uint8_t *piola_world_body_constraint_flags(const piola_world *world,
                                                          piola_body_id body);

/* Replaces positions (m) and/or velocities (m/s) of a body (either may be NULL; 3 per node)
 * and recomputes its elastic forces, as piola_world_solid_set_state does for a solid. */
PIOLA_API piola_status piola_world_body_set_state(piola_world *world, piola_body_id body,
                                                  const double *positions,
                                                  const double *velocities);

typedef struct piola_body_stats {
  double kinetic_energy;  /* J, 1/2 sum m |v|^2 over the nodes */
  double elastic_energy;  /* J, at the last force update: a solid's strain energy, a shell's
                             membrane plus bending energy */
  double momentum[3];     /* kg m/s, sum m v over the nodes */
  int32_t inverted_count; /* inverted elements: tets with det F < 0, triangles opposing their
                             reference normal */
} piola_body_stats;

/* Stats of one body at the current state (zeros for an id that names no body). */
PIOLA_API piola_body_stats piola_world_body_stats(const piola_world *world, piola_body_id body);

#ifdef __cplusplus
}
#endif

#endif
