/* Frames on disk: the renderer reads the VTU files piola writes, extracts the boundary
 * surface with each face's tet, carries per-cell flags and fields to the faces, and the
 * inverted colouring shows red exactly when the frame has inverted tets. Also: PNG round
 * trip and contact sheets. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/mesh_io.h"
#include "piola/render.h"
#include "test_render_support.h"
#include "test_support.h"

static char folder[256];

static int make_folder(void **state) {
  (void)state;
  return test_make_scratch_folder(folder, sizeof folder, "piola_test_render_frame");
}

static int remove_folder(void **state) {
  (void)state;
  return test_remove_scratch_folder(folder);
}

/* An n x n x n grid of unit cubes of size h, each cut into 6 tets around its main
 * diagonal (Kuhn), all positively oriented. */
static piola_tet_mesh cube_grid(int n, double h) {
  piola_tet_mesh m;
  memset(&m, 0, sizeof m);
  int p = n + 1;
  m.vertex_count = p * p * p;
  m.tet_count = 6 * n * n * n;
  m.positions = malloc(3 * (size_t)m.vertex_count * sizeof(double));
  m.tets = malloc(4 * (size_t)m.tet_count * sizeof(int32_t));
  for (int k = 0; k < p; ++k)
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < p; ++i) {
        double *x = m.positions + 3 * ((size_t)(k * p + j) * p + i);
        x[0] = i * h, x[1] = j * h, x[2] = k * h;
      }
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int32_t t = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int q = 0; q < 6; ++q) {
          int c[3] = {i, j, k};
          int32_t *tet = m.tets + 4 * (size_t)t++;
          tet[0] = (c[2] * p + c[1]) * p + c[0];
          for (int s = 0; s < 3; ++s) {
            c[perms[q][s]]++;
            tet[s + 1] = (c[2] * p + c[1]) * p + c[0];
          }
        }
  piola_tet_mesh_orient(&m);
  return m;
}

static void write_frame(const char *path, const piola_tet_mesh *m, bool with_inverted_field) {
  double *inverted = malloc((size_t)m->tet_count * sizeof(double));
  double *energy = malloc((size_t)m->tet_count * sizeof(double));
  double *solid = malloc((size_t)m->tet_count * sizeof(double));
  for (int32_t t = 0; t < m->tet_count; ++t) {
    inverted[t] = piola_tet_mesh_signed_volume(m, t) < 0 ? 1 : 0;
    energy[t] = t;
    solid[t] = 0;
  }
  piola_vtu_field cells[3] = {
      {"inverted", 1, inverted}, {"energy_density", 1, energy}, {"solid", 1, solid}};
  piola_vtu_frame frame = {.tets = m,
                           .cell_fields = with_inverted_field ? cells : cells + 1,
                           .cell_field_count = with_inverted_field ? 3 : 2};
  assert_int_equal(piola_vtu_write(path, &frame), PIOLA_OK);
  free(inverted), free(energy), free(solid);
}

