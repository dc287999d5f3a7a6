/* Fracture under backward Euler (docs/fracture.md, "Implicit integrators"): the done-when
 * checks of the cut in free flight, with the implicit integrator stepping the cut body.
 *  - A stretched, spinning block (as in test_backward_euler.c's free flight) is cut by a
 *    slanted plane through its tets between two implicit steps: linear and angular momentum
 *    and the mass are the same to rounding across the cut; the Newton steps after it
 *    converge, keep the linear momentum as for the uncut block (1e-10) and change the
 *    angular momentum exactly as backward Euler's discrete balance says, to the share the
 *    Newton tolerance leaves; and the two fragments come apart (the crack opens as each
 *    stretched half recoils).
 *  - The same block with the cut scripted (`piola_fracture_def.cuts`) at a time between two
 *    implicit steps gives, after it, the same state as the cut applied by hand. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "block_scenes.h"
#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/world.h"
#include "piola/world_fracture.h"

#define DT (1.0 / 120)
#define NEWTON_TOLERANCE 1e-5

static const double CUT_POINT[3] = {0.16, 0.1, 0.1}, CUT_NORMAL[3] = {1, 0.25, -0.15};

static piola_world *spinning_block(void) {
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  wd.integrator = PIOLA_INTEGRATOR_BACKWARD_EULER;
  wd.implicit_dt = DT;
  wd.newton_tolerance = NEWTON_TOLERANCE;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh = block_mesh(6, 4, 4, 0.3, 0.2, 0.2);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 2e5;
  sd.material.poisson_ratio = 0.4;
  sd.shear_viscosity = piola_track_constant(20);
  sd.bulk_viscosity = piola_track_constant(10);
  sd.initial_matrix = (piola_mat3){{{1.3, 0.2, 0}, {0, 0.8, 0.1}, {0.1, 0, 1.1}}};
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  spin_block(w, 0.3, 0);
  block_mesh_free(&mesh);
  return w;
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static double total_mass(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *m = piola_elastic_body_masses(b);
  double sum = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(b); ++i) sum += m[i];
  return sum;
}

/* The smallest distance between a vertex of fragment 0's surface and one of fragment 1's
 * (the crack faces' vertices coincide when the cut is made). */
static double nearest_vertices_of_fragments(const piola_world *w) {
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  assert_int_equal(s.fragment_count, 2);
  double nearest = INFINITY;
  for (int32_t a = 0; a < 3 * s.fragment_start[1]; ++a)
    for (int32_t b = 3 * s.fragment_start[1]; b < 3 * s.fragment_start[2]; ++b) {
      const double *p = s.positions + 3 * s.triangles[a], *q = s.positions + 3 * s.triangles[b];
      const double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
      nearest = fmin(nearest, norm3(d));
    }
  piola_fracture_surface_free(&s);
  return nearest;
}

