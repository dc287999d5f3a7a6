/* Cutting tets that are cut already (MBF04's pieces, src/sim/fracture*.c,
 * docs/fracture.md "Supported cases"): one tet's cells under two and three planes against
 * their analytic volumes, with closed polygons; a box cut through its middle by x = 0.5 and
 * then y = 0.5 falls into exactly four quarters whose closed surfaces enclose 0.25 m^3 each,
 * with the body's mass; random pairs and triples of planes through random meshes keep every
 * invariant; a second cut in free flight keeps the momentum; a solid cut twice goes through
 * a checkpoint bit for bit, and a format-4 checkpoint (tets cut once) still reads. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "block_scenes.h"
#include "checkpoint_files.h"
#include "fracture_checks.h"
#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "sim/fracture_internal.h"

/* The vector area of a cell's polygons in barycentric coordinates (0 when they close). */
static void add_vector_area(const cell_point *poly, int32_t n, double sum[3]) {
  for (int32_t i = 1; i + 1 < n; ++i) {
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) u[k] = poly[i].w[k + 1] - poly[0].w[k + 1], v[k] = poly[i + 1].w[k + 1] - poly[0].w[k + 1];
    sum[0] += u[1] * v[2] - u[2] * v[1], sum[1] += u[2] * v[0] - u[0] * v[2], sum[2] += u[0] * v[1] - u[1] * v[0];
  }
}

static double cell_fraction(const copy_cut *cuts, int32_t n, const int32_t ids[4]) {
  cell_polygons poly;
  piola__fracture_cell_polygons(cuts, n, ids, &poly);
  double area[3] = {0, 0, 0};
  for (int k = 0; k < 4; ++k) add_vector_area(poly.face[k], poly.face_size[k], area);
  for (int32_t j = 0; j < n; ++j) add_vector_area(poly.crack[j], poly.crack_size[j], area);
  for (int k = 0; k < 3; ++k) assert_true(fabs(area[k]) < 1e-13);
  return poly.fraction;
}

/* The reference tet (lambda_1, lambda_2, lambda_3 >= 0, sum <= 1) cut by lambda_1 = a,
 * lambda_2 = b and lambda_3 = c: the cell beyond all three planes is the corner tet of edge
 * 1 - a - b - c, fraction (1 - a - b - c)^3, and by inclusion-exclusion every other cell
 * has a fraction of such cubes. With two planes (c = 0) the same with (1 - a - b)^3. The
 * vertex ids are shuffled, so the canonical order the weights use is not the corners'. */
static void cells_match_their_analytic_volumes(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(15);
  for (int trial = 0; trial < 200; ++trial) {
    int32_t ids[4] = {0, 1, 2, 3};
    for (int k = 3; k > 0; --k) {
      const int j = (int)(test_rng_next(&rng) % (uint64_t)(k + 1));
      const int32_t t = ids[k];
      ids[k] = ids[j], ids[j] = t;
    }
    const double a = test_rng_uniform(&rng, 0.05, 0.3), b = test_rng_uniform(&rng, 0.05, 0.3);
    const double c = test_rng_uniform(&rng, 0.05, 0.3);
    const double level[3] = {a, b, c};
    copy_cut cuts[3];
    for (int j = 0; j < 3; ++j) {
      cuts[j].event = (int32_t)((j + trial) % 3); /* events in another order than cuts */
      for (int k = 0; k < 4; ++k) cuts[j].dist[k] = (k == j + 1 ? 1 : 0) - level[j];
    }
    /* two planes: all four cells */
    double sum = 0;
    for (int s = 0; s < 4; ++s) {
      cuts[0].side = s & 1 ? -1 : 1, cuts[1].side = s & 2 ? -1 : 1;
      const double f = cell_fraction(cuts, 2, ids);
      const double pp = pow(1 - a - b, 3), p0 = pow(1 - a, 3), p1 = pow(1 - b, 3);
      const double expected = s == 0 ? pp : s == 1 ? p1 - pp : s == 2 ? p0 - pp : 1 - p0 - p1 + pp;
      assert_close(f, expected, 1e-14);
      sum += f;
    }
    assert_close(sum, 1.0, 1e-14);
    /* three planes: the corner cell, which has a point inside the tet where all three meet */
    for (int j = 0; j < 3; ++j) cuts[j].side = 1;
    assert_close(cell_fraction(cuts, 3, ids), pow(1 - a - b - c, 3), 1e-14);
    /* and its complement within the cell beyond the first two */
    cuts[2].side = -1;
    assert_close(cell_fraction(cuts, 3, ids), pow(1 - a - b, 3) - pow(1 - a - b - c, 3), 1e-14);
  }
  /* random planes: the cells of two and of three planes add up to the tet */
  for (int trial = 0; trial < 200; ++trial) {
    const int32_t ids[4] = {7, 2, 9, 4};
    copy_cut cuts[3];
    for (int j = 0; j < 3; ++j) {
      cuts[j].event = j;
      for (int k = 0; k < 4; ++k) {
        const double d = test_rng_uniform(&rng, -1, 1);
        cuts[j].dist[k] = fabs(d) < 1e-3 ? 1e-3 : d;
      }
    }
    for (int n = 2; n <= 3; ++n) {
      double sum = 0;
      for (int s = 0; s < (1 << n); ++s) {
        for (int j = 0; j < n; ++j) cuts[j].side = s >> j & 1 ? -1 : 1;
        const double f = cell_fraction(cuts, n, ids);
        assert_true(f >= -1e-15);
        sum += f;
      }
      assert_close(sum, 1.0, 1e-13);
    }
  }
}

