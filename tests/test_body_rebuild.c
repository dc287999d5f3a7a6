/* Bodies that change their mesh between steps (src/sim/body_rebuild.c), as fracture and
 * refinement will: after a solid is replaced by a refined copy its energy, plastic state and
 * forces are those of the same deformation (forces against finite differences of the
 * energy); after it is split in two its momentum is kept, the pieces collide with each
 * other through the rebuilt collision surface and the world goes on stepping; a cloth
 * coupled to it reads its new surface; constraints follow the parent nodes; a bad change
 * leaves the body as it was. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/world_bodies.h"
#include "sim/world_internal.h"
#include "test_support.h"

/* nx x ny x nz cubes of edge h from the origin (6 tets each). */
static piola_tet_mesh grid(int nx, int ny, int nz, double h) {
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_box_grid(nx, ny, nz, (piola_vec3){h, h, h}, &m), PIOLA_OK);
  return m;
}

static void free_tets(piola_tet_mesh *m) { free(m->positions), free(m->tets); }

static piola_world *world_without_gravity(void) {
  piola_world_def wdef = piola_default_world_def();
  wdef.gravity[2].value = 0;
  wdef.max_dt = 5e-4;
  piola_world *w;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  return w;
}

/* Barycentric weights of p in tet (a, b, c, d). */
static void barycentric(const double *a, const double *b, const double *c, const double *d,
                        const double *p, double w[4]) {
  double m[3][3], r[3];
  for (int i = 0; i < 3; ++i) m[i][0] = b[i] - a[i], m[i][1] = c[i] - a[i], m[i][2] = d[i] - a[i], r[i] = p[i] - a[i];
  double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  double s[3];
  for (int k = 0; k < 3; ++k) {
    double q[3][3];
    memcpy(q, m, sizeof q);
    for (int i = 0; i < 3; ++i) q[i][k] = r[i];
    s[k] = (q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) - q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
            q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0])) / det;
  }
  w[0] = 1 - s[0] - s[1] - s[2], w[1] = s[0], w[2] = s[1], w[3] = s[2];
}

/* The old tet of body whose rest shape holds rest point p, and p's weights in it. */
static int32_t containing_tet(const piola_elastic_body *body, const double *p, double w[4]) {
  const double *X = piola_elastic_body_rest_positions(body);
  const int32_t *tets = piola_elastic_body_tets(body);
  for (int32_t t = 0; t < piola_elastic_body_tet_count(body); ++t) {
    const int32_t *v = tets + 4 * t;
    barycentric(X + 3 * v[0], X + 3 * v[1], X + 3 * v[2], X + 3 * v[3], p, w);
    if (w[0] >= -1e-9 && w[1] >= -1e-9 && w[2] >= -1e-9 && w[3] >= -1e-9) return t;
  }
  fail_msg("no tet holds (%g, %g, %g)", p[0], p[1], p[2]);
  return -1;
}

/* The field f (3 per old node) at rest point p, interpolated in the tet that holds p. */
static void interpolate(const piola_elastic_body *body, const double *f, const double *p, double out[3]) {
  double w[4];
  const int32_t *v = piola_elastic_body_tets(body) + 4 * containing_tet(body, p, w);
  for (int k = 0; k < 3; ++k)
    out[k] = w[0] * f[3 * v[0] + k] + w[1] * f[3 * v[1] + k] + w[2] * f[3 * v[2] + k] + w[3] * f[3 * v[3] + k];
}

static double energy_at(piola_world *w, piola_body_id id, const double *x) {
  assert_int_equal(piola_world_body_set_state(w, id, x, NULL), PIOLA_OK);
  return piola_world_body_stats(w, id).elastic_energy;
}

/* A plastic cube of 2 x 2 x 2 cells, squeezed and stepped until it yields, is replaced by
 * the 4 x 4 x 4 refinement of its rest shape carrying the same piecewise linear deformation:
 * every new tet lies inside an old one, so it has its parent's F and (inherited) Fp, and the
 * elastic energy is unchanged. The new forces are minus the energy's gradient. */
