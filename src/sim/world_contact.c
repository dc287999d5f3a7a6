/* Contact between deformable surfaces, run after every world step (paper section 9: "outside
 * the step"), with the BFA02 collision module (piola/collision_surface.h): self-collision of
 * the solids' boundary surfaces and of shells (cloth), and two-way contact between them.
 *
 * One collision surface holds the boundary triangles of every solid and the triangles of
 * every shell with self_collision enabled, over each body's own vertex numbering shifted by
 * an offset per body (interior nodes of a solid sit in the arrays but belong to no triangle,
 * so they take no part); each body has its thickness and friction. All bodies are in the same
 * surface, so they collide with each other as well as with themselves, and since every
 * impulse acts on both sides of a pair with the lumped masses, solid-shell contact is two-way
 * and conserves momentum.
 *
 * A shell is an open sheet: it has no inside, and none is needed. The repulsion thickness
 * keeps two sheets (or two layers of one) apart, and continuous collision detection stops
 * any vertex from passing through a triangle and any edge through an edge, boundary edges of
 * the sheet included (they are ordinary edges of the surface, with one triangle instead of
 * two). A solid's boundary is closed, but the module does not use that either.
 *
 * A step moved every body from x_old to x. The average velocity of the step, (x - x_old)/dt,
 * is what collision processing corrects: x = x_old + dt v_c'. The final velocity changes by
 * the same amount, v += v_c' - v_c, as in BFA02, and the elastic forces of a body whose
 * positions changed are recomputed, since the next step starts from them. Constrained nodes
 * count as pinned (infinite mass).
 *
 * With a collision interval dt_c > 0 (piola_world_def.collision_interval) this is BFA02's
 * collision step: the internal dynamics takes as many steps as its stability needs, and
 * collision processing runs once, after the first step that reaches the interval's end (or
 * on advance_to's target), from the positions x_c kept when it opened to the positions after
 * that step, with the average velocity (x - x_c)/dt_c, dt_c the time since it opened (at
 * least the interval, less than the interval plus one step). Steps are not shortened to end
 * on intervals: that would add a step per interval whenever the steps do not divide it. x_c was collision-free (the previous
 * interval's result), and the linear trajectories from it are what CCD checks, so the end of
 * every interval is collision-free whatever the steps inside it did; the detection passes,
 * which dominate the cost of a cloth, run once per interval instead of once per step. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "contact/bvh.h"
#include "contact/proximity.h"
#include "contact/surface_intersection.h"
#include "force/elastic_body_internal.h"
#include "piola/collision_surface.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

typedef struct world_contact {
  piola_collision_surface *surface;
  uint64_t bodies_version; /* the world's bodies_version when built */
  int32_t vertex_count;
  int32_t *offset; /* per body of the table: first global vertex, or -1 when off */
  double *x0, *v, *v_before, *mass;
  /* collision_interval > 0: x0 holds the positions at t_start, the start of the open
   * interval */
  int open;
  double t_start;
} world_contact;

void piola__world_contact_free(piola_world *w) {
  world_contact *c = w->contact;
  if (!c) return;
  piola_collision_surface_destroy(c->surface);
  free(c->offset), free(c->x0), free(c->v), free(c->v_before), free(c->mass);
  free(c);
  w->contact = NULL;
}

/* The collision triangles of body i: a cut solid's fragment surfaces, with crack faces
 * moved into their material (below), as points between two nodes (*where); otherwise its
 * boundary or shell triangles over its own nodes. */
typedef struct body_surface {
  piola_tri_mesh triangles;
  int owned;
  piola_fracture_surface fragments;
  fracture_surface_point *where; /* per vertex, for a cut solid */
  int32_t vertices;              /* collision vertices */
} body_surface;

static piola_status body_surface_build(const world_body *s, body_surface *out) {
  if (s->kind == PIOLA_BODY_SOLID && s->fracture) {
    /* The two faces of a crack coincide when it is made: each is moved into its material
     * by up to half the thickness (less than the cut's snap distance, so every polygon
     * keeps its shape), and they start that far apart instead of touching. */
    const double inset = fmin(0.5 * s->self_collision.thickness, 0.9 * piola__fracture_snap(s));
    PIOLA_TRY(piola__fracture_surface_build(s, inset, &out->fragments, &out->where));
    out->triangles.triangle_count = out->fragments.triangle_count;
    out->triangles.triangles = out->fragments.triangles;
    out->vertices = out->fragments.vertex_count;
    return PIOLA_OK;
  }
  out->vertices = s->n;
  return piola__body_collision_triangles(s, &out->triangles, &out->owned);
}