/* Every invariant of a cut solid: fractions in (0, 1] adding up to 1 per original tet, at
 * most FRACTURE_MAX_COPIES copies per tet, finite positions, each fragment's surface
 * enclosing exactly its material; returns the fragments' unpaired edges. */
static int32_t check_cut_solid(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const int32_t nt = piola_elastic_body_tet_count(b);
  const double *f = piola_world_solid_material_fractions(w, 0);
  const int32_t *parent = piola_world_solid_parent_tets(w, 0);
  assert_non_null(f);
  int32_t original = 0;
  for (int32_t t = 0; t < nt; ++t) original = parent[t] + 1 > original ? parent[t] + 1 : original;
  double *sum = calloc((size_t)original, sizeof(double));
  int32_t *count = calloc((size_t)original, sizeof(int32_t));
  for (int32_t t = 0; t < nt; ++t) {
    if (!(f[t] > 0 && f[t] <= 1)) fail_msg("tet %d has material fraction %g", (int)t, f[t]);
    sum[parent[t]] += f[t], count[parent[t]]++;
  }
  for (int32_t t = 0; t < original; ++t) {
    assert_close(sum[t], 1.0, 1e-12);
    assert_true(count[t] <= FRACTURE_MAX_COPIES);
  }
  free(sum), free(count);
  const double *x = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(b); ++i) assert_true(isfinite(x[i]));
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  double *material = fracture_material_volumes(w);
  int32_t open = 0;
  for (int32_t g = 0; g < s.fragment_count; ++g) {
    const double enclosed = fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]);
    if (!(fabs(enclosed - material[g]) <= 1e-9 * (fabs(material[g]) + 1e-12)))
      fail_msg("fragment %d encloses %.12g m^3, holds %.12g m^3", (int)g, enclosed, material[g]);
    open += fracture_unpaired_edges(&s, s.fragment_start[g], s.fragment_start[g + 1]);
  }
  for (int32_t i = 0; i < 3 * s.vertex_count; ++i) assert_true(isfinite(s.positions[i]));
  free(material);
  piola_fracture_surface_free(&s);
  return open;
}

/* The unit box of 5 x 5 x 5 cubes cut by x = 0.5 and then y = 0.5 (both through tets, on
 * no vertex): four quarters of 0.25 m^3, the second plane splitting the copies the first
 * one made in the middle column of cubes. The inner vertices are moved a little within the
 * box (not across the planes), so that the line where the planes meet does not run along
 * the middle cubes' diagonal faces. */
