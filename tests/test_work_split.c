/* The elastic body's work split (piola/work_split.h), without MPI: two "processes" are two
 * bodies in this one process. Part 0's operations run part 1's update (or damping product)
 * when they need its share, and part 1's operations only record what it hands over, so the
 * exchanges happen in the order MPI would make them. Checked against the unsplit body:
 *  - a split into one part changes no bit of forces, per-tet state or damping forces;
 *  - split into two (contiguous halves, or alternating blocks that break the loop's block
 *    pairs), the per-tet state (det F, Fhat) and the damping forces are bit-identical, and
 *    the elastic forces equal the whole loop's to rounding (shared nodes add the parts'
 *    partial sums, in another order);
 *  - both for a small body (one serial pass) and for one large enough for the chunked loop;
 *  - in the local mode (part 0 holds its own blocks and the ghost blocks part 1 sends), its
 *    own tets' state and the damping forces of every node are the same bits (the ghosts
 *    matter: without them part 0's rows differ), and the body, once its split is taken off,
 *    refuses to step alone or to be split again; its stiffness rows (the Newton matrix's)
 *    are the same bits once its ghost blocks' Fhat is shared, and differ before; both
 *    parts, stepping their step bound together (two threads), get the whole body's largest
 *    rate and the tet that sets it;
 *  - splits with parts out of range or missing operations are refused;
 *  - a split planned before the solid is built (piola_world_set_work_split_planner) writes
 *    its own tets' state with the whole solid's bits and never the tets it does not hold;
 *  - a split solid that a cut rebuilds gets the replanner's split for its new mesh
 *    (piola_world_set_work_split_replanner), in the replicated mode, and steps with it;
 *  - while replans are deferred (piola_world_defer_work_split_replans, a checkpoint read's
 *    cut state) the rebuilt solid stays whole and pending, the replanner is not asked, and
 *    piola_world_solid_replan_work_split later gives it the replanner's split (pending or
 *    still split) with which it steps as the unsplit world does. */
#include "test_support.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "force/stiffness_matrix.h"
#include "piola/elastic_body.h"
#include "piola/work_split.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "test_elastic_body_fixtures.h"

typedef struct fake_part {
  piola_elastic_body *body;    /* this part's copy of the body */
  struct fake_part *other;     /* part 1, seen from part 0 */
  const double *x, *v;         /* the positions and velocities both parts use */
  double *other_values;        /* part 1's recorded node values (3 per node) */
  double *other_blocks;        /* part 1's recorded block buffer */
  int32_t node_count;
  int32_t block_count;
  int32_t *block_part, *node_part;
  piola_work_split split;
} fake_part;

/* part 1: record what would be sent */
static void record_nodes(void *context, double *values) {
  fake_part *p = context;
  memcpy(p->other_values, values, 3 * sizeof(double) * (size_t)p->node_count);
}
static void record_blocks(void *context, double *values, int32_t width) {
  fake_part *p = context;
  memcpy(p->other_blocks, values, sizeof(double) * (size_t)width * (size_t)p->block_count);
}

/* part 0: run part 1 to get its share */
static void sum_from_other(void *context, double *values) {
  fake_part *p = context;
  double *f1 = malloc(3 * sizeof(double) * (size_t)p->node_count);
  assert_int_equal(piola_elastic_body_update(p->other->body, p->x, 1.0, f1, NULL), PIOLA_OK);
  /* owner first, then the other part: the order the MPI halo sums in */
  for (int32_t i = 0; i < 3 * p->node_count; ++i) values[i] += p->other->other_values[i];
  free(f1);
}
static void share_from_other(void *context, double *values) {
  fake_part *p = context;
  double *d1 = malloc(3 * sizeof(double) * (size_t)p->node_count);
  piola_elastic_body_damping_forces(p->other->body, p->v, 0.7, 0.3, d1);
  for (int32_t i = 0; i < p->node_count; ++i)
    if (p->node_part[i] == 1)
      for (int c = 0; c < 3; ++c) values[3 * i + c] = p->other->other_values[3 * i + c];
  free(d1);
}
static void blocks_from_other(void *context, double *values, int32_t width) {
  fake_part *p = context;
  for (int32_t b = 0; b < p->block_count; ++b)
    if (p->block_part[b] == 1)
      memcpy(values + (size_t)b * (size_t)width, p->other->other_blocks + (size_t)b * (size_t)width,
             sizeof(double) * (size_t)width);
}