static void cut_between_implicit_steps_keeps_momentum_and_separates(void **state) {
  (void)state;
  piola_world *w = spinning_block();
  piola_step_stats st = {0};
  assert_int_equal(piola_world_advance_to(w, 3 * DT, &st), PIOLA_OK);
  double p0[3], l0[3], p1[3], l1[3];
  solid_momenta(w, p0, l0, NULL);
  const double mass = total_mass(w), pn = norm3(p0), ln = norm3(l0);
  int32_t cut = 0;
  assert_int_equal(piola_world_solid_cut(w, 0, CUT_POINT, CUT_NORMAL, &cut), PIOLA_OK);
  assert_true(cut > 0);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  /* across the cut: nothing moved, momentum and mass to rounding */
  solid_momenta(w, p1, l1, NULL);
  assert_close(total_mass(w), mass, 1e-13 * mass);
  for (int k = 0; k < 3; ++k) {
    assert_close(p1[k], p0[k], 1e-13 * pn);
    assert_close(l1[k], l0[k], 1e-13 * ln);
  }
  const double gap0 = nearest_vertices_of_fragments(w);
  assert_true(gap0 < 1e-6);
  /* the implicit steps after it converge, keep the linear momentum as for an uncut body, and
   * change the angular momentum only as backward Euler does: with x' = x + dt v' and
   * internal forces f(x') that have no torque, L' - L = dt sum m v' x v + sum x' x rho,
   * rho_i = m_i (v'_i - v_i) - dt f_i(x') the impulse Newton leaves unbalanced. Its
   * mass-weighted RMS per mass is below tol g dt, so |sum x' x rho| <= r M tol g dt (r the
   * largest |x'|): a copy whose forces had a torque (a cut that broke the balance of its
   * material fraction) would show here. */
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  const double *m = piola_elastic_body_masses(piola_world_solid_body(w, 0));
  double *v_before = malloc(3 * sizeof(double) * (size_t)n);
  assert_non_null(v_before);
  for (int s = 1; s <= 24; ++s) {
    memcpy(v_before, piola_world_solid_velocities(w, 0), 3 * sizeof(double) * (size_t)n);
    solid_momenta(w, p0, l0, NULL);
    memset(&st, 0, sizeof st);
    assert_int_equal(piola_world_advance_to(w, (3 + s) * DT, &st), PIOLA_OK);
    assert_int_equal(st.substeps, 1);
    assert_int_equal(st.newton_failures, 0);
    assert_true(st.newton_iterations >= 1);
    const double *x = piola_world_solid_positions(w, 0), *v = piola_world_solid_velocities(w, 0);
    double predicted[3] = {0, 0, 0}, r = 0;
    for (int32_t i = 0; i < n; ++i) {
      const double *a = v + 3 * i, *b = v_before + 3 * i;
      predicted[0] += DT * m[i] * (a[1] * b[2] - a[2] * b[1]);
      predicted[1] += DT * m[i] * (a[2] * b[0] - a[0] * b[2]);
      predicted[2] += DT * m[i] * (a[0] * b[1] - a[1] * b[0]);
      r = fmax(r, norm3(x + 3 * i));
    }
    solid_momenta(w, p1, l1, NULL);
    const double unbalanced = r * mass * NEWTON_TOLERANCE * 9.81 * DT;
    for (int k = 0; k < 3; ++k) {
      assert_close(p1[k], p0[k], 1e-10 * pn);
      if (!(fabs(l1[k] - l0[k] - predicted[k]) <= unbalanced + 1e-12 * ln))
        fail_msg("step %d: angular momentum changed by %g, backward Euler's dt sum m v' x v is %g, "
                 "the Newton tolerance allows %g", s, l1[k] - l0[k], predicted[k], unbalanced);
    }
  }
  free(v_before);
  /* the pieces come apart: the block was stretched 1.3 times along the cut's normal, and
   * each half recoils towards its rest length, opening the crack (1.4 cm by the end) */
  const double gap = nearest_vertices_of_fragments(w);
  if (!(gap > 0.005)) fail_msg("the crack did not open: its faces' nearest vertices %g m apart", gap);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  piola_world_destroy(w);
}

/* A cut scripted at a time between two implicit steps is applied before the next step, on
 * the same state as the cut by hand: the runs agree bit for bit afterwards. */
static void scripted_cut_matches_the_cut_by_hand(void **state) {
  (void)state;
  piola_world *hand = spinning_block(), *scripted = spinning_block();
  piola_fracture_cut c = {.time = 2.5 * DT, .point = {CUT_POINT[0], CUT_POINT[1], CUT_POINT[2]},
                          .normal = {CUT_NORMAL[0], CUT_NORMAL[1], CUT_NORMAL[2]}};
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = &c, def.cut_count = 1;
  assert_int_equal(piola_world_solid_set_fracture(scripted, 0, &def), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(hand, 3 * DT, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(scripted, 3 * DT, NULL), PIOLA_OK);
  int32_t cut = 0;
  assert_int_equal(piola_world_solid_cut(hand, 0, CUT_POINT, CUT_NORMAL, &cut), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(hand, 8 * DT, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(scripted, 8 * DT, NULL), PIOLA_OK);
  assert_int_equal(piola_world_solid_cut_tet_count(scripted, 0), cut);
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(hand, 0));
  assert_int_equal(piola_elastic_body_vertex_count(piola_world_solid_body(scripted, 0)), n);
  assert_memory_equal(piola_world_solid_positions(hand, 0), piola_world_solid_positions(scripted, 0),
                      3 * sizeof(double) * (size_t)n);
  assert_memory_equal(piola_world_solid_velocities(hand, 0), piola_world_solid_velocities(scripted, 0),
                      3 * sizeof(double) * (size_t)n);
  piola_world_destroy(hand);
  piola_world_destroy(scripted);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(cut_between_implicit_steps_keeps_momentum_and_separates),
      cmocka_unit_test(scripted_cut_matches_the_cut_by_hand),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
