/* Mesh readers on the real files in shared/data: counts from SOURCES.md (counted there by an
 * independent parser), orientation, boundaries, regions, and equivalence of one mesh stored
 * in several formats. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"

#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/mesh_quality.h"

typedef struct tet_file {
  const char *path;
  int32_t vertices, tets, boundary;
  double min_quality; /* from SOURCES.md, rounded to 3 digits */
  int euler;
} tet_file;

static const tet_file tet_files[] = {
    {"tetgen/armadillo_4k.node", 1180, 3717, 2102, 0.023, 2},
    {"tetgen/octahedron.ele", 330, 1224, 464, 0.107, 2},
    {"tetgen/armadillo_10k.node", 14779, 54855, 23010, 0.024, 2},
    {"gmsh/msh_tetra.msh", 66, 127, 128, 0.418, 2},
    {"gmsh/cubes_v22.msh", 7714, 32981, 7610, 0.232, 2},
    {"gmsh/cubes_v41.msh", 7714, 32981, 7610, 0.232, 2},
    {"gmsh/msh_test/22_ascii.msh", 8, 5, 12, 0.657, 2},
    {"gmsh/msh_test/22_binary.msh", 8, 5, 12, 0.657, 2},
    {"gmsh/msh_test/41_ascii.msh", 8, 5, 12, 0.657, 2},
    {"gmsh/msh_test/41_binary.msh", 8, 5, 12, 0.657, 2},
    {"gmsh/gmsh_physical_sides_3d_v41.msh", 5, 2, 6, 0.770, 2},
    {"gmsh/tet.msh", 4, 1, 4, 0.770, 2},
    {"gmsh/cube.msh", 8, 6, 12, 0.657, 2},
    {"gmsh/torus.msh", 200, 491, 400, 0.080, 0},
    {"gmsh/bar-186.msh", 86, 186, 168, 0.020, 2},
    {"gmsh/bar-2523.msh", 886, 2523, 1618, 0.020, 2},
    {"gmsh/bunny.msh", 4670, 19379, 6266, 0.004, 2},
    {"gmsh/Armadillo13K.msh", 13230, 54985, 17296, 0.020, 2},
    {"medit/cylinder.mesh", 354, 1348, 440, 0.361, 2},
    {"medit/cube_medium_tetra.mesh", 448, 1782, 528, 0.377, 2},
    {"medit/unit_ball.mesh", 363, 1110, 602, 0.176, 2},
    {"medit/elbow.mesh", 1823, 8161, 1678, 0.326, 2},
    {"medit/square_beam.mesh", 739, 2886, 894, 0.303, 2},
    {"medit/octopus-low.mesh", 452, 1140, 898, 0.010, 2},
    {"vega/beam3_tet.veg", 208, 450, 412, 0.570, 2},
    {"vega/turtle-volumetric-homogeneous.veg", 347, 1185, 530, 0.139, 2},
    {"vega/asianDragon.veg", 959, 2591, 1854, 0.069, 2},
    {"vega/torus-easy.veg", 20186, 97878, 15044, 0.570, -2},
};

static void load(const char *relative, piola_tet_mesh *mesh) {
  piola_status s = piola_tet_mesh_read(test_data_path(relative), mesh);
  if (s != PIOLA_OK) fail_msg("%s: %s", relative, piola_last_error());
}