/* The local mode's ghost blocks: part 1's blocks with a tet on a node part 0 owns. */
static int ghost_of_part0(const fake_part *p, const int32_t *tv, int32_t tet_count, int32_t b) {
  if (p->block_part[b] != 1) return 0;
  for (int32_t t = b * PIOLA_WORK_SPLIT_BLOCK; t < (b + 1) * PIOLA_WORK_SPLIT_BLOCK && t < tet_count; ++t)
    for (int c = 0; c < 4; ++c)
      if (p->node_part[tv[4 * t + c]] == 0) return 1;
  return 0;
}
/* part 1: record what it would send to part 0 */
static void record_ghosts(void *context, void *owner, piola_work_split_pack pack,
                          piola_work_split_unpack unpack, int32_t width) {
  fake_part *p = context;
  (void)unpack;
  const int32_t *tv = piola_elastic_body_tets(owner); /* p->body may not be set yet */
  const int32_t nt = piola_elastic_body_tet_count(owner);
  for (int32_t b = 0; b < p->block_count; ++b)
    if (ghost_of_part0(p, tv, nt, b)) pack(owner, b, p->other_blocks + (size_t)b * (size_t)width);
}
/* part 0: its ghosts from part 1's record (part 1 ran inside sum_from_other) */
static void ghosts_from_other(void *context, void *owner, piola_work_split_pack pack,
                              piola_work_split_unpack unpack, int32_t width) {
  fake_part *p = context;
  (void)pack;
  const int32_t *tv = piola_elastic_body_tets(owner); /* p->body may not be set yet */
  const int32_t nt = piola_elastic_body_tet_count(owner);
  for (int32_t b = 0; b < p->block_count; ++b)
    if (ghost_of_part0(p, tv, nt, b))
      unpack(owner, b, p->other->other_blocks + (size_t)b * (size_t)width);
}
static void unused_reduce(void *context, double *values, int32_t count, piola_work_split_reduction op) {
  (void)context, (void)values, (void)count, (void)op;
  fail_msg("no reduction in a force update or a damping product");
}
static void unused_collect(void *context, void *owner, piola_work_split_pack pack,
                           piola_work_split_unpack unpack, int32_t width) {
  (void)context, (void)owner, (void)pack, (void)unpack, (void)width;
  fail_msg("no collect in a force update or a damping product");
}

static void noop_nodes(void *context, double *values) { (void)context, (void)values; }
static void noop_blocks(void *context, double *values, int32_t width) {
  (void)context, (void)values, (void)width;
}

/* The step bound in the local mode (stable_step.c): the two parts run in two threads whose
 * reduce is an all-gather behind a barrier, as MPI_Allgather makes it; each part must get
 * the whole body's largest rate and the tet that sets it (the first one near it), found by
 * the part that holds it while the other skips its search. */
typedef struct lockstep {
  pthread_barrier_t barrier;
  double slots[2][8];
} lockstep;
static lockstep *the_lockstep;

static void lockstep_reduce(void *context, double *values, int32_t count, piola_work_split_reduction op) {
  const fake_part *p = context;
  lockstep *l = the_lockstep;
  memcpy(l->slots[p->split.part], values, sizeof(double) * (size_t)count);
  pthread_barrier_wait(&l->barrier);
  for (int32_t i = 0; i < count; ++i) {
    const double a = l->slots[0][i], b = l->slots[1][i];
    values[i] = op == PIOLA_WORK_SPLIT_SUM ? a + b : op == PIOLA_WORK_SPLIT_MAX ? fmax(a, b) : fmin(a, b);
  }
  pthread_barrier_wait(&l->barrier); /* both have read the slots before the next call */
}

typedef struct rate_job {
  fake_part *part;
  double rate2;
  int32_t worst;
} rate_job;

static void *part_rate(void *arg) { /* no assertion here: cmocka's belong to the main thread */
  rate_job *j = arg;
  j->rate2 = piola__elastic_body_state_rate2(j->part->body, &j->worst);
  return NULL;
}