static void body_surface_free(body_surface *b) {
  if (b->owned) piola_tri_mesh_free(&b->triangles);
  piola_fracture_surface_free(&b->fragments);
  free(b->where);
}

static piola_status build(piola_world *w) {
  piola__world_contact_free(w);
  world_contact *c = calloc(1, sizeof(*c));
  if (!c) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  w->contact = c;
  c->bodies_version = w->bodies_version;
  const int32_t count = w->body_count;
  c->offset = malloc(sizeof(int32_t) * (size_t)(count > 0 ? count : 1));
  if (!c->offset) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  /* nv nodes (every body's, the arrays processing takes), nsv collision vertices: the same
   * unless a cut solid is in the surface, whose vertices are embedded in its nodes */
  int32_t nv = 0, nsv = 0, nt = 0, bodies = 0;
  int embedded = 0;
  body_surface *surfaces = calloc((size_t)(count > 0 ? count : 1), sizeof(body_surface));
  int32_t *vertex_offset = calloc((size_t)(count > 0 ? count : 1), sizeof(int32_t));
  if (!surfaces || !vertex_offset) {
    free(surfaces), free(vertex_offset);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  }
  piola_status st = PIOLA_OK;
  for (int32_t i = 0; i < count; ++i) c->offset[i] = -1;
  for (int32_t i = 0; i < count && st == PIOLA_OK; ++i) {
    const world_body *s = &w->bodies[i];
    if (!s->self_collision.enabled || s->collision_waits) continue;
    st = body_surface_build(s, &surfaces[i]);
    embedded |= surfaces[i].where != NULL;
    c->offset[i] = nv, vertex_offset[i] = nsv;
    nv += s->n, nsv += surfaces[i].vertices, nt += surfaces[i].triangles.triangle_count, ++bodies;
  }
  int32_t *tris = NULL, *vertex_body = NULL, *embed_nodes = NULL;
  double *embed_weights = NULL;
  piola_collision_body_def *defs = NULL;
  if (st == PIOLA_OK) {
    tris = malloc(sizeof(int32_t) * 3 * (size_t)(nt > 0 ? nt : 1));
    vertex_body = malloc(sizeof(int32_t) * (size_t)(nsv > 0 ? nsv : 1));
    defs = malloc(sizeof(*defs) * (size_t)(bodies > 0 ? bodies : 1));
    c->x0 = malloc(sizeof(double) * 3 * (size_t)(nv > 0 ? nv : 1));
    c->v = malloc(sizeof(double) * 3 * (size_t)(nv > 0 ? nv : 1));
    c->v_before = malloc(sizeof(double) * 3 * (size_t)(nv > 0 ? nv : 1));
    c->mass = malloc(sizeof(double) * (size_t)(nv > 0 ? nv : 1));
    if (embedded) {
      embed_nodes = malloc(sizeof(int32_t) * PIOLA_COLLISION_EMBED_NODES * (size_t)(nsv > 0 ? nsv : 1));
      embed_weights = malloc(sizeof(double) * PIOLA_COLLISION_EMBED_NODES * (size_t)(nsv > 0 ? nsv : 1));
    }
    if (!tris || !vertex_body || !defs || !c->x0 || !c->v || !c->v_before || !c->mass ||
        (embedded && (!embed_nodes || !embed_weights)))
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  }
  if (st == PIOLA_OK) {
    int32_t t = 0, b = 0;
    for (int32_t i = 0; i < count; ++i) {
      if (c->offset[i] < 0) continue;
      const world_body *s = &w->bodies[i];
      const body_surface *bs = &surfaces[i];
      for (int32_t k = 0; k < 3 * bs->triangles.triangle_count; ++k)
        tris[3 * t + k] = vertex_offset[i] + bs->triangles.triangles[k];
      t += bs->triangles.triangle_count;
      for (int32_t k = 0; k < bs->vertices; ++k) vertex_body[vertex_offset[i] + k] = b;
      for (int32_t k = 0; embedded && k < bs->vertices; ++k) {
        int32_t *node = embed_nodes + PIOLA_COLLISION_EMBED_NODES * (size_t)(vertex_offset[i] + k);
        double *weight = embed_weights + PIOLA_COLLISION_EMBED_NODES * (size_t)(vertex_offset[i] + k);
        for (int j = 0; j < PIOLA_COLLISION_EMBED_NODES; ++j) node[j] = -1, weight[j] = 0;
        if (!bs->where) {
          node[0] = c->offset[i] + k, weight[0] = 1;
        } else {
          /* its nodes with positive weight (the first of them, a corner's or an edge
           * crossing's first node, taking the rest of 1, as a single cut always had) */
          const fracture_surface_point *p = &bs->where[k];
          double rest = 1;
          int used = 0;
          for (int j = 0; j < 4 && p->node[j] >= 0; ++j) {
            if (!(p->w[j] > 0)) continue; /* the weights sum to 1: one at least is positive */
            node[used] = c->offset[i] + p->node[j], weight[used] = fmin(p->w[j], 1);
            if (used++ > 0) rest -= weight[used - 1];
          }
          weight[0] = rest;
        }
      }
      defs[b] = piola_default_collision_body_def();
      defs[b].thickness = s->self_collision.thickness;
      defs[b].friction = s->self_collision.friction;
      ++b;
    }
    piola_collision_surface_def def = piola_default_collision_surface_def();
    def.vertex_count = nsv, def.triangle_count = nt, def.triangles = tris;
    def.body_count = bodies > 0 ? bodies : 1, def.bodies = defs, def.vertex_body = vertex_body;
    if (embedded) def.node_count = nv, def.embed_nodes = embed_nodes, def.embed_weights = embed_weights;
    if (bodies == 0) defs[0] = piola_default_collision_body_def();
    st = piola_collision_surface_create(&def, &c->surface);
  }
  c->vertex_count = nv;
  for (int32_t i = 0; i < count; ++i) body_surface_free(&surfaces[i]);
  free(surfaces), free(vertex_offset), free(tris), free(vertex_body), free(defs);
  free(embed_nodes), free(embed_weights);
  return st;
}

