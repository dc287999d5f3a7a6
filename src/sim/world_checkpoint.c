/* Checkpoints (piola/checkpoint.h): the world's state as a flat, checksummed byte stream.
 *
 * Layout (docs/file-formats.md): a 48-byte header (magic, format version, byte-order mark,
 * scene key, frame, payload length, body counts), the payload, and an FNV-1a 64 checksum
 * of everything before it. The payload is a sequence of arrays, each a u64 element count
 * then the elements, in a fixed order per body of the world's body table (its order: by
 * kind, then as added), each by its kind's own function (a switch on the kind, so a new kind
 * without checkpoint code does not compile, -Wswitch), then the self-collision state (the
 * collision trees as contact/surface_history.h writes them). Reading runs the payload twice:
 * a dry pass that checks every count against the world, then the pass that stores, so a
 * mismatched file changes nothing.
 *
 * Why raw per-element state instead of recomputing it from the positions: the force of the
 * last update was computed before the plastic update changed Dm^-1 Fp^-1 (the plastic lag
 * is one step, world_plasticity.c), and the damping operator assembled then is reused by
 * the next step, so a recomputation would not reproduce their bits. What is saved is what
 * the next step reads; scratch arrays are not. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "contact/surface_history.h"
#include "force/elastic_body_internal.h"
#include "piola/files.h"
#include "piola/checkpoint.h"
#include "plasticity/plastic_state.h"
#include "shell/shell_body_internal.h"
#include "sim/fracture_internal.h"
#include "common/fnv1a.h"
#include "sim/fracture_restore.h"
#include "sim/world_internal.h"

enum { HEADER_BYTES = 48 };
static const char magic[8] = {'P', 'I', 'O', 'L', 'A', 'C', 'K', 'P'};
static const uint32_t byte_order_mark = 0x01020304u;

int piola_world_checkpoint_supported(const piola_world *w, const char **why) {
  (void)w; /* every part of a world is covered */
  if (why) *why = NULL;
  return 1;
}

uint64_t piola_world_scene_key(const piola_world *w, const void *scene, size_t length) {
  uint64_t h = PIOLA_FNV_OFFSET;
  if (scene) h = piola__fnv1a(h, scene, length);
  for (int32_t i = 0; w && i < w->body_count; ++i) {
    const world_body *b = &w->bodies[i];
    int32_t kind = (int32_t)b->kind;
    h = piola__fnv1a(h, &kind, sizeof kind);
    switch (b->kind) {
      case PIOLA_BODY_SOLID: {
        const piola_elastic_body *e = b->solid;
        h = piola__fnv1a(h, e->rest_positions, 3 * (size_t)e->vertex_count * sizeof(double));
        h = piola__fnv1a(h, e->tets, 4 * (size_t)e->tet_count * sizeof(int32_t));
        h = piola__fnv1a(h, e->masses, (size_t)e->vertex_count * sizeof(double));
        break;
      }
      case PIOLA_BODY_SHELL: {
        const piola_shell_body *sh = b->shell;
        h = piola__fnv1a(h, sh->rest_positions, 3 * (size_t)sh->vertex_count * sizeof(double));
        h = piola__fnv1a(h, sh->triangle_indices, 3 * (size_t)sh->triangle_count * sizeof(int32_t));
        h = piola__fnv1a(h, sh->masses, (size_t)sh->vertex_count * sizeof(double));
        break;
      }
      case PIOLA_BODY_NONE:
        break;
    }
  }
  int32_t counts[2] = {w ? w->body_count : 0, w ? w->obstacle_count : 0};
  return piola__fnv1a(h, counts, sizeof counts);
}

/* ------------------------------------------------------------------ the byte stream */

/* Writing appends to data; reading (data fixed) advances pos and, when store is 0, only
 * checks. failed is set on a count mismatch, a short payload or out of memory. */
typedef struct stream {
  unsigned char *data;
  size_t length, capacity, pos;
  int reading, store, failed;
  uint32_t version; /* the format read (reading; writing writes the newest) */
  char what[160]; /* the first mismatch, for the message */
} stream;

static void put(stream *s, const void *p, size_t n) {
  if (s->failed) return;
  if (s->length + n > s->capacity) {
    size_t cap = s->capacity ? s->capacity : 1 << 16;
    while (cap < s->length + n) cap *= 2;
    unsigned char *grown = realloc(s->data, cap);
    if (!grown) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "out of memory");
      return;
    }
    s->data = grown;
    s->capacity = cap;
  }
  memcpy(s->data + s->length, p, n);
  s->length += n;
}