static void refined_solid_keeps_energy_and_forces(void **state) {
  (void)state;
  const double size = 0.2;
  piola_tet_mesh coarse = grid(2, 2, 2, size / 2), fine = grid(4, 4, 4, size / 4);
  piola_world *w = world_without_gravity();
  piola_solid_def def = piola_default_solid_def();
  def.mesh = &coarse;
  def.name = "cube";
  def.material.youngs_modulus = 1e5;
  def.shear_viscosity.value = 2;
  def.initial_matrix.m[0][0] = 1.25, def.initial_matrix.m[2][2] = 0.8, def.initial_matrix.m[0][1] = 0.1;
  def.velocity = (piola_vec3){0.1, 0.2, -0.1};
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  plasticity.yield = 0.02;
  def.plasticity = &plasticity;
  assert_int_equal(piola_world_add_solid(w, &def, NULL), PIOLA_OK);
  const piola_body_id id = piola_world_body_at(w, 0);
  for (int s = 0; s < 5; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  world_body *b = piola__world_body(w, id);
  const piola_elastic_body *old = b->solid;
  double fp_stretch = 0;
  piola_plastic_state_measure(piola_world_solid_plastic_state(w, 0), &fp_stretch, NULL);
  assert_true(fp_stretch > 0.01); /* it yielded */
  /* the new state: the old deformation and velocity, interpolated */
  const int32_t n = fine.vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    interpolate(old, b->x, fine.positions + 3 * i, x + 3 * i);
    interpolate(old, b->v, fine.positions + 3 * i, v + 3 * i);
  }
  int32_t *parent = malloc(sizeof(int32_t) * (size_t)fine.tet_count);
  for (int32_t t = 0; t < fine.tet_count; ++t) {
    double c[3] = {0, 0, 0}, wts[4];
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * fine.positions[3 * fine.tets[4 * t + k] + a];
    parent[t] = containing_tet(old, c, wts);
  }
  const double energy_before = piola_world_body_stats(w, id).elastic_energy;
  assert_true(energy_before > 0);
  const int32_t old_tets = piola_elastic_body_tet_count(old);
  double *fp_before = malloc(9 * sizeof(double) * (size_t)old_tets);
  memcpy(fp_before, piola_plastic_state_fp_inverse(piola_world_solid_plastic_state(w, 0)),
         9 * sizeof(double) * (size_t)old_tets);
  body_change change = {.solid_rest = &fine, .x = x, .v = v, .element_parent = parent};
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_OK);
  /* the same body, with the new mesh */
  assert_int_equal(piola_world_body_at(w, 0), id);
  assert_string_equal(piola_world_body_name(w, id), "cube");
  assert_int_equal(piola_world_body_node_count(w, id), n);
  assert_int_equal(piola_world_body_element_count(w, id), fine.tet_count);
  const piola_plastic_state *plastic = piola_world_solid_plastic_state(w, 0);
  assert_int_equal(piola_plastic_state_tet_count(plastic), fine.tet_count);
  for (int32_t t = 0; t < fine.tet_count; ++t)
    assert_memory_equal(piola_plastic_state_fp_inverse(plastic) + 9 * t, fp_before + 9 * parent[t],
                        9 * sizeof(double));
  const double energy_after = piola_world_body_stats(w, id).elastic_energy;
  assert_close(energy_after, energy_before, 1e-9 * energy_before);
  /* forces against central differences of the energy, on a sample of coordinates */
  b = piola__world_body(w, id);
  double *force = malloc(3 * sizeof(double) * (size_t)n), *probe = malloc(3 * sizeof(double) * (size_t)n);
  memcpy(force, b->force, 3 * sizeof(double) * (size_t)n);
  memcpy(probe, b->x, 3 * sizeof(double) * (size_t)n);
  double fmax_abs = 0;
  for (int64_t j = 0; j < 3 * (int64_t)n; ++j) fmax_abs = fmax(fmax_abs, fabs(force[j]));
  const double step = 1e-6 * size;
  test_rng rng = test_rng_seeded(7);
  const long samples = test_samples(40, 8);
  for (long k = 0; k < samples; ++k) {
    int64_t j = (int64_t)(test_rng_next(&rng) % (uint64_t)(3 * n));
    const double x0 = probe[j];
    probe[j] = x0 + step;
    double e_plus = energy_at(w, id, probe);
    probe[j] = x0 - step;
    double e_minus = energy_at(w, id, probe);
    probe[j] = x0;
    assert_close(-(e_plus - e_minus) / (2 * step), force[j], 1e-5 * fmax_abs);
  }
  assert_int_equal(piola_world_body_set_state(w, id, probe, NULL), PIOLA_OK);
  /* and the world goes on */
  for (int s = 0; s < 20; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  const double *xs = piola_world_body_positions(w, id);
  for (int64_t j = 0; j < 3 * (int64_t)n; ++j) assert_true(isfinite(xs[j]));
  free(x), free(v), free(parent), free(fp_before), free(force), free(probe);
  piola_world_destroy(w);
  free_tets(&coarse), free_tets(&fine);
}