/* Bodies with self_collision enabled. */
static int any_enabled(piola_world *w) {
  int any = 0;
  for (int32_t i = 0; i < w->body_count; ++i) any |= w->bodies[i].self_collision.enabled;
  return any;
}

/* Bodies in the collision surface: self_collision enabled, not waiting to untangle. */
static int any_self_collision(piola_world *w) {
  int any = 0;
  for (int32_t i = 0; i < w->body_count; ++i)
    any |= w->bodies[i].self_collision.enabled && !w->bodies[i].collision_waits;
  return any;
}

/* A tangled start. Collision processing keeps an intersection-free surface free; it cannot
 * untangle one, and on a solid started scrambled, collapsed or mirrored its impulses and
 * rigid zones hold the tangle in place: an octopus (1,140 tets) scrambled by a quarter of its
 * size kept 571 tets inverted through 1 s of backward Euler, 40 times slower than without
 * self-collision, which untangled it within 0.13 s; collapsed to a point it never left the
 * point. So a solid that is tangled at the world's first collision pass from t = 0 stays out
 * of the collision surface (it collides with nothing else either) until it has untangled: no
 * tet inverted or nearly flat (det F above JOIN_MIN_DET) and its boundary free of intersections
 * (the exact test of surface_intersection.h; a cut solid's fragment surfaces are not tested).
 * Then it joins the surface for good. Shells do not wait. */
#define TANGLE_MIN_DET 1e-6
/* A waiting solid joins once every tet's det F is above this, a margin over flat: judged at
 * the step's end instead of its start (as it was first written), a solid that joined as soon
 * as no tet was flat still had nearly flat tets unfolding, and the collision pass held one of
 * them inverted for 0.5 s (the scrambled octopus above), which 0.1 and 0.5 alike avoided.
 * Judged at the step's start, 1e-6 and 0.1 both untangle these scenes cleanly. */
#define JOIN_MIN_DET 0.1

