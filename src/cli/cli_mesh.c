/* `piola mesh info|convert|generate`: inspect, convert and generate meshes. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli/commands.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/elastic_body.h"
#include "piola/mesh_quality.h"
#include "piola/settling.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: piola mesh info FILE [--json] [--material E,NU,RHO [--viscosity BETA[,ALPHA]]]\n"
          "                                        counts, bounding box, volume, regions, quality,\n"
          "                                        smallest altitude, boundary checks; with\n"
          "                                        --material (Pa, -, kg/m^3) the explicit time step;\n"
          "                                        with --viscosity (shear, bulk; Pa s) the lowest\n"
          "                                        vibration mode and the settling time\n"
          "       piola mesh convert IN OUT        convert by extension (.node/.ele .msh .mesh .veg\n"
          "                                        .vtu .obj .off .stl)\n"
          "       piola mesh generate ...          see `piola mesh generate --help`\n");
}

/* --material E,NU,RHO: Young's modulus (Pa), Poisson ratio, density (kg/m^3). */
typedef struct info_material {
  bool given;
  double youngs_modulus, poisson_ratio, density;
} info_material;

static bool parse_material(const char *s, info_material *m) {
  double v[3];
  const char *p = s;
  char *end = NULL;
  for (int k = 0; k < 3; ++k) {
    v[k] = strtod(p, &end);
    if (end == p || !isfinite(v[k]) || (k < 2 && *end != ',')) return false;
    p = end + (k < 2);
  }
  if (*end || !(v[0] > 0) || !(v[1] > -1 && v[1] < 0.5) || !(v[2] > 0)) return false;
  *m = (info_material){true, v[0], v[1], v[2]};
  return true;
}

/* --viscosity BETA[,ALPHA]: shear and bulk viscosity (Pa s, >= 0; ALPHA defaults to BETA). */
static bool parse_viscosity(const char *s, double v[2]) {
  char *end = NULL;
  v[0] = strtod(s, &end);
  if (end == s || !isfinite(v[0]) || !(v[0] >= 0)) return false;
  v[1] = v[0];
  if (*end == ',') {
    const char *p = end + 1;
    v[1] = strtod(p, &end);
    if (end == p || !isfinite(v[1]) || !(v[1] >= 0)) return false;
  }
  return *end == 0;
}

/* The settling estimate (piola/settling.h) of mesh m in `material` (any model: near rest
 * they all are linear elasticity with its mu and lambda) under viscosity; point_error is the
 * shape error of a collapse to a point, the largest distance of a vertex from the
 * mass-weighted centroid (m). */
static piola_status settling(const piola_tet_mesh *m, const info_material *material,
                             const double viscosity[2], piola_settling_estimate *est,
                             double *point_error) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_ROTATED_LINEAR;
  def.youngs_modulus = material->youngs_modulus;
  def.poisson_ratio = material->poisson_ratio;
  piola_material mat;
  piola_status s = piola_material_init(&def, &mat);
  if (s != PIOLA_OK) return s;
  piola_elastic_body_def bd = piola_default_elastic_body_def();
  bd.rest_mesh = m;
  bd.materials = &mat;
  bd.material_count = 1;
  bd.density = material->density;
  piola_elastic_body *body = NULL;
  s = piola_elastic_body_create(&bd, &body);
  if (s != PIOLA_OK) return s;
  s = piola_elastic_body_settling_estimate(body, viscosity[0], viscosity[1], est);
  const double *x = piola_elastic_body_rest_positions(body), *mass = piola_elastic_body_masses(body);
  double c[3] = {0}, total = 0, worst = 0;
  for (int32_t v = 0; v < m->vertex_count; ++v) {
    total += mass[v];
    for (int i = 0; i < 3; ++i) c[i] += mass[v] * x[3 * v + i];
  }
  for (int32_t v = 0; v < m->vertex_count; ++v)
    if (mass[v] > 0)
      worst = fmax(worst, hypot(hypot(x[3 * v] - c[0] / total, x[3 * v + 1] - c[1] / total),
                                x[3 * v + 2] - c[2] / total));
  *point_error = worst;
  piola_elastic_body_destroy(body);
  return s;
}

/* The dilatational wave speed sqrt((lambda + 2 mu) / rho), m/s: the speed that bounds the
 * explicit step (docs/time-stepping.md). */
static double wave_speed(const info_material *m) {
  double e = m->youngs_modulus, nu = m->poisson_ratio;
  double lambda = e * nu / ((1 + nu) * (1 - 2 * nu)), mu = e / (2 * (1 + nu));
  return sqrt((lambda + 2 * mu) / m->density);
}