static void every_tet_file_loads_with_the_documented_counts(void **state) {
  (void)state;
  for (size_t i = 0; i < sizeof tet_files / sizeof tet_files[0]; ++i) {
    const tet_file *f = &tet_files[i];
    piola_tet_mesh mesh;
    load(f->path, &mesh);
    if (mesh.vertex_count != f->vertices || mesh.tet_count != f->tets)
      fail_msg("%s: %d vertices, %d tets; expected %d, %d", f->path, mesh.vertex_count, mesh.tet_count, f->vertices,
               f->tets);
    assert_int_equal(piola_tet_mesh_validate(&mesh), PIOLA_OK);
    for (int32_t t = 0; t < mesh.tet_count; ++t)
      if (!(piola_tet_mesh_signed_volume(&mesh, t) > 0)) fail_msg("%s: tet %d not positive", f->path, t);
    piola_tri_mesh boundary;
    assert_int_equal(piola_tet_mesh_boundary(&mesh, &boundary), PIOLA_OK);
    if (boundary.triangle_count != f->boundary)
      fail_msg("%s: %d boundary triangles, expected %d", f->path, boundary.triangle_count, f->boundary);
    piola_surface_topology topo;
    assert_int_equal(piola_tri_mesh_topology(&boundary, &topo), PIOLA_OK);
    if (!topo.closed || !topo.manifold || !topo.oriented || topo.euler_characteristic != f->euler)
      fail_msg("%s: closed %d manifold %d oriented %d euler %d", f->path, topo.closed, topo.manifold, topo.oriented,
               topo.euler_characteristic);
    /* Outward winding: the boundary encloses the mesh volume. */
    piola_tet_mesh_quality q;
    assert_int_equal(piola_tet_mesh_measure(&mesh, &q), PIOLA_OK);
    assert_close(piola_tri_mesh_enclosed_volume(&boundary), q.volume, 1e-9 * fabs(q.volume));
    if (fabs(q.min_mean_ratio - f->min_quality) > 0.0005 + 1e-12)
      fail_msg("%s: min quality %.4f, SOURCES.md says %.3f", f->path, q.min_mean_ratio, f->min_quality);
    piola_tri_mesh_free(&boundary);
    piola_tet_mesh_free(&mesh);
  }
}

static void octahedron_volume_is_exact(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  load("tetgen/octahedron.node", &mesh);
  piola_tet_mesh_quality q;
  assert_int_equal(piola_tet_mesh_measure(&mesh, &q), PIOLA_OK);
  /* |x|+|y|+|z| <= 4: volume 4/3 * 4^3 = 85.333... */
  assert_close(q.volume, 4.0 / 3.0 * 64.0, 1e-9);
  assert_non_null(mesh.tet_regions);
  for (int32_t t = 0; t < mesh.tet_count; ++t) assert_int_equal(mesh.tet_regions[t], 100);
  piola_tet_mesh_free(&mesh);
}

/* Same mesh: identical tets in the same order, same coordinates per tet corner. */
static void assert_same_mesh(const char *a_path, const char *b_path, int compare_regions) {
  piola_tet_mesh a, b;
  load(a_path, &a);
  load(b_path, &b);
  assert_int_equal(a.vertex_count, b.vertex_count);
  assert_int_equal(a.tet_count, b.tet_count);
  for (int32_t t = 0; t < a.tet_count; ++t)
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) {
        double x = a.positions[3 * a.tets[4 * t + k] + d], y = b.positions[3 * b.tets[4 * t + k] + d];
        if (x != y) fail_msg("%s vs %s: tet %d corner %d differs (%.17g vs %.17g)", a_path, b_path, t, k, x, y);
      }
  if (compare_regions)
    for (int32_t t = 0; t < a.tet_count; ++t) assert_int_equal(a.tet_regions[t], b.tet_regions[t]);
  piola_tet_mesh_free(&a);
  piola_tet_mesh_free(&b);
}

static void one_mesh_in_several_formats_loads_the_same(void **state) {
  (void)state;
  assert_same_mesh("gmsh/msh_test/22_ascii.msh", "gmsh/msh_test/22_binary.msh", 1);
  assert_same_mesh("gmsh/msh_test/22_ascii.msh", "gmsh/msh_test/41_ascii.msh", 1);
  assert_same_mesh("gmsh/msh_test/22_ascii.msh", "gmsh/msh_test/41_binary.msh", 1);
  assert_same_mesh("gmsh/cubes_v22.msh", "gmsh/cubes_v41.msh", 1);
}

static void count_region(const piola_tet_mesh *m, int32_t region, int32_t expected) {
  int32_t n = 0;
  for (int32_t t = 0; t < m->tet_count; ++t) n += m->tet_regions[t] == region;
  if (n != expected) fail_msg("region %d has %d tets, expected %d", region, n, expected);
}