static int take(stream *s, void *p, size_t n, const char *what) {
  if (s->failed) return 0;
  if (s->length - s->pos < n) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "%s: the payload ends early", what);
    return 0;
  }
  if (s->store && p) memcpy(p, s->data + s->pos, n);
  s->pos += n;
  return 1;
}

/* An array's element count: written, or read and checked against count (1 when it fits). */
static int count_of(stream *s, uint64_t count, const char *what) {
  if (!s->reading) {
    put(s, &count, sizeof count);
    return !s->failed;
  }
  uint64_t stored;
  int store = s->store;
  s->store = 1; /* the count is always read */
  int ok = take(s, &stored, sizeof stored, what);
  s->store = store;
  if (!ok) return 0;
  if (stored != count) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "%s: %llu values, this scene has %llu", what,
             (unsigned long long)stored, (unsigned long long)count);
    return 0;
  }
  return 1;
}

/* One array of count elements of size bytes: its count, then the bytes. */
static void field(stream *s, void *p, uint64_t count, size_t size, const char *what) {
  if (!count_of(s, count, what) || !count) return;
  if (s->reading) take(s, p, (size_t)count * size, what);
  else put(s, p, (size_t)count * size);
}

static void doubles(stream *s, double *p, uint64_t n, const char *what) {
  field(s, p, n, sizeof(double), what);
}
static void one_double(stream *s, double *p, const char *what) {
  field(s, p, 1, sizeof(double), what);
}
static void one_int(stream *s, int32_t *p, const char *what) {
  field(s, p, 1, sizeof(int32_t), what);
}

/* Values the reader needs on both passes (flags that decide later counts): stored into the
 * caller's locals even on the dry pass. */
static void local_doubles(stream *s, double *p, uint64_t n, const char *what) {
  int store = s->store;
  s->store = 1;
  doubles(s, p, n, what);
  s->store = store;
}
static void local_int(stream *s, int32_t *p, const char *what) {
  int store = s->store;
  s->store = 1;
  one_int(s, p, what);
  s->store = store;
}

/* ------------------------------------------------------------------ per body */

/* An array the reader needs on both passes, into memory of its own (*p, allocated when
 * reading; the caller frees it). */
static void local_array(stream *s, void **p, uint64_t count, size_t size, const char *what) {
  if (s->reading) {
    if (s->failed) return;
    if (!(*p = malloc((size_t)(count > 0 ? count : 1) * size))) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "out of memory");
      return;
    }
  }
  int store = s->store;
  s->store = 1;
  field(s, *p, count, size, what);
  s->store = store;
}

/* A cut solid's cut state (sim/fracture_internal.h), before its positions: the node and
 * element counts of everything after it depend on it. On reading, the solid is given that
 * state on the dry pass already (fracture_restore.c), so the dry pass can check the rest
 * against it; the counters of scripted cuts are stored on the second pass. */
