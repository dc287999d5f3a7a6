/* What the fracture tests measure on a cut solid (fracture_checks.h). */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "block_scenes.h"
#include "checkpoint_files.h"
#include "fracture_checks.h"
#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "sim/fracture_internal.h"

void fracture_add_solid(piola_world *w, const piola_tet_mesh *mesh, double viscosity) {
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 2e4;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(viscosity);
  sd.bulk_viscosity = piola_track_constant(viscosity);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
}

piola_world *fracture_spinning_bar(const piola_tet_mesh *mesh, double stretch, double y_centre) {
  piola_world *w = weightless_world(5e-4);
  fracture_add_solid(w, mesh, 0);
  const int32_t n = mesh->vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    const double *p = mesh->positions + 3 * i;
    x[3 * i] = stretch * p[0] + 0.1 * p[1], x[3 * i + 1] = 0.9 * p[1], x[3 * i + 2] = p[2] + 0.05 * p[0];
    v[3 * i] = 0.5 - 3.0 * (p[1] - y_centre), v[3 * i + 1] = -0.2 + 3.0 * (p[0] - 0.15), v[3 * i + 2] = 0.1 + p[1];
  }
  assert_int_equal(piola_world_solid_set_state(w, 0, x, v), PIOLA_OK);
  free(x), free(v);
  return w;
}

void fracture_set_cuts(piola_world *w, const piola_fracture_cut *cuts, int32_t count) {
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = cuts, def.cut_count = count;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
}

void fracture_mesh_bounds(const piola_tet_mesh *mesh, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (int32_t i = 0; i < mesh->vertex_count; ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = fmin(lo[k], mesh->positions[3 * i + k]), hi[k] = fmax(hi[k], mesh->positions[3 * i + k]);
}

double fracture_enclosed_volume(const piola_fracture_surface *s, int32_t first, int32_t end) {
  double v = 0;
  for (int32_t i = first; i < end; ++i) {
    const double *a = s->positions + 3 * s->triangles[3 * i], *b = s->positions + 3 * s->triangles[3 * i + 1],
                 *c = s->positions + 3 * s->triangles[3 * i + 2];
    v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
  }
  return v;
}

typedef struct edge {
  int32_t a, b;
} edge;

static int by_edge(const void *pa, const void *pb) {
  const edge *p = pa, *q = pb;
  if (p->a != q->a) return p->a < q->a ? -1 : 1;
  return p->b < q->b ? -1 : p->b > q->b;
}

int32_t fracture_unpaired_edges(const piola_fracture_surface *s, int32_t first, int32_t end) {
  const size_t n = 3 * (size_t)(end - first);
  edge *e = malloc(sizeof *e * (n ? n : 1));
  assert_non_null(e);
  for (int32_t i = first; i < end; ++i)
    for (int k = 0; k < 3; ++k)
      e[3 * (size_t)(i - first) + (size_t)k] = (edge){s->triangles[3 * i + k], s->triangles[3 * i + (k + 1) % 3]};
  qsort(e, n, sizeof *e, by_edge);
  int32_t unpaired = 0;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && !by_edge(&e[j], &e[i])) ++j;
    const edge r = {e[i].b, e[i].a};
    /* count the opposite edges: the run of r in the sorted list */
    size_t lo = 0, hi = n;
    while (lo < hi) {
      const size_t mid = (lo + hi) / 2;
      if (by_edge(&e[mid], &r) < 0) lo = mid + 1;
      else hi = mid;
    }
    size_t opposite = 0;
    while (lo + opposite < n && !by_edge(&e[lo + opposite], &r)) ++opposite;
    if (j - i != 1 || opposite != 1) unpaired += (int32_t)(j - i);
    i = j;
  }
  free(e);
  return unpaired;
}

double fracture_rest_section_area(const piola_world *w, double x0) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *rest = piola_elastic_body_rest_positions(b), *x = piola_world_solid_positions(w, 0);
  const int32_t *tets = piola_elastic_body_tets(b);
  double area = 0;
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) {
    const int32_t *c = tets + 4 * t;
    double dist[4];
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; ++k) {
      dist[k] = rest[3 * c[k]] - x0;
      pos |= dist[k] > 0, neg |= dist[k] < 0;
    }
    if (!pos || !neg) continue;
    copy_polygons poly;
    piola__fracture_copy_polygons(dist, 1, c, &poly);
    double p[4][3], sum[3] = {0, 0, 0};
    for (int32_t i = 0; i < poly.crack_size; ++i)
      for (int a = 0; a < 3; ++a) {
        const double *lo = x + 3 * c[poly.crack[i].lo], *hi = x + 3 * c[poly.crack[i].hi];
        p[i][a] = lo[a] + poly.crack[i].t * (hi[a] - lo[a]);
      }
    for (int32_t i = 1; i + 1 < poly.crack_size; ++i) {
      double u[3], v[3];
      for (int a = 0; a < 3; ++a) u[a] = p[i][a] - p[0][a], v[a] = p[i + 1][a] - p[0][a];
      sum[0] += u[1] * v[2] - u[2] * v[1], sum[1] += u[2] * v[0] - u[0] * v[2], sum[2] += u[0] * v[1] - u[1] * v[0];
    }
    area += 0.5 * sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  }
  return area;
}