/* The scene's default `integrator.cfl` (docs/scene-format.md). */
#define INFO_DEFAULT_CFL 0.5

static void bounds(const double *x, int32_t n, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) lo[k] = n > 0 ? INFINITY : 0, hi[k] = n > 0 ? -INFINITY : 0;
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], x[3 * (size_t)i + (size_t)k]);
      hi[k] = fmax(hi[k], x[3 * (size_t)i + (size_t)k]);
    }
}

/* Smallest altitude (m) over the tets: 3 |volume| / largest face area of each, the length
 * the CFL bound uses. */
static double min_altitude(const piola_tet_mesh *m) {
  double best = INFINITY;
  for (int32_t t = 0; t < m->tet_count; ++t) {
    const double *p[4];
    for (int c = 0; c < 4; ++c) p[c] = m->positions + 3 * (size_t)m->tets[4 * (size_t)t + (size_t)c];
    double e[3][3];
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) e[c][k] = p[c + 1][k] - p[0][k];
    double volume6 = fabs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]));
    static const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    double max_area2 = 0; /* twice the area */
    for (int f = 0; f < 4; ++f) {
      const double *a = p[faces[f][0]], *b = p[faces[f][1]], *c = p[faces[f][2]];
      double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      max_area2 = fmax(max_area2, sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
    /* altitude = 3 V / A = (6 V) / (2 A) */
    double h = max_area2 > 0 ? volume6 / max_area2 : 0;
    if (h < best) best = h;
  }
  return m->tet_count > 0 ? best : 0;
}

