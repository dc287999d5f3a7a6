/* piola: fracture of solids by the virtual node algorithm (Molino, Bao and Fedkiw 2004),
 * see docs/fracture.md.
 *
 * A cut is a plane or a triangle surface in world space, applied to a solid's current
 * (deformed) shape, or a crack grown tet by tet by a breaking criterion (stress or plastic
 * strain). Every tet it splits is replaced by two copies, one per side; each copy keeps the whole tet's
 * shape functions and carries only its side's share of the material (its material
 * fraction: mass, elastic and damping forces are scaled by it). Nodes are duplicated per
 * connected piece of material around them, so the pieces move apart. The crack inside a
 * copy is a polygon kept in the tet's barycentric coordinates. A tet is cut at most once:
 * a later cut leaves the tets it finds already cut as they are (the new crack stops there).
 *
 *   piola_fracture_cut cut = {.time = 0.1, .point = {0, 0, 0.5}, .normal = {0, 0, 1}};
 *   piola_fracture_def def = piola_default_fracture_def();
 *   def.cuts = &cut; def.cut_count = 1;
 *   piola_world_solid_set_fracture(world, 0, &def);   // cut at the first step from t = 0.1 s
 *   ...
 *   printf("%d fragments\n", piola_world_solid_fragment_count(world, 0)); */
