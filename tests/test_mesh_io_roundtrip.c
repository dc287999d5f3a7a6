/* Writers read back by the readers, the decimal parser against strtod, and malformed input
 * (from memory) refused with a status and a message naming the file and line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "test_support.h"

#include "io/mesh_io_internal.h"
#include "io/mesh_writers.h"
#include "io/text_scanner.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/mesh_quality.h"

static char tmpdir[256];

static int setup(void **state) {
  (void)state;
  return test_make_scratch_folder(tmpdir, sizeof tmpdir, "piola_mesh_io");
}

static int teardown(void **state) {
  (void)state;
  return test_remove_scratch_folder(tmpdir);
}

static const char *tmp(const char *name) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", tmpdir, name);
  return path;
}

static void load(const char *relative, piola_tet_mesh *mesh) {
  if (piola_tet_mesh_read(test_data_path(relative), mesh) != PIOLA_OK) fail_msg("%s", piola_last_error());
}

static void assert_identical(const piola_tet_mesh *a, const piola_tet_mesh *b, int regions) {
  assert_int_equal(a->vertex_count, b->vertex_count);
  assert_int_equal(a->tet_count, b->tet_count);
  assert_memory_equal(a->positions, b->positions, 3 * (size_t)a->vertex_count * sizeof(double));
  assert_memory_equal(a->tets, b->tets, 4 * (size_t)a->tet_count * sizeof(int32_t));
  if (regions) {
    assert_non_null(b->tet_regions);
    assert_memory_equal(a->tet_regions, b->tet_regions, (size_t)a->tet_count * sizeof(int32_t));
  }
}

static void tet_writers_round_trip_exactly(void **state) {
  (void)state;
  const char *sources[] = {"gmsh/cubes_v41.msh", "medit/cube_medium_tetra.mesh", "tetgen/armadillo_4k.node",
                           "vega/asianDragon.veg"};
  const char *outputs[] = {"out.msh", "out.mesh", "out.node", "out.vtu"};
  for (size_t i = 0; i < 4; ++i) {
    piola_tet_mesh a;
    load(sources[i], &a);
    /* Gmsh physical tags must be positive: shift Vega's material indices. */
    if (a.tet_regions)
      for (int32_t t = 0; t < a.tet_count; ++t) a.tet_regions[t] += 1;
    for (size_t k = 0; k < 4; ++k) {
      if (piola_tet_mesh_write(tmp(outputs[k]), &a) != PIOLA_OK) fail_msg("%s", piola_last_error());
      piola_tet_mesh b;
      if (piola_tet_mesh_read(tmp(outputs[k]), &b) != PIOLA_OK) fail_msg("%s", piola_last_error());
      assert_identical(&a, &b, a.tet_regions != NULL);
      piola_tet_mesh_free(&b);
    }
    piola_tet_mesh_free(&a);
  }
}

/* The same five-tet mesh as VTU written by piola (appended raw), by meshio (ascii and
 * inline base64) and by VTK 9's own writer (inline base64, each vector array followed by an
 * <InformationKey> child) reads like the Gmsh original. */
static void vtu_variants_read_like_the_original(void **state) {
  (void)state;
  piola_tet_mesh original;
  load("gmsh/msh_test/22_ascii.msh", &original);
  const char *files[] = {"five_tets_raw.vtu", "five_tets_ascii.vtu", "five_tets_base64.vtu",
                         "five_tets_vtk_base64.vtu"};
  for (int i = 0; i < 4; ++i) {
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/data/%s", PIOLA_SOURCE_DIR, files[i]);
    piola_tet_mesh m;
    if (piola_tet_mesh_read(path, &m) != PIOLA_OK) fail_msg("%s", piola_last_error());
    assert_int_equal(m.vertex_count, original.vertex_count);
    assert_int_equal(m.tet_count, original.tet_count);
    for (int32_t t = 0; t < m.tet_count; ++t)
      for (int k = 0; k < 4; ++k)
        for (int d = 0; d < 3; ++d)
          assert_close(m.positions[3 * m.tets[4 * t + k] + d], original.positions[3 * original.tets[4 * t + k] + d], 0);
    piola_tet_mesh_free(&m);
  }
  piola_tet_mesh_free(&original);
}