/* Sum of m v over the nodes of a body. */
static void momentum(piola_world *w, piola_body_id id, double p[3]) {
  const double *m = piola_world_body_masses(w, id), *v = piola_world_body_velocities(w, id);
  p[0] = p[1] = p[2] = 0;
  for (int32_t i = 0; i < piola_world_body_node_count(w, id); ++i)
    for (int k = 0; k < 3; ++k) p[k] += m[i] * v[3 * i + k];
}

/* A bar of 4 x 2 x 2 cells moving and spinning is split at its middle plane into two
 * pieces (the nodes on the plane doubled): its momentum is kept, since each doubled node's
 * lumped mass is shared by its two copies. The pieces are then sent into each other: they
 * meet in the rebuilt collision surface, do not pass through each other, and the momentum
 * stays zero. */
static void split_solid_keeps_momentum_and_collides(void **state) {
  (void)state;
  const double h = 0.05, gap = 0.01;
  piola_tet_mesh bar = grid(4, 2, 2, h);
  piola_world *w = world_without_gravity();
  piola_solid_def def = piola_default_solid_def();
  def.mesh = &bar;
  def.name = "bar";
  def.material.youngs_modulus = 5e4;
  def.shear_viscosity.value = 1;
  def.velocity = (piola_vec3){0.3, -0.1, 0.2};
  def.initial_matrix.m[1][2] = 0.05;
  def.self_collision.enabled = true;
  def.self_collision.thickness = 1e-3;
  def.self_collision.friction = 0;
  assert_int_equal(piola_world_add_solid(w, &def, NULL), PIOLA_OK);
  const piola_body_id id = piola_world_body_at(w, 0);
  for (int s = 0; s < 3; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  double p_before[3];
  momentum(w, id, p_before);

  /* the split: nodes on x = 2h get a copy for the tets on the right, which move by gap */
  world_body *b = piola__world_body(w, id);
  const int32_t n0 = bar.vertex_count;
  int32_t *copy_of = malloc(sizeof(int32_t) * (size_t)n0);
  int32_t n = n0;
  for (int32_t i = 0; i < n0; ++i) copy_of[i] = fabs(bar.positions[3 * i] - 2 * h) < 1e-12 ? n++ : -1;
  piola_tet_mesh split = {.vertex_count = n, .tet_count = bar.tet_count};
  split.positions = malloc(3 * sizeof(double) * (size_t)n);
  split.tets = malloc(4 * sizeof(int32_t) * (size_t)bar.tet_count);
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
  int32_t *node_parent = malloc(sizeof(int32_t) * (size_t)n), *tet_parent = malloc(sizeof(int32_t) * (size_t)bar.tet_count);
  uint8_t *right = calloc((size_t)n, 1);
  for (int32_t i = 0; i < n0; ++i) {
    node_parent[i] = i;
    if (copy_of[i] >= 0) node_parent[copy_of[i]] = i;
  }
  for (int32_t i = 0; i < n; ++i) {
    const int32_t p = node_parent[i];
    memcpy(split.positions + 3 * i, bar.positions + 3 * p, 3 * sizeof(double));
    memcpy(x + 3 * i, b->x + 3 * p, 3 * sizeof(double));
    memcpy(v + 3 * i, b->v + 3 * p, 3 * sizeof(double));
  }
  for (int32_t t = 0; t < bar.tet_count; ++t) {
    double cx = 0;
    for (int k = 0; k < 4; ++k) cx += 0.25 * bar.positions[3 * bar.tets[4 * t + k]];
    tet_parent[t] = t;
    for (int k = 0; k < 4; ++k) {
      int32_t i = bar.tets[4 * t + k];
      split.tets[4 * t + k] = cx > 2 * h && copy_of[i] >= 0 ? copy_of[i] : i;
      if (cx > 2 * h) right[split.tets[4 * t + k]] = 1;
    }
  }
  for (int32_t i = 0; i < n; ++i)
    if (right[i]) split.positions[3 * i] += gap, x[3 * i] += gap;
  body_change change = {.solid_rest = &split, .x = x, .v = v, .node_parent = node_parent,
                        .element_parent = tet_parent};
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_OK);
  assert_int_equal(piola_world_body_node_count(w, id), n);
  double p_after[3];
  momentum(w, id, p_after);
  const double scale = sqrt(p_before[0] * p_before[0] + p_before[1] * p_before[1] + p_before[2] * p_before[2]);
  for (int k = 0; k < 3; ++k) assert_close(p_after[k], p_before[k], 1e-12 * scale);

  /* the pieces into each other, at 0.5 m/s each: they would overlap by 2 cm without contact */
  const double speed = 0.5;
  for (int32_t i = 0; i < n; ++i) v[3 * i] = right[i] ? -speed : speed, v[3 * i + 1] = v[3 * i + 2] = 0;
  assert_int_equal(piola_world_body_set_state(w, id, NULL, v), PIOLA_OK);
  double mass = 0;
  for (int32_t i = 0; i < n; ++i) mass += piola_world_body_masses(w, id)[i];
  piola_step_stats stats = {0};
  while (piola_world_time(w) < 0.05) {
    piola_step_stats one;
    assert_int_equal(piola_world_step(w, 0, &one), PIOLA_OK);
    stats.contacts += one.contacts, stats.impacts += one.impacts;
  }
  assert_true(stats.contacts + stats.impacts > 0);
  const double *xs = piola_world_body_positions(w, id);
  double left_max = -INFINITY, right_min = INFINITY;
  for (int32_t i = 0; i < n; ++i) {
    if (right[i]) right_min = fmin(right_min, xs[3 * i]);
    else left_max = fmax(left_max, xs[3 * i]);
  }
  assert_true(right_min > left_max);
  momentum(w, id, p_after);
  for (int k = 0; k < 3; ++k) assert_close(p_after[k], 0.0, 1e-9 * mass * speed);
  free(copy_of), free(split.positions), free(split.tets), free(x), free(v);
  free(node_parent), free(tet_parent), free(right);
  piola_world_destroy(w);
  free_tets(&bar);
}