static void test_boundary_of_cube_grids(void **state) {
  (void)state;
  for (int n = 1; n <= 3; ++n) {
    piola_tet_mesh m = cube_grid(n, 0.1);
    char path[512];
    snprintf(path, sizeof path, "%s/grid%d.vtu", folder, n);
    write_frame(path, &m, true);
    piola_render_frame *f;
    assert_int_equal(piola_render_frame_read(path, &f), PIOLA_OK);
    piola_render_mesh rm;
    assert_int_equal(piola_render_frame_mesh(f, NULL, 0, &rm), PIOLA_OK);
    /* 6 sides of n x n squares, 2 triangles each */
    assert_int_equal(rm.triangle_count, 12 * n * n);
    assert_int_equal(rm.vertex_count, m.vertex_count);
    assert_int_equal(piola_render_frame_inverted_count(f), 0);
    /* faces are wound outward: the signed volume enclosed is the cube's */
    double vol = 0;
    for (int32_t t = 0; t < rm.triangle_count; ++t) {
      const double *a = rm.positions + 3 * rm.triangles[3 * t],
                   *b = rm.positions + 3 * rm.triangles[3 * t + 1],
                   *c = rm.positions + 3 * rm.triangles[3 * t + 2];
      vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) /
             6;
    }
    assert_close(vol, pow(0.1 * n, 3), 1e-12);
    /* per-face values come from the face's tet */
    assert_true(piola_render_frame_has_field(f, "energy_density"));
    assert_false(piola_render_frame_has_field(f, "stress"));
    assert_int_equal(piola_render_frame_mesh(f, "stress", 0, &rm), PIOLA_ERROR_INVALID_ARGUMENT);
    assert_int_equal(piola_render_frame_mesh(f, "energy_density", 0, &rm), PIOLA_OK);
    for (int32_t t = 0; t < rm.triangle_count; ++t) {
      int32_t tet = (int32_t)rm.values[t]; /* energy_density was set to the tet index */
      int shared = 0;
      for (int k = 0; k < 3; ++k)
        for (int q = 0; q < 4; ++q) shared += m.tets[4 * tet + q] == rm.triangles[3 * t + k];
      assert_int_equal(shared, 3);
    }
    piola_vec3 lo, hi;
    piola_render_frame_bounds(f, &lo, &hi);
    assert_close(lo.x, 0, 1e-15);
    assert_close(hi.z, 0.1 * n, 1e-15);
    piola_render_frame_destroy(f);
    piola_tet_mesh_free(&m);
  }
}

static long render_red(const piola_render_frame *f) {
  piola_render_def def = piola_default_render_def();
  def.width = 320;
  def.height = 240;
  def.color = PIOLA_RENDER_COLOR_INVERTED;
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  piola_vec3 lo, hi;
  piola_render_frame_bounds(f, &lo, &hi);
  piola_renderer_fit_camera(r, lo, hi);
  piola_render_mesh rm;
  assert_int_equal(piola_render_frame_mesh(f, NULL, 0, &rm), PIOLA_OK);
  piola_image img = {0};
  assert_int_equal(piola_renderer_render(r, &rm, &img), PIOLA_OK);
  long red = test_count_red(&img);
  piola_image_free(&img);
  piola_renderer_destroy(r);
  return red;
}

/* Push one corner vertex of a 2x2x2 grid through the opposite face of its tets: the frame
 * then has inverted tets, and the inverted colouring shows red; with the vertex back, none.
 * Both with the `inverted` field and, without it, from the tets' signed volumes. */
static void test_inverted_colouring_follows_the_frame(void **state) {
  (void)state;
  for (int with_field = 0; with_field < 2; ++with_field) {
    piola_tet_mesh m = cube_grid(2, 0.1);
    char path[512];
    snprintf(path, sizeof path, "%s/inv%d.vtu", folder, with_field);
    write_frame(path, &m, with_field);
    piola_render_frame *f;
    assert_int_equal(piola_render_frame_read(path, &f), PIOLA_OK);
    assert_int_equal(piola_render_frame_inverted_count(f), 0);
    assert_int_equal(render_red(f), 0);
    piola_render_frame_destroy(f);
    /* vertex 0 at the origin moves inside past the cube's main diagonal plane */
    m.positions[0] = m.positions[1] = m.positions[2] = 0.16;
    int32_t expected = 0;
    for (int32_t t = 0; t < m.tet_count; ++t) expected += piola_tet_mesh_signed_volume(&m, t) < 0;
    assert_true(expected > 0);
    write_frame(path, &m, with_field);
    assert_int_equal(piola_render_frame_read(path, &f), PIOLA_OK);
    assert_int_equal(piola_render_frame_inverted_count(f), expected);
    assert_true(render_red(f) > 0);
    piola_render_frame_destroy(f);
    piola_tet_mesh_free(&m);
  }
}

/* Shells: triangle cells are drawn as they are, next to the boundary of the tets, and take
 * their own cell data. */