static void crossing_planes_quarter_a_box(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.2, 0.2, 0.2}, &mesh), PIOLA_OK);
  test_rng rng = test_rng_seeded(4);
  for (int32_t i = 0; i < 3 * mesh.vertex_count; ++i)
    if (mesh.positions[i] > 1e-9 && mesh.positions[i] < 1 - 1e-9) mesh.positions[i] += test_rng_uniform(&rng, -0.03, 0.03);
  piola_world *w = weightless_world(1e-3);
  fracture_add_solid(w, &mesh, 0);
  const double mass = fracture_total_mass(w);
  piola_fracture_cut cuts[2] = {{.time = 0, .point = {0.5, 0.5, 0.5}, .normal = {1, 0, 0}},
                                {.time = 0, .point = {0.5, 0.5, 0.5}, .normal = {0, 1, 0}}};
  fracture_set_cuts(w, cuts, 2);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 4);
  assert_true(fracture_recut_tets(w) > 0);
  assert_close(fracture_total_mass(w), mass, 1e-13 * mass);
  assert_int_equal(check_cut_solid(w), 0);
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  assert_int_equal(s.fragment_count, 4);
  int seen = 0;
  for (int32_t g = 0; g < 4; ++g) {
    assert_close(fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]), 0.25, 0.005 * 0.25);
    /* each fragment is one quarter: its vertices' mean lies in that quadrant */
    double mean[2] = {0, 0};
    int32_t n = 0;
    for (int32_t i = s.fragment_start[g]; i < s.fragment_start[g + 1]; ++i, ++n)
      for (int a = 0; a < 2; ++a) mean[a] += s.positions[3 * s.triangles[3 * i] + a];
    seen |= 1 << ((mean[0] / n > 0.5) + 2 * (mean[1] / n > 0.5));
  }
  assert_int_equal(seen, 15);
  piola_fracture_surface_free(&s);
  /* the quarters move apart: each flies off diagonally at 0.5 m/s */
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const int32_t n = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  const int32_t *tets = piola_elastic_body_tets(body);
  const double *rest = piola_elastic_body_rest_positions(body), *fr = piola_world_solid_material_fractions(w, 0);
  double *v = calloc(3 * (size_t)n, sizeof(double));
  const int32_t *frag = piola_world_solid_fragments(w, 0);
  double centre[4][2] = {{0}}, weight[4] = {0};
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      for (int a = 0; a < 2; ++a) centre[frag[t]][a] += fr[t] * rest[3 * tets[4 * t + k] + a];
      weight[frag[t]] += fr[t];
    }
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 2; ++a)
        v[3 * tets[4 * t + k] + a] = centre[frag[t]][a] / weight[frag[t]] > 0.5 ? 0.5 : -0.5;
  assert_int_equal(piola_world_solid_set_state(w, 0, NULL, v), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(w, 0.1, NULL), PIOLA_OK);
  assert_int_equal(check_cut_solid(w), 0);
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  for (int32_t g = 0; g < 4; ++g) /* apart, and still a quarter each */
    assert_close(fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]), 0.25, 0.005 * 0.25);
  double gap = INFINITY; /* nearest crack vertex to the planes: 0.05 m away after 0.1 s */
  for (int32_t i = 0; i < s.vertex_count; ++i)
    gap = fmin(gap, fmin(fabs(s.positions[3 * i] - 0.5), fabs(s.positions[3 * i + 1] - 0.5)));
  assert_close(gap, 0.05, 1e-3);
  piola_fracture_surface_free(&s);
  free(v), free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* Random pairs and triples of planes through a jittered box and real meshes: every
 * invariant after each plane (fractions, their sum per tet, mass, each fragment's surface
 * closed, consistently oriented and enclosing exactly its material) and the body steps on
 * without NaN. */
static void random_planes_keep_every_invariant_mesh(const piola_tet_mesh *mesh, test_rng *rng, int trials,
                                                    int32_t *recut, int32_t *open_surfaces) {
  double lo[3], hi[3];
  fracture_mesh_bounds(mesh, lo, hi);
  for (int trial = 0; trial < trials; ++trial) {
    piola_world *w = weightless_world(1e-3);
    fracture_add_solid(w, mesh, 1);
    const double mass = fracture_total_mass(w);
    const int planes = 2 + trial % 2;
    for (int plane = 0; plane < planes; ++plane) {
      double point[3], normal[3];
      for (int k = 0; k < 3; ++k)
        point[k] = test_rng_uniform(rng, 0.3 * lo[k] + 0.7 * hi[k], 0.7 * lo[k] + 0.3 * hi[k]),
        normal[k] = test_rng_normal(rng);
      assert_int_equal(piola_world_solid_cut(w, 0, point, normal, NULL), PIOLA_OK);
      assert_close(fracture_total_mass(w), mass, 1e-12 * mass);
      *open_surfaces += check_cut_solid(w) > 0;
    }
    *recut += fracture_recut_tets(w);
    assert_int_equal(piola_world_advance_to(w, 0.01, NULL), PIOLA_OK);
    check_cut_solid(w);
    piola_world_destroy(w);
  }
}