/* det [b - a, c - a, d - a] of four points given by index into x. */
static double corner_det(const double *x, const int32_t *c) {
  double e[3][3];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) e[k][d] = x[3 * (size_t)c[k + 1] + d] - x[3 * (size_t)c[0] + d];
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
         e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

/* The first tet of solid s at positions x whose det F is at most LIMIT (its value in *det), or
 * -1 for none.
 * From the node positions, which every process of a split run holds whole, so every process
 * decides alike (mpi.md, "Self-collision: replicated"). */
int32_t piola__solid_flat_or_inverted_tet(const world_body *s, const double *x, double *det,
                                          double limit) {
  const piola_elastic_body *e = s->solid;
  for (int32_t t = 0; t < e->tet_count; ++t) {
    const int32_t *c = e->tets + 4 * (size_t)t;
    *det = corner_det(x, c) / corner_det(e->rest_positions, c);
    if (!(*det > limit)) return t;
  }
  return -1;
}

/* 1 when solid s's boundary surface at positions x passes through itself (the tet test
 * passed), 0 when it does not, -1 out of memory. */
static int surface_tangled(const world_body *s, const double *x) {
  if (s->fracture) return 0;
  piola_tri_mesh tris = {0};
  int owned = 0;
  if (piola__body_collision_triangles(s, &tris, &owned) != PIOLA_OK) return -1;
  const int found = piola__surface_intersects(x, tris.triangles, tris.triangle_count);
  if (owned) piola_tri_mesh_free(&tris);
  return found;
}

/* Of the surface (x, tris, nt triangles, each of body group[t]; nv vertices), the vertex
 * closest to a triangle of another body among the pairs closer than the mean of their bodies'
 * collision thicknesses: its index, with *triangle and *gap (m); -1 for none, -2 out of
 * memory. */
static int32_t closest_within_thickness(const piola_world *w, const double *x, const int32_t *tris,
                                        const int32_t *group, int32_t nt, int32_t nv,
                                        int32_t *triangle, double *gap) {
  int32_t *owner = malloc(sizeof(int32_t) * (size_t)(nv > 0 ? nv : 1));
  piola__box *boxes = malloc(sizeof(piola__box) * (size_t)(nt > 0 ? nt : 1));
  piola__bvh tree = {0};
  piola__index_list near = {0};
  int32_t best = -2;
  if (!owner || !boxes) goto done;
  double widest = 0;
  for (int32_t v = 0; v < nv; ++v) owner[v] = -1; /* not on a surface */
  for (int32_t t = 0; t < nt; ++t) {
    const int32_t *c = tris + 3 * (size_t)t;
    for (int k = 0; k < 3; ++k) owner[c[k]] = group[t];
    boxes[t] = piola__triangle_box(x, c);
    widest = fmax(widest, w->bodies[group[t]].self_collision.thickness);
  }
  if (piola__bvh_build(&tree, boxes, nt) != 0) goto done;
  best = -1;
  double best_gap = INFINITY;
  for (int32_t v = 0; v < nv; ++v) {
    if (owner[v] < 0) continue;
    const double *p = x + 3 * (size_t)v;
    const piola__box query = piola__box_around(p, widest);
    near.count = 0;
    if (piola__bvh_query(&tree, &query, &near) != 0) {
      best = -2;
      goto done;
    }
    for (int64_t k = 0; k < near.count; ++k) {
      const int32_t t = near.items[k];
      if (group[t] == owner[v]) continue;
      const int32_t *c = tris + 3 * (size_t)t;
      const double h = 0.5 * (w->bodies[owner[v]].self_collision.thickness +
                              w->bodies[group[t]].self_collision.thickness);
      double bary[3];
      const vec3 a = {x[3 * (size_t)c[0]], x[3 * (size_t)c[0] + 1], x[3 * (size_t)c[0] + 2]};
      const vec3 b = {x[3 * (size_t)c[1]], x[3 * (size_t)c[1] + 1], x[3 * (size_t)c[1] + 2]};
      const vec3 e = {x[3 * (size_t)c[2]], x[3 * (size_t)c[2] + 1], x[3 * (size_t)c[2] + 2]};
      const double d = sqrt(piola__point_triangle_closest((vec3){p[0], p[1], p[2]}, a, b, e, bary));
      if (d < h && d < best_gap) best = v, best_gap = d, *triangle = t;
    }
  }
  *gap = best_gap;
done:
  piola__bvh_free(&tree);
  free(near.items), free(owner), free(boxes);
  return best;
}