static void add_bounds_json(cJSON *o, const double lo[3], const double hi[3]) {
  cJSON_AddItemToObject(o, "bounding_box_min", cJSON_CreateDoubleArray(lo, 3));
  cJSON_AddItemToObject(o, "bounding_box_max", cJSON_CreateDoubleArray(hi, 3));
  double size[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  cJSON_AddItemToObject(o, "size", cJSON_CreateDoubleArray(size, 3));
}

static void print_bounds(const double lo[3], const double hi[3]) {
  printf("bounding box:     [%.6g, %.6g, %.6g] to [%.6g, %.6g, %.6g] m\n", lo[0], lo[1], lo[2], hi[0],
         hi[1], hi[2]);
  printf("size:             %.6g x %.6g x %.6g m\n", hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

/* 2 for bad input (malformed, unsupported, degenerate), 1 for other failures (I/O, memory). */
static int fail(piola_status s) {
  fprintf(stderr, "piola mesh: %s\n", piola_last_error());
  return (s == PIOLA_ERROR_IO || s == PIOLA_ERROR_OUT_OF_MEMORY) ? 1 : 2;
}

int cli_is_surface_path(const char *path) {
  const char *dot = strrchr(path, '.');
  const char *slash = strrchr(path, '/');
  if (!dot || (slash && dot < slash)) return 0;
  return strcasecmp(dot, ".obj") == 0 || strcasecmp(dot, ".off") == 0 || strcasecmp(dot, ".stl") == 0;
}

static int cmp_int32(const void *a, const void *b) {
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

static void add_topology(cJSON *o, const piola_surface_topology *t) {
  cJSON_AddBoolToObject(o, "closed", t->closed);
  cJSON_AddBoolToObject(o, "manifold", t->manifold);
  cJSON_AddBoolToObject(o, "oriented", t->oriented);
  cJSON_AddNumberToObject(o, "euler_characteristic", t->euler_characteristic);
  cJSON_AddNumberToObject(o, "open_edges", t->open_edges);
  cJSON_AddNumberToObject(o, "nonmanifold_edges", t->nonmanifold_edges);
}

static void print_topology(const piola_surface_topology *t) {
  printf("boundary:         %s, %s, %s (Euler characteristic %d; %d open, %d non-manifold edges)\n",
         t->closed ? "closed" : "open", t->manifold ? "manifold" : "NOT manifold",
         t->oriented ? "consistently oriented" : "NOT consistently oriented", t->euler_characteristic, t->open_edges,
         t->nonmanifold_edges);
}

static int print_json(cJSON *o) {
  char *text = cJSON_Print(o);
  cJSON_Delete(o);
  if (!text) {
    fprintf(stderr, "piola mesh: out of memory\n");
    return 1;
  }
  printf("%s\n", text);
  free(text);
  return 0;
}

static int info_surface(const char *path, int json, const info_material *material) {
  if (material->given) {
    fprintf(stderr, "piola mesh info: --material: %s is a surface, it has no tets and so no time "
                    "step; mesh it first (piola mesh generate %s -o OUT.msh)\n",
            path, path);
    return 2;
  }
  piola_tri_mesh m;
  piola_status s = piola_tri_mesh_read(path, &m);
  if (s != PIOLA_OK) return fail(s);
  piola_surface_topology topo;
  s = piola_tri_mesh_topology(&m, &topo);
  if (s != PIOLA_OK) {
    piola_tri_mesh_free(&m);
    return fail(s);
  }
  double volume = piola_tri_mesh_enclosed_volume(&m);
  double lo[3], hi[3];
  bounds(m.positions, m.vertex_count, lo, hi);
  int rc = 0;
  if (json) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "file", path);
    cJSON_AddStringToObject(o, "kind", "surface");
    cJSON_AddNumberToObject(o, "vertices", m.vertex_count);
    cJSON_AddNumberToObject(o, "triangles", m.triangle_count);
    cJSON_AddNumberToObject(o, "boundary_faces", m.triangle_count);
    add_bounds_json(o, lo, hi);
    cJSON_AddNumberToObject(o, "volume", volume);
    add_topology(o, &topo);
    rc = print_json(o);
  } else {
    printf("file:             %s (triangle surface)\n", path);
    printf("vertices:         %d\n", (int)m.vertex_count);
    printf("triangles:        %d\n", (int)m.triangle_count);
    print_bounds(lo, hi);
    printf("enclosed volume:  %.9g m^3\n", volume);
    print_topology(&topo);
  }
  piola_tri_mesh_free(&m);
  return rc;
}

static int info_tets(const char *path, int json, const info_material *material,
                     const double *viscosity) {
  piola_tet_mesh m;
  piola_status s = piola_tet_mesh_read(path, &m);
  if (s != PIOLA_OK) return fail(s);
  piola_tri_mesh boundary;
  piola_tet_mesh_quality q;
  piola_surface_topology topo;
  s = piola_tet_mesh_boundary(&m, &boundary);
  if (s != PIOLA_OK) {
    piola_tet_mesh_free(&m);
    return fail(s);
  }
  s = piola_tet_mesh_measure(&m, &q);
  if (s == PIOLA_OK) s = piola_tri_mesh_topology(&boundary, &topo);
  /* Regions: sorted ids with counts. */
  int32_t *ids = malloc((size_t)m.tet_count * sizeof(int32_t) + 1);
  if (s != PIOLA_OK || !ids) {
    free(ids);
    piola_tri_mesh_free(&boundary);
    piola_tet_mesh_free(&m);
    if (s == PIOLA_OK) {
      fprintf(stderr, "piola mesh: out of memory\n");
      return 1;
    }
    return fail(s);
  }
  for (int32_t t = 0; t < m.tet_count; ++t) ids[t] = m.tet_regions ? m.tet_regions[t] : 0;
  qsort(ids, (size_t)m.tet_count, sizeof(int32_t), cmp_int32);
  double lo[3], hi[3];
  bounds(m.positions, m.vertex_count, lo, hi);
  double h_min = min_altitude(&m);
  double speed = material->given ? wave_speed(material) : 0;
  piola_settling_estimate est = {0};
  double point_error = 0, point_time = 0;
  if (viscosity) {
    s = settling(&m, material, viscosity, &est, &point_error);
    if (s != PIOLA_OK) {
      free(ids);
      piola_tri_mesh_free(&boundary);
      piola_tet_mesh_free(&m);
      return fail(s);
    }
    point_time = piola_settling_time(&est, point_error, 0.01 * est.diagonal);
  }
  int rc = 0;
  if (json) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "file", path);
    cJSON_AddStringToObject(o, "kind", "tets");
    cJSON_AddNumberToObject(o, "vertices", m.vertex_count);
    cJSON_AddNumberToObject(o, "tets", m.tet_count);
    cJSON_AddNumberToObject(o, "boundary_faces", boundary.triangle_count);
    cJSON_AddBoolToObject(o, "fibers", m.tet_fibers != NULL);
    add_bounds_json(o, lo, hi);
    cJSON_AddNumberToObject(o, "volume", q.volume);
    cJSON_AddNumberToObject(o, "min_tet_volume", q.min_volume);
    cJSON_AddNumberToObject(o, "max_tet_volume", q.max_volume);
    cJSON_AddNumberToObject(o, "min_dihedral_degrees", q.min_dihedral_degrees);
    cJSON_AddNumberToObject(o, "max_dihedral_degrees", q.max_dihedral_degrees);
    cJSON_AddNumberToObject(o, "min_mean_ratio", q.min_mean_ratio);
    cJSON_AddNumberToObject(o, "min_altitude", h_min);
    if (material->given) {
      cJSON *mat = cJSON_AddObjectToObject(o, "material");
      cJSON_AddNumberToObject(mat, "youngs_modulus", material->youngs_modulus);
      cJSON_AddNumberToObject(mat, "poisson_ratio", material->poisson_ratio);
      cJSON_AddNumberToObject(mat, "density", material->density);
      cJSON_AddNumberToObject(mat, "wave_speed", speed);
      cJSON_AddNumberToObject(mat, "explicit_dt", h_min / speed);
      cJSON_AddNumberToObject(mat, "explicit_dt_default_cfl", INFO_DEFAULT_CFL * h_min / speed);
    }
    if (viscosity) {
      cJSON *st = cJSON_AddObjectToObject(o, "settling");
      cJSON_AddNumberToObject(st, "shear_viscosity", viscosity[0]);
      cJSON_AddNumberToObject(st, "bulk_viscosity", viscosity[1]);
      cJSON_AddNumberToObject(st, "lowest_frequency", est.lowest_frequency);
      cJSON_AddNumberToObject(st, "lowest_damping", est.lowest_damping);
      cJSON_AddNumberToObject(st, "lowest_decay_rate", est.lowest_decay_rate);
      cJSON_AddNumberToObject(st, "relaxation_rate", est.relaxation_rate);
      cJSON_AddNumberToObject(st, "decay_rate", est.decay_rate);
      cJSON_AddNumberToObject(st, "crossing_time", est.crossing_time);
      cJSON_AddNumberToObject(st, "reexpansion_time", est.reexpansion_time);
      cJSON_AddNumberToObject(st, "point_collapse_error", point_error);
      cJSON_AddNumberToObject(st, "point_collapse_settling_time", point_time);
    }
    cJSON *worst = cJSON_AddArrayToObject(o, "worst_aspect_ratios");
    for (int i = 0; i < q.worst_count; ++i) {
      cJSON *w = cJSON_CreateObject();
      cJSON_AddNumberToObject(w, "tet", q.worst_tets[i]);
      cJSON_AddNumberToObject(w, "aspect_ratio", q.worst_aspect[i]);
      cJSON_AddItemToArray(worst, w);
    }
    cJSON *regions = cJSON_AddArrayToObject(o, "regions");
    for (int32_t i = 0; i < m.tet_count && m.tet_regions;) {
      int32_t j = i + 1;
      while (j < m.tet_count && ids[j] == ids[i]) ++j;
      cJSON *r = cJSON_CreateObject();
      cJSON_AddNumberToObject(r, "id", ids[i]);
      cJSON_AddNumberToObject(r, "tets", j - i);
      cJSON_AddItemToArray(regions, r);
      i = j;
    }
    add_topology(o, &topo);
    rc = print_json(o);
  } else {
    printf("file:             %s\n", path);
    printf("vertices:         %d\n", (int)m.vertex_count);
    printf("tets:             %d\n", (int)m.tet_count);
    printf("boundary faces:   %d\n", (int)boundary.triangle_count);
    printf("fibres:           %s\n", m.tet_fibers ? "one direction per tet" : "none");
    print_bounds(lo, hi);
    printf("volume:           %.9g m^3 (tets from %.3g to %.3g m^3)\n", q.volume, q.min_volume, q.max_volume);
    printf("regions:         %s", m.tet_regions ? "" : " none (the file has no region ids)");
    for (int32_t i = 0; i < m.tet_count && m.tet_regions;) {
      int32_t j = i + 1;
      while (j < m.tet_count && ids[j] == ids[i]) ++j;
      printf(" %d: %d tets%s", (int)ids[i], (int)(j - i), j < m.tet_count ? "," : "");
      i = j;
    }
    printf("\n");
    printf("dihedral angles:  min %.2f, max %.2f degrees\n", q.min_dihedral_degrees, q.max_dihedral_degrees);
    printf("mean ratio:       min %.4f (1 = regular tet)\n", q.min_mean_ratio);
    printf("min altitude:     %.4g m (of any tet: the length of the CFL bound)\n", h_min);
    printf("worst aspect:    ");
    for (int i = 0; i < q.worst_count; ++i)
      printf(" tet %d: %.3g%s", (int)q.worst_tets[i], q.worst_aspect[i], i + 1 < q.worst_count ? "," : "");
    printf(" (1 = regular tet)\n");
    print_topology(&topo);
    if (material->given)
      printf("explicit step:    %.4g s = h / c (c = %.4g m/s for E %g Pa, nu %g, rho %g kg/m^3); "
             "%.4g s at the scenes' default cfl %g\n",
             h_min / speed, speed, material->youngs_modulus, material->poisson_ratio,
             material->density, INFO_DEFAULT_CFL * h_min / speed, INFO_DEFAULT_CFL);
    if (viscosity) {
      printf("lowest mode:      %.4g rad/s (period %.4g s), damped at %.4g /s: decays at %.4g /s "
             "(viscosity %g, %g Pa s)\n",
             est.lowest_frequency, 2 * M_PI / est.lowest_frequency, est.lowest_damping,
             est.lowest_decay_rate, viscosity[0], viscosity[1]);
      printf("settling:         decay rate %.4g /s (overdamped floor %.4g /s), D / c_p %.4g s; "
             "from a point collapse (%.4g m) to 1%% of the diagonal in %.4g s\n",
             est.decay_rate, est.relaxation_rate, est.crossing_time, point_error, point_time);
    }
  }
  free(ids);
  piola_tri_mesh_free(&boundary);
  piola_tet_mesh_free(&m);
  return rc;
}