static void regions_come_from_physical_groups_and_refs(void **state) {
  (void)state;
  const char *cubes[] = {"gmsh/cubes_v22.msh", "gmsh/cubes_v41.msh"};
  for (int i = 0; i < 2; ++i) {
    piola_tet_mesh m;
    load(cubes[i], &m);
    count_region(&m, 1, 12285);
    count_region(&m, 2, 8726);
    count_region(&m, 3, 11970);
    piola_tet_mesh_free(&m);
  }
  piola_tet_mesh m;
  load("gmsh/msh_test/41_ascii.msh", &m);
  /* 3 volumes with 1/3/1 tets */
  int32_t counts[8] = {0};
  for (int32_t t = 0; t < m.tet_count; ++t) {
    assert_true(m.tet_regions[t] >= 0 && m.tet_regions[t] < 8);
    counts[m.tet_regions[t]]++;
  }
  int ones = 0, threes = 0;
  for (int r = 0; r < 8; ++r) {
    ones += counts[r] == 1;
    threes += counts[r] == 3;
  }
  assert_int_equal(ones, 2);
  assert_int_equal(threes, 1);
  piola_tet_mesh_free(&m);
  load("medit/cube_medium_tetra.mesh", &m);
  count_region(&m, 1, 891);
  count_region(&m, 2, 891);
  piola_tet_mesh_free(&m);
  load("gmsh/tet.msh", &m); /* no $Entities, entity tag 0 */
  count_region(&m, 0, 1);
  piola_tet_mesh_free(&m);
}

static void vega_materials_and_regions(void **state) {
  (void)state;
  piola_tet_mesh m;
  piola_vega_material *materials = NULL;
  int32_t count = 0;
  assert_int_equal(piola_vega_read(test_data_path("vega/asianDragon.veg"), &m, &materials, &count), PIOLA_OK);
  assert_int_equal(count, 2);
  assert_string_equal(materials[0].name, "defaultMaterial");
  assert_string_equal(materials[1].name, "BODY");
  assert_close(materials[1].density, 1000, 0);
  assert_close(materials[1].youngs_modulus, 1e7, 0);
  assert_close(materials[1].poisson_ratio, 0.4, 0);
  assert_close(materials[0].youngs_modulus, 1e9, 0);
  count_region(&m, 1, 2591); /* *REGION allElements, BODY */
  free(materials);
  piola_tet_mesh_free(&m);
}

static void cubic_vega_elements_are_refused(void **state) {
  (void)state;
  piola_tet_mesh m;
  piola_status s = piola_tet_mesh_read(test_data_path("vega/beam3.veg"), &m);
  assert_int_equal(s, PIOLA_ERROR_UNSUPPORTED);
  assert_non_null(strstr(piola_last_error(), "beam3.veg:216:"));
  assert_non_null(strstr(piola_last_error(), "CUBIC"));
  assert_null(m.positions);
  assert_null(m.tets);
}

typedef struct tri_file {
  const char *path;
  int32_t vertices, triangles;
  double volume;
  int genus;
} tri_file;

static void every_surface_loads_closed_with_its_volume(void **state) {
  (void)state;
  static const tri_file files[] = {
      {"surface/torus.obj", 400, 800, 4.77458, 1},
      {"surface/sphere.obj", 382, 760, 4.09487, 0},
      {"surface/bunny_10k.obj", 5002, 10000, 0.222823, 0},
      {"surface/armadillo_low_res.obj", 2013, 4022, 0.000229329, 0},
      {"surface/armadillo_high_res.obj", 7502, 15000, 0.000229329, 0},
      {"surface/starfish.stl", 8436, 16868, 127225, 0},
  };
  for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
    piola_tri_mesh m;
    piola_status s = piola_tri_mesh_read(test_data_path(files[i].path), &m);
    if (s != PIOLA_OK) fail_msg("%s", piola_last_error());
    if (m.vertex_count != files[i].vertices || m.triangle_count != files[i].triangles)
      fail_msg("%s: %d vertices %d triangles", files[i].path, m.vertex_count, m.triangle_count);
    piola_surface_topology topo;
    assert_int_equal(piola_tri_mesh_topology(&m, &topo), PIOLA_OK);
    assert_true(topo.closed && topo.manifold && topo.oriented);
    assert_int_equal(topo.euler_characteristic, 2 - 2 * files[i].genus);
    assert_close(piola_tri_mesh_enclosed_volume(&m), files[i].volume, 1e-5 * files[i].volume);
    piola_tri_mesh_free(&m);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_tet_file_loads_with_the_documented_counts),
      cmocka_unit_test(octahedron_volume_is_exact),
      cmocka_unit_test(one_mesh_in_several_formats_loads_the_same),
      cmocka_unit_test(regions_come_from_physical_groups_and_refs),
      cmocka_unit_test(vega_materials_and_regions),
      cmocka_unit_test(cubic_vega_elements_are_refused),
      cmocka_unit_test(every_surface_loads_closed_with_its_volume),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
