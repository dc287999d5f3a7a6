/* A cut solid put back into a saved cut state (fracture_restore.h), for checkpoints.
 *
 * The state is rebuilt from the solid's original mesh, whatever cut state the solid is in
 * now (a world just built from its scene may have been cut already by scripted cuts at
 * t = 0): a copy's corner k is corner k of its original tet, so every saved node names one
 * original node, whose rest position and constraint it has, and every copy one original
 * tet, whose material and fibre it has. The rest (positions, velocities, per-tet and
 * plastic state) is what the checkpoint stores next; what the rebuild derives from the
 * mesh (masses, rest volumes times the fractions, the damping pattern) is computed from the
 * same mesh and fractions as in the run that wrote the checkpoint, so it has the same
 * bits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "sim/fracture_internal.h"
#include "sim/fracture_restore.h"

#define BAD(...) PIOLA_FAIL(PIOLA_ERROR_PARSE, __VA_ARGS__)

/* Ranges, and the original node of every saved node (origin, node_count entries). */
static piola_status check_saved(const solid_fracture *f, const fracture_saved *s, const char *name,
                                int32_t *origin) {
  const int32_t nc = s->copy_count, nn = s->node_count;
  enum { MORE = FRACTURE_MAX_CUTS - 1 };
  if (nc < f->tet_count || nc > FRACTURE_MAX_COPIES * f->tet_count || nn < 1)
    return BAD("solid '%s': %d copies and %d nodes do not fit its %d tets", name, (int)nc, (int)nn,
               (int)f->tet_count);
  if (s->events < 0 || s->fragment_count < 1 || s->fragment_count > nc)
    return BAD("solid '%s': %d cuts, %d fragments", name, (int)s->events, (int)s->fragment_count);
  for (int32_t i = 0; i < nn; ++i) origin[i] = -1;
  for (int32_t c = 0; c < nc; ++c) {
    const int32_t t = s->parent[c];
    if (t < 0 || t >= f->tet_count || s->event[c] < -1 || s->event[c] >= s->events ||
        (s->side[c] != 1 && s->side[c] != -1) || !(s->fraction[c] > 0 && s->fraction[c] <= 1) ||
        s->fragment[c] < 0 || s->fragment[c] >= s->fragment_count ||
        (s->event[c] < 0 && s->fraction[c] != 1.0))
      return BAD("solid '%s': copy %d is not a copy of its mesh", name, (int)c);
    for (int j = 0; j < MORE; ++j) {
      const int32_t e = s->more_event[MORE * c + j];
      const int ended = j > 0 && s->more_event[MORE * c + j - 1] < 0;
      int finite = 1;
      for (int k = 0; k < 4; ++k) finite &= isfinite(s->more_dist[4 * (MORE * c + j) + k]) != 0;
      if (e < -1 || e >= s->events || (e >= 0 && (ended || s->event[c] < 0 || !finite ||
                                                  (s->more_side[MORE * c + j] != 1 && s->more_side[MORE * c + j] != -1))))
        return BAD("solid '%s': copy %d has further cuts that do not fit", name, (int)c);
    }
    for (int k = 0; k < 4; ++k) {
      const int32_t node = s->tets[4 * c + k];
      if (!isfinite(s->dist[4 * c + k]) || node < 0 || node >= nn ||
          (origin[node] >= 0 && origin[node] != f->tets[4 * t + k]))
        return BAD("solid '%s': copy %d corner %d does not fit its mesh", name, (int)c, k);
      origin[node] = f->tets[4 * t + k];
    }
  }
  for (int32_t i = 0; i < nn; ++i)
    if (origin[i] < 0) return BAD("solid '%s': node %d is in no copy", name, (int)i);
  for (int32_t t = 0; t < f->tet_count; ++t)
    for (int j = 0; j < FRACTURE_MAX_COPIES; ++j) {
      const int32_t c = s->copies[FRACTURE_MAX_COPIES * t + j];
      if ((j == 0 && c < 0) || c < -1 || c >= nc || (c >= 0 && s->parent[c] != t))
        return BAD("solid '%s': the copies of tet %d do not fit", name, (int)t);
    }
  return PIOLA_OK;
}