static void check_local_step_bound(piola_elastic_body *whole, fake_part *p0, fake_part *p1) {
  int32_t worst = -1;
  const double rate2 = piola__elastic_body_state_rate2(whole, &worst);
  assert_true(rate2 > 0 && worst >= 0);
  lockstep l;
  the_lockstep = &l;
  assert_int_equal(pthread_barrier_init(&l.barrier, NULL, 2), 0);
  p0->split.reduce = p1->split.reduce = lockstep_reduce;
  rate_job jobs[2] = {{p0, 0, -1}, {p1, 0, -1}};
  pthread_t thread;
  assert_int_equal(pthread_create(&thread, NULL, part_rate, &jobs[1]), 0);
  part_rate(&jobs[0]);
  assert_int_equal(pthread_join(thread, NULL), 0);
  pthread_barrier_destroy(&l.barrier);
  p0->split.reduce = p1->split.reduce = unused_reduce;
  for (int k = 0; k < 2; ++k) {
    assert_memory_equal(&jobs[k].rate2, &rate2, sizeof(double));
    assert_int_equal(jobs[k].worst, worst);
  }
}

/* The stiffness assembly in the local mode (the implicit integrators' Newton matrix): part
 * 0's rows, the rows of the nodes it owns, times a random field are the same bits as the
 * whole body's, once the ghost blocks' Fhat is shared (part 1 records what it sends, then
 * part 0 receives it). Before that part 0 holds its ghost blocks' Fhat at rest, and its
 * rows differ: on MPI the rows of two processes then disagreed, and the matrix was not
 * symmetric (docs/mpi.md). */
static double owned_rows_difference(piola_elastic_body *whole, piola_elastic_body *part0,
                                    const int32_t *node_part, int32_t nv) {
  piola__stiffness_matrix mw, m0;
  assert_int_equal(piola__stiffness_matrix_init(&mw, whole), PIOLA_OK);
  assert_int_equal(piola__stiffness_matrix_init(&m0, part0), PIOLA_OK);
  double *mass = malloc(sizeof(double) * (size_t)nv), *p = malloc(sizeof(double) * 3 * (size_t)nv);
  double *aw = malloc(sizeof(double) * 3 * (size_t)nv), *a0 = malloc(sizeof(double) * 3 * (size_t)nv);
  test_rng rng = test_rng_seeded(21);
  for (int32_t i = 0; i < nv; ++i) mass[i] = 0.01;
  for (int32_t j = 0; j < 3 * nv; ++j) p[j] = test_rng_uniform(&rng, -1, 1);
  piola__stiffness_matrix_assemble(&mw, whole, -1.0, 0.0, mass, 1.0);
  piola__stiffness_matrix_assemble(&m0, part0, -1.0, 0.0, mass, 1.0);
  piola__stiffness_matrix_apply(&mw, whole, mass, 1.0, p, aw);
  piola__stiffness_matrix_apply(&m0, part0, mass, 1.0, p, a0);
  double worst = 0;
  for (int32_t i = 0; i < nv; ++i)
    if (node_part[i] == 0)
      for (int c = 0; c < 3; ++c) worst = fmax(worst, fabs(a0[3 * i + c] - aw[3 * i + c]));
  free(mass), free(p), free(aw), free(a0);
  piola__stiffness_matrix_free(&mw);
  piola__stiffness_matrix_free(&m0);
  return worst;
}

static void check_local_stiffness(piola_elastic_body *whole, fake_part *p0, fake_part *p1) {
  assert_true(owned_rows_difference(whole, p0->body, p0->node_part, p0->node_count) > 0);
  piola__elastic_body_split_share_fhat(p1->body);
  piola__elastic_body_split_share_fhat(p0->body);
  assert_true(owned_rows_difference(whole, p0->body, p0->node_part, p0->node_count) == 0);
}

/* x: the rest positions stretched, sheared and jittered; v: a random velocity field. */
static void deformed_state(const piola_tet_mesh *mesh, double *x, double *v) {
  test_rng rng = test_rng_seeded(20);
  for (int32_t i = 0; i < mesh->vertex_count; ++i) {
    const double *p = mesh->positions + 3 * i;
    x[3 * i] = 1.2 * p[0] + 0.3 * p[1] + test_rng_uniform(&rng, -0.01, 0.01);
    x[3 * i + 1] = 0.9 * p[1] + test_rng_uniform(&rng, -0.01, 0.01);
    x[3 * i + 2] = p[2] - 0.2 * p[0] + test_rng_uniform(&rng, -0.01, 0.01);
    for (int c = 0; c < 3; ++c) v[3 * i + c] = test_rng_uniform(&rng, -1, 1);
  }
}