/* Bodies placed through each other. Their surfaces intersect from the first step, and
 * collision processing cannot separate them: its impulses act on pairs already through each
 * other and hold them hooked where they cross. Unlike one solid's tangle this is no state the
 * elastic forces leave (each body is at rest in its own shape), so no body waits: the world
 * warns, once, at its first collision pass from t = 0, naming the first two bodies found
 * through each other (bodies in the surface only: not waiting, not cut by fracture, whose
 * fragment surfaces are not tested). Returns -1 out of memory. */
static int warn_bodies_through_each_other(piola_world *w, int at_step_start) {
  int32_t nv = 0, nt = 0, bodies = 0;
  piola_tri_mesh *surfaces =
      calloc((size_t)(w->body_count > 0 ? w->body_count : 1), sizeof(piola_tri_mesh));
  int *owned = calloc((size_t)(w->body_count > 0 ? w->body_count : 1), sizeof(int));
  int found = -1;
  double *x = NULL;
  int32_t *tris = NULL, *group = NULL;
  if (!surfaces || !owned) goto done;
  for (int32_t i = 0; i < w->body_count; ++i) {
    const world_body *b = &w->bodies[i];
    if (!b->self_collision.enabled || b->collision_waits || b->fracture) continue;
    if (piola__body_collision_triangles(b, &surfaces[i], &owned[i]) != PIOLA_OK) goto done;
    nv += b->n, nt += surfaces[i].triangle_count, ++bodies;
  }
  found = 0;
  if (bodies < 2) goto done;
  found = -1;
  x = malloc(sizeof(double) * 3 * (size_t)nv);
  tris = malloc(sizeof(int32_t) * 3 * (size_t)(nt > 0 ? nt : 1));
  group = malloc(sizeof(int32_t) * (size_t)(nt > 0 ? nt : 1));
  if (!x || !tris || !group) goto done;
  int32_t v0 = 0, t0 = 0;
  for (int32_t i = 0; i < w->body_count; ++i) {
    const world_body *b = &w->bodies[i];
    if (!b->self_collision.enabled || b->collision_waits || b->fracture) continue;
    memcpy(x + 3 * (size_t)v0, at_step_start ? b->x_old : b->x, sizeof(double) * 3 * (size_t)b->n);
    for (int32_t t = 0; t < surfaces[i].triangle_count; ++t, ++t0) {
      for (int c = 0; c < 3; ++c)
        tris[3 * (size_t)t0 + c] = v0 + surfaces[i].triangles[3 * (size_t)t + c];
      group[t0] = i;
    }
    v0 += b->n;
  }
  int32_t pair[2];
  found = piola__surfaces_cross(x, tris, group, nt, pair);
  if (found == 1) {
    const world_body *a = &w->bodies[group[pair[0]]], *b = &w->bodies[group[pair[1]]];
    piola__world_warn(w, PIOLA_WARNING_BODIES_CROSS,
                      "%s '%s' and %s '%s' start through each other (their surfaces intersect): "
                      "collision processing cannot separate surfaces that already pass through "
                      "each other, and holds them hooked where they cross; move one (its "
                      "`transform`) so that they start apart (contact.md, \"Limits\")",
                      piola__body_kind_name(a->kind), a->name, piola__body_kind_name(b->kind),
                      b->name);
  } else if (found == 0) {
    /* apart, but closer than their thickness: the first pass's repulsion pushes them out to
     * it at once (two boxes started 2 mm apart with a 10 mm thickness flew apart with 0.19 J
     * in their first frame, from rest) */
    int32_t t = -1;
    double gap = 0;
    const int32_t v = closest_within_thickness(w, x, tris, group, nt, nv, &t, &gap);
    if (v == -2) {
      found = -1;
      goto done;
    }
    if (v >= 0) {
      int32_t owner = -1, first = 0;
      for (int32_t i = 0, start = 0; i < w->body_count && owner < 0; ++i) {
        const world_body *b = &w->bodies[i];
        if (!b->self_collision.enabled || b->collision_waits || b->fracture) continue;
        if (v < start + b->n) owner = i, first = start;
        start += b->n;
      }
      const world_body *a = &w->bodies[owner], *b = &w->bodies[group[t]];
      const double h = 0.5 * (a->self_collision.thickness + b->self_collision.thickness);
      piola__world_warn(w, PIOLA_WARNING_WITHIN_THICKNESS,
                        "%s '%s' and %s '%s' start %.3g m apart (vertex %d of the first, "
                        "numbered from 0, to the second's surface), closer than their collision "
                        "thickness %.3g m (the mean of their self_collision.thickness): the "
                        "first collision pass pushes them apart to it at once, a kick from "
                        "rest; start them at least that far apart (their `transform`) or give "
                        "them a smaller thickness (contact.md, \"Parameters\")",
                        piola__body_kind_name(a->kind), a->name, piola__body_kind_name(b->kind),
                        b->name, gap, (int)(v - first), h);
    }
  }
done:
  for (int32_t i = 0; surfaces && owned && i < w->body_count; ++i)
    if (owned[i]) piola_tri_mesh_free(&surfaces[i]);
  free(surfaces), free(owned), free(x), free(tris), free(group);
  return found;
}

