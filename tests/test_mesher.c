/* The built-in mesher on analytic primitives: valid, well-shaped elements, the right volume,
 * a closed manifold boundary of the right topology, nodes on the surface, and conforming
 * red-green refinement. Every check is computed here from the output mesh alone. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#include "geometry/analytic_shapes.h"
#include "mesher/bcc_lattice.h"
#include "mesher/lattice_phi.h"
#include "mesher/red_green.h"
#include "piola/mesher.h"
#include "piola/threads.h"

/* The dihedral-angle bound the mesher documents (docs/mesher.md). */
#define MIN_DIHEDRAL_DEG 10.0

typedef struct mesh_report {
  double volume, min_volume, min_dihedral, max_dihedral;
  int faces_shared_by_more_than_two;
  int boundary_faces, boundary_edges, boundary_vertices;
  int nonmanifold_edges, misoriented_edges;
  int euler;
} mesh_report;

static vec3 node(const piola_tet_mesh *m, int32_t v) { return vec3_load(m->positions + 3 * (size_t)v); }

static const int face_of[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

typedef struct face_key {
  int32_t v[3];   /* sorted */
  int32_t w[3];   /* as wound */
} face_key;

static int compare_face(const void *pa, const void *pb) {
  const face_key *a = pa, *b = pb;
  for (int k = 0; k < 3; ++k)
    if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
  return 0;
}

typedef struct edge_key {
  int32_t a, b; /* sorted */
  int32_t from;
} edge_key;

static int compare_edge(const void *pa, const void *pb) {
  const edge_key *a = pa, *b = pb;
  if (a->a != b->a) return a->a < b->a ? -1 : 1;
  if (a->b != b->b) return a->b < b->b ? -1 : 1;
  return 0;
}

static int compare_triple(const void *pa, const void *pb) {
  const int32_t *a = pa, *b = pb;
  for (int k = 0; k < 3; ++k)
    if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
  return 0;
}

static void sort3(int32_t *v) {
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2 - i; ++j)
      if (v[j] > v[j + 1]) {
        int32_t t = v[j];
        v[j] = v[j + 1];
        v[j + 1] = t;
      }
}

static double dihedral_min_max(vec3 x[4], double *max_out) {
  vec3 n[4];
  for (int f = 0; f < 4; ++f) {
    vec3 a = x[face_of[f][0]], b = x[face_of[f][1]], c = x[face_of[f][2]];
    vec3 m = vec3_cross(vec3_sub(b, a), vec3_sub(c, a));
    n[f] = vec3_scale(m, 1.0 / vec3_norm(m));
  }
  double lo = 180, hi = 0;
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) {
      double ang = acos(fmax(-1, fmin(1, -vec3_dot(n[f], n[g])))) * 180 / M_PI;
      lo = fmin(lo, ang);
      hi = fmax(hi, ang);
    }
  *max_out = hi;
  return lo;
}