/* Rebuilds b with the saved mesh. origin: the original node of each saved node. */
static piola_status rebuild(piola_world *w, world_body *b, const fracture_saved *s,
                            const int32_t *origin) {
  const solid_fracture *f = b->fracture;
  const int32_t nn = s->node_count, nc = s->copy_count;
  const int32_t *now = piola_elastic_body_tets(b->solid);
  const double *rest_now = piola_elastic_body_rest_positions(b->solid);
  /* a node of the current mesh for every original node (the current mesh is cut from the
   * original one too, so each original node has at least one) */
  int32_t originals = 0;
  for (int32_t i = 0; i < 4 * f->tet_count; ++i) originals = f->tets[i] >= originals ? f->tets[i] + 1 : originals;
  int32_t *of_original = malloc(sizeof(int32_t) * (size_t)(originals > 0 ? originals : 1));
  int32_t *node_parent = malloc(sizeof(int32_t) * (size_t)nn);
  int32_t *element_parent = malloc(sizeof(int32_t) * (size_t)nc);
  double *rest = malloc(3 * sizeof(double) * (size_t)nn), *v = calloc(3 * (size_t)nn, sizeof(double));
  piola_status st = PIOLA_OK;
  if (!of_original || !node_parent || !element_parent || !rest || !v)
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "solid '%s': out of memory", b->name);
  if (st == PIOLA_OK) {
    for (int32_t c = 0; c < f->copy_count; ++c)
      for (int k = 0; k < 4; ++k) of_original[f->tets[4 * f->parent[c] + k]] = now[4 * c + k];
    for (int32_t i = 0; i < nn; ++i) {
      const int32_t p = of_original[origin[i]];
      node_parent[i] = p;
      memcpy(rest + 3 * (size_t)i, rest_now + 3 * (size_t)p, 3 * sizeof(double));
    }
    for (int32_t c = 0; c < nc; ++c) element_parent[c] = f->copies[FRACTURE_MAX_COPIES * s->parent[c]];
    piola_tet_mesh mesh = {.vertex_count = nn, .positions = rest, .tet_count = nc,
                           .tets = (int32_t *)s->tets};
    body_change change = {.solid_rest = &mesh, .x = rest, .v = v, .node_parent = node_parent,
                          .element_parent = element_parent, .element_fraction = s->fraction};
    st = piola__body_rebuild(w, b, &change);
  }
  free(of_original), free(node_parent), free(element_parent), free(rest), free(v);
  return st;
}

piola_status piola__fracture_restore(piola_world *w, world_body *b, const fracture_saved *s) {
  solid_fracture *f = b->fracture;
  const int32_t nc = s->copy_count;
  int32_t *origin = malloc(sizeof(int32_t) * (size_t)(s->node_count > 0 ? s->node_count : 1));
  if (!origin) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "solid '%s': out of memory", b->name);
  piola_status st = check_saved(f, s, b->name, origin);
  /* the arrays of the new state, allocated before anything changes */
  int32_t *parent = malloc(sizeof(int32_t) * (size_t)nc), *event = malloc(sizeof(int32_t) * (size_t)nc);
  int32_t *fragment = malloc(sizeof(int32_t) * (size_t)nc);
  int32_t *copies = malloc(FRACTURE_MAX_COPIES * sizeof(int32_t) * (size_t)f->tet_count);
  int8_t *side = malloc((size_t)nc);
  double *dist = malloc(4 * sizeof(double) * (size_t)nc), *fraction = malloc(sizeof(double) * (size_t)nc);
  const size_t more = (FRACTURE_MAX_CUTS - 1) * (size_t)nc;
  int32_t *more_event = malloc(sizeof(int32_t) * more);
  int8_t *more_side = malloc(more);
  double *more_dist = malloc(4 * sizeof(double) * more);
  if (st == PIOLA_OK && (!parent || !event || !fragment || !copies || !side || !dist || !fraction ||
                         !more_event || !more_side || !more_dist))
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "solid '%s': out of memory", b->name);
  const int same = st == PIOLA_OK && nc == f->copy_count && s->node_count == b->n &&
                   memcmp(s->tets, piola_elastic_body_tets(b->solid), 4 * sizeof(int32_t) * (size_t)nc) == 0 &&
                   memcmp(s->fraction, f->fraction, sizeof(double) * (size_t)nc) == 0;
  if (st == PIOLA_OK && !same) st = rebuild(w, b, s, origin);
  if (st == PIOLA_OK) {
    f = b->fracture;
    memcpy(parent, s->parent, sizeof(int32_t) * (size_t)nc);
    memcpy(event, s->event, sizeof(int32_t) * (size_t)nc);
    memcpy(fragment, s->fragment, sizeof(int32_t) * (size_t)nc);
    memcpy(copies, s->copies, FRACTURE_MAX_COPIES * sizeof(int32_t) * (size_t)f->tet_count);
    memcpy(more_event, s->more_event, sizeof(int32_t) * more);
    memcpy(more_side, s->more_side, more);
    memcpy(more_dist, s->more_dist, 4 * sizeof(double) * more);
    memcpy(side, s->side, (size_t)nc);
    memcpy(dist, s->dist, 4 * sizeof(double) * (size_t)nc);
    memcpy(fraction, s->fraction, sizeof(double) * (size_t)nc);
    free(f->parent), free(f->event), free(f->fragment), free(f->copies), free(f->side);
    free(f->dist), free(f->fraction), free(f->more_event), free(f->more_side), free(f->more_dist);
    f->parent = parent, f->event = event, f->fragment = fragment, f->copies = copies;
    f->side = side, f->dist = dist, f->fraction = fraction;
    f->more_event = more_event, f->more_side = more_side, f->more_dist = more_dist;
    parent = event = fragment = copies = more_event = NULL, side = more_side = NULL;
    dist = fraction = more_dist = NULL;
    f->copy_count = nc;
    f->fragment_count = s->fragment_count;
  }
  free(origin), free(parent), free(event), free(fragment), free(copies), free(side), free(dist);
  free(fraction), free(more_event), free(more_side), free(more_dist);
  return st;
}
