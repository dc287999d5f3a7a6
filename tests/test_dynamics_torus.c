/* The default demo at a coarse mesh (paper Figure 2): a torus whose stiffness is keyframed
 * to zero falls into a puddle on the ground, where most elements flatten or invert, and
 * recovers its rest volume when the stiffness comes back. Built through the scene loader,
 * so the keyframed stiffness and damping, the mesher and the ground plane are all on the
 * path under test. Like examples/torus_puddle.json it sets LINEAR at 0.3: neo-Hookean's default
 * CLAMP at 0.5 brings the puddle back more slowly (materials.md, "Defaults that recover"). */
#include "test_support.h"

#include <math.h>
#include <stdio.h>

#include "piola/scene.h"
#include "piola/threads.h"

static double volume(const piola_world *w, const double *x) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const int32_t *tets = piola_elastic_body_tets(b);
  double v = 0;
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) {
    const double *a = x + 3 * tets[4 * t], *p = x + 3 * tets[4 * t + 1], *q = x + 3 * tets[4 * t + 2],
                 *r = x + 3 * tets[4 * t + 3];
    double e1[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double e2[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]};
    double e3[3] = {r[0] - a[0], r[1] - a[1], r[2] - a[2]};
    v += (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
          e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) / 6;
  }
  return v;
}

static const char *SCENE =
    "{\"fps\": 20, \"gravity\": [0, 0, -9.81], \"integrator\": {\"max_dt\": 0.002, \"cfl\": 0.7},\n"
    " \"solids\": [{\"mesh\": {\"generate\": \"torus\", \"axis\": [0, 1, 0], \"radius\": 0.3,\n"
    "                        \"minor_radius\": 0.12, \"cell_size\": 0.1},\n"
    "   \"transform\": {\"translate\": [0, 0, 0.45]},\n"
    "   \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 2e4, \"poisson_ratio\": 0.3,\n"
    "                \"inversion\": {\"mode\": \"linear\", \"threshold\": 0.3},\n"
    "                \"stiffness_scale\": {\"keys\": [[0.2, 1], [0.3, 0], [1.2, 0], [1.5, 1]]}},\n"
    "   \"damping\": {\"shear\": {\"keys\": [[0.2, 40], [0.3, 1], [1.2, 1], [1.5, 40]]},\n"
    "               \"bulk\": {\"keys\": [[0.2, 40], [0.3, 1], [1.2, 1], [1.5, 40]]}}}],\n"
    " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1], \"friction\": 0.4}]}";

static void torus_collapses_and_recovers_its_volume(void **state) {
  (void)state;
  piola_scene *scene = NULL;
  if (piola_scene_load_string(SCENE, ".", "torus", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  int32_t tets = piola_elastic_body_tet_count(b);
  double rest = volume(w, piola_elastic_body_rest_positions(b));
  assert_true(rest > 0);
  int32_t most_inverted = 0;
  double smallest = INFINITY, final_sum = 0;
  int final_count = 0;
  for (int f = 1; f <= 60; ++f) {
    if (piola_world_advance_to(w, f / 20.0, NULL) != PIOLA_OK) fail_msg("frame %d: %s", f, piola_last_error());
    /* stiffness off: judge the collapse on the geometry (det F of the positions) */
    const double *det = piola_elastic_body_det_f(b);
    /* in the puddle every node lies on the ground, so most elements are exactly flat
     * (det F = 0) rather than strictly inverted: count flat and inverted together */
    int32_t inverted = 0;
    for (int32_t t = 0; t < tets; ++t) inverted += det[t] < 1e-3;
    if (inverted > most_inverted) most_inverted = inverted;
    double v = volume(w, piola_world_solid_positions(w, 0));
    if (v < smallest) smallest = v;
    if (f > 50) final_sum += v, final_count++;
  }
  double recovered = final_sum / final_count;
  printf("# torus: %d tets, rest volume %.5g m^3, smallest %.5g, recovered %.5g; at most %d flat or inverted\n",
         (int)tets, rest, smallest, recovered, (int)most_inverted);
  if (!(smallest < 0.5 * rest)) fail_msg("did not collapse: smallest volume %g of rest %g", smallest, rest);
  if (!(most_inverted > tets / 2))
    fail_msg("only %d of %d tets flat or inverted", (int)most_inverted, (int)tets);
  if (fabs(recovered - rest) > 0.05 * rest)
    fail_msg("recovered volume %g m^3 is not within 5%% of rest %g m^3", recovered, rest);
  piola_scene_destroy(scene);
}

int main(void) {
  /* tiny meshes: one thread avoids OpenMP barrier overhead on a shared machine; forces are
   * identical whatever the thread count */
  piola_set_thread_count(1); /* every parallel loop of piola, collisions included */
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(torus_collapses_and_recovers_its_volume),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