/* Boundary faces (used by one tet) are collected into *boundary (3 ints each, outward). */
static mesh_report analyse(const piola_tet_mesh *m, int32_t **boundary_out) {
  mesh_report r = {0};
  r.min_volume = INFINITY;
  r.min_dihedral = 180;
  size_t nf = (size_t)m->tet_count * 4;
  face_key *faces = malloc(nf * sizeof(face_key));
  for (int32_t t = 0; t < m->tet_count; ++t) {
    vec3 x[4];
    for (int k = 0; k < 4; ++k) x[k] = node(m, m->tets[4 * t + k]);
    double vol = vec3_dot(vec3_sub(x[1], x[0]), vec3_cross(vec3_sub(x[2], x[0]), vec3_sub(x[3], x[0]))) / 6;
    r.volume += vol;
    r.min_volume = fmin(r.min_volume, vol);
    double hi;
    double lo = dihedral_min_max(x, &hi);
    r.min_dihedral = fmin(r.min_dihedral, lo);
    r.max_dihedral = fmax(r.max_dihedral, hi);
    for (int f = 0; f < 4; ++f) {
      face_key *k = &faces[4 * (size_t)t + f];
      for (int i = 0; i < 3; ++i) k->v[i] = k->w[i] = m->tets[4 * t + face_of[f][i]];
      sort3(k->v);
    }
  }
  qsort(faces, nf, sizeof(face_key), compare_face);
  int32_t *bnd = malloc((nf + 1) * 3 * sizeof(int32_t));
  size_t nb = 0;
  for (size_t i = 0; i < nf;) {
    size_t j = i;
    while (j < nf && compare_face(&faces[i], &faces[j]) == 0) ++j;
    if (j - i > 2) r.faces_shared_by_more_than_two++;
    if (j - i == 1) {
      memcpy(bnd + 3 * nb, faces[i].w, 3 * sizeof(int32_t));
      nb++;
    }
    i = j;
  }
  free(faces);
  r.boundary_faces = (int)nb;
  edge_key *edges = malloc((nb * 3 + 1) * sizeof(edge_key));
  for (size_t f = 0; f < nb; ++f)
    for (int k = 0; k < 3; ++k) {
      int32_t a = bnd[3 * f + k], b = bnd[3 * f + (k + 1) % 3];
      edges[3 * f + k] = (edge_key){a < b ? a : b, a < b ? b : a, a};
    }
  qsort(edges, nb * 3, sizeof(edge_key), compare_edge);
  for (size_t i = 0; i < nb * 3;) {
    size_t j = i;
    while (j < nb * 3 && compare_edge(&edges[i], &edges[j]) == 0) ++j;
    r.boundary_edges++;
    if (j - i != 2)
      r.nonmanifold_edges++;
    else if (edges[i].from == edges[i + 1].from)
      r.misoriented_edges++;
    i = j;
  }
  free(edges);
  char *used = calloc((size_t)m->vertex_count, 1);
  for (size_t f = 0; f < nb * 3; ++f) used[bnd[f]] = 1;
  for (int32_t v = 0; v < m->vertex_count; ++v) r.boundary_vertices += used[v];
  free(used);
  r.euler = r.boundary_vertices - r.boundary_edges + r.boundary_faces;
  if (boundary_out)
    *boundary_out = bnd;
  else
    free(bnd);
  return r;
}

typedef double (*distance_fn)(vec3 p, const piola_shape *s);

static double shape_distance(vec3 p, const piola_shape *s) {
  switch (s->type) {
    case PIOLA_SHAPE_SPHERE: return piola__shape_sphere_distance(p, s->center, s->radius, NULL);
    case PIOLA_SHAPE_BOX: return piola__shape_box_distance(p, s->center, s->half_extents, NULL);
    case PIOLA_SHAPE_TORUS: return piola__shape_torus_distance(p, s->center, s->axis, s->radius, s->minor_radius, NULL);
    case PIOLA_SHAPE_CYLINDER: return piola__shape_cylinder_distance(p, s->center, s->axis, s->radius, s->half_length, NULL);
    case PIOLA_SHAPE_CAPSULE: return piola__shape_capsule_distance(p, s->center, s->axis, s->radius, s->half_length, NULL);
    default: return NAN;
  }
}

static void free_tet_mesh(piola_tet_mesh *m) {
  free(m->positions);
  free(m->tets);
  free(m->tet_regions);
  memset(m, 0, sizeof(*m));
}