static void fracture_state(stream *s, piola_world *w, world_body *b) {
  solid_fracture *f = b->fracture;
  int32_t present = f != NULL;
  local_int(s, &present, "fracture");
  if (s->failed) return;
  if (present != (f != NULL)) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "solid '%s': fracture differs from this scene", b->name);
    return;
  }
  if (!f) return;
  int32_t counts[6] = {f->copy_count, b->n, f->events, f->fragment_count, f->next_cut, f->cut_tets};
  {
    int store = s->store;
    s->store = 1; /* the counts decide what follows: read on both passes */
    field(s, counts, 6, sizeof(int32_t), "fracture counts");
    s->store = store;
  }
  if (s->failed) return;
  const int32_t nc = counts[0];
  /* format 4 cut a tet once: 2 copies per tet, no further cuts */
  const int old_format = s->reading && s->version == 4;
  const int32_t per_tet = old_format ? 2 : FRACTURE_MAX_COPIES, more = FRACTURE_MAX_CUTS - 1;
  if (s->reading && (nc < f->tet_count || nc > per_tet * f->tet_count || counts[1] < 1 ||
                     counts[1] > 4 * nc || /* every node is a corner of a copy */
                     counts[4] < 0 || counts[4] > f->cut_count || counts[5] < 0 ||
                     counts[5] > f->tet_count)) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "solid '%s': fracture counts do not fit its mesh", b->name);
    return;
  }
  void *parent = f->parent, *event = f->event, *fragment = f->fragment, *copies = f->copies;
  void *tets = (void *)piola_elastic_body_tets(b->solid), *side = f->side, *dist = f->dist;
  void *fraction = f->fraction, *more_event = f->more_event, *more_side = f->more_side;
  void *more_dist = f->more_dist;
  if (s->reading) parent = event = fragment = copies = tets = side = dist = fraction = NULL;
  if (s->reading) more_event = more_side = more_dist = NULL;
  local_array(s, &parent, (uint64_t)nc, sizeof(int32_t), "copy tets");
  local_array(s, &event, (uint64_t)nc, sizeof(int32_t), "copy cuts");
  local_array(s, &side, (uint64_t)nc, 1, "copy sides");
  local_array(s, &dist, 4 * (uint64_t)nc, sizeof(double), "copy distances");
  local_array(s, &fraction, (uint64_t)nc, sizeof(double), "material fractions");
  local_array(s, &fragment, (uint64_t)nc, sizeof(int32_t), "fragments");
  local_array(s, &tets, 4 * (uint64_t)nc, sizeof(int32_t), "copy nodes");
  local_array(s, &copies, (uint64_t)per_tet * (uint64_t)f->tet_count, sizeof(int32_t), "copies of tets");
  if (!old_format) {
    local_array(s, &more_event, (uint64_t)more * (uint64_t)nc, sizeof(int32_t), "copy further cuts");
    local_array(s, &more_side, (uint64_t)more * (uint64_t)nc, 1, "copy further sides");
    local_array(s, &more_dist, 4 * (uint64_t)more * (uint64_t)nc, sizeof(double), "copy further distances");
  } else if (!s->failed) {
    /* a format-4 state in this format's layout: copies padded to FRACTURE_MAX_COPIES per
     * tet, no further cuts */
    int32_t *wide = malloc(FRACTURE_MAX_COPIES * sizeof(int32_t) * (size_t)(f->tet_count > 0 ? f->tet_count : 1));
    more_event = malloc(sizeof(int32_t) * (size_t)(more * nc > 0 ? more * nc : 1));
    more_side = calloc((size_t)(more * nc > 0 ? more * nc : 1), 1);
    more_dist = calloc((size_t)(4 * more * nc > 0 ? 4 * more * nc : 1), sizeof(double));
    if (!wide || !more_event || !more_side || !more_dist) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "out of memory");
    } else {
      for (int32_t t = 0; t < f->tet_count; ++t)
        for (int j = 0; j < FRACTURE_MAX_COPIES; ++j)
          wide[FRACTURE_MAX_COPIES * t + j] = j < 2 ? ((int32_t *)copies)[2 * t + j] : -1;
      for (int32_t i = 0; i < more * nc; ++i) ((int32_t *)more_event)[i] = -1;
    }
    free(copies);
    copies = wide;
  }
  /* the criterion's state: the plastic strain per copy at its last pass (plastic_strain
   * criterion, once it ran), the crack all its cracks share, and per original vertex the
   * crack that reached it first, that crack's value there and when it got there */
  int32_t has_last = f->last_strain != NULL;
  local_int(s, &has_last, "criterion strains present");
  void *last = s->reading ? NULL : f->last_strain;
  if (!s->failed && has_last) local_array(s, &last, (uint64_t)nc, sizeof(double), "criterion strains");
  one_int(s, &f->grown_crack, "grown crack");
  field(s, f->vertex_crack, (uint64_t)f->vertex_count, sizeof(int32_t), "cracks at vertices");
  doubles(s, f->vertex_value, (uint64_t)f->vertex_count, "crack values at vertices");
  doubles(s, f->vertex_time, (uint64_t)f->vertex_count, "crack times at vertices");
  /* per scripted cut, a moving blade's crack and the time of its last cut (fracture_blade.c) */
  field(s, f->sweep_crack, (uint64_t)f->cut_count, sizeof(int32_t), "moving blades' cracks");
  doubles(s, f->swept_to, (uint64_t)f->cut_count, "moving blades' last cut times");
  if (s->reading) {
    if (!s->failed) {
      fracture_saved saved = {.copy_count = nc, .node_count = counts[1], .events = counts[2],
                              .fragment_count = counts[3], .parent = parent, .event = event,
                              .fragment = fragment, .tets = tets, .copies = copies, .side = side,
                              .dist = dist, .fraction = fraction, .more_event = more_event,
                              .more_side = more_side, .more_dist = more_dist};
      if (piola__fracture_restore(w, b, &saved) != PIOLA_OK) {
        s->failed = 1;
        snprintf(s->what, sizeof s->what, "%s", piola_last_error());
      } else if (s->store) {
        f = b->fracture;
        f->events = counts[2], f->next_cut = counts[4], f->cut_tets = counts[5];
        free(f->last_strain);
        f->last_strain = has_last ? last : NULL;
        last = NULL;
      }
    }
    free(last);
    free(parent), free(event), free(fragment), free(copies), free(tets), free(side), free(dist);
    free(fraction), free(more_event), free(more_side), free(more_dist);
  }
}