/* A text mesh that starts with a UTF-8 byte order mark (as editors on Windows save it)
 * reads as without one: Medit and Gmsh 2.2, two tets each. */
static void byte_order_mark_is_skipped(void **state) {
  (void)state;
  const char *files[] = {"bom_two_tets.mesh", "bom_two_tets.msh"};
  for (int i = 0; i < 2; ++i) {
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/data/%s", PIOLA_SOURCE_DIR, files[i]);
    piola_tet_mesh m;
    if (piola_tet_mesh_read(path, &m) != PIOLA_OK) fail_msg("%s", piola_last_error());
    assert_int_equal(m.tet_count, 2);
    piola_tet_mesh_free(&m);
  }
}

static void boundary_obj_is_the_closed_boundary(void **state) {
  (void)state;
  piola_tet_mesh a;
  load("medit/elbow.mesh", &a);
  assert_int_equal(piola_tet_mesh_write(tmp("boundary.obj"), &a), PIOLA_OK);
  piola_tri_mesh s, direct;
  assert_int_equal(piola_tri_mesh_read(tmp("boundary.obj"), &s), PIOLA_OK);
  assert_int_equal(piola_tet_mesh_boundary(&a, &direct), PIOLA_OK);
  assert_int_equal(s.triangle_count, direct.triangle_count);
  piola_surface_topology topo;
  assert_int_equal(piola_tri_mesh_topology(&s, &topo), PIOLA_OK);
  assert_true(topo.closed && topo.manifold && topo.oriented);
  assert_int_equal(topo.used_vertices, s.vertex_count); /* interior vertices dropped */
  piola_tet_mesh_quality q;
  assert_int_equal(piola_tet_mesh_measure(&a, &q), PIOLA_OK);
  assert_close(piola_tri_mesh_enclosed_volume(&s), q.volume, 1e-9 * q.volume);
  piola_tri_mesh_free(&s);
  piola_tri_mesh_free(&direct);
  piola_tet_mesh_free(&a);
}

static void surface_writers_round_trip(void **state) {
  (void)state;
  piola_tri_mesh a;
  assert_int_equal(piola_tri_mesh_read(test_data_path("surface/torus.obj"), &a), PIOLA_OK);
  const char *outputs[] = {"s.obj", "s.off", "s.stl"};
  for (int k = 0; k < 3; ++k) {
    assert_int_equal(piola_tri_mesh_write(tmp(outputs[k]), &a), PIOLA_OK);
    piola_tri_mesh b;
    if (piola_tri_mesh_read(tmp(outputs[k]), &b) != PIOLA_OK) fail_msg("%s", piola_last_error());
    assert_int_equal(a.vertex_count, b.vertex_count);
    assert_int_equal(a.triangle_count, b.triangle_count);
    /* STL is float32 (coordinates within single precision) and welding numbers vertices by
     * first appearance, so compare the corners of each triangle. */
    double tol = k == 2 ? 1e-6 : 0;
    for (int32_t i = 0; i < 3 * a.triangle_count; ++i)
      for (int d = 0; d < 3; ++d)
        assert_close(a.positions[3 * a.triangles[i] + d], b.positions[3 * b.triangles[i] + d], tol);
    piola_tri_mesh_free(&b);
  }
  piola_tri_mesh_free(&a);
}