/* Constraints follow the parent nodes (a fixed end stays fixed, at its new rest position);
 * a change with a parent out of range, non-finite positions or a shell is refused and the
 * body is left as it was. */
static void constraints_follow_parents_and_bad_changes_are_refused(void **state) {
  (void)state;
  const double h = 0.05;
  piola_tet_mesh bar = grid(4, 1, 1, h), fine = grid(8, 2, 2, h / 2);
  piola_world_def wdef = piola_default_world_def();
  piola_world *w;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  piola_solid_def def = piola_default_solid_def();
  def.mesh = &bar;
  def.material.youngs_modulus = 1e5;
  def.shear_viscosity.value = 5;
  piola_constraint_def wall;
  memset(&wall, 0, sizeof wall);
  wall.selector.type = PIOLA_SELECT_BOX;
  wall.selector.box_min = (piola_vec3){-1, -1, -1};
  wall.selector.box_max = (piola_vec3){1e-9, 1, 1};
  def.constraints = &wall;
  def.constraint_count = 1;
  assert_int_equal(piola_world_add_solid(w, &def, NULL), PIOLA_OK);
  const piola_body_id id = piola_world_body_at(w, 0);
  for (int s = 0; s < 5; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  world_body *b = piola__world_body(w, id);
  const int32_t n = fine.vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = calloc(3 * (size_t)n, sizeof(double));
  int32_t *node_parent = malloc(sizeof(int32_t) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    interpolate(b->solid, b->x, fine.positions + 3 * i, x + 3 * i);
    /* nodes on the wall take a fixed parent; the others a free one (node 1 is at x = h) */
    node_parent[i] = fine.positions[3 * i] < 1e-9 ? 0 : 1;
  }
  body_change change = {.solid_rest = &fine, .x = x, .v = v, .node_parent = node_parent};
  /* refused: a parent out of range, a non-finite position, a missing mesh */
  const double *x_before = piola_world_body_positions(w, id);
  node_parent[3] = b->n;
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_ERROR_INVALID_ARGUMENT);
  node_parent[3] = fine.positions[9] < 1e-9 ? 0 : 1;
  x[5] = NAN;
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_ERROR_NOT_FINITE);
  interpolate(b->solid, b->x, fine.positions + 3, x + 3);
  change.solid_rest = NULL;
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_ERROR_INVALID_ARGUMENT);
  change.solid_rest = &fine;
  assert_int_equal(piola_world_body_node_count(w, id), bar.vertex_count);
  assert_ptr_equal(piola_world_body_positions(w, id), x_before);
  /* accepted: the wall nodes of the fine mesh are fixed where they rest */
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_OK);
  const uint8_t *flags = piola_world_body_constraint_flags(w, id);
  for (int s = 0; s < 20; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  const double *xs = piola_world_body_positions(w, id);
  int32_t fixed = 0;
  double sag = 0;
  for (int32_t i = 0; i < n; ++i) {
    const int on_wall = fine.positions[3 * i] < 1e-9;
    assert_int_equal(flags[i], on_wall ? NODE_FIXED : NODE_FREE);
    if (on_wall) {
      ++fixed;
      assert_memory_equal(xs + 3 * i, fine.positions + 3 * i, 3 * sizeof(double));
    }
    sag = fmin(sag, xs[3 * i + 2] - fine.positions[3 * i + 2]);
  }
  assert_int_equal(fixed, 3 * 3);
  assert_true(sag < 0); /* the free end falls under gravity */
  /* shells cannot change their mesh (yet): refused, not half done */
  piola_tri_mesh sheet;
  assert_int_equal(piola_tri_mesh_rectangle(0.2, 0.2, 2, 2, &sheet), PIOLA_OK);
  piola_shell_def sd = piola_default_shell_def();
  sd.mesh = &sheet;
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_OK);
  world_body *shell = piola__world_body_of(w, PIOLA_BODY_SHELL, 0);
  assert_int_equal(piola__body_rebuild(w, shell, &change), PIOLA_ERROR_UNSUPPORTED);
  assert_int_equal(shell->n, sheet.vertex_count);
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  piola_tri_mesh_free(&sheet);
  free(x), free(v), free(node_parent);
  piola_world_destroy(w);
  free_tets(&bar), free_tets(&fine);
}