/* A per-tet array of a body split in the local mode (piola/work_split.h): the runs of `run`
 * doubles of the blocks this process holds (held[b]), its own and ghost blocks, the only
 * ones it computes and reads; the other blocks' memory is never touched. */
static void held_doubles(stream *s, const uint8_t *held, double *base, uint64_t blocks,
                         uint64_t run, const char *what) {
  uint64_t count = 0;
  for (uint64_t b = 0; b < blocks; ++b) count += held[b] ? run : 0;
  if (!count_of(s, count, what)) return;
  for (uint64_t b = 0; b < blocks && !s->failed; ++b) {
    if (!held[b]) continue;
    if (s->reading) take(s, base + b * run, (size_t)run * sizeof(double), what);
    else put(s, base + b * run, (size_t)run * sizeof(double));
  }
}

/* The step bound's weights (stable_step.c), built once from the Dm^-1 the body has at its
 * first step bound: for a plastic solid a cut rebuilt, the effective Dm^-1 of then, which
 * the rest of the state does not give back. Only solids with fracture and plasticity have
 * them in the file (format 6; older files leave them to be built on the next step bound),
 * after the plastic state, so that a file whose plasticity differs is refused for that. */
static void step_weights(stream *s, world_body *b) {
  piola_elastic_body *e = b->solid;
  if (!b->fracture || !b->plastic) return;
  int32_t present = e->step_weight != NULL;
  local_int(s, &present, "step weights present");
  if (s->failed || !present) return;
  const uint64_t nt = (uint64_t)e->tet_count;
  double *w = e->step_weight, *g = e->step_gram;
  if (s->reading && s->store) { /* into memory of their own, swapped in once read */
    w = malloc((size_t)(nt > 0 ? nt : 1) * sizeof(double));
    g = malloc(6 * (size_t)(nt > 0 ? nt : 1) * sizeof(double));
    if (!w || !g) {
      free(w), free(g);
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "out of memory");
      return;
    }
  }
  doubles(s, w, nt, "step weights");
  doubles(s, g, 6 * nt, "step direction weights");
  if (s->reading && s->store) {
    if (s->failed) {
      free(w), free(g);
      return;
    }
    free(e->step_weight), free(e->step_gram);
    e->step_weight = w, e->step_gram = g;
  }
}

static void elastic_state(stream *s, world_body *b) {
  piola_elastic_body *e = b->solid;
  const uint64_t np = (uint64_t)e->padded_tet_count, n3 = 3 * (uint64_t)b->n;
  doubles(s, b->force, n3, "elastic force");
  const uint8_t *held = piola__local_split(e) ? e->split_held : NULL;
  const uint64_t blocks = np / PIOLA_WORK_SPLIT_BLOCK, B = PIOLA_WORK_SPLIT_BLOCK;
  if (held) { /* a process of a split run (docs/mpi.md, "Checkpoints") */
    for (int k = 0; k < 9; ++k) held_doubles(s, held, e->u[0] + (uint64_t)k * np, blocks, B, "U");
    for (int k = 0; k < 9; ++k) held_doubles(s, held, e->v[0] + (uint64_t)k * np, blocks, B, "V");
    held_doubles(s, held, e->fhat, blocks, 3 * B, "Fhat");
    held_doubles(s, held, e->det_f, blocks, B, "det F");
  } else {
    doubles(s, e->u[0], 9 * np, "U");
    doubles(s, e->v[0], 9 * np, "V");
    doubles(s, e->fhat, 3 * np, "Fhat");
    doubles(s, e->det_f, np, "det F");
  }
  doubles(s, e->positions, 3 * (uint64_t)e->vertex_count, "update positions");
  for (int k = 0; k < 9; ++k)
    if (held) held_doubles(s, held, e->dm_inv[k], blocks, B, "effective Dm^-1");
    else doubles(s, e->dm_inv[k], np, "effective Dm^-1");
  one_double(s, &e->activation, "activation");
  one_double(s, &e->last_stiffness_scale, "stiffness scale");
  one_double(s, &b->quasistatic_mu, "quasistatic regularization");
  int32_t has_state = e->has_state;
  local_int(s, &has_state, "has_state");
  /* the damping operator the next step starts from: its viscosities and blocks, and
   * whether the last solve's product (taken with it) is current */
  piola__damping_matrix *m = &e->damping;
  int32_t ready = m->ready && m->blocks;
  local_int(s, &ready, "damping ready");
  double visc[2] = {m->shear_viscosity, m->bulk_viscosity};
  local_doubles(s, visc, 2, "damping viscosities");
  const uint64_t edge_values = ready ? 9 * (uint64_t)m->edge_count : 0;
  double *saved = NULL;
  if (s->reading && s->store && edge_values && !(saved = malloc((size_t)edge_values * sizeof(double)))) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "out of memory");
    return;
  }
  doubles(s, s->reading ? saved : m->blocks, edge_values, "damping blocks");
  int32_t product = b->product_valid && ready && b->product_generation == m->generation;
  local_int(s, &product, "product valid");
  one_double(s, &b->product_h, "product h");
  doubles(s, b->av_product, product ? n3 : 0, "product A v");
  doubles(s, b->v_product, product ? n3 : 0, "product v");
  if (s->reading && s->store && !s->failed) {
    e->has_state = has_state;
    e->energy_valid = 0; /* recomputed from Fhat when asked */
    b->elastic_stale = 1;
    b->state_rate_valid = 0; /* the step bound: recomputed from the restored Fhat */
    m->ready = 0;
    if (ready) {
      /* allocate and assemble (the structure), then put back the saved blocks */
      piola__elastic_body_damping_prepare(e, visc[0], visc[1]);
      memcpy(m->blocks, saved, (size_t)edge_values * sizeof(double));
    }
    b->product_valid = product;
    if (product) b->product_generation = m->generation;
  }
  free(saved);
}

