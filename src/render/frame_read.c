/* Turning a frame that piola wrote (a VTU file) into a renderable surface.
 *
 * The file is read by piola_vtu_read (src/io/read_vtu.c), the one VTU reader, which checks
 * every offset and count against the file size, so a truncated frame of a running
 * simulation fails cleanly. The surface is the set of tet faces used by exactly one tet,
 * each remembering its cell, so per-cell data (inverted, energy density, solid) colour the
 * faces; triangle cells (shells) are drawn as they are. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/mesh_io.h"
#include "render/render_internal.h"

void piola_render_frame_destroy(piola_render_frame *f) {
  if (!f) return;
  for (int i = 0; i < f->field_count; ++i) free(f->fields[i].values);
  free(f->fields), free(f->points), free(f->surface), free(f->surface_cell), free(f->cell_inverted);
  free(f->rest), free(f->tets), free(f->tet_cell);
  free(f->face_inverted), free(f->face_values), free(f->face_parts);
  free(f);
}

typedef struct face_key {
  int32_t v[3]; /* sorted */
  int32_t corner[3];
  int32_t cell;
} face_key;

static int compare_face(const void *a, const void *b) {
  const face_key *x = a, *y = b;
  for (int k = 0; k < 3; ++k)
    if (x->v[k] != y->v[k]) return x->v[k] < y->v[k] ? -1 : 1;
  return (x->cell > y->cell) - (x->cell < y->cell);
}

