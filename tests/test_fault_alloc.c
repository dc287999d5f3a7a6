/* Allocation failures at every allocation of scene loading, mesh reading and world creation.
 *
 * This test is linked with -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc (CMakeLists.txt),
 * so every allocation piola makes goes through the wrappers below; cJSON's go there too
 * (cJSON_InitHooks). An operation is first run to count its allocations, then once per
 * allocation k with the k-th one failing (as SQLite's malloc tests do): each run must
 * return an error with a message (or succeed, where the code has a fallback), free what
 * it took (AddressSanitizer's leak check fails the test otherwise) and never crash. */
#include <cjson/cJSON.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"

#include "piola/mesh_io.h"
#include "piola/scene.h"
#include "piola/threads.h"

void *__real_malloc(size_t size);
void *__real_calloc(size_t count, size_t size);
void *__real_realloc(void *p, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t count, size_t size);
void *__wrap_realloc(void *p, size_t size);

static atomic_long allocations; /* since arm() */
static long fail_at = -1;       /* the allocation (1-based) that fails; -1: none */
static atomic_int failed;       /* the armed failure happened */

static int fails_now(void) {
  long k = atomic_fetch_add(&allocations, 1) + 1;
  if (k != fail_at) return 0;
  atomic_store(&failed, 1);
  return 1;
}
void *__wrap_malloc(size_t size) { return fails_now() ? NULL : __real_malloc(size); }
void *__wrap_calloc(size_t count, size_t size) {
  return fails_now() ? NULL : __real_calloc(count, size);
}
void *__wrap_realloc(void *p, size_t size) { return fails_now() ? NULL : __real_realloc(p, size); }
static void *json_malloc(size_t size) { return __wrap_malloc(size); }

static void arm(long k) {
  atomic_store(&allocations, 0);
  atomic_store(&failed, 0);
  fail_at = k;
}

/* An operation under test: returns its status and frees whatever it built. */
typedef piola_status (*operation)(const void *arg);

/* Runs op once per allocation it makes, failing that allocation. */
static void fail_each_allocation(operation op, const void *arg, const char *name) {
  arm(-1);
  assert_int_equal(op(arg), PIOLA_OK);
  long total = atomic_load(&allocations);
  assert_true(total > 0);
  /* every allocation normally; a stride under the sanitizers' smaller PIOLA_TEST_SCALE */
  long stride = (long)(1.0 / test_scale() + 0.5);
  if (stride < 1) stride = 1;
  long errors = 0, runs = 0;
  for (long k = 1; k <= total; k += stride) {
    arm(k);
    piola_clear_error();
    piola_status st = op(arg);
    arm(-1);
    runs++;
    if (st != PIOLA_OK) {
      errors++;
      if (piola_last_error()[0] == '\0')
        fail_msg("%s: allocation %ld of %ld failed: status %d without a message", name, k, total,
                 st);
    }
  }
  printf(
      "%s: %ld allocations, %ld failed in turn: %ld gave an error with a message, %ld recovered\n",
      name, total, runs, errors, runs - errors);
  /* nearly every allocation is essential: most failures must be reported */
  assert_true(errors >= runs / 2);
}

static piola_status load_scene(const void *arg) {
  piola_scene *scene = NULL;
  piola_status st = piola_scene_load_string(arg, PIOLA_DATA_DIR "/tetgen", "fault.json", &scene);
  piola_scene_destroy(scene);
  return st;
}

static piola_status read_tets(const void *arg) {
  piola_tet_mesh mesh = {0};
  piola_status st = piola_tet_mesh_read(arg, &mesh);
  piola_tet_mesh_free(&mesh);
  return st;
}

static piola_status read_surface(const void *arg) {
  piola_tri_mesh mesh = {0};
  piola_status st = piola_tri_mesh_read(arg, &mesh);
  piola_tri_mesh_free(&mesh);
  return st;
}

/* Scene loading and world creation: a solid from a mesh file, a generated plastic solid
 * with constraints, a shell, obstacles with motions and a bone. */