static void plastic_state(stream *s, world_body *b) {
  piola_plastic_state *p = b->plastic;
  int32_t present = p != NULL;
  local_int(s, &present, "plasticity");
  if (s->failed || !present || !p) {
    if (s->reading && !s->failed && present != (p != NULL)) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "solid '%s': plasticity differs from this scene", b->name);
    }
    return;
  }
  const uint64_t np = (uint64_t)p->padded_count;
  doubles(s, p->fp_inv, 9 * np, "Fp^-1");
  doubles(s, p->alpha, np, "plastic strain");
  doubles(s, p->stretch_bound, np, "stretch bound");
  doubles(s, p->block_bound, np / PIOLA_PLASTIC_LANES, "block bound");
  one_int(s, &p->refresh_phase, "refresh phase");
  doubles(s, p->log_fp, p->controlled ? 6 * (uint64_t)p->tet_count : 0, "log Fp");
  field(s, &b->plastic_stats, 1, sizeof b->plastic_stats, "plastic stats");
}

static void shell_state(stream *s, world_body *b) {
  piola_shell_body *sh = b->shell;
  const uint64_t nt = (uint64_t)sh->triangle_count, nh = (uint64_t)sh->hinge_count;
  doubles(s, b->force, 3 * (uint64_t)b->n, "shell force");
  for (uint64_t t = 0; t < nt; ++t) {
    shell_triangle *tri = &sh->triangles[t];
    doubles(s, tri->fp_inv, 4, "triangle Fp^-1");
    doubles(s, tri->dm_inv_eff, 4, "triangle Dm^-1 Fp^-1");
    doubles(s, tri->u, 6, "triangle U");
    doubles(s, tri->vrot, 4, "triangle V");
    doubles(s, tri->fhat, 2, "triangle Fhat");
    one_double(s, &tri->energy_density, "triangle energy density");
  }
  for (uint64_t h = 0; h < nh; ++h) {
    one_double(s, &sh->hinges[h].angle, "hinge angle");
    one_double(s, &sh->hinges[h].rest_angle, "hinge rest angle"); /* bending plasticity moves it */
    doubles(s, sh->hinges[h].grad, 12, "hinge gradient");
  }
  doubles(s, sh->triangle_forces, 9 * nt, "triangle forces");
  doubles(s, sh->hinge_forces, sh->hinge_forces ? 12 * nh : 0, "hinge forces");
  doubles(s, sh->angles, sh->angles ? nh : 0, "angles");
  doubles(s, sh->rest_angles, sh->rest_angles ? nh : 0, "rest angles");
  doubles(s, sh->fhat, 2 * nt, "shell Fhat");
  doubles(s, sh->fp_inv, 4 * nt, "shell Fp^-1");
  one_double(s, &sh->last_stiffness_scale, "shell stiffness scale");
  one_double(s, &b->quasistatic_mu, "shell quasistatic regularization");
  field(s, &b->shell_stats, 1, sizeof b->shell_stats, "shell stats");
  if (s->reading && s->store && !s->failed) b->state_rate_valid = 0; /* from the restored state */
}

/* A byte string of variable length: its length, then the bytes. Reading hands out where
 * they are in the file (*at, *n) instead of copying them. */