static void sort3(int32_t v[3]) {
  int32_t t;
  if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
  if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
  if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

static piola_status build_surface(piola_render_frame *f, const piola_vtu_data *d,
                                  const char *path) {
  if (4 * (int64_t)d->tet_count + d->triangle_count > INT32_MAX / 4)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: too many cells to render", path);
  int64_t nf = 4 * (int64_t)d->tet_count;
  face_key *faces = malloc((size_t)(nf > 0 ? nf : 1) * sizeof *faces);
  if (!faces) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  static const int local[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (int32_t t = 0; t < d->tet_count; ++t) {
    const int32_t *tet = d->tets + 4 * (size_t)t;
    for (int k = 0; k < 4; ++k) {
      face_key *fk = &faces[4 * (size_t)t + (size_t)k];
      for (int j = 0; j < 3; ++j) fk->v[j] = fk->corner[j] = tet[local[k][j]];
      sort3(fk->v);
      fk->cell = d->tet_cells[t];
    }
  }
  qsort(faces, (size_t)nf, sizeof *faces, compare_face);
  int64_t cap = nf + d->triangle_count;
  f->surface = malloc(3 * (size_t)(cap > 0 ? cap : 1) * sizeof *f->surface);
  f->surface_cell = malloc((size_t)(cap > 0 ? cap : 1) * sizeof *f->surface_cell);
  if (!f->surface || !f->surface_cell) {
    free(faces);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  int32_t n = 0;
  for (int64_t i = 0; i < nf;) {
    int64_t j = i + 1;
    while (j < nf && memcmp(faces[j].v, faces[i].v, sizeof faces[i].v) == 0) ++j;
    if (j - i == 1) {
      memcpy(f->surface + 3 * (size_t)n, faces[i].corner, sizeof faces[i].corner);
      f->surface_cell[n++] = faces[i].cell;
    }
    i = j;
  }
  free(faces);
  for (int32_t t = 0; t < d->triangle_count; ++t) {
    memcpy(f->surface + 3 * (size_t)n, d->triangles + 3 * (size_t)t, 3 * sizeof(int32_t));
    f->surface_cell[n++] = d->triangle_cells[t];
  }
  f->surface_count = n;
  return PIOLA_OK;
}

static double signed_volume(const double *x, const int32_t *t) {
  vec3 a = vec3_load(x + 3 * (size_t)t[0]);
  vec3 e1 = vec3_sub(vec3_load(x + 3 * (size_t)t[1]), a),
       e2 = vec3_sub(vec3_load(x + 3 * (size_t)t[2]), a);
  vec3 e3 = vec3_sub(vec3_load(x + 3 * (size_t)t[3]), a);
  return vec3_dot(e1, vec3_cross(e2, e3)) / 6;
}

/* Moves what the renderer needs out of d (positions, tets, scalar cell fields) into f. */
static piola_status build_frame(piola_render_frame *f, piola_vtu_data *d, const char *path) {
  f->point_count = d->point_count;
  f->cell_count = d->cell_count;
  f->points = d->positions;
  d->positions = NULL;
  for (int32_t i = 0; i < d->cell_field_count; ++i) {
    piola_vtu_array *a = &d->cell_fields[i];
    if (a->components != 1 || !a->name[0]) continue;
    render_cell_field *grown = realloc(f->fields, (size_t)(f->field_count + 1) * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    f->fields = grown;
    memcpy(grown[f->field_count].name, a->name, sizeof a->name);
    grown[f->field_count++].values = a->values;
    a->values = NULL;
  }
  PIOLA_TRY(build_surface(f, d, path));
  f->cell_inverted = calloc((size_t)(f->cell_count > 0 ? f->cell_count : 1), 1);
  if (!f->cell_inverted) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  const double *inv = NULL; /* the frame's own flags, else the sign of each tet's volume */
  for (int i = 0; i < f->field_count; ++i)
    if (strcmp(f->fields[i].name, "inverted") == 0) inv = f->fields[i].values;
  if (inv) {
    for (int64_t c = 0; c < f->cell_count; ++c) f->cell_inverted[c] = inv[c] > 0.5;
  } else {
    for (int32_t t = 0; t < d->tet_count; ++t)
      if (signed_volume(f->points, d->tets + 4 * (size_t)t) < 0)
        f->cell_inverted[d->tet_cells[t]] = 1;
  }
  for (int64_t c = 0; c < f->cell_count; ++c) f->inverted_count += f->cell_inverted[c];
  /* the tets (for stresses) and the rest positions, when the frame has displacements */
  f->tets = d->tets;
  f->tet_cell = d->tet_cells;
  f->tet_count = d->tet_count;
  d->tets = NULL;
  d->tet_cells = NULL;
  for (int32_t i = 0; i < d->point_field_count && !f->rest; ++i) {
    piola_vtu_array *u = &d->point_fields[i];
    if (u->components != 3 || strcmp(u->name, "displacement") != 0) continue;
    f->rest = u->values;
    u->values = NULL;
    for (int64_t k = 0; k < 3 * f->point_count; ++k) f->rest[k] = f->points[k] - f->rest[k];
  }
  return PIOLA_OK;
}

piola_status piola_render_frame_read(const char *path, piola_render_frame **out) {
  if (!path || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render frame: NULL argument");
  *out = NULL;
  piola_vtu_data data;
  PIOLA_TRY(piola_vtu_read(path, &data));
  piola_render_frame *f = calloc(1, sizeof *f);
  piola_status st = f ? build_frame(f, &data, path)
                      : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  piola_vtu_data_free(&data);
  if (st != PIOLA_OK) {
    piola_render_frame_destroy(f);
    return st;
  }
  *out = f;
  return PIOLA_OK;
}

static const double *field(const piola_render_frame *f, const char *name) {
  for (int i = 0; i < f->field_count; ++i)
    if (strcmp(f->fields[i].name, name) == 0) return f->fields[i].values;
  return NULL;
}

bool piola_render_frame_has_field(const piola_render_frame *f, const char *name) {
  return f && name && field(f, name) != NULL;
}

int32_t piola_render_frame_inverted_count(const piola_render_frame *f) {
  return f ? f->inverted_count : 0;
}

void piola_render_frame_bounds(const piola_render_frame *f, piola_vec3 *lo, piola_vec3 *hi) {
  vec3 a = {INFINITY, INFINITY, INFINITY}, b = {-INFINITY, -INFINITY, -INFINITY};
  for (int64_t i = 0; f && i < f->point_count; ++i) {
    const double *p = f->points + 3 * i;
    a.x = fmin(a.x, p[0]), a.y = fmin(a.y, p[1]), a.z = fmin(a.z, p[2]);
    b.x = fmax(b.x, p[0]), b.y = fmax(b.y, p[1]), b.z = fmax(b.z, p[2]);
  }
  if (lo) *lo = a;
  if (hi) *hi = b;
}

piola_status piola_render_frame_mesh(const piola_render_frame *cf, const char *value_field,
                                     double time, piola_render_mesh *out) {
  if (!cf || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render frame: NULL argument");
  piola_render_frame *f = (piola_render_frame *)cf; /* the per-face arrays are a cache */
  const double *values = NULL;
  if (value_field) {
    values = field(f, value_field);
    if (!values)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "frame has no cell field '%s'", value_field);
  }
  const double *solid = field(f, "solid");
  size_t n = (size_t)(f->surface_count > 0 ? f->surface_count : 1);
  if (!f->face_inverted) {
    f->face_inverted = malloc(n);
    f->face_values = malloc(n * sizeof *f->face_values);
    f->face_parts = malloc(n * sizeof *f->face_parts);
    if (!f->face_inverted || !f->face_values || !f->face_parts)
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render frame: out of memory");
  }
  for (int32_t t = 0; t < f->surface_count; ++t) {
    int32_t c = f->surface_cell[t];
    f->face_inverted[t] = f->cell_inverted[c];
    f->face_values[t] = values ? values[c] : 0;
    double s = solid ? solid[c] : 0;
    f->face_parts[t] = isfinite(s) && fabs(s) < 1e9 ? (int32_t)s : 0;
  }
  out->vertex_count = (int32_t)f->point_count;
  out->positions = f->points;
  out->triangle_count = f->surface_count;
  out->triangles = f->surface;
  out->inverted = f->face_inverted;
  out->values = values ? f->face_values : NULL;
  out->parts = f->face_parts;
  out->time = time;
  return PIOLA_OK;
}