static void writers_never_leave_partial_files(void **state) {
  (void)state;
  piola_tet_mesh a;
  load("gmsh/cube.msh", &a);
  assert_int_equal(piola_tet_mesh_write(tmp("keep.msh"), &a), PIOLA_OK);
  /* An invalid mesh is refused before anything is written; the old file stays. */
  a.tets[0] = 99;
  assert_int_not_equal(piola_tet_mesh_write(tmp("keep.msh"), &a), PIOLA_OK);
  a.tets[0] = 0;
  piola_tet_mesh b;
  assert_int_equal(piola_tet_mesh_read(tmp("keep.msh"), &b), PIOLA_OK);
  assert_int_equal(b.tet_count, 6);
  piola_tet_mesh_free(&b);
  /* A folder that does not exist: an I/O error, no crash. */
  assert_int_equal(piola_tet_mesh_write("/nonexistent-folder/x.msh", &a), PIOLA_ERROR_IO);
  piola_tet_mesh_free(&a);
}

/* A VTU with tets, triangles, point and cell fields, checked by VTK's own reader (through
 * Debian's python3-vtk9) when it is installed. */
static void vtu_with_fields_is_read_by_vtk(void **state) {
  (void)state;
  piola_tet_mesh tets;
  load("gmsh/cube.msh", &tets);
  piola_tri_mesh shell;
  assert_int_equal(piola_tet_mesh_boundary(&tets, &shell), PIOLA_OK);
  int32_t np = tets.vertex_count + shell.vertex_count, nc = tets.tet_count + shell.triangle_count;
  double *temperature = malloc((size_t)np * sizeof(double));
  double *velocity = malloc(3 * (size_t)np * sizeof(double));
  double *stress = malloc((size_t)nc * sizeof(double));
  for (int32_t i = 0; i < np; ++i) {
    temperature[i] = 300.0 + i;
    for (int k = 0; k < 3; ++k) velocity[3 * i + k] = 0.5 * i + k;
  }
  for (int32_t i = 0; i < nc; ++i) stress[i] = 1e6 * (i + 1);
  piola_vtu_field point_fields[2] = {{"temperature", 1, temperature}, {"velocity", 3, velocity}};
  piola_vtu_field cell_fields[1] = {{"stress", 1, stress}};
  piola_vtu_frame frame = {0};
  frame.tets = &tets;
  frame.triangles = &shell;
  frame.point_fields = point_fields;
  frame.point_field_count = 2;
  frame.cell_fields = cell_fields;
  frame.cell_field_count = 1;
  assert_int_equal(piola_vtu_write(tmp("frame.vtu"), &frame), PIOLA_OK);
  if (access("/usr/bin/python3", X_OK) == 0 &&
      system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") == 0) {
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 -c \""
             "import vtk, sys\n"
             "r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName('%s'); r.Update(); g = r.GetOutput()\n"
             "ok = g.GetNumberOfPoints() == %d and g.GetNumberOfCells() == %d\n"
             "ok = ok and [g.GetCellType(i) for i in (0, %d)] == [10, 5]\n"
             "t = g.GetPointData().GetArray('temperature'); v = g.GetPointData().GetArray('velocity')\n"
             "s = g.GetCellData().GetArray('stress')\n"
             "ok = ok and t.GetValue(%d) == %.1f and v.GetTuple3(2) == (1.0, 2.0, 3.0) and s.GetValue(%d) == %.1f\n"
             "sys.exit(0 if ok else 1)\"",
             tmp("frame.vtu"), np, nc, nc - 1, np - 1, 300.0 + np - 1, nc - 1, 1e6 * nc);
    assert_int_equal(system(cmd), 0);
  }
  free(temperature);
  free(velocity);
  free(stress);
  piola_tri_mesh_free(&shell);
  piola_tet_mesh_free(&tets);
}

/* piola_vtu_write -> piola_vtu_read gives back the same points, cells (tets then triangles,
 * in the file's vertex order, with their cell indices) and every field bit for bit; every
 * truncation of the file (a frame still being written) is refused. */