static void bytes_field(stream *s, unsigned char *p, uint64_t n, const unsigned char **at,
                        uint64_t *length, const char *what) {
  if (!s->reading) {
    put(s, &n, sizeof n);
    if (n) put(s, p, (size_t)n);
    return;
  }
  int store = s->store;
  s->store = 1; /* the length is always read */
  int ok = take(s, length, sizeof *length, what);
  s->store = store;
  if (!ok) return;
  if (*length > s->length - s->pos) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "%s: the payload ends early", what);
    return;
  }
  *at = s->data + s->pos;
  s->pos += (size_t)*length;
}

/* Self-collision: whether the collision surface is built (with its history), and the open
 * collision interval. On reading, the surface is built first (on the dry pass as well: a
 * surface built anew is what the next step would build, so nothing the world does changes). */
static void contact_state(stream *s, piola_world *w) {
  piola__contact_state c = piola__world_contact_state(w);
  int32_t built = c.built;
  local_int(s, &built, "contact surface built");
  if (s->failed) return;
  if (s->reading && (built || s->store)) {
    piola_status st = piola__world_contact_prepare(w, built);
    if (st != PIOLA_OK) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "contact: %s", piola_last_error());
      return;
    }
    c = piola__world_contact_state(w);
  }
  if (!built) return;
  int32_t open = *c.open;
  local_int(s, &open, "collision interval open");
  double t_start = *c.t_start;
  local_doubles(s, &t_start, 1, "collision interval start");
  doubles(s, c.x0, open ? 3 * (uint64_t)c.vertex_count : 0, "collision interval positions");
  unsigned char *history = NULL;
  uint64_t length = 0;
  const unsigned char *at = NULL;
  if (!s->reading) {
    length = piola__collision_surface_history_size(c.surface);
    if (!(history = malloc((size_t)length))) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "out of memory");
      return;
    }
    piola__collision_surface_history_save(c.surface, history);
  }
  bytes_field(s, history, length, &at, &length, "collision trees");
  free(history);
  if (!s->reading || s->failed) return;
  int loaded = piola__collision_surface_history_load(c.surface, at, (size_t)length, s->store);
  if (loaded != 0) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "%s",
             loaded == -2 ? "out of memory" : "collision trees do not fit this scene");
    return;
  }
  if (s->store) *c.open = open, *c.t_start = t_start;
}

/* The recent steps' bounds (format 7 on; an older file starts with none, as a new run). */
static void recent_bounds(stream *s, piola_world *w) {
  if (s->reading && s->version < 7) {
    if (s->store) w->recent_bound_count = 0, w->recent_bound_next = 0;
    return;
  }
  int32_t count = w->recent_bound_count, next = w->recent_bound_next;
  local_int(s, &count, "recent step bounds");
  local_int(s, &next, "next step bound");
  if (!s->failed && (count < 0 || count > STEP_BOUND_WINDOW || next < 0 || next >= STEP_BOUND_WINDOW)) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "recent step bounds: %d, next %d (at most %d)", (int)count,
             (int)next, STEP_BOUND_WINDOW);
    return;
  }
  doubles(s, w->recent_bounds, STEP_BOUND_WINDOW, "recent step bound values");
  if (s->store && !s->failed) w->recent_bound_count = count, w->recent_bound_next = next;
}

/* A flag of the body's (0 or 1; anything else fails the stream, naming WHAT): 1 when read
 * and to be stored. */
static int local_flag(stream *s, int32_t *flag, const char *what) {
  local_int(s, flag, what);
  if (s->failed) return 0;
  if (*flag != 0 && *flag != 1) {
    s->failed = 1;
    snprintf(s->what, sizeof s->what, "%s: %d (0 or 1)", what, (int)*flag);
    return 0;
  }
  return s->store;
}

/* Whether a solid with self-collision waits for it to untangle (format 8 on; an older
 * file's solids take part, as they did then). */
static void collision_waits(stream *s, piola_world *w, world_body *b) {
  if (!b->self_collision.enabled) return;
  int32_t waits = b->collision_waits;
  if (local_flag(s, &waits, "self-collision waits")) piola__world_set_collision_waits(w, b, waits);
}

/* Whether a backward Euler solid's last step kept its start's positions (format 9 on; an
 * older file's solids did not, as none was told then). */
static void kept_start(stream *s, piola_world *w, world_body *b) {
  if (w->def.integrator != PIOLA_INTEGRATOR_BACKWARD_EULER) return;
  int32_t kept = b->kept_start;
  if (local_flag(s, &kept, "backward Euler kept start")) b->kept_start = kept;
}