static void random_planes_keep_every_invariant(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(1515);
  const int trials = (int)test_samples(12, 2);
  int32_t recut = 0, open = 0;
  piola_tet_mesh box;
  assert_int_equal(piola_tet_mesh_box_grid(4, 3, 3, (piola_vec3){0.1, 0.1, 0.1}, &box), PIOLA_OK);
  for (int32_t i = 0; i < box.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) box.positions[3 * i + k] += test_rng_uniform(&rng, -0.02, 0.02);
  random_planes_keep_every_invariant_mesh(&box, &rng, trials, &recut, &open);
  free(box.positions), free(box.tets);
  static const char *const real[] = {"medit/unit_ball.mesh", "gmsh/bar-186.msh"};
  for (int r = 0; r < 2; ++r) {
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_read(test_data_path(real[r]), &mesh), PIOLA_OK);
    random_planes_keep_every_invariant_mesh(&mesh, &rng, (trials + 1) / 2, &recut, &open);
    piola_tet_mesh_free(&mesh);
  }
  assert_int_equal(open, 0);
  assert_true(recut > 0); /* the later planes did cut tets cut before */
}

/* A spinning, stretched bar in free flight cut at 0.03 s by one plane and at 0.06 s by a
 * second that crosses it: the step of the second cut (which splits copies of the first)
 * keeps the momentum to rounding, and so does the flight after it. */