static void scene_loading_and_world_creation(void **state) {
  (void)state;
  static const char scene[] =
      "{\"fps\": 30, \"frames\": 2, \"gravity\": [0, 0, -9.81],"
      " \"solids\": ["
      "  {\"name\": \"oct\", \"mesh\": \"octahedron.node\", \"transform\": {\"scale\": 0.1}},"
      "  {\"name\": \"bar\", \"mesh\": {\"generate\": \"box\", \"center\": [1, 0, 0], "
      "\"half_extents\": [0.2, 0.05, 0.05], \"cell_size\": 0.05},"
      "   \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 1e5, \"poisson_ratio\": "
      "0.3},"
      "   \"damping\": {\"shear\": 1, \"bulk\": 1}, \"fixed\": [{\"box\": [[0.7, -1, -1], [0.85, "
      "1, 1]]}],"
      "   \"plasticity\": {\"yield\": 0.01, \"limit\": 1.0, \"hardening\": 0.5}}],"
      " \"shells\": [{\"name\": \"sheet\", \"mesh\": {\"generate\": \"torus\", \"radius\": 0.2, "
      "\"minor_radius\": 0.05,"
      "   \"segments\": [8, 6], \"sweep_degrees\": 180}, \"transform\": {\"translate\": [0, 1, "
      "0]}, \"thickness\": 0.004,"
      "   \"bending\": {\"stiffness\": 1e-3}}],"
      " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, -1], \"normal\": [0, 0, 1]},"
      "   {\"type\": \"sphere\", \"center\": [0, 0, 1], \"radius\": 0.1,"
      "    \"motion\": {\"translation\": [0, 0, {\"keys\": [[0, 0], [1, -0.5]]}]}}],"
      " \"bones\": [{\"name\": \"grip\", \"type\": \"box\", \"center\": [1.2, 0, 0], "
      "\"half_extents\": [0.02, 0.1, 0.1],"
      "   \"attachments\": [{\"solid\": \"bar\", \"within\": 0.01}]}]}";
  fail_each_allocation(load_scene, scene, "scene");
}

static void mesh_reading(void **state) {
  (void)state;
  static const char *const tets[] = {PIOLA_DATA_DIR "/tetgen/octahedron.node",
                                     PIOLA_DATA_DIR "/gmsh/tet.msh",
                                     PIOLA_DATA_DIR "/gmsh/msh_tetra.msh",
                                     PIOLA_DATA_DIR "/medit/unit_ball.mesh",
                                     PIOLA_DATA_DIR "/vega/beam3_tet.veg",
                                     PIOLA_SOURCE_DIR "/tests/data/five_tets_base64.vtu"};
  for (size_t i = 0; i < sizeof tets / sizeof *tets; ++i)
    fail_each_allocation(read_tets, tets[i], tets[i]);
  fail_each_allocation(read_surface, PIOLA_DATA_DIR "/surface/sphere.obj", "sphere.obj");
  /* OFF and STL: written from the sphere first */
  piola_tri_mesh sphere = {0};
  assert_int_equal(piola_tri_mesh_read(PIOLA_DATA_DIR "/surface/sphere.obj", &sphere), PIOLA_OK);
  char dir[] = "/tmp/piola_fault_XXXXXX", off[64], stl[64];
  assert_non_null(mkdtemp(dir));
  snprintf(off, sizeof off, "%s/s.off", dir);
  snprintf(stl, sizeof stl, "%s/s.stl", dir);
  assert_int_equal(piola_tri_mesh_write(off, &sphere), PIOLA_OK);
  assert_int_equal(piola_tri_mesh_write(stl, &sphere), PIOLA_OK);
  piola_tri_mesh_free(&sphere);
  fail_each_allocation(read_surface, off, "s.off");
  fail_each_allocation(read_surface, stl, "s.stl");
  remove(off), remove(stl), remove(dir);
}

int main(void) {
  piola_set_thread_count(1); /* one allocation order */
  cJSON_Hooks hooks = {json_malloc, free};
  cJSON_InitHooks(&hooks);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(mesh_reading),
      cmocka_unit_test(scene_loading_and_world_creation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