static void world_state(stream *s, piola_world *w) {
  one_double(s, &w->time, "time");
  recent_bounds(s, w);
  for (int32_t i = 0; i < w->body_count && !s->failed; ++i) {
    world_body *b = &w->bodies[i];
    int32_t kind = (int32_t)b->kind;
    local_int(s, &kind, "body kind");
    if (!s->failed && kind != (int32_t)b->kind) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "body %d is a %s in this scene", (int)i,
               piola__body_kind_name(b->kind));
      return;
    }
    if (b->kind == PIOLA_BODY_SOLID) fracture_state(s, w, b);
    if (s->failed) return;
    doubles(s, b->x, 3 * (uint64_t)b->n, "positions");
    doubles(s, b->v, 3 * (uint64_t)b->n, "velocities");
    switch (b->kind) {
      case PIOLA_BODY_SOLID:
        elastic_state(s, b);
        plastic_state(s, b);
        if (!s->reading || s->version >= 6) step_weights(s, b);
        if (!s->reading || s->version >= 8) collision_waits(s, w, b);
        if (!s->reading || s->version >= 9) kept_start(s, w, b);
        /* the step bound's cache from the restored Fhat and weights, with the force loop's
         * bits (stable_step_modulus.h; none without a state) */
        if (s->reading && s->store && !s->failed) piola__elastic_body_refill_step_cache(b->solid);
        break;
      case PIOLA_BODY_SHELL:
        shell_state(s, b);
        break;
      case PIOLA_BODY_NONE:
        break;
    }
  }
  if (!s->failed) contact_state(s, w);
}

/* ------------------------------------------------------------------ files */

/* Header word 44: 0 for a single process's checkpoint; for a process of a split run
 * (docs/mpi.md) its process count << 16 | its process, from the first split solid (or one
 * whose split waits for its replan: work_split.h). */
static uint32_t split_tag(const piola_world *w) {
  for (int32_t i = 0; i < w->body_count; ++i) {
    const world_body *b = &w->bodies[i];
    if (b->kind == PIOLA_BODY_SOLID && b->split_pending) return b->split_pending;
    if (b->kind != PIOLA_BODY_SOLID || !b->solid->split || b->solid->split->part_count < 2) continue;
    return (uint32_t)b->solid->split->part_count << 16 | (uint32_t)b->solid->split->part;
  }
  return 0;
}

static void put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint32_t get_u32(const unsigned char *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}
static uint64_t get_u64(const unsigned char *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

piola_status piola_world_checkpoint_write(const piola_world *world, const char *path,
                                          uint64_t scene_key, int32_t frame) {
  if (!world || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "checkpoint: NULL argument");
  if (frame < 0) /* the header stores it unsigned, and read gives back an int32_t */
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: checkpoint frame must be >= 0, got %d",
                      path, (int)frame);
  const char *why;
  if (!piola_world_checkpoint_supported(world, &why))
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: %s", path, why);
  stream s = {0};
  unsigned char header[HEADER_BYTES] = {0};
  put(&s, header, sizeof header);
  world_state(&s, (piola_world *)world); /* writing only reads the world */
  if (s.failed) {
    free(s.data);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: %s", path, s.what);
  }
  unsigned char *h = s.data;
  memcpy(h, magic, 8);
  put_u32(h + 8, PIOLA_CHECKPOINT_VERSION);
  put_u32(h + 12, byte_order_mark);
  put_u64(h + 16, scene_key);
  put_u32(h + 24, (uint32_t)frame);
  put_u32(h + 28, (uint32_t)(world->body_count));
  put_u64(h + 32, (uint64_t)(s.length - HEADER_BYTES));
  put_u32(h + 40, (uint32_t)(world->obstacle_count));
  put_u32(h + 44, split_tag(world));
  uint64_t sum = piola__fnv1a(PIOLA_FNV_OFFSET, s.data, s.length);
  put(&s, &sum, sizeof sum);
  if (s.failed) {
    free(s.data);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  piola_atomic_file f;
  piola_status st = piola_atomic_file_open(&f, path);
  if (st == PIOLA_OK) {
    if (fwrite(s.data, 1, s.length, f.stream) != s.length) {
      piola_atomic_file_abort(&f);
      st = PIOLA_FAIL(PIOLA_ERROR_IO, "%s: write failed", path);
    } else {
      st = piola_atomic_file_commit(&f);
    }
  }
  free(s.data);
  return st;
}

/* Format 4 (tets cut once) differs from 5 only in the cut state (fracture_state), 5 from 6
 * only in the step weights of cut plastic solids (step_weights). */
#define OLDEST_READ_VERSION 4

static int has_fracture(const piola_world *w) {
  for (int32_t i = 0; i < w->body_count; ++i)
    if (w->bodies[i].fracture) return 1;
  return 0;
}

/* Reads a whole payload (after its header) into world: a checking pass, then the storing
 * one. Returns 1 when it fitted. */
static int read_state(stream *s, piola_world *world) {
  s->reading = 1;
  for (int pass = 0; pass < 2 && !s->failed; ++pass) {
    s->pos = HEADER_BYTES;
    s->store = pass;
    world_state(s, world);
    if (!s->failed && s->pos != s->length) {
      s->failed = 1;
      snprintf(s->what, sizeof s->what, "%zu bytes left over", s->length - s->pos);
    }
  }
  return !s->failed;
}

static piola_status read_file(const char *path, stream *s) {
  FILE *f = fopen(path, "rb");
  if (!f) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open", path);
  unsigned char buf[1 << 16];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) put(s, buf, n);
  int bad = ferror(f);
  fclose(f);
  if (bad) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: read error", path);
  if (s->failed) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  return PIOLA_OK;
}