/* Meshes one primitive and checks everything; returns the report for extra checks. */
static mesh_report check_primitive(piola_shape shape, double h, int levels, double exact_volume,
                                   int expected_euler, double volume_tolerance) {
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0] = shape;
  def.shape_count = 1;
  def.cell_size = h;
  def.refinement_levels = levels;
  piola_tet_mesh mesh;
  piola_status st = piola_mesher_generate(&def, &mesh);
  if (st != PIOLA_OK) fail_msg("mesher failed: %s", piola_last_error());
  int32_t *bnd = NULL;
  mesh_report r = analyse(&mesh, &bnd);
  /* Distance of boundary nodes from the surface. */
  double worst = 0, mean = 0;
  int count = 0;
  char *seen = calloc((size_t)mesh.vertex_count, 1);
  for (int f = 0; f < r.boundary_faces * 3; ++f) {
    int32_t v = bnd[f];
    if (seen[v]) continue;
    seen[v] = 1;
    double d = fabs(shape_distance(node(&mesh, v), &shape));
    worst = fmax(worst, d);
    mean += d;
    count++;
  }
  mean /= count;
  double h_fine = h / (1 << levels);
  printf("  shape %d h %g levels %d: %d tets %d nodes, volume %.6g (exact %.6g, error %.3f%%), "
         "dihedral [%.2f, %.2f] deg, boundary chi %d, surface distance mean %.2e max %.2e (%.3f h)\n",
         (int)shape.type, h, levels, (int)mesh.tet_count, (int)mesh.vertex_count, r.volume,
         exact_volume, 100 * (r.volume - exact_volume) / exact_volume, r.min_dihedral,
         r.max_dihedral, r.euler, mean, worst, worst / h_fine);
  assert_true(r.min_volume > 0);
  assert_true(r.min_dihedral >= MIN_DIHEDRAL_DEG - 1e-9);
  assert_int_equal(r.faces_shared_by_more_than_two, 0);
  assert_int_equal(r.nonmanifold_edges, 0);
  assert_int_equal(r.misoriented_edges, 0);
  assert_int_equal(r.euler, expected_euler);
  assert_true(fabs(r.volume - exact_volume) <= volume_tolerance * exact_volume);
  /* Boundary nodes on the surface: mean far below the lattice spacing, none far off. */
  assert_true(mean < 1e-3 * h_fine);
  assert_true(worst < 0.05 * h_fine);
  /* Every node is inside or near the shape. */
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    assert_true(shape_distance(node(&mesh, v), &shape) < 0.5 * h_fine);
  free(seen);
  free(bnd);
  free_tet_mesh(&mesh);
  return r;
}

static piola_shape base_shape(piola_shape_type type) {
  piola_mesher_def def = piola_default_mesher_def();
  piola_shape s = def.shapes[0];
  s.type = type;
  s.center = vec3_make(0.1, -0.2, 0.3);
  return s;
}

static void sphere_is_meshed(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_SPHERE);
  s.radius = 1.0;
  check_primitive(s, 0.12, 0, 4.0 / 3.0 * M_PI, 2, 0.01);
}

static void box_is_meshed(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_BOX);
  s.half_extents = vec3_make(1.0, 0.5, 0.7);
  check_primitive(s, 0.05, 0, 8 * 1.0 * 0.5 * 0.7, 2, 0.01);
}

static void torus_is_meshed(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_TORUS);
  s.axis = vec3_make(0, 0.6, 0.8);
  s.radius = 1.0;
  s.minor_radius = 0.4;
  check_primitive(s, 0.07, 0, 2 * M_PI * M_PI * 1.0 * 0.4 * 0.4, 0, 0.01);
}

static void cylinder_is_meshed(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_CYLINDER);
  s.axis = vec3_make(1, 0, 0);
  s.radius = 0.5;
  s.half_length = 1.0;
  check_primitive(s, 0.07, 0, M_PI * 0.25 * 2.0, 2, 0.01);
}

static void capsule_is_meshed(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_CAPSULE);
  s.axis = vec3_make(0.6, 0.8, 0);
  s.radius = 0.5;
  s.half_length = 0.8;
  check_primitive(s, 0.08, 0, M_PI * 0.25 * 1.6 + 4.0 / 3.0 * M_PI * 0.125, 2, 0.01);
}

/* Refinement: conforming (boundary faces all on the surface, every interior face shared
 * by two tets, closed manifold boundary), fine tets near the surface, coarse lattice tets
 * untouched deep inside, and more tets than the unrefined lattice. */