static void check_split(int n, int alternate, int local) {
  piola_tet_mesh mesh = fixture_grid(n, 0.1);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *whole = fixture_body(&mesh, &material);
  const int32_t nv = mesh.vertex_count, nt = mesh.tet_count;
  const int32_t blocks = piola_elastic_body_block_count(whole);
  assert_int_equal(blocks, (nt + PIOLA_WORK_SPLIT_BLOCK - 1) / PIOLA_WORK_SPLIT_BLOCK);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *v = malloc(sizeof(double) * 3 * (size_t)nv);
  deformed_state(&mesh, x, v);
  double *f = malloc(sizeof(double) * 3 * (size_t)nv), *d = malloc(sizeof(double) * 3 * (size_t)nv);
  assert_int_equal(piola_elastic_body_update(whole, x, 1.0, f, NULL), PIOLA_OK);
  piola_elastic_body_damping_forces(whole, v, 0.7, 0.3, d);

  /* one part: the same bits */
  int32_t *all0 = calloc((size_t)blocks, sizeof(int32_t)), *nodes0 = calloc((size_t)nv, sizeof(int32_t));
  piola_work_split one = {0, 1, all0, nodes0, NULL, noop_nodes, noop_nodes, noop_blocks, NULL, NULL, NULL, NULL};
  piola_elastic_body *single = fixture_body(&mesh, &material);
  assert_int_equal(piola_elastic_body_set_work_split(single, &one), PIOLA_OK);
  double *fs = malloc(sizeof(double) * 3 * (size_t)nv), *ds = malloc(sizeof(double) * 3 * (size_t)nv);
  assert_int_equal(piola_elastic_body_update(single, x, 1.0, fs, NULL), PIOLA_OK);
  piola_elastic_body_damping_forces(single, v, 0.7, 0.3, ds);
  assert_memory_equal(fs, f, sizeof(double) * 3 * (size_t)nv);
  assert_memory_equal(ds, d, sizeof(double) * 3 * (size_t)nv);

  /* two parts */
  int32_t *block_part = malloc(sizeof(int32_t) * (size_t)blocks);
  int32_t *node_part = malloc(sizeof(int32_t) * (size_t)nv);
  for (int32_t b = 0; b < blocks; ++b)
    block_part[b] = alternate ? b % 2 : (int32_t)(2 * (int64_t)b / blocks);
  for (int32_t i = 0; i < nv; ++i) node_part[i] = 1;
  const int32_t *tv = piola_elastic_body_tets(whole);
  for (int32_t t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c)
      if (block_part[t / PIOLA_WORK_SPLIT_BLOCK] == 0) node_part[tv[4 * t + c]] = 0;
  fake_part p0 = {0}, p1 = {0};
  double *values = malloc(sizeof(double) * 3 * (size_t)nv);
  double *block_values = malloc(sizeof(double) * 256 * (size_t)blocks);
  p1 = (fake_part){fixture_body(&mesh, &material), NULL, x, v, values, block_values, nv, blocks,
                   block_part, node_part, {1, 2, block_part, node_part, &p1, record_nodes,
                                           record_nodes, record_blocks, NULL, NULL, NULL, NULL}};
  p0 = (fake_part){fixture_body(&mesh, &material), &p1, x, v, NULL, NULL, nv, blocks, block_part,
                   node_part, {0, 2, block_part, node_part, &p0, sum_from_other, share_from_other,
                               blocks_from_other, NULL, NULL, NULL, NULL}};
  p1.split.context = &p1;
  p0.split.context = &p0;
  if (local) {
    p1.split.share_ghosts = record_ghosts;
    p0.split.share_ghosts = ghosts_from_other;
    p0.split.reduce = p1.split.reduce = unused_reduce;
    p0.split.collect_blocks = p1.split.collect_blocks = unused_collect;
  }
  assert_int_equal(piola_elastic_body_set_work_split(p1.body, &p1.split), PIOLA_OK);
  assert_int_equal(piola_elastic_body_set_work_split(p0.body, &p0.split), PIOLA_OK);
  double *f0 = malloc(sizeof(double) * 3 * (size_t)nv), *d0 = malloc(sizeof(double) * 3 * (size_t)nv);
  assert_int_equal(piola_elastic_body_update(p0.body, x, 1.0, f0, NULL), PIOLA_OK);
  double scale = fixture_max_abs(f, 3 * nv), worst = 0;
  assert_true(scale > 0);
  for (int32_t i = 0; i < 3 * nv; ++i) worst = fmax(worst, fabs(f0[i] - f[i]));
  assert_true(worst <= 1e-13 * scale);
  assert_int_equal(piola_elastic_body_split_is_local(p0.body), local);
  if (local) { /* part 0 holds the state of its own tets */
    for (int32_t t = 0; t < nt; ++t) {
      if (block_part[t / PIOLA_WORK_SPLIT_BLOCK] != 0) continue;
      assert_memory_equal(&piola_elastic_body_det_f(p0.body)[t], &piola_elastic_body_det_f(whole)[t],
                          sizeof(double));
      assert_memory_equal(piola_elastic_body_fhat(p0.body) + 3 * t,
                          piola_elastic_body_fhat(whole) + 3 * t, 3 * sizeof(double));
    }
  } else {
    assert_memory_equal(piola_elastic_body_det_f(p0.body), piola_elastic_body_det_f(whole),
                        sizeof(double) * (size_t)nt);
    assert_memory_equal(piola_elastic_body_fhat(p0.body), piola_elastic_body_fhat(whole),
                        sizeof(double) * 3 * (size_t)nt);
  }
  /* the damping rows use the shared (replicated) or ghost (local) rotations: the same bits
   * as the whole body's */
  piola_elastic_body_damping_forces(p0.body, v, 0.7, 0.3, d0);
  assert_memory_equal(d0, d, sizeof(double) * 3 * (size_t)nv);
  if (local) {
    check_local_stiffness(whole, &p0, &p1);
    check_local_step_bound(whole, &p0, &p1);
    /* a local split keeps only its part: the body cannot step alone again, nor be split anew */
    assert_int_equal(piola_elastic_body_set_work_split(p0.body, NULL), PIOLA_OK);
    assert_int_equal(piola_elastic_body_update(p0.body, x, 1.0, f0, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(piola_elastic_body_set_work_split(p0.body, &p0.split), PIOLA_ERROR_INVALID_ARGUMENT);
  }

  /* refused splits */
  piola_work_split bad = p0.split;
  bad.part = 2;
  assert_int_equal(piola_elastic_body_set_work_split(single, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  bad = p0.split;
  bad.share_blocks = NULL;
  assert_int_equal(piola_elastic_body_set_work_split(single, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  bad = p0.split;
  int32_t *wrong = malloc(sizeof(int32_t) * (size_t)blocks);
  memcpy(wrong, block_part, sizeof(int32_t) * (size_t)blocks);
  wrong[blocks - 1] = 5;
  bad.block_part = wrong;
  assert_int_equal(piola_elastic_body_set_work_split(single, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_elastic_body_set_work_split(single, NULL), PIOLA_OK);

  free(wrong), free(f0), free(d0), free(values), free(block_values), free(block_part);
  free(node_part), free(fs), free(ds), free(all0), free(nodes0), free(x), free(v), free(f), free(d);
  piola_elastic_body_destroy(p0.body);
  piola_elastic_body_destroy(p1.body);
  piola_elastic_body_destroy(single);
  piola_elastic_body_destroy(whole);
  fixture_mesh_free(&mesh);
}

static void small_body_halves(void **state) {
  (void)state;
  check_split(3, 0, 0);
}
static void small_body_alternating_blocks(void **state) {
  (void)state;
  check_split(3, 1, 0);
}
static void chunked_body_halves(void **state) {
  (void)state;
  check_split(12, 0, 0); /* 10,368 tets: 1,296 blocks, 648 per part, the chunked loop */
}
static void chunked_body_alternating_blocks(void **state) {
  (void)state;
  check_split(12, 1, 0);
}
/* The local mode: part 0 holds its blocks and the ghosts part 1 sends. */
static void local_small_body_halves(void **state) {
  (void)state;
  check_split(3, 0, 1);
}
static void local_small_body_alternating_blocks(void **state) {
  (void)state;
  check_split(3, 1, 1);
}
static void local_chunked_body_halves(void **state) {
  (void)state;
  check_split(12, 0, 1);
}

/* ---- a split planned before the solid is built (piola_world_set_work_split_planner) */

typedef struct planned_part {
  fake_part part;
  int calls;              /* the planner's calls */
  int give;               /* 0: the planner leaves the solid whole */
} planned_part;

static piola_status plan_part(void *context, int32_t solid, const piola_tet_mesh *mesh,
                              const piola_work_split **out) {
  planned_part *p = context;
  assert_int_equal(solid, 0);
  assert_int_equal((mesh->tet_count + PIOLA_WORK_SPLIT_BLOCK - 1) / PIOLA_WORK_SPLIT_BLOCK,
                   p->part.block_count);
  p->calls++;
  *out = p->give ? &p->part.split : NULL;
  return PIOLA_OK;
}

/* One process's values are the combined ones (this test's parts hold the same bounds). */
static void own_reduce(void *context, double *values, int32_t count, piola_work_split_reduction op) {
  (void)context, (void)values, (void)count, (void)op;
}

/* A world of one stretched jelly solid; planner may be NULL. */
static piola_world *planned_world(const piola_tet_mesh *mesh, const piola_work_split_planner *planner,
                                  int plastic) {
  piola_world *w = NULL;
  piola_world_def wd = piola_default_world_def();
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_world_set_work_split_planner(w, planner);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.4;
  sd.initial_matrix = (piola_mat3){{{1.1, 0.2, 0}, {0, 0.95, 0}, {0.1, 0, 1}}};
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  if (plastic) sd.plasticity = &plasticity;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  return w;
}

/* Two worlds play two processes whose planner hands each solid its split before the body is
 * built (part 1's world first; part 0's halo sum runs part 1's update). Part 0 then holds
 * its own tets' state with the whole solid's bits, and the tets of the blocks it neither
 * owns nor ghosts were never written (zero, where the state at rest is det F = 1); a
 * planner that leaves the solid whole changes no bit; a solid with plasticity is not
 * offered to the planner. */
/* ---- a split solid that a cut rebuilds (piola_world_set_work_split_replanner) */

typedef struct replan_part {
  int calls;
  int32_t tet_count;            /* of the last mesh offered */
  int32_t *block_part, *node_part;
  piola_work_split split;
} replan_part;

/* Part 0 of 2 holding every block: its partial sums are the totals, so the split steps with
 * the whole loop's bits (work_split.c) and no exchange is needed. */
static piola_work_split all_on_part_zero(void *context, int32_t *block_part, int32_t *node_part) {
  return (piola_work_split){0, 2, block_part, node_part, context, noop_nodes, noop_nodes,
                            noop_blocks, NULL, NULL, NULL, NULL};
}

static piola_status replan_part_zero(void *context, int32_t solid, const piola_tet_mesh *mesh,
                                     const piola_work_split **out) {
  replan_part *p = context;
  assert_int_equal(solid, 0);
  const int32_t blocks = (mesh->tet_count + PIOLA_WORK_SPLIT_BLOCK - 1) / PIOLA_WORK_SPLIT_BLOCK;
  free(p->block_part), free(p->node_part); /* no body refers to the old split any more */
  p->block_part = calloc((size_t)blocks, sizeof(int32_t));
  p->node_part = calloc((size_t)mesh->vertex_count, sizeof(int32_t));
  assert_non_null(p->block_part);
  assert_non_null(p->node_part);
  p->split = all_on_part_zero(p, p->block_part, p->node_part);
  p->calls++;
  p->tet_count = mesh->tet_count;
  *out = &p->split;
  return PIOLA_OK;
}

/* Splits solid 0 of w on part 0 alone (p holds the arrays) and gives w the replanner that
 * splits every rebuilt body the same way. */
static void split_on_part_zero_with_replanner(piola_world *w, replan_part *p,
                                              int32_t vertex_count) {
  const int32_t blocks = piola_elastic_body_block_count(piola_world_solid_body(w, 0));
  p->block_part = calloc((size_t)blocks, sizeof(int32_t));
  p->node_part = calloc((size_t)vertex_count, sizeof(int32_t));
  p->split = all_on_part_zero(p, p->block_part, p->node_part);
  assert_int_equal(piola_world_solid_set_work_split(w, 0, &p->split), PIOLA_OK);
  const piola_work_split_planner replanner = {replan_part_zero, p}; /* the world copies it */
  piola_world_set_work_split_replanner(w, &replanner);
}

/* The same plane cut of solid 0, now, in both worlds. */
static void cut_both_now(piola_world *whole, piola_world *w) {
  piola_fracture_cut cut = {.time = 0, .point = {0.3, 0.3, 0.3}, .normal = {1, 0.2, 0.1}};
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = &cut, def.cut_count = 1;
  assert_int_equal(piola_world_solid_set_fracture(whole, 0, &def), PIOLA_OK);
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
}

/* Three steps of each world leave solid 0 at the same positions, bit for bit. */
static void steps_as_the_whole_does(piola_world *whole, piola_world *w) {
  for (int k = 0; k < 3; ++k) {
    assert_int_equal(piola_world_step(whole, 0, NULL), PIOLA_OK);
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  }
  const int32_t nv = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  assert_int_equal(nv, piola_elastic_body_vertex_count(piola_world_solid_body(whole, 0)));
  assert_memory_equal(piola_world_solid_positions(w, 0), piola_world_solid_positions(whole, 0),
                      3 * sizeof(double) * (size_t)nv);
}

/* A plane cut of a split solid: the rebuilt body takes the replanner's split for its new mesh
 * (replicated), and the world steps with it as the unsplit world does, bit for bit. */
static void cut_solid_is_split_again(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(6, 0.1);
  piola_world *whole = planned_world(&mesh, NULL, 0), *w = planned_world(&mesh, NULL, 0);
  replan_part p = {0};
  split_on_part_zero_with_replanner(w, &p, mesh.vertex_count);
  cut_both_now(whole, w);
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  assert_int_equal(p.calls, 1);
  assert_int_equal(p.tet_count, piola_elastic_body_tet_count(b));
  assert_true(p.tet_count > mesh.tet_count);
  assert_ptr_equal(piola_elastic_body_work_split(b), &p.split);
  assert_false(piola_elastic_body_split_is_local(b));
  steps_as_the_whole_does(whole, w);
  piola_world_destroy(w);
  piola_world_destroy(whole);
  free(p.block_part), free(p.node_part);
  free(mesh.positions), free(mesh.tets);
}

/* Replans deferred: the cut leaves the solid whole and pending without asking the
 * replanner; the later replan splits it (and replans a solid still split, taking its old
 * split off first), and the world steps with the unsplit world's bits. */
static void deferred_replan_waits_for_the_call(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(6, 0.1);
  piola_world *whole = planned_world(&mesh, NULL, 0), *w = planned_world(&mesh, NULL, 0);
  replan_part p = {0};
  split_on_part_zero_with_replanner(w, &p, mesh.vertex_count);
  assert_false(piola_world_solid_split_pending(w, 0));
  piola_world_defer_work_split_replans(w, 1);
  cut_both_now(whole, w);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  assert_int_equal(p.calls, 0);
  assert_null(piola_elastic_body_work_split(piola_world_solid_body(w, 0)));
  assert_true(piola_world_solid_split_pending(w, 0));
  piola_world_defer_work_split_replans(w, 0);
  assert_true(piola_world_solid_split_pending(w, 0)); /* the mark outlives the deferral */
  assert_int_equal(piola_world_solid_replan_work_split(w, 0), PIOLA_OK);
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  assert_int_equal(p.calls, 1);
  assert_int_equal(p.tet_count, piola_elastic_body_tet_count(b));
  assert_true(p.tet_count > mesh.tet_count);
  assert_ptr_equal(piola_elastic_body_work_split(b), &p.split);
  assert_false(piola_world_solid_split_pending(w, 0));
  /* a solid still split is replanned too (the replanner frees the split it had) */
  assert_int_equal(piola_world_solid_replan_work_split(w, 0), PIOLA_OK);
  assert_int_equal(p.calls, 2);
  assert_ptr_equal(piola_elastic_body_work_split(b), &p.split);
  assert_false(piola_elastic_body_split_is_local(b));
  steps_as_the_whole_does(whole, w);
  piola_world_destroy(w);
  piola_world_destroy(whole);
  free(p.block_part), free(p.node_part);
  free(mesh.positions), free(mesh.tets);
}

static void planned_solid_holds_its_part_only(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(12, 0.1);
  piola_world *whole = planned_world(&mesh, NULL, 0);
  const piola_elastic_body *wb = piola_world_solid_body(whole, 0);
  const int32_t nv = mesh.vertex_count, nt = mesh.tet_count;
  const int32_t blocks = piola_elastic_body_block_count(wb);
  const double *x = piola_world_solid_positions(whole, 0);
  int32_t *block_part = malloc(sizeof(int32_t) * (size_t)blocks);
  int32_t *node_part = malloc(sizeof(int32_t) * (size_t)nv);
  for (int32_t b = 0; b < blocks; ++b) block_part[b] = (int32_t)(2 * (int64_t)b / blocks);
  for (int32_t i = 0; i < nv; ++i) node_part[i] = 1;
  const int32_t *tv = piola_elastic_body_tets(wb);
  for (int32_t t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c)
      if (block_part[t / PIOLA_WORK_SPLIT_BLOCK] == 0) node_part[tv[4 * t + c]] = 0;
  double *values = malloc(sizeof(double) * 3 * (size_t)nv);
  double *block_values = malloc(sizeof(double) * 256 * (size_t)blocks);
  planned_part p0 = {0}, p1 = {0};
  p1.part = (fake_part){NULL, NULL, x, NULL, values, block_values, nv, blocks, block_part, node_part,
                        {1, 2, block_part, node_part, &p1.part, record_nodes, record_nodes,
                         record_blocks, record_ghosts, own_reduce, unused_collect, NULL}};
  p0.part = (fake_part){NULL, &p1.part, x, NULL, NULL, NULL, nv, blocks, block_part, node_part,
                        {0, 2, block_part, node_part, &p0.part, sum_from_other, share_from_other,
                         blocks_from_other, ghosts_from_other, own_reduce, unused_collect, NULL}};
  p0.give = p1.give = 1;
  piola_work_split_planner planner1 = {plan_part, &p1}, planner0 = {plan_part, &p0};
  piola_world *w1 = planned_world(&mesh, &planner1, 0);
  p1.part.body = (piola_elastic_body *)piola_world_solid_body(w1, 0);
  piola_world *w0 = planned_world(&mesh, &planner0, 0);
  p0.part.body = (piola_elastic_body *)piola_world_solid_body(w0, 0);
  assert_int_equal(p0.calls, 1);
  assert_true(piola_elastic_body_split_is_local(p0.part.body));
  const double *det0 = piola_elastic_body_det_f(p0.part.body), *det = piola_elastic_body_det_f(wb);
  int32_t unwritten = 0;
  for (int32_t t = 0; t < nt; ++t) {
    const int32_t b = t / PIOLA_WORK_SPLIT_BLOCK;
    if (block_part[b] == 0) {
      assert_memory_equal(&det0[t], &det[t], sizeof(double));
      assert_memory_equal(piola_elastic_body_fhat(p0.part.body) + 3 * t,
                          piola_elastic_body_fhat(wb) + 3 * t, 3 * sizeof(double));
      assert_true(det[t] != 1.0); /* the stretch is in the state */
    } else if (!ghost_of_part0(&p0.part, tv, nt, b)) {
      assert_true(det0[t] == 0.0);
      unwritten++;
    }
  }
  assert_true(unwritten > nt / 4); /* most of part 1's tets */

  /* a planner that leaves the solid whole: the same bits as no planner */
  planned_part none = {0};
  none.part.block_count = blocks;
  piola_work_split_planner leave = {plan_part, &none};
  piola_world *w2 = planned_world(&mesh, &leave, 0);
  assert_int_equal(none.calls, 1);
  assert_memory_equal(piola_elastic_body_det_f(piola_world_solid_body(w2, 0)), det,
                      sizeof(double) * (size_t)nt);
  /* plasticity keeps the replicated mode: not offered */
  piola_world *w3 = planned_world(&mesh, &leave, 1);
  assert_int_equal(none.calls, 1);

  piola_world_destroy(w3);
  piola_world_destroy(w2);
  piola_world_destroy(w0);
  piola_world_destroy(w1);
  piola_world_destroy(whole);
  free(values), free(block_values), free(block_part), free(node_part);
  fixture_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(planned_solid_holds_its_part_only),
      cmocka_unit_test(cut_solid_is_split_again),
      cmocka_unit_test(deferred_replan_waits_for_the_call),
      cmocka_unit_test(small_body_halves),
      cmocka_unit_test(small_body_alternating_blocks),
      cmocka_unit_test(chunked_body_halves),
      cmocka_unit_test(chunked_body_alternating_blocks),
      cmocka_unit_test(local_small_body_halves),
      cmocka_unit_test(local_small_body_alternating_blocks),
      cmocka_unit_test(local_chunked_body_halves),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