#ifndef PIOLA_WORLD_FRACTURE_H
#define PIOLA_WORLD_FRACTURE_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A scripted cut, applied to the solid's shape at the first step that starts at or after
 * time (s): the plane through point (m) with normal (any length > 0), world space, or, when
 * blade is not NULL, that triangle surface (world space, m; copied): it splits the tets it
 * passes all the way through (piola_world_solid_cut_by_surface).
 *
 * A moving blade: with end_time > time (s), the blade (given at its position at `time`)
 * translates at velocity (m/s) until end_time, and before every step that starts in
 * [time, end_time], and once more at the first step from end_time, it cuts the tets that
 * its surface at that time, together with the band its border swept since its last cut,
 * passes all the way through: one crack, growing step by step (docs/fracture.md, "A moving
 * blade"). end_time <= time (the default 0 included) and velocity 0: a cut at one time. */
typedef struct piola_fracture_cut {
  double time;
  piola_vec3 point, normal;
  const piola_tri_mesh *blade;
  double end_time;     /* s; > time: a moving blade (needs blade) */
  piola_vec3 velocity; /* m/s, world space; nonzero only with end_time > time */
} piola_fracture_cut;

/* When material breaks by itself (besides the scripted cuts). */
typedef enum piola_fracture_criterion {
  PIOLA_FRACTURE_SCRIPTED = 0, /* only the scripted cuts (default) */
  PIOLA_FRACTURE_STRESS = 1,   /* brittle: a tet whose largest principal Cauchy stress
                                  exceeds threshold (Pa) cracks */
  PIOLA_FRACTURE_PLASTIC_STRAIN = 2, /* ductile: a tet whose accumulated plastic log strain
                                  exceeds threshold (dimensionless) cracks; the solid needs
                                  plasticity */
} piola_fracture_criterion;
/* Before each step, every uncut tet on a crack's front (it shares a face with a tet the
 * crack cut, and the crack ends on an edge of that face) whose measure is past
 * growth_threshold is cut so that the crack runs on into it: the crack's points on the
 * shared faces are kept and it turns as close as they allow to normal to the neighbours'
 * crack (stress criterion) or to the tet's largest principal stress (plastic strain). If no
 * crack grows or waits (max_crack_speed), the tet past threshold with the largest measure
 * starts a new one unless a crack touches it: the plane through its centroid normal to its
 * largest principal stress, in that tet only. So cracks grow tet by tet as surfaces
 * (docs/fracture.md). */

typedef struct piola_fracture_def {
  const piola_fracture_cut *cuts; /* cut_count cuts, copied; any order (applied by time) */
  int32_t cut_count;
  int32_t max_cuts_per_step;      /* at most this many scripted cuts are applied before one
                                     step; the others wait for the next steps. 0 (default): no
                                     limit */
  piola_fracture_criterion criterion; /* default PIOLA_FRACTURE_SCRIPTED */
  double threshold;               /* > 0: Pa (stress) or plastic log strain (plastic_strain) */
  int32_t max_tets_per_step;      /* the criterion cuts at most this many tets before one step.
                                     0 (default): no limit */
  double growth_threshold;        /* >= 0, the unit of threshold: a crack front grows into a
                                     tet whose measure exceeds it; a new crack still needs
                                     threshold. 0 (default): threshold */
  double max_crack_speed;         /* m/s: a crack front crosses a tet (its mean rest edge) in
                                     no less than that edge over this speed, counted from when
                                     the crack reached the tet; while a front waits, no new
                                     crack starts. 0 (default): no limit */
} piola_fracture_def;

PIOLA_API piola_fracture_def piola_default_fracture_def(void);

/* Gives solid `solid` its fracture def. Cuts due at the world's current time are applied at
 * once. Bad cuts (non-finite, zero normal) are refused naming their index. */
PIOLA_API piola_status piola_world_solid_set_fracture(piola_world *world, int32_t solid,
                                                      const piola_fracture_def *def);

/* Cuts solid `solid` now by the plane through point (m) with normal (any length > 0).
 * *cut_tets (may be NULL) receives how many tets this cut split. */
PIOLA_API piola_status piola_world_solid_cut(piola_world *world, int32_t solid,
                                             const double point[3], const double normal[3],
                                             int32_t *cut_tets);

/* Cuts solid `solid` now by a triangle surface (world space, m): each tet the surface passes
 * all the way through (every edge whose ends lie on opposite sides of it crosses one of its
 * triangles) and that was never cut is split along the zero set of the corner distances to
 * the surface (signed by the nearest triangle's normal). Tets the surface only enters keep
 * their material whole. *cut_tets (may be NULL) receives how many tets it split. */
PIOLA_API piola_status piola_world_solid_cut_by_surface(piola_world *world, int32_t solid,
                                                        const piola_tri_mesh *surface,
                                                        int32_t *cut_tets);

/* Whether the solid has fracture state (a def or a cut so far). */
PIOLA_API int piola_world_solid_has_fracture(const piola_world *world, int32_t solid);
/* Connected pieces of material (1 for a solid never cut). */
PIOLA_API int32_t piola_world_solid_fragment_count(const piola_world *world, int32_t solid);
/* Tets of the solid's original mesh split so far. */
PIOLA_API int32_t piola_world_solid_cut_tet_count(const piola_world *world, int32_t solid);
/* Per tet of the current mesh (piola_elastic_body_tets): its fragment (0 ..
 * fragment_count - 1, numbered in order of first tet) and material fraction in (0, 1], and
 * the tet of the original mesh it is a copy of. NULL for a solid without fracture state. */
PIOLA_API const int32_t *piola_world_solid_fragments(const piola_world *world, int32_t solid);
PIOLA_API const double *piola_world_solid_material_fractions(const piola_world *world,
                                                              int32_t solid);
PIOLA_API const int32_t *piola_world_solid_parent_tets(const piola_world *world, int32_t solid);

/* The surface of each fragment at the current positions: the solid's boundary faces
 * clipped to each copy's material and the crack polygons, triangulated, outward oriented.
 * Triangles of fragment f are [fragment_start[f], fragment_start[f + 1]); vertices are not
 * shared between fragments. Free with piola_fracture_surface_free. */
typedef struct piola_fracture_surface {
  int32_t fragment_count;
  int32_t vertex_count, triangle_count;
  double *positions;       /* 3 per vertex, m */
  int32_t *triangles;      /* 3 per triangle */
  int32_t *fragment_start; /* fragment_count + 1 triangle offsets */
} piola_fracture_surface;

PIOLA_API piola_status piola_world_solid_fracture_surface(const piola_world *world, int32_t solid,
                                                          piola_fracture_surface *out);
PIOLA_API void piola_fracture_surface_free(piola_fracture_surface *surface);

#ifdef __cplusplus
}
#endif

#endif