static void vtu_fields_round_trip_exactly(void **state) {
  (void)state;
  piola_tet_mesh tets;
  load("gmsh/cube.msh", &tets);
  piola_tri_mesh shell;
  assert_int_equal(piola_tet_mesh_boundary(&tets, &shell), PIOLA_OK);
  int32_t np = tets.vertex_count + shell.vertex_count, nc = tets.tet_count + shell.triangle_count;
  test_rng rng = test_rng_seeded(2026);
  double *x = malloc(3 * (size_t)np * sizeof(double));
  double *scalar = malloc((size_t)np * sizeof(double));
  double *vector = malloc(3 * (size_t)np * sizeof(double));
  double *energy = malloc((size_t)nc * sizeof(double));
  double *stretch = malloc(3 * (size_t)nc * sizeof(double));
  for (int32_t i = 0; i < 3 * np; ++i)
    x[i] = test_rng_normal(&rng), vector[i] = test_rng_normal(&rng) * 1e-300;
  for (int32_t i = 0; i < np; ++i)
    scalar[i] = i % 7 == 0 ? -0.0 : test_rng_uniform(&rng, -1e300, 1e300);
  for (int32_t i = 0; i < nc; ++i) energy[i] = i % 5 == 0 ? 5e-324 : test_rng_normal(&rng);
  for (int32_t i = 0; i < 3 * nc; ++i) stretch[i] = test_rng_normal(&rng) / 3;
  piola_vtu_field point_fields[2] = {{"temperature", 1, scalar}, {"velocity", 3, vector}};
  piola_vtu_field cell_fields[2] = {{"energy_density", 1, energy},
                                    {"principal_stretch", 3, stretch}};
  piola_vtu_frame frame = {0};
  frame.tets = &tets;
  frame.triangles = &shell;
  frame.point_fields = point_fields;
  frame.point_field_count = 2;
  frame.cell_fields = cell_fields;
  frame.cell_field_count = 2;
  frame.positions = x;
  assert_int_equal(piola_vtu_write(tmp("fields.vtu"), &frame), PIOLA_OK);
  piola_vtu_data d;
  if (piola_vtu_read(tmp("fields.vtu"), &d) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_int_equal(d.point_count, np);
  assert_int_equal(d.cell_count, nc);
  assert_memory_equal(d.positions, x, 3 * (size_t)np * sizeof(double));
  assert_int_equal(d.tet_count, tets.tet_count);
  assert_memory_equal(d.tets, tets.tets, 4 * (size_t)tets.tet_count * sizeof(int32_t));
  assert_int_equal(d.triangle_count, shell.triangle_count);
  for (int32_t t = 0; t < d.tet_count; ++t) assert_int_equal(d.tet_cells[t], t);
  for (int32_t t = 0; t < d.triangle_count; ++t) {
    assert_int_equal(d.triangle_cells[t], tets.tet_count + t);
    for (int k = 0; k < 3; ++k)
      assert_int_equal(d.triangles[3 * t + k], tets.vertex_count + shell.triangles[3 * t + k]);
  }
  assert_int_equal(d.point_field_count, 2);
  assert_int_equal(d.cell_field_count, 2);
  const piola_vtu_field *written[4] = {&point_fields[0], &point_fields[1], &cell_fields[0],
                                       &cell_fields[1]};
  for (int i = 0; i < 4; ++i) {
    const piola_vtu_array *a =
        i < 2 ? piola_vtu_find_field(d.point_fields, d.point_field_count, written[i]->name)
              : piola_vtu_find_field(d.cell_fields, d.cell_field_count, written[i]->name);
    assert_non_null(a);
    assert_int_equal(a->components, written[i]->components);
    size_t count = (size_t)(i < 2 ? np : nc) * (size_t)a->components;
    assert_memory_equal(a->values, written[i]->values, count * sizeof(double));
  }
  assert_null(piola_vtu_find_field(d.cell_fields, d.cell_field_count, "temperature"));
  piola_vtu_data_free(&d);
  assert_null(d.positions);
  /* truncated copies */
  FILE *in = fopen(tmp("fields.vtu"), "rb");
  assert_non_null(in);
  fseek(in, 0, SEEK_END);
  long size = ftell(in);
  fseek(in, 0, SEEK_SET);
  char *bytes = malloc((size_t)size);
  assert_int_equal(fread(bytes, 1, (size_t)size, in), (size_t)size);
  fclose(in);
  const char *tail = "\n  </AppendedData>\n</VTKFile>\n";
  long data_end = size - (long)strlen(tail);
  assert_memory_equal(bytes + data_end, tail, strlen(tail));
  for (long keep = 0; keep < data_end; keep += 1 + keep / 64) {
    FILE *out = fopen(tmp("cut.vtu"), "wb");
    assert_non_null(out);
    fwrite(bytes, 1, (size_t)keep, out);
    fclose(out);
    piola_status cut_status = piola_vtu_read(tmp("cut.vtu"), &d);
    /* a cut inside the opening tags may read as another dataset type (UNSUPPORTED) */
    if (cut_status != PIOLA_ERROR_PARSE && cut_status != PIOLA_ERROR_UNSUPPORTED)
      fail_msg("cut at %ld of %ld: %d %s", keep, size, (int)cut_status, piola_last_error());
    assert_null(d.positions);
    assert_int_equal(d.point_field_count, 0);
  }
  free(bytes);
  free(x);
  free(scalar);
  free(vector);
  free(energy);
  free(stretch);
  piola_tri_mesh_free(&shell);
  piola_tet_mesh_free(&tets);
}

static int ulps_apart(double a, double b) {
  if (a == b) return 0;
  int64_t x, y;
  memcpy(&x, &a, 8);
  memcpy(&y, &b, 8);
  int64_t d = x > y ? x - y : y - x;
  return d > 1000 ? 1000 : (int)d;
}

static void decimal_parser_is_within_one_ulp_of_strtod(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(7);
  const char *formats[] = {"%.17g", "%.15g", "%.6e", "%.9f", "%.3f", "%.16e", "%.20g", "%.0f"};
  long n = test_samples(200000, 2000);
  long exact = 0, total = 0;
  for (long i = 0; i < n; ++i) {
    double mag = pow(10.0, test_rng_uniform(&rng, -30, 30));
    double v = test_rng_uniform(&rng, -1, 1) * mag;
    if (i % 7 == 0) v = (double)(int64_t)(test_rng_uniform(&rng, -1e6, 1e6));
    char buf[64];
    int len = snprintf(buf, sizeof buf, formats[i % 8], v);
    double parsed = 0;
    size_t used = piola__parse_double(buf, buf + len, &parsed);
    if (used != (size_t)len) fail_msg("'%s': parsed %zu of %d bytes", buf, used, len);
    double reference = strtod(buf, NULL);
    int d = ulps_apart(parsed, reference);
    if (d > 1) fail_msg("'%s': %.17g vs strtod %.17g (%d ulps)", buf, parsed, reference, d);
    exact += d == 0;
    ++total;
  }
  /* Nearly all are correctly rounded, not just within an ulp. */
  assert_true(exact >= total * 99 / 100);
  const char *special[] = {"0", "-0", "1e308", "2.2250738585072014e-308", "4.9e-324", "123456789012345678901234",
                           "0.000000000000000000000000000001", ".5", "5.", "+3", "1E5", "9007199254740993"};
  for (size_t i = 0; i < sizeof special / sizeof special[0]; ++i) {
    double parsed;
    size_t len = strlen(special[i]);
    assert_int_equal(piola__parse_double(special[i], special[i] + len, &parsed), len);
    assert_true(ulps_apart(parsed, strtod(special[i], NULL)) <= 1);
  }
}

static void written_doubles_read_back_exactly(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  long n = test_samples(200000, 2000);
  for (long i = 0; i < n; ++i) {
    double v;
    if (i % 3 == 0) { /* arbitrary bit patterns, finite */
      uint64_t bits = test_rng_next(&rng);
      memcpy(&v, &bits, 8);
      if (!isfinite(v)) continue;
    } else if (i % 3 == 1) {
      v = test_rng_uniform(&rng, -1, 1) * pow(10.0, test_rng_uniform(&rng, -40, 40));
    } else { /* short decimals, as in hand-written files */
      v = (double)(int64_t)test_rng_uniform(&rng, -1e6, 1e6) / 1000.0;
    }
    char buf[32];
    int len = piola__format_double(buf, v);
    assert_true(len > 0 && len < 32);
    if (strtod(buf, NULL) != v) fail_msg("%.17g written as '%s'", v, buf);
    if (i % 3 == 2) assert_true(len <= 12); /* short values stay short */
  }
}

typedef struct bad_case {
  const char *name; /* decides the reader */
  const char *text;
  piola_status status;
  const char *message; /* substring expected in the error */
} bad_case;

static piola_status read_named(const char *name, const char *text, size_t size) {
  piola_tet_mesh m;
  piola_tri_mesh s;
  piola_status st;
  const char *ext = strrchr(name, '.');
  if (strcmp(ext, ".msh") == 0) st = piola__read_gmsh_mem(name, text, size, &m);
  else if (strcmp(ext, ".mesh") == 0) st = piola__read_medit_mem(name, text, size, &m);
  else if (strcmp(ext, ".veg") == 0) {
    piola_vega_material *mat;
    int32_t n;
    st = piola__read_vega_mem(name, text, size, &m, &mat, &n);
    if (st == PIOLA_OK) free(mat);
  } else if (strcmp(ext, ".ele") == 0) {
    const char *node = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
    st = piola__read_tetgen_mem("a.node", node, strlen(node), name, text, size, &m);
  } else if (strcmp(ext, ".node") == 0) {
    const char *ele = "1 4 0\n1 1 2 3 4\n";
    st = piola__read_tetgen_mem(name, text, size, "a.ele", ele, strlen(ele), &m);
  } else if (strcmp(ext, ".obj") == 0) st = piola__read_obj_mem(name, text, size, &s);
  else if (strcmp(ext, ".off") == 0) st = piola__read_off_mem(name, text, size, &s);
  else st = piola__read_stl_mem(name, text, size, &s);
  if (st == PIOLA_OK) fail_msg("%s was accepted", name);
  return st;
}

static void malformed_input_is_refused_with_file_and_line(void **state) {
  (void)state;
  static const bad_case cases[] = {
      {"trunc.node", "2 3 0 0\n1 0 0 0\n2 1.5 0.25", PIOLA_ERROR_PARSE, "trunc.node:3: unexpected end of file"},
      {"nan.node", "4 3 0 0\n1 0 0 0\n2 nan 0 0\n3 0 1 0\n4 0 0 1\n", PIOLA_ERROR_PARSE, "nan.node:3: coordinate is not finite"},
      {"inf.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1e999 0\n4 0 0 1\n", PIOLA_ERROR_PARSE, "inf.node:4:"},
      {"huge.node", "2000000000 3 0 0\n1 0 0 0\n", PIOLA_ERROR_PARSE, "huge.node:1: node count 2000000000 does not fit"},
      {"range.ele", "1 4 0\n1 1 2 3 9\n", PIOLA_ERROR_PARSE, "range.ele:2: tet 1: node 9 out of range"},
      {"flat.ele", "1 4 0\n1 1 2 3 3\n", PIOLA_ERROR_DEGENERATE_ELEMENT, "flat.ele:2: tet 0"},
      {"twice.ele", "2 4 0\n1 1 2 3 4\n2 2 1 3 4\n", PIOLA_ERROR_PARSE, "twice.ele:3: tet 1 (element 2 in the file) duplicates tet 0"},
      {"words.ele", "1 4 0\n1 1 2 three 4\n", PIOLA_ERROR_PARSE, "words.ele:2: expected node index (an integer), got 'three'"},
      {"none.msh", "", PIOLA_ERROR_PARSE, "none.msh:1: not a Gmsh file"},
      {"v3.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", PIOLA_ERROR_UNSUPPORTED, "v3.msh:2: MSH version '3.0'"},
      {"notets.msh",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 2 0 1 2 3\n$EndElements\n",
       PIOLA_ERROR_PARSE, "notets.msh: the mesh has no tetrahedra"},
      {"count.msh",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n",
       PIOLA_ERROR_PARSE, "count.msh:9: expected $EndNodes"},
      {"tag.msh",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 7\n$EndElements\n",
       PIOLA_ERROR_PARSE, "uses node tag 7"},
      {"big.msh", "$MeshFormat\n4.1 1 8\n\x00\x00\x00\x01\n$EndMeshFormat\n", PIOLA_ERROR_UNSUPPORTED, "big-endian"},
      {"nover.mesh", "MeshVersionFormatted 2\nDimension 2\n", PIOLA_ERROR_UNSUPPORTED, "nover.mesh:2: Dimension 2"},
      {"kw.mesh", "MeshVersionFormatted 2\nDimension 3\nBananas 3\n", PIOLA_ERROR_UNSUPPORTED, "kw.mesh:3: unknown keyword 'Bananas'"},
      {"empty.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n0\nTetrahedra\n0\nEnd\n", PIOLA_ERROR_PARSE, "no tetrahedra"},
      {"cubic.veg", "*VERTICES\n1 3 0 0\n1 0 0 0\n*ELEMENTS\nCUBIC\n", PIOLA_ERROR_UNSUPPORTED, "cubic.veg:5: element type CUBIC"},
      {"mat.veg", "*VERTICES\n4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n*ELEMENTS\nTET\n1 4 0\n1 1 2 3 4\n*REGION\nallElements, NOPE\n",
       PIOLA_ERROR_PARSE, "mat.veg:12: *REGION names unknown material 'NOPE'"},
      {"face.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n", PIOLA_ERROR_PARSE, "face.obj:3: face vertex index 3 out of range"},
      {"neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", PIOLA_ERROR_PARSE, "neg.obj:4:"},
      {"off.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", PIOLA_ERROR_PARSE, "off.off:6: face 0: vertex 5 out of range"},
      {"bad.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n", PIOLA_ERROR_PARSE, "bad.stl:6:"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const bad_case *c = &cases[i];
    size_t size = strlen(c->text);
    if (strcmp(c->name, "big.msh") == 0) size = 42; /* contains NUL bytes */
    piola_status s = read_named(c->name, c->text, size);
    if (s != c->status || !strstr(piola_last_error(), c->message))
      fail_msg("%s: status %d, message '%s'; expected %d and '%s'", c->name, s, piola_last_error(), c->status,
               c->message);
  }
}

static void mixed_face_forms_and_polygons_in_obj(void **state) {
  (void)state;
  const char *text = "# quad and triangle with every corner form\n"
                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
                     "f 1 2/1 3//1 4/1/1\n"
                     "f -5 -4 -1\n";
  piola_tri_mesh m;
  assert_int_equal(piola__read_obj_mem("forms.obj", text, strlen(text), &m), PIOLA_OK);
  assert_int_equal(m.vertex_count, 5);
  assert_int_equal(m.triangle_count, 3);
  const int32_t expected[9] = {0, 1, 2, 0, 2, 3, 0, 1, 4};
  assert_memory_equal(m.triangles, expected, sizeof expected);
  piola_tri_mesh_free(&m);
}

static void ascii_stl_is_welded_and_off_polygons_split(void **state) {
  (void)state;
  /* The unit tet's surface, wound outward, corners repeated per facet. */
  const char *stl = "solid tet\n"
                    " facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0\n"
                    "  endloop\n endfacet\n"
                    " facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 0 1\n"
                    "  endloop\n endfacet\n"
                    " facet normal -1 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 0 0 1\n   vertex -0 1 0\n"
                    "  endloop\n endfacet\n"
                    " facet normal 1 1 1\n  outer loop\n   vertex 1 0 0\n   vertex 0 1 0\n   vertex 0 0 1\n"
                    "  endloop\n endfacet\n"
                    "endsolid tet\n";
  piola_tri_mesh m;
  if (piola__read_stl_mem("tet.stl", stl, strlen(stl), &m) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_int_equal(m.vertex_count, 4); /* 12 corners welded, -0 with +0 */
  assert_int_equal(m.triangle_count, 4);
  piola_surface_topology topo;
  assert_int_equal(piola_tri_mesh_topology(&m, &topo), PIOLA_OK);
  assert_true(topo.closed && topo.manifold && topo.oriented);
  assert_int_equal(topo.euler_characteristic, 2);
  assert_close(piola_tri_mesh_enclosed_volume(&m), 1.0 / 6.0, 1e-15);
  piola_tri_mesh_free(&m);
  /* A cube as six quads: 12 triangles, closed, volume 1. */
  const char *off = "OFF\n# cube\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7 255 0 0\n";
  assert_int_equal(piola__read_off_mem("cube.off", off, strlen(off), &m), PIOLA_OK);
  assert_int_equal(m.triangle_count, 12);
  assert_int_equal(piola_tri_mesh_topology(&m, &topo), PIOLA_OK);
  assert_true(topo.closed && topo.manifold && topo.oriented);
  assert_close(piola_tri_mesh_enclosed_volume(&m), 1.0, 1e-15);
  piola_tri_mesh_free(&m);
}

static void loaded_tets_are_oriented_positively(void **state) {
  (void)state;
  /* The second tet is stored inverted; the reader flips it. */
  const char *node = "# comment\n5 3 0 0\n0 0 0 0\n1 1 0 0 # trailing comment\n2 0 1 0\n3 0 0 1\n4 0 0 -1\n";
  const char *ele = "2 4 1\n0 0 1 2 3 7\n1 0 1 2 4 8\n";
  piola_tet_mesh m;
  assert_int_equal(piola__read_tetgen_mem("o.node", node, strlen(node), "o.ele", ele, strlen(ele), &m), PIOLA_OK);
  assert_int_equal(m.vertex_count, 5);
  for (int32_t t = 0; t < 2; ++t) assert_true(piola_tet_mesh_signed_volume(&m, t) > 0);
  assert_int_equal(m.tet_regions[0], 7);
  assert_int_equal(m.tet_regions[1], 8);
  piola_tet_mesh_free(&m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(tet_writers_round_trip_exactly),
      cmocka_unit_test(vtu_variants_read_like_the_original),
      cmocka_unit_test(byte_order_mark_is_skipped),
      cmocka_unit_test(boundary_obj_is_the_closed_boundary),
      cmocka_unit_test(surface_writers_round_trip),
      cmocka_unit_test(writers_never_leave_partial_files),
      cmocka_unit_test(vtu_with_fields_is_read_by_vtk),
      cmocka_unit_test(vtu_fields_round_trip_exactly),
      cmocka_unit_test(decimal_parser_is_within_one_ulp_of_strtod),
      cmocka_unit_test(written_doubles_read_back_exactly),
      cmocka_unit_test(malformed_input_is_refused_with_file_and_line),
      cmocka_unit_test(mixed_face_forms_and_polygons_in_obj),
      cmocka_unit_test(loaded_tets_are_oriented_positively),
      cmocka_unit_test(ascii_stl_is_welded_and_off_polygons_split),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
