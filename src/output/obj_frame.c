/* The OBJ surface of a frame, for Blender and Houdini: one named object per body
 * (`o <name>`: each solid's boundary, each shell's triangles), with only the vertices its
 * faces use. Interior nodes of the tets are left out: an importer would otherwise keep them
 * as loose points. Positions only (no normals: importers compute smooth ones from the
 * faces, and a frame stays small).
 *
 * The layout (which vertices, which faces, in which object) does not change between frames,
 * so it is built once; each frame writes the current positions through it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "output/output_internal.h"
#include "piola/world_fracture.h"

void piola__obj_layout_free(obj_layout *l) {
  if (!l) return;
  free(l->vertices), free(l->faces), free(l->body_vertex_start), free(l->body_face_start);
  free(l->names);
  memset(l, 0, sizeof *l);
}

piola_status piola__obj_layout_build(const piola_tri_mesh *surface, const int32_t *body_first_vertex,
                                     int32_t body_count, const char *const *names,
                                     int32_t vertex_count, obj_layout *l) {
  memset(l, 0, sizeof *l);
  int32_t nt = surface->triangle_count;
  l->body_count = body_count;
  l->vertices = malloc((size_t)(vertex_count > 0 ? vertex_count : 1) * sizeof *l->vertices);
  l->faces = malloc(3 * (size_t)(nt > 0 ? nt : 1) * sizeof *l->faces);
  l->body_vertex_start = calloc((size_t)body_count + 1, sizeof *l->body_vertex_start);
  l->body_face_start = calloc((size_t)body_count + 1, sizeof *l->body_face_start);
  l->names = calloc((size_t)(body_count > 0 ? body_count : 1), sizeof *l->names);
  int32_t *obj_index = malloc((size_t)(vertex_count > 0 ? vertex_count : 1) * sizeof *obj_index);
  if (!l->vertices || !l->faces || !l->body_vertex_start || !l->body_face_start || !l->names ||
      !obj_index) {
    free(obj_index);
    piola__obj_layout_free(l);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "OBJ output: out of memory");
  }
  for (int32_t v = 0; v < vertex_count; ++v) obj_index[v] = -1;
  int32_t nv_out = 0, nf_out = 0;
  for (int32_t b = 0; b < body_count; ++b) {
    snprintf(l->names[b], sizeof l->names[b], "%s", names[b]);
    /* an OBJ name ends at whitespace, a line break would start a record of its own and '#'
     * a comment: all become '_' */
    for (char *c = l->names[b]; *c; ++c)
      if ((unsigned char)*c <= ' ' || *c == 0x7f || *c == '#') *c = '_';
    l->body_vertex_start[b] = nv_out;
    l->body_face_start[b] = nf_out;
    int32_t lo = body_first_vertex[b], hi = body_first_vertex[b + 1];
    /* a body's faces use only its own vertices (bodies share no nodes) */
    for (int32_t t = 0; t < nt; ++t) {
      const int32_t *tri = surface->triangles + 3 * (size_t)t;
      if (tri[0] < lo || tri[0] >= hi) continue;
      for (int k = 0; k < 3; ++k) {
        if (obj_index[tri[k]] < 0) {
          obj_index[tri[k]] = nv_out;
          l->vertices[nv_out++] = tri[k];
        }
        l->faces[3 * (size_t)nf_out + (size_t)k] = obj_index[tri[k]] + 1; /* OBJ is 1-based */
      }
      ++nf_out;
    }
  }
  l->body_vertex_start[body_count] = nv_out;
  l->body_face_start[body_count] = nf_out;
  free(obj_index);
  return PIOLA_OK;
}

/* Body b of the layout as one object, its face indices shifted by shift. */
static void write_body(FILE *stream, const obj_layout *l, const double *positions, int32_t b,
                       int32_t shift) {
  fprintf(stream, "o %s\n", l->names[b]);
  for (int32_t i = l->body_vertex_start[b]; i < l->body_vertex_start[b + 1]; ++i) {
    const double *p = positions + 3 * (size_t)l->vertices[i];
    fprintf(stream, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
  }
  for (int32_t t = l->body_face_start[b]; t < l->body_face_start[b + 1]; ++t) {
    const int32_t *tri = l->faces + 3 * (size_t)t;
    fprintf(stream, "f %d %d %d\n", (int)(tri[0] + shift), (int)(tri[1] + shift),
            (int)(tri[2] + shift));
  }
}

piola_status piola__obj_layout_write(const obj_layout *l, const char *path, const double *positions) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "# piola frame: one object per body, its surface only\n");
  for (int32_t b = 0; b < l->body_count; ++b) write_body(f.stream, l, positions, b, 0);
  if (ferror(f.stream)) {
    piola_atomic_file_abort(&f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: write failed", path);
  }
  return piola_atomic_file_commit(&f);
}

piola_status piola__obj_write_fragments(const obj_layout *l, const char *path, const double *positions,
                                        const piola_world *world) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "# piola frame: one object per body, its surface only; a cut solid: one per fragment\n");
  const int32_t ns = piola_world_solid_count(world);
  int32_t written = 0; /* vertices so far: OBJ indices are global */
  piola_status st = PIOLA_OK;
  for (int32_t b = 0; b < l->body_count && st == PIOLA_OK; ++b) {
    if (b >= ns || !piola_world_solid_has_fracture(world, b)) {
      /* the layout's 1-based indices count from the body's first vertex in the layout */
      const int32_t shift = written - l->body_vertex_start[b];
      write_body(f.stream, l, positions, b, shift);
      written += l->body_vertex_start[b + 1] - l->body_vertex_start[b];
      continue;
    }
    piola_fracture_surface s;
    st = piola_world_solid_fracture_surface(world, b, &s);
    if (st != PIOLA_OK) break;
    int32_t first_vertex = 0; /* fragments' vertices are consecutive, in fragment order */
    for (int32_t g = 0; g < s.fragment_count; ++g) {
      int32_t lo = s.vertex_count, hi = -1;
      for (int32_t t = s.fragment_start[g]; t < s.fragment_start[g + 1]; ++t)
        for (int k = 0; k < 3; ++k) {
          int32_t v = s.triangles[3 * (size_t)t + k];
          lo = v < lo ? v : lo, hi = v > hi ? v : hi;
        }
      if (hi < 0) lo = first_vertex, hi = first_vertex - 1;
      fprintf(f.stream, "o %s_%d\n", l->names[b], (int)g);
      for (int32_t v = lo; v <= hi; ++v) {
        const double *p = s.positions + 3 * (size_t)v;
        fprintf(f.stream, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
      }
      for (int32_t t = s.fragment_start[g]; t < s.fragment_start[g + 1]; ++t) {
        const int32_t *tri = s.triangles + 3 * (size_t)t;
        fprintf(f.stream, "f %d %d %d\n", (int)(tri[0] - lo + written + 1), (int)(tri[1] - lo + written + 1),
                (int)(tri[2] - lo + written + 1));
      }
      written += hi - lo + 1;
      first_vertex = hi + 1;
    }
    piola_fracture_surface_free(&s);
  }
  if (st == PIOLA_OK && ferror(f.stream)) st = PIOLA_FAIL(PIOLA_ERROR_IO, "%s: write failed", path);
  if (st != PIOLA_OK) {
    piola_atomic_file_abort(&f);
    return st;
  }
  return piola_atomic_file_commit(&f);
}