piola_status piola_world_checkpoint_read(piola_world *world, const char *path, uint64_t scene_key,
                                         int32_t *frame) {
  if (!world || !path)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "checkpoint: NULL world or path");
  stream s = {0};
  piola_status st = read_file(path, &s);
  if (st != PIOLA_OK) {
    free(s.data);
    return st;
  }
  const unsigned char *h = s.data;
  if (s.length < HEADER_BYTES + 8 || memcmp(h, magic, 8) != 0)
    st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: not a piola checkpoint", path);
  else if (get_u32(h + 8) > PIOLA_CHECKPOINT_VERSION || get_u32(h + 8) < OLDEST_READ_VERSION)
    st = PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                    "%s: checkpoint format version %u, this piola reads versions %d to %d only", path,
                    (unsigned)get_u32(h + 8), OLDEST_READ_VERSION, PIOLA_CHECKPOINT_VERSION);
  else if (get_u32(h + 12) != byte_order_mark)
    st =
        PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: written on a machine of another byte order", path);
  else if (get_u64(h + 32) != s.length - HEADER_BYTES - 8)
    st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: %zu bytes, the header says %llu (a truncated file)",
                    path, s.length, (unsigned long long)get_u64(h + 32) + HEADER_BYTES + 8);
  else if (piola__fnv1a(PIOLA_FNV_OFFSET, s.data, s.length - 8) != get_u64(s.data + s.length - 8))
    st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: checksum mismatch (a damaged file)", path);
  else if (get_u64(h + 16) != scene_key)
    st = PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                    "%s was written for another scene (its scene file or meshes differ: key "
                    "%016llx, this scene's %016llx)",
                    path, (unsigned long long)get_u64(h + 16), (unsigned long long)scene_key);
  else if (get_u32(h + 44) != split_tag(world))
    st = PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s was written by process %u of %u, this is process %u of %u "
                    "(1 of 1: a single process)", path, (unsigned)(get_u32(h + 44) & 0xffff) + 1,
                    get_u32(h + 44) ? (unsigned)(get_u32(h + 44) >> 16) : 1u,
                    (unsigned)(split_tag(world) & 0xffff) + 1,
                    split_tag(world) ? (unsigned)(split_tag(world) >> 16) : 1u);
  else if ((int32_t)get_u32(h + 28) != world->body_count ||
           (int32_t)get_u32(h + 40) != world->obstacle_count)
    st = PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: body or obstacle counts differ from this scene",
                    path);
  /* A cut solid takes the file's cut state on the checking pass (fracture_state): the world
   * as it is now is kept in memory first, and put back when the file turns out not to fit. */
  s.version = s.length >= HEADER_BYTES ? get_u32(h + 8) : 0;
  stream before = {.version = PIOLA_CHECKPOINT_VERSION};
  if (st == PIOLA_OK && has_fracture(world)) {
    unsigned char header[HEADER_BYTES] = {0};
    put(&before, header, sizeof header);
    world_state(&before, world);
    if (before.failed) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  if (st == PIOLA_OK) {
    s.length -= 8; /* the checksum */
    if (!read_state(&s, world)) {
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: does not fit this scene: %s", path, s.what);
      if (before.data && !read_state(&before, world)) /* it fits: it was written from world */
        st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: does not fit, and the world could not be put "
                        "back (%s)", path, before.what);
    } else {
      if (frame) *frame = (int32_t)get_u32(h + 24);
    }
  }
  free(before.data);
  free(s.data);
  return st;
}