/* A cloth coupled one-way to a block (collide_with_solids) lands on it; the block is then
 * replaced by its refinement in the same place. The coupling reads the new block's boundary
 * (the old one, in the old numbering, would name nodes near the bottom of the new mesh): the
 * cloth keeps resting on top instead of falling into the block. */
static void cloth_rests_on_a_refined_block(void **state) {
  (void)state;
  const double size = 0.2;
  piola_tet_mesh coarse = grid(2, 2, 2, size / 2), fine = grid(4, 4, 4, size / 4);
  piola_world_def wdef = piola_default_world_def();
  wdef.max_dt = 1e-3;
  piola_world *w;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  piola_obstacle_def ground = piola_default_obstacle_def();
  assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
  piola_solid_def def = piola_default_solid_def();
  def.mesh = &coarse;
  def.material.youngs_modulus = 1e6;
  def.shear_viscosity.value = 20;
  assert_int_equal(piola_world_add_solid(w, &def, NULL), PIOLA_OK);
  piola_tri_mesh sheet;
  assert_int_equal(piola_tri_mesh_rectangle(0.16, 0.16, 8, 8, &sheet), PIOLA_OK);
  for (int32_t i = 0; i < sheet.vertex_count; ++i)
    sheet.positions[3 * i] += 0.5 * size, sheet.positions[3 * i + 1] += 0.5 * size,
        sheet.positions[3 * i + 2] = size + 0.002;
  piola_shell_def sd = piola_default_shell_def();
  sd.mesh = &sheet;
  sd.material.youngs_modulus = 1e5;
  sd.density = 200;
  sd.shear_viscosity.value = 0.5;
  sd.collide_with_solids = true;
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_OK);
  const piola_body_id block = piola_world_body_of(w, PIOLA_BODY_SOLID, 0);
  const piola_body_id cloth = piola_world_body_of(w, PIOLA_BODY_SHELL, 0);
  while (piola_world_time(w) < 0.04) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  world_body *b = piola__world_body(w, block);
  const int32_t n = fine.vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    interpolate(b->solid, b->x, fine.positions + 3 * i, x + 3 * i);
    interpolate(b->solid, b->v, fine.positions + 3 * i, v + 3 * i);
  }
  body_change change = {.solid_rest = &fine, .x = x, .v = v};
  assert_int_equal(piola__body_rebuild(w, b, &change), PIOLA_OK);
  while (piola_world_time(w) < 0.12) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  /* the block's top, and the cloth over it */
  const double *xb = piola_world_body_positions(w, block), *xc = piola_world_body_positions(w, cloth);
  double top = INFINITY;
  for (int32_t i = 0; i < n; ++i)
    if (fine.positions[3 * i + 2] > size - 1e-9) top = fmin(top, xb[3 * i + 2]);
  assert_true(top > 0.9 * size);
  for (int32_t i = 0; i < sheet.vertex_count; ++i)
    assert_true(xc[3 * i + 2] > top - 0.01 * size);
  free(x), free(v);
  piola_tri_mesh_free(&sheet);
  piola_world_destroy(w);
  free_tets(&coarse), free_tets(&fine);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(refined_solid_keeps_energy_and_forces),
      cmocka_unit_test(split_solid_keeps_momentum_and_collides),
      cmocka_unit_test(constraints_follow_parents_and_bad_changes_are_refused),
      cmocka_unit_test(cloth_rests_on_a_refined_block),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