static void test_triangle_cells_are_drawn(void **state) {
  (void)state;
  piola_tet_mesh m = cube_grid(1, 0.1);
  double sx[12] = {0, 0, 0.3, 0.2, 0, 0.3, 0, 0.2, 0.3, 0.2, 0.2, 0.3};
  int32_t st[6] = {0, 1, 2, 1, 3, 2};
  piola_tri_mesh shell = {4, sx, 2, st};
  int32_t nc = m.tet_count + 2;
  double *energy = malloc((size_t)nc * sizeof(double));
  for (int32_t c = 0; c < nc; ++c) energy[c] = c;
  piola_vtu_field cells[1] = {{"energy_density", 1, energy}};
  piola_vtu_frame frame = {
      .tets = &m, .triangles = &shell, .cell_fields = cells, .cell_field_count = 1};
  char path[512];
  snprintf(path, sizeof path, "%s/shell.vtu", folder);
  assert_int_equal(piola_vtu_write(path, &frame), PIOLA_OK);
  piola_render_frame *f;
  assert_int_equal(piola_render_frame_read(path, &f), PIOLA_OK);
  piola_render_mesh rm;
  assert_int_equal(piola_render_frame_mesh(f, "energy_density", 0, &rm), PIOLA_OK);
  assert_int_equal(rm.triangle_count, 12 + 2);
  assert_int_equal(rm.vertex_count, m.vertex_count + 4);
  /* the last two faces are the shell's, numbered after the tet points, with their cells' data */
  for (int t = 12; t < 14; ++t) {
    for (int k = 0; k < 3; ++k)
      assert_int_equal(rm.triangles[3 * t + k], m.vertex_count + st[3 * (t - 12) + k]);
    assert_close(rm.values[t], m.tet_count + (t - 12), 0);
  }
  assert_int_equal(piola_render_frame_inverted_count(f), 0);
  piola_render_frame_destroy(f);
  free(energy);
  piola_tet_mesh_free(&m);
}

/* Stresses from a frame: a grid deformed homogeneously by F (written with its displacement
 * field) has in every tet the von Mises equivalent of Phat at the singular values of F, for
 * any rotation applied on top; a mirror (inverted) stays finite; the solid index picks the
 * material; no displacements or too few materials are errors. */
static double von_mises_of(const piola_material_def *def, double a, double b, double c) {
  piola_material m;
  assert_int_equal(piola_material_init(def, &m), PIOLA_OK);
  double fhat[3] = {a, b, c}, p[3];
  piola_material_stress(&m, fhat, p);
  return sqrt(0.5 * ((p[0] - p[1]) * (p[0] - p[1]) + (p[1] - p[2]) * (p[1] - p[2]) +
                     (p[2] - p[0]) * (p[2] - p[0])));
}

static piola_render_frame *deformed_frame(const double F[3][3], bool with_displacement,
                                          double solid_index) {
  piola_tet_mesh m = cube_grid(2, 0.1);
  double *rest = malloc(3 * (size_t)m.vertex_count * sizeof(double));
  double *disp = malloc(3 * (size_t)m.vertex_count * sizeof(double));
  double *solid = malloc((size_t)m.tet_count * sizeof(double));
  for (int32_t v = 0; v < m.vertex_count; ++v) {
    double *x = m.positions + 3 * (size_t)v, X[3] = {x[0], x[1], x[2]};
    for (int i = 0; i < 3; ++i) {
      rest[3 * v + i] = X[i];
      x[i] = F[i][0] * X[0] + F[i][1] * X[1] + F[i][2] * X[2] + 0.3 * i;
      disp[3 * v + i] = x[i] - X[i];
    }
  }
  for (int32_t t = 0; t < m.tet_count; ++t) solid[t] = solid_index;
  piola_vtu_field points[1] = {{"displacement", 3, disp}};
  piola_vtu_field cells[1] = {{"solid", 1, solid}};
  piola_vtu_frame frame = {.tets = &m,
                           .point_fields = points,
                           .point_field_count = with_displacement ? 1 : 0,
                           .cell_fields = cells,
                           .cell_field_count = 1};
  char path[512];
  snprintf(path, sizeof path, "%s/stress.vtu", folder);
  assert_int_equal(piola_vtu_write(path, &frame), PIOLA_OK);
  piola_render_frame *f;
  assert_int_equal(piola_render_frame_read(path, &f), PIOLA_OK);
  free(rest), free(disp), free(solid);
  piola_tet_mesh_free(&m);
  return f;
}