static void second_cut_in_free_flight_keeps_momentum(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(6, 3, 3, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_world *w = fracture_spinning_bar(&mesh, 1.2, 0.075);
  /* planes through the bar's centre as it will be then (it drifts by (0.5, -0.2, 0.1) m/s) */
  piola_fracture_cut cuts[2] = {{.time = 0.03, .point = {0.2, 0.06, 0.09}, .normal = {1, 0.3, -0.2}},
                                {.time = 0.06, .point = {0.21, 0.05, 0.09}, .normal = {0.1, 1, 0.3}}};
  fracture_set_cuts(w, cuts, 2);
  assert_int_equal(piola_world_advance_to(w, 0.06, NULL), PIOLA_OK);
  const int32_t once = piola_world_solid_cut_tet_count(w, 0);
  assert_true(once > 0);
  assert_int_equal(fracture_recut_tets(w), 0);
  double p0[3], l0[3], p1[3], l1[3];
  solid_momenta(w, p0, l0, NULL);
  const double mass = fracture_total_mass(w);
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  assert_true(fracture_recut_tets(w) > 0);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 4);
  assert_close(fracture_total_mass(w), mass, 1e-13 * mass);
  solid_momenta(w, p1, l1, NULL);
  const double ls = sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  const double ps = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  for (int k = 0; k < 3; ++k) {
    assert_close(p1[k], p0[k], 1e-12 * ps);
    assert_close(l1[k], l0[k], 1e-9 * ls);
  }
  assert_int_equal(piola_world_advance_to(w, 0.15, NULL), PIOLA_OK);
  solid_momenta(w, p1, l1, NULL);
  for (int k = 0; k < 3; ++k) {
    assert_close(p1[k], p0[k], 1e-12 * ps);
    assert_close(l1[k], l0[k], 1e-6 * ls);
  }
  const double *xs = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(piola_world_solid_body(w, 0)); ++i)
    assert_true(isfinite(xs[i]));
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* A stretched, drifting box cut at t = 0 by x = 0.1 and at 0.01 s by y = 0.1, crossing it. */
static piola_world *twice_cut_box(const piola_tet_mesh *mesh, int second) {
  piola_world *w = weightless_world(5e-4);
  fracture_add_solid(w, mesh, 1);
  const int32_t n = mesh->vertex_count;
  double *v = malloc(3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = 0.3 * (mesh->positions[3 * i + k] - 0.1) + 0.1 * k;
  assert_int_equal(piola_world_solid_set_state(w, 0, NULL, v), PIOLA_OK);
  free(v);
  const piola_fracture_cut cuts[2] = {{.time = 0, .point = {0.1, 0.1, 0.1}, .normal = {1, 0.1, 0.05}},
                                      {.time = 0.01, .point = {0.1, 0.1, 0.1}, .normal = {0.05, 1, 0.1}}};
  fracture_set_cuts(w, cuts, second ? 2 : 1);
  return w;
}

/* Rewrites the checkpoint at path (one solid, its tets cut at most once) as format 4 wrote
 * it (docs/file-formats.md): two copies per tet, no further cuts. */
static void rewrite_as_format_4(const char *path) {
  size_t length;
  unsigned char *data = checkpoint_file_read(path, &length), *out = malloc(length);
  assert_non_null(out);
  size_t pos = CHECKPOINT_HEADER_BYTES;
  checkpoint_skip_array(data, &pos, 8); /* time */
  const size_t bounds_at = pos; /* the recent step bounds (format 7 on), not in format 4 */
  checkpoint_skip_array(data, &pos, 4);
  checkpoint_skip_array(data, &pos, 4);
  checkpoint_skip_array(data, &pos, 8);
  const size_t bounds_end = pos;
  checkpoint_skip_array(data, &pos, 4); /* body kind */
  checkpoint_skip_array(data, &pos, 4); /* fracture present */
  checkpoint_skip_array(data, &pos, 4); /* counts */
  static const size_t per_copy[7] = {4, 4, 1, 8, 8, 4, 4}; /* parent .. nodes */
  for (int a = 0; a < 7; ++a) checkpoint_skip_array(data, &pos, per_copy[a]);
  const size_t copies_at = pos;
  const uint64_t slots = checkpoint_skip_array(data, &pos, 4);
  for (int a = 0; a < 3; ++a) checkpoint_skip_array(data, &pos, a == 0 ? 4 : a == 1 ? 1 : 8);
  const size_t rest_at = pos;
  size_t n = 0;
  memcpy(out, data, bounds_at), n = bounds_at;
  memcpy(out + n, data + bounds_end, copies_at - bounds_end), n += copies_at - bounds_end;
  const uint64_t tets = slots / FRACTURE_MAX_COPIES, two = 2 * tets;
  memcpy(out + n, &two, 8), n += 8;
  for (uint64_t t = 0; t < tets; ++t) {
    int32_t third;
    memcpy(&third, data + copies_at + 8 + 4 * (FRACTURE_MAX_COPIES * t + 2), 4);
    assert_int_equal(third, -1); /* cut once */
    memcpy(out + n, data + copies_at + 8 + 4 * FRACTURE_MAX_COPIES * t, 8), n += 8;
  }
  memcpy(out + n, data + rest_at, length - 8 - rest_at), n += length - 8 - rest_at;
  checkpoint_file_write(path, out, n, 4);
  free(data), free(out);
}

/* A box cut twice (tets cut again by the second plane) goes through a checkpoint bit for
 * bit into a world built the same way (so cut once), which then runs on like the writer;
 * a box cut once, saved as format 4 saved it, reads as well. */
static void twice_cut_solid_resumes_bit_for_bit(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(4, 4, 4, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_world *a = twice_cut_box(&mesh, 1), *b = twice_cut_box(&mesh, 1);
  assert_int_equal(piola_world_advance_to(a, 0.02, NULL), PIOLA_OK);
  assert_true(fracture_recut_tets(a) > 0);
  assert_int_equal(piola_world_solid_fragment_count(a, 0), 4);
  assert_int_equal(fracture_recut_tets(b), 0);
  char path[] = "/tmp/piola_recut_checkpoint_XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  fracture_checkpoint_round_trip(a, b, path, 3);
  fracture_same_state(a, b);
  assert_int_equal(piola_world_advance_to(a, 0.03, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.03, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  piola_world_destroy(a), piola_world_destroy(b);
  /* format 4 */
  a = twice_cut_box(&mesh, 0), b = twice_cut_box(&mesh, 0);
  assert_int_equal(piola_world_advance_to(a, 0.01, NULL), PIOLA_OK);
  const uint64_t key = piola_world_scene_key(b, NULL, 0);
  assert_int_equal(piola_world_checkpoint_write(a, path, key, 2), PIOLA_OK);
  rewrite_as_format_4(path);
  int32_t frame = -1;
  assert_int_equal(piola_world_checkpoint_read(b, path, key, &frame), PIOLA_OK);
  assert_int_equal(frame, 2);
  fracture_same_state(a, b);
  assert_int_equal(piola_world_advance_to(a, 0.02, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.02, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  unlink(path);
  piola_world_destroy(a), piola_world_destroy(b);
  free(mesh.positions), free(mesh.tets);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(cells_match_their_analytic_volumes),
      cmocka_unit_test(crossing_planes_quarter_a_box),
      cmocka_unit_test(random_planes_keep_every_invariant),
      cmocka_unit_test(second_cut_in_free_flight_keeps_momentum),
      cmocka_unit_test(twice_cut_solid_resumes_bit_for_bit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