static int convert(const char *in, const char *out) {
  piola_status s;
  if (cli_is_surface_path(in)) {
    piola_tri_mesh m;
    s = piola_tri_mesh_read(in, &m);
    if (s != PIOLA_OK) return fail(s);
    s = piola_tri_mesh_write(out, &m);
    piola_tri_mesh_free(&m);
  } else {
    piola_tet_mesh m;
    s = piola_tet_mesh_read(in, &m);
    if (s != PIOLA_OK) return fail(s);
    s = piola_tet_mesh_write(out, &m);
    piola_tet_mesh_free(&m);
  }
  return s == PIOLA_OK ? 0 : fail(s);
}

int cli_mesh(int argc, char **argv);
int cli_mesh(int argc, char **argv) {
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  const char *sub = argv[1];
  if (strcmp(sub, "--help") == 0 || strcmp(sub, "-h") == 0 || strcmp(sub, "help") == 0) {
    usage(stdout);
    return 0;
  }
  if (strcmp(sub, "generate") == 0) return cli_mesh_generate(argc - 1, argv + 1);
  if (strcmp(sub, "info") == 0) {
    const char *path = NULL;
    int json = 0;
    info_material material = {0};
    double viscosity[2];
    bool viscosity_given = false;
    for (int i = 2; i < argc; ++i) {
      if (strcmp(argv[i], "--json") == 0) json = 1;
      else if (strcmp(argv[i], "--viscosity") == 0) {
        if (++i >= argc || !parse_viscosity(argv[i], viscosity)) {
          fprintf(stderr, "piola mesh info: --viscosity needs BETA[,ALPHA]: shear and bulk "
                          "viscosity >= 0 (Pa s)\n");
          return 2;
        }
        viscosity_given = true;
      }
      else if (strcmp(argv[i], "--material") == 0) {
        if (++i >= argc || !parse_material(argv[i], &material)) {
          fprintf(stderr, "piola mesh info: --material needs E,NU,RHO: Young's modulus > 0 (Pa), "
                          "Poisson ratio in (-1, 0.5), density > 0 (kg/m^3)\n");
          return 2;
        }
      }
      else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
        usage(stdout);
        return 0;
      } else if (argv[i][0] == '-' && argv[i][1]) {
        fprintf(stderr, "piola mesh info: unknown option '%s'\n", argv[i]);
        return 2;
      } else if (!path) path = argv[i];
      else {
        fprintf(stderr, "piola mesh info: more than one file given\n");
        return 2;
      }
    }
    if (!path) {
      usage(stderr);
      return 2;
    }
    if (viscosity_given && !material.given) {
      fprintf(stderr, "piola mesh info: --viscosity needs --material E,NU,RHO\n");
      return 2;
    }
    if (viscosity_given && cli_is_surface_path(path)) {
      fprintf(stderr, "piola mesh info: --viscosity: %s is a surface, it has no tets and so no "
                      "vibration modes; fill it with `piola mesh generate` first\n", path);
      return 2;
    }
    return cli_is_surface_path(path)
               ? info_surface(path, json, &material)
               : info_tets(path, json, &material, viscosity_given ? viscosity : NULL);
  }
  if (strcmp(sub, "convert") == 0) {
    for (int i = 2; i < argc; ++i)
      if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
        usage(stdout);
        return 0;
      }
    if (argc != 4) {
      usage(stderr);
      return 2;
    }
    return convert(argv[2], argv[3]);
  }
  fprintf(stderr, "piola mesh: unknown subcommand '%s'\n", sub);
  usage(stderr);
  return 2;
}