double fracture_total_mass(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *m = piola_elastic_body_masses(b);
  double sum = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(b); ++i) sum += m[i];
  return sum;
}

static double tet_volume(const double *x, const int32_t *t) {
  double a[3], b[3], c[3];
  for (int k = 0; k < 3; ++k)
    a[k] = x[3 * t[1] + k] - x[3 * t[0] + k], b[k] = x[3 * t[2] + k] - x[3 * t[0] + k],
    c[k] = x[3 * t[3] + k] - x[3 * t[0] + k];
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
}

double *fracture_material_volumes(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const int32_t nt = piola_elastic_body_tet_count(b), nf = piola_world_solid_fragment_count(w, 0);
  const int32_t *frag = piola_world_solid_fragments(w, 0);
  const double *f = piola_world_solid_material_fractions(w, 0);
  double *v = calloc((size_t)nf, sizeof(double));
  assert_non_null(v);
  for (int32_t t = 0; t < nt; ++t)
    v[frag[t]] += f[t] * tet_volume(piola_elastic_body_rest_positions(b), piola_elastic_body_tets(b) + 4 * t);
  return v;
}

void fracture_checkpoint_round_trip(const piola_world *a, piola_world *b, const char *path, int32_t frame) {
  const uint64_t key = piola_world_scene_key(b, NULL, 0); /* piola run takes it when built */
  assert_int_equal(piola_world_checkpoint_write(a, path, key, frame), PIOLA_OK);
  int32_t read_frame = -1;
  assert_int_equal(piola_world_checkpoint_read(b, path, key, &read_frame), PIOLA_OK);
  assert_int_equal(read_frame, frame);
}

void fracture_checkpoint_round_trip_via_temp_file(const piola_world *a, piola_world *b,
                                                  int32_t frame) {
  char path[4096];
  checkpoint_temp_file(path, sizeof path, "piola_fracture_checkpoint");
  fracture_checkpoint_round_trip(a, b, path, frame);
  unlink(path);
}

void fracture_same_state(const piola_world *a, const piola_world *b) {
  const piola_elastic_body *ea = piola_world_solid_body(a, 0), *eb = piola_world_solid_body(b, 0);
  const int32_t n = piola_elastic_body_vertex_count(ea), nt = piola_elastic_body_tet_count(ea);
  assert_int_equal(piola_elastic_body_vertex_count(eb), n);
  assert_int_equal(piola_elastic_body_tet_count(eb), nt);
  assert_memory_equal(piola_elastic_body_tets(ea), piola_elastic_body_tets(eb), 4 * sizeof(int32_t) * (size_t)nt);
  assert_memory_equal(piola_world_solid_positions(a, 0), piola_world_solid_positions(b, 0), 3 * sizeof(double) * (size_t)n);
  assert_memory_equal(piola_world_solid_velocities(a, 0), piola_world_solid_velocities(b, 0), 3 * sizeof(double) * (size_t)n);
  assert_memory_equal(piola_elastic_body_masses(ea), piola_elastic_body_masses(eb), sizeof(double) * (size_t)n);
  assert_memory_equal(piola_world_solid_material_fractions(a, 0), piola_world_solid_material_fractions(b, 0),
                      sizeof(double) * (size_t)nt);
  assert_memory_equal(piola_world_solid_fragments(a, 0), piola_world_solid_fragments(b, 0), sizeof(int32_t) * (size_t)nt);
  assert_int_equal(piola_world_solid_fragment_count(a, 0), piola_world_solid_fragment_count(b, 0));
  assert_int_equal(piola_world_solid_cut_tet_count(a, 0), piola_world_solid_cut_tet_count(b, 0));
  assert_true(piola_world_time(a) == piola_world_time(b));
}


int32_t fracture_recut_tets(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const int32_t nt = piola_elastic_body_tet_count(b), *parent = piola_world_solid_parent_tets(w, 0);
  int32_t original = 0, recut = 0;
  for (int32_t t = 0; t < nt; ++t) original = parent[t] + 1 > original ? parent[t] + 1 : original;
  int32_t *count = calloc((size_t)original, sizeof(int32_t));
  assert_non_null(count);
  for (int32_t t = 0; t < nt; ++t) recut += ++count[parent[t]] == 3;
  free(count);
  return recut;
}