static void refinement_is_conforming_and_graded(void **state) {
  (void)state;
  piola_shape s = base_shape(PIOLA_SHAPE_SPHERE);
  s.radius = 1.0;
  double h = 0.25;
  int levels = 2;
  check_primitive(s, h, levels, 4.0 / 3.0 * M_PI, 2, 0.01);
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0] = s;
  def.shape_count = 1;
  def.cell_size = h;
  piola_tet_mesh coarse, fine;
  assert_int_equal(piola_mesher_generate(&def, &coarse), PIOLA_OK);
  def.refinement_levels = levels;
  assert_int_equal(piola_mesher_generate(&def, &fine), PIOLA_OK);
  assert_true(fine.tet_count > 4 * coarse.tet_count);
  double lattice_volume = h * h * h / 12;
  int deep = 0, deep_coarse = 0;
  for (int32_t t = 0; t < fine.tet_count; ++t) {
    vec3 x[4], c = {0, 0, 0};
    for (int k = 0; k < 4; ++k) {
      x[k] = node(&fine, fine.tets[4 * t + k]);
      c = vec3_add(c, vec3_scale(x[k], 0.25));
    }
    double vol = vec3_dot(vec3_sub(x[1], x[0]), vec3_cross(vec3_sub(x[2], x[0]), vec3_sub(x[3], x[0]))) / 6;
    if (shape_distance(c, &s) < -2.5 * h) {
      deep++;
      deep_coarse += fabs(vol - lattice_volume) < 1e-9 * lattice_volume;
    }
  }
  mesh_report rc = analyse(&coarse, NULL), rf = analyse(&fine, NULL);
  printf("  refinement: %d tets (unrefined %d, uniform refinement would give %d); %d of %d deep "
         "tets are coarse lattice tets; boundary faces %d -> %d\n",
         (int)fine.tet_count, (int)coarse.tet_count, (int)coarse.tet_count * 64, deep_coarse, deep,
         rc.boundary_faces, rf.boundary_faces);
  /* Deep inside, the coarse lattice is untouched. */
  assert_true(deep > 0);
  assert_int_equal(deep_coarse, deep);
  /* At the surface the faces are two levels finer: 4 times smaller per level. */
  assert_true(rf.boundary_faces > 10 * rc.boundary_faces);
  /* And far fewer tets than refining everything. */
  assert_true(fine.tet_count < 32 * coarse.tet_count);
  free_tet_mesh(&coarse);
  free_tet_mesh(&fine);
}

static void union_of_shapes_is_meshed(void **state) {
  (void)state;
  /* Two overlapping spheres: volume of the union by the lens formula. */
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0] = base_shape(PIOLA_SHAPE_SPHERE);
  def.shapes[0].center = vec3_make(0, 0, 0);
  def.shapes[1] = def.shapes[0];
  def.shapes[1].center = vec3_make(1.0, 0, 0);
  def.shape_count = 2;
  def.cell_size = 0.1;
  piola_tet_mesh mesh;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_OK);
  mesh_report r = analyse(&mesh, NULL);
  double R = 1, dd = 1;
  double lens = M_PI * (4 * R + dd) * (2 * R - dd) * (2 * R - dd) / 12;
  double exact = 2 * 4.0 / 3.0 * M_PI - lens;
  printf("  union: %d tets volume %.5g exact %.5g (%.3f%%) dihedral [%.2f, %.2f] chi %d\n",
         (int)mesh.tet_count, r.volume, exact, 100 * (r.volume - exact) / exact, r.min_dihedral,
         r.max_dihedral, r.euler);
  assert_true(r.min_dihedral >= MIN_DIHEDRAL_DEG - 1e-9);
  assert_int_equal(r.nonmanifold_edges, 0);
  assert_int_equal(r.euler, 2);
  assert_true(fabs(r.volume - exact) < 0.01 * exact);
  free_tet_mesh(&mesh);
}

static void bad_arguments_are_refused(void **state) {
  (void)state;
  piola_mesher_def def = piola_default_mesher_def();
  piola_tet_mesh mesh;
  def.shape_count = 1;
  def.cell_size = 0;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "cell_size"));
  def.cell_size = 0.1;
  def.shapes[0].radius = -1;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "radius"));
  def.shapes[0].radius = 1;
  def.refinement_levels = 99;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_ERROR_INVALID_ARGUMENT);
  def.refinement_levels = 0;
  def.cell_size = 1e-7;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_ERROR_INVALID_ARGUMENT);
  def.shape_count = 0;
  def.cell_size = 0.1;
  assert_int_equal(piola_mesher_generate(&def, &mesh), PIOLA_ERROR_INVALID_ARGUMENT);
}

/* Red-green refinement alone (before any tet is dropped or node moved): every face is shared
 * by exactly two tets except the lattice's own outer faces, which are unchanged; the volume
 * is unchanged (no gaps, no overlaps); all tets are positive; the BCC lattice tets have 60
 * degree, and green tets at least 25 degree, minimum dihedral angles. */