static void test_stress_from_displacements(void **state) {
  (void)state;
  piola_material_def mats[2] = {piola_default_material_def(), piola_default_material_def()};
  mats[1].model = PIOLA_MODEL_NEOHOOKEAN;
  mats[1].youngs_modulus = 3e6;
  const double c = cos(0.7), s = sin(0.7);
  /* stretch 1.2 along x, squash 0.9 along z, then a rotation about z */
  const double cases[3][3][3] = {{{1.2, 0, 0}, {0, 1, 0}, {0, 0, 0.9}},
                                 {{1.2 * c, -s, 0}, {1.2 * s, c, 0}, {0, 0, 0.9}},
                                 {{-1.2, 0, 0}, {0, 1, 0}, {0, 0, 0.9}}}; /* mirrored: inverted */
  for (int which = 0; which < 2; ++which)
    for (int k = 0; k < 3; ++k) {
      piola_render_frame *f = deformed_frame(cases[k], true, which);
      assert_true(piola_render_frame_has_rest_positions(f));
      assert_int_equal(piola_render_frame_add_stress(f, mats, 2), PIOLA_OK);
      assert_true(piola_render_frame_has_field(f, "von_mises_stress"));
      piola_render_mesh rm;
      assert_int_equal(piola_render_frame_mesh(f, "von_mises_stress", 0, &rm), PIOLA_OK);
      double expected = k < 2 ? von_mises_of(&mats[which], 1.2, 1, 0.9) : NAN;
      for (int32_t t = 0; t < rm.triangle_count; ++t) {
        assert_true(isfinite(rm.values[t]) && rm.values[t] > 0);
        if (k < 2)
          assert_close(rm.values[t], expected, 1e-9 * expected);
        else
          assert_close(rm.values[t], rm.values[0], 1e-9 * rm.values[0]); /* homogeneous */
      }
      if (k == 2) assert_int_equal(piola_render_frame_inverted_count(f), 48);
      piola_render_frame_destroy(f);
    }
  /* the two materials differ, so the index matters */
  assert_true(fabs(von_mises_of(&mats[0], 1.2, 1, 0.9) - von_mises_of(&mats[1], 1.2, 1, 0.9)) >
              1e3);
  piola_render_frame *f = deformed_frame(cases[0], false, 0);
  assert_false(piola_render_frame_has_rest_positions(f));
  assert_int_equal(piola_render_frame_add_stress(f, mats, 2), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_render_frame_destroy(f);
  f = deformed_frame(cases[0], true, 1);
  assert_int_equal(piola_render_frame_add_stress(f, mats, 1), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_render_frame_destroy(f);
}

/* Materials come from a scene's solids, in order (only the parser runs: mesh files need not
 * exist). */
static void test_scene_materials(void **state) {
  (void)state;
  char path[512];
  snprintf(path, sizeof path, "%s/scene.json", folder);
  FILE *out = fopen(path, "w");
  fputs(
      "{\"solids\": [{\"mesh\": \"missing.msh\", \"material\": {\"youngs_modulus\": 2e5}},\n"
      " {\"mesh\": \"other.msh\", \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": "
      "7e6, "
      "\"poisson_ratio\": 0.45}}]}\n",
      out);
  fclose(out);
  piola_material_def mats[4];
  int32_t n = -1;
  assert_int_equal(piola_render_scene_materials(path, mats, 4, &n), PIOLA_OK);
  assert_int_equal(n, 2);
  assert_close(mats[0].youngs_modulus, 2e5, 0);
  assert_close(mats[1].youngs_modulus, 7e6, 0);
  assert_close(mats[1].poisson_ratio, 0.45, 0);
  assert_int_equal(mats[1].model, PIOLA_MODEL_NEOHOOKEAN);
  assert_int_equal(piola_render_scene_materials("/nonexistent/scene.json", mats, 4, &n),
                   PIOLA_ERROR_IO);
}

static void test_truncated_and_foreign_files_fail_cleanly(void **state) {
  (void)state;
  piola_tet_mesh m = cube_grid(1, 0.1);
  char path[512], cut[512];
  snprintf(path, sizeof path, "%s/whole.vtu", folder);
  snprintf(cut, sizeof cut, "%s/cut.vtu", folder);
  write_frame(path, &m, true);
  FILE *in = fopen(path, "rb");
  assert_non_null(in);
  char buf[1 << 16];
  size_t n = fread(buf, 1, sizeof buf, in);
  fclose(in);
  piola_render_frame *f = NULL;
  for (size_t keep = n / 8; keep < n - 30; keep += n / 9) {
    FILE *out = fopen(cut, "wb");
    fwrite(buf, 1, keep, out);
    fclose(out);
    assert_int_not_equal(piola_render_frame_read(cut, &f), PIOLA_OK);
    assert_null(f);
  }
  FILE *out = fopen(cut, "wb");
  fputs("solid x\nendsolid x\n", out);
  fclose(out);
  assert_int_equal(piola_render_frame_read(cut, &f), PIOLA_ERROR_PARSE);
  assert_int_equal(piola_render_frame_read("/nonexistent/frame.vtu", &f), PIOLA_ERROR_IO);
  piola_tet_mesh_free(&m);
}

static void test_png_round_trip_and_contact_sheet(void **state) {
  (void)state;
  piola_image imgs[5];
  memset(imgs, 0, sizeof imgs);
  for (int i = 0; i < 5; ++i) {
    imgs[i].width = 64, imgs[i].height = 48;
    imgs[i].rgb = malloc(3 * 64 * 48);
    for (int p = 0; p < 3 * 64 * 48; ++p) imgs[i].rgb[p] = (uint8_t)(40 * i + p % 7);
  }
  char path[512];
  snprintf(path, sizeof path, "%s/img.png", folder);
  assert_int_equal(piola_image_write_png(path, &imgs[3]), PIOLA_OK);
  piola_image back = {0};
  assert_int_equal(piola_image_read_png(path, &back), PIOLA_OK);
  assert_int_equal(back.width, 64);
  assert_int_equal(back.height, 48);
  assert_memory_equal(back.rgb, imgs[3].rgb, 3 * 64 * 48);
  /* 5 tiles in 3 columns: 2 rows of 32 x 24 tiles with 4-pixel gaps */
  piola_image sheet = {0};
  const char *labels[5] = {"0", "1", "2", "3", NULL};
  assert_int_equal(piola_image_contact_sheet(imgs, labels, 5, 3, 32, &sheet), PIOLA_OK);
  assert_int_equal(sheet.width, 3 * 32 + 4 * 4);
  assert_int_equal(sheet.height, 2 * 24 + 3 * 4);
  /* tile 4 (unlabelled, row 1, column 1): its mean equals the source image's mean */
  double mean_src = 0, mean_tile = 0;
  for (int p = 0; p < 3 * 64 * 48; ++p) mean_src += imgs[4].rgb[p];
  mean_src /= 3 * 64 * 48;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x)
      for (int c = 0; c < 3; ++c)
        mean_tile += sheet.rgb[3 * ((size_t)(4 + 24 + 4 + y) * (size_t)sheet.width +
                                    (size_t)(4 + 32 + 4 + x)) +
                               c];
  mean_tile /= 3 * 32 * 24;
  assert_close(mean_tile, mean_src, 1.0);
  assert_int_equal(piola_image_contact_sheet(imgs, NULL, 0, 3, 32, &sheet),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_image_read_png("/nonexistent.png", &back), PIOLA_ERROR_IO);
  for (int i = 0; i < 5; ++i) piola_image_free(&imgs[i]);
  piola_image_free(&back);
  piola_image_free(&sheet);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_boundary_of_cube_grids),
      cmocka_unit_test(test_inverted_colouring_follows_the_frame),
      cmocka_unit_test(test_triangle_cells_are_drawn),
      cmocka_unit_test(test_stress_from_displacements),
      cmocka_unit_test(test_scene_materials),
      cmocka_unit_test(test_truncated_and_foreign_files_fail_cleanly),
      cmocka_unit_test(test_png_round_trip_and_contact_sheet),
  };
  return cmocka_run_group_tests(tests, make_folder, remove_folder);
}