/* Starts a tangled solid waiting at the world's first collision pass from t = 0 (a resumed
 * run reads the waits from its checkpoint), and lets each waiting solid that has untangled
 * join the surface (rebuilt). Judged at the positions the pass starts from, which collision
 * processing takes to be intersection-free: the step's start (AT_STEP_START, x_old) when
 * every step is processed, else the current positions as a collision interval opens. */
static piola_status update_waits(piola_world *w, int at_step_start) {
  int changed = 0;
  const int first = !w->tangle_checked && w->time == 0.0;
  w->tangle_checked = 1;
  for (int32_t i = 0; i < w->body_count; ++i) {
    world_body *s = &w->bodies[i];
    if (s->kind != PIOLA_BODY_SOLID || !s->self_collision.enabled ||
        (!first && !s->collision_waits))
      continue;
    const double *x = at_step_start ? s->x_old : s->x;
    double det = 0;
    const int32_t tet =
        piola__solid_flat_or_inverted_tet(s, x, &det, first ? TANGLE_MIN_DET : JOIN_MIN_DET);
    const int through = tet >= 0 ? 0 : surface_tangled(s, x);
    if (through < 0) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
    const int tangled = tet >= 0 || through;
    if (first && tangled) {
      char why[160];
      if (tet >= 0)
        snprintf(why, sizeof why, "tet %d (numbered from 0 in file order) has det F = %.3g",
                 (int)tet, det);
      else
        snprintf(why, sizeof why, "its boundary surface passes through itself");
      piola__world_warn(w, PIOLA_WARNING_TANGLED_START,
                        "solid '%s' starts tangled (%s): collision processing cannot untangle a "
                        "surface, so the solid's self-collision waits until it has untangled "
                        "(det F > %g in every tet, its surface free of intersections) and it "
                        "collides with nothing else until then (contact.md, \"A tangled start\")",
                        s->name, why, JOIN_MIN_DET);
    }
    if (tangled != s->collision_waits) s->collision_waits = tangled, changed = 1;
  }
  if (first && warn_bodies_through_each_other(w, at_step_start) < 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  if (changed) piola__world_contact_free(w);
  return PIOLA_OK;
}

void piola__world_set_collision_waits(piola_world *w, world_body *s, int waits) {
  if (s->collision_waits == waits) return;
  s->collision_waits = waits;
  piola__world_contact_free(w);
}

static piola_status ensure_built(piola_world *w) {
  if (!w->contact || w->contact->bodies_version != w->bodies_version) PIOLA_TRY(build(w));
  return PIOLA_OK;
}

void piola__world_collision_reset(piola_world *w) {
  if (w->contact) w->contact->open = 0;
}

piola__contact_state piola__world_contact_state(const piola_world *w) {
  world_contact *c = w->contact; /* the state points into it, for reading it back */
  if (!c || c->bodies_version != w->bodies_version) return (piola__contact_state){0};
  return (piola__contact_state){.built = 1,
                                .open = &c->open,
                                .t_start = &c->t_start,
                                .x0 = c->x0,
                                .vertex_count = c->vertex_count,
                                .surface = c->surface};
}

piola_status piola__world_contact_prepare(piola_world *w, int built) {
  if (!built) {
    piola__world_contact_free(w);
    return PIOLA_OK;
  }
  return ensure_built(w);
}

piola_status piola__world_collision_open(piola_world *w, double *left) {
  *left = INFINITY;
  if (!(w->def.collision_interval > 0) || !any_enabled(w)) return PIOLA_OK;
  /* the waits change only as an interval opens: its start is what processing takes to be
   * free of intersections */
  if (!w->contact || !w->contact->open) PIOLA_TRY(update_waits(w, 0));
  if (!any_self_collision(w)) return PIOLA_OK;
  PIOLA_TRY(ensure_built(w));
  world_contact *c = w->contact;
  if (!c->open) {
    for (int32_t i = 0; i < w->body_count; ++i) {
      if (c->offset[i] < 0) continue;
      const world_body *s = &w->bodies[i];
      memcpy(c->x0 + 3 * (size_t)c->offset[i], s->x, sizeof(double) * 3 * (size_t)s->n);
    }
    c->t_start = w->time;
    c->open = 1;
  }
  *left = c->t_start + w->def.collision_interval - w->time;
  /* advance_to's target ends the interval when it comes first, or only a rounding error
   * after the interval's end (an interval that divides the frame time): then the interval
   * ends on the target, not on a step a rounding error before it, which would leave a sliver
   * of an interval to the target */
  const double to_deadline = w->collision_deadline - w->time; /* NAN outside advance_to */
  if (to_deadline <= *left + 1e-6 * w->def.collision_interval) *left = to_deadline;
  return PIOLA_OK;
}

piola_status piola__world_self_collide(piola_world *w, double dt, double t1, int closes,
                                       piola_step_stats *stats) {
  const int32_t count = w->body_count;
  const int per_step = !(w->def.collision_interval > 0);
  if (!any_enabled(w)) return PIOLA_OK;
  if (per_step) PIOLA_TRY(update_waits(w, 1));
  if (!any_self_collision(w)) return PIOLA_OK;
  if (!per_step && (!closes || !w->contact || !w->contact->open)) return PIOLA_OK;
  PIOLA_TRY(ensure_built(w));
  world_contact *c = w->contact;
  if (!per_step) dt = t1 - c->t_start; /* the collision step: the whole interval */
  for (int32_t i = 0; i < count; ++i) {
    if (c->offset[i] < 0) continue;
    const world_body *s = &w->bodies[i];
    for (int32_t k = 0; k < s->n; ++k) {
      const int32_t g = c->offset[i] + k;
      if (per_step)
        for (int d = 0; d < 3; ++d) c->x0[3 * g + d] = s->x_old[3 * k + d];
      for (int d = 0; d < 3; ++d) c->v[3 * g + d] = (s->x[3 * k + d] - c->x0[3 * g + d]) / dt;
      c->mass[g] = s->flags[k] != NODE_FREE || s->inverse_mass[k] == 0.0 ? INFINITY : s->mass[k];
    }
  }
  memcpy(c->v_before, c->v, sizeof(double) * 3 * (size_t)c->vertex_count);
  piola_collision_stats cs;
  PIOLA_TRY(piola_collision_surface_process(c->surface, c->x0, c->v, c->mass, dt, NULL, &cs));
  stats->contacts += cs.contacts;
  stats->impacts += cs.impacts;
  stats->impact_zones += cs.impact_zones;
  stats->collision_steps += 1;
  for (int32_t i = 0; i < count; ++i) {
    if (c->offset[i] < 0) continue;
    world_body *s = &w->bodies[i];
    int changed = 0;
    for (int32_t k = 0; k < 3 * s->n; ++k) {
      const int32_t g = 3 * c->offset[i] + k;
      const double dv = c->v[g] - c->v_before[g];
      if (dv == 0.0) continue;
      changed = 1;
      s->x[k] = c->x0[g] + dt * c->v[g];
      s->v[k] += dv;
    }
    if (changed) PIOLA_TRY(piola__body_update_forces(s, t1));
  }
  c->open = 0;
  return PIOLA_OK;
}
