/* piola: the built-in tetrahedral mesher (Molino, Bridson, Teran, Fedkiw 2003).
 *
 * A body-centred cubic lattice covers the shape; tets are kept by inside/outside tests,
 * boundary nodes are moved onto the surface, and red-green refinement grades the lattice
 * toward the surface where asked. Shapes are analytic primitives (and unions of them) or
 * a closed triangle surface (inside/outside by generalized winding numbers). */
#ifndef PIOLA_MESHER_H
#define PIOLA_MESHER_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_shape_type {
  PIOLA_SHAPE_SPHERE = 0, /* center, radius */
  PIOLA_SHAPE_BOX,        /* center, half_extents */
  PIOLA_SHAPE_TORUS,      /* center, axis, radius (major), minor_radius */
  PIOLA_SHAPE_CYLINDER,   /* center, axis, radius, half_length */
  PIOLA_SHAPE_CAPSULE,    /* center, axis, radius, half_length (of the segment) */
  PIOLA_SHAPE_SURFACE,    /* surface: a closed, manifold triangle mesh */
} piola_shape_type;

typedef struct piola_shape {
  piola_shape_type type;
  piola_vec3 center;        /* m */
  piola_vec3 axis;          /* unit, default (0, 0, 1) */
  double radius;            /* m */
  double minor_radius;      /* m */
  double half_length;       /* m */
  piola_vec3 half_extents;  /* m */
  const piola_tri_mesh *surface;
} piola_shape;

#define PIOLA_MESHER_MAX_SHAPES 16

typedef struct piola_mesher_def {
  piola_shape shapes[PIOLA_MESHER_MAX_SHAPES]; /* the union of these shapes is meshed */
  int shape_count;
  double cell_size;        /* m: BCC lattice spacing (cube edge). Required, > 0 */
  int refinement_levels;   /* red-green refinement levels toward the surface. Default 0 */
} piola_mesher_def;

PIOLA_API piola_mesher_def piola_default_mesher_def(void);

/* Meshes the union of the shapes. An open or non-manifold surface is refused with a message
 * naming an offending edge. */
PIOLA_API piola_status piola_mesher_generate(const piola_mesher_def *def, piola_tet_mesh *out);

#ifdef __cplusplus
}
#endif

#endif