static void red_green_alone_is_conforming(void **state) {
  (void)state;
  double h = 0.5;
  piola__bcc_lattice lattice;
  assert_int_equal(piola__bcc_lattice_build(vec3_make(-2, -2, -2), vec3_make(2, 2, 2), h, 1 << 24, &lattice), PIOLA_OK);
  piola_tet_mesh before = {lattice.vertex_count, lattice.positions, lattice.tet_count, lattice.tets, NULL, NULL};
  int32_t *hull = NULL;
  mesh_report r0 = analyse(&before, &hull);
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0] = base_shape(PIOLA_SHAPE_SPHERE);
  def.shapes[0].radius = 0.7;
  def.shape_count = 1;
  piola__shape_union shapes;
  assert_int_equal(piola__shape_union_create(&def, &shapes), PIOLA_OK);
  piola__tet_soup soup = {lattice.vertex_count, lattice.vertex_count, lattice.positions, NULL,
                          lattice.tet_count, lattice.tet_count, lattice.tets};
  soup.phi = malloc((size_t)soup.vertex_count * sizeof(double));
  assert_int_equal(piola__lattice_phi(&shapes, soup.positions, soup.vertex_count, soup.tets, soup.tet_count, 1.5 * h, soup.phi), PIOLA_OK);
  assert_int_equal(piola__red_green_refine(&soup, &shapes, 2, h), PIOLA_OK);
  piola_tet_mesh after = {soup.vertex_count, soup.positions, soup.tet_count, soup.tets, NULL, NULL};
  int32_t *hull_after = NULL;
  mesh_report r1 = analyse(&after, &hull_after);
  printf("  red-green alone: %d -> %d tets, volume %.12g -> %.12g, dihedral min %.2f, outer faces %d -> %d\n",
         (int)before.tet_count, (int)after.tet_count, r0.volume, r1.volume,
         r1.min_dihedral, r0.boundary_faces, r1.boundary_faces);
  assert_true(after.tet_count > before.tet_count);
  assert_true(r1.min_volume > 0);
  assert_int_equal(r1.faces_shared_by_more_than_two, 0);
  assert_close(r1.volume, r0.volume, 1e-10 * r0.volume);
  assert_true(r1.min_dihedral >= 25.0);
  /* The faces used once are exactly the lattice's outer faces: no hanging node inside. */
  assert_int_equal(r1.boundary_faces, r0.boundary_faces);
  for (int f = 0; f < r0.boundary_faces; ++f) {
    sort3(hull + 3 * f);
    sort3(hull_after + 3 * f);
  }
  qsort(hull, (size_t)r0.boundary_faces, 3 * sizeof(int32_t), compare_triple);
  qsort(hull_after, (size_t)r1.boundary_faces, 3 * sizeof(int32_t), compare_triple);
  assert_memory_equal(hull, hull_after, (size_t)r0.boundary_faces * 3 * sizeof(int32_t));
  free(hull);
  free(hull_after);
  piola__tet_soup_free(&soup);
  piola__shape_union_destroy(&shapes);
}

/* The output does not depend on the number of threads (bit for bit). */
static void output_is_independent_of_thread_count(void **state) {
  (void)state;
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0] = base_shape(PIOLA_SHAPE_TORUS);
  def.shapes[0].radius = 1.0;
  def.shapes[0].minor_radius = 0.3;
  def.shape_count = 1;
  def.cell_size = 0.12;
  def.refinement_levels = 1;
  piola_tet_mesh one, many;
  piola_set_thread_count(1);
  assert_int_equal(piola_mesher_generate(&def, &one), PIOLA_OK);
  piola_set_thread_count(4);
  assert_int_equal(piola_mesher_generate(&def, &many), PIOLA_OK);
  piola_set_thread_count(0);
  assert_int_equal(one.tet_count, many.tet_count);
  assert_int_equal(one.vertex_count, many.vertex_count);
  assert_memory_equal(one.tets, many.tets, (size_t)one.tet_count * 4 * sizeof(int32_t));
  assert_memory_equal(one.positions, many.positions, (size_t)one.vertex_count * 3 * sizeof(double));
  free_tet_mesh(&one);
  free_tet_mesh(&many);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(sphere_is_meshed),   cmocka_unit_test(box_is_meshed),
      cmocka_unit_test(torus_is_meshed),    cmocka_unit_test(cylinder_is_meshed),
      cmocka_unit_test(capsule_is_meshed),  cmocka_unit_test(refinement_is_conforming_and_graded),
      cmocka_unit_test(union_of_shapes_is_meshed), cmocka_unit_test(bad_arguments_are_refused),
      cmocka_unit_test(output_is_independent_of_thread_count),
      cmocka_unit_test(red_green_alone_is_conforming),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
