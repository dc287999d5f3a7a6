/* `piola mesh generate SHAPE -o OUT [options]`: the built-in BCC mesher (docs/mesher.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli/cli_numbers.h"
#include "cli/commands.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/mesher.h"

static void usage(FILE *out) {
  fprintf(
      out,
      "usage: piola mesh generate SHAPE -o OUT [options]\n"
      "\n"
      "SHAPE is sphere, box, torus, cylinder, capsule, a closed surface file (.obj .off .stl),\n"
      "or a tet mesh file (.msh .mesh .node .veg .vtu), remeshed inside its boundary surface.\n"
      "OUT is a tet mesh file (.msh .vtu .node .mesh, or .obj .off .stl for its boundary).\n"
      "\n"
      "options (lengths in metres):\n"
      "  --cell-size H          BCC lattice spacing (cube edge). Default: 1/20 of the shape's "
      "size\n"
      "                         (for surfaces: of the largest extent, at most 1/8 of the "
      "smallest)\n"
      "  --refine N             red-green refinement levels toward the surface (0..6, default 0)\n"
      "  --radius R             sphere, cylinder, capsule radius; torus major radius (default 1)\n"
      "  --minor-radius r       torus tube radius (default 0.25)\n"
      "  --half-extents a,b,c   box half sizes (default 1,1,1)\n"
      "  --half-length h        cylinder half height, capsule half segment (default 1)\n"
      "  --center x,y,z         shape centre (default 0,0,0)\n"
      "  --axis x,y,z           torus, cylinder, capsule axis (default 0,0,1)\n");
}

/* SHAPE as a closed surface: a surface file, or the boundary of a tet mesh file (remeshing a
 * mesh whose slivers force tiny steps: the sliver warning suggests it, docs/cli.md). */
static piola_status read_shape_surface(const char *path, piola_tri_mesh *surface) {
  if (cli_is_surface_path(path)) return piola_tri_mesh_read(path, surface);
  piola_tet_mesh tets;
  piola_status st = piola_tet_mesh_read(path, &tets);
  if (st != PIOLA_OK) return st;
  st = piola_tet_mesh_boundary(&tets, surface);
  piola_tet_mesh_free(&tets);
  return st;
}

static double shape_size(const piola_shape *s) {
  switch (s->type) {
    case PIOLA_SHAPE_BOX: return 2 * fmax(s->half_extents.x, fmax(s->half_extents.y, s->half_extents.z));
    case PIOLA_SHAPE_TORUS: return 2 * (s->radius + s->minor_radius);
    case PIOLA_SHAPE_CYLINDER:
    case PIOLA_SHAPE_CAPSULE: return 2 * fmax(s->radius, s->half_length + (s->type == PIOLA_SHAPE_CAPSULE ? s->radius : 0));
    case PIOLA_SHAPE_SURFACE: {
      double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      for (int32_t v = 0; v < s->surface->vertex_count; ++v)
        for (int k = 0; k < 3; ++k) {
          lo[k] = fmin(lo[k], s->surface->positions[3 * (size_t)v + k]);
          hi[k] = fmax(hi[k], s->surface->positions[3 * (size_t)v + k]);
        }
      /* 20 cells along the largest extent, but at least 8 across the thinnest one. */
      double largest = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
      double smallest = fmin(hi[0] - lo[0], fmin(hi[1] - lo[1], hi[2] - lo[2]));
      return fmin(largest, 2.5 * smallest);
    }
    default: return 2 * s->radius;
  }
}

int cli_mesh_generate(int argc, char **argv) {
  const char *shape_arg = NULL, *out_path = NULL;
  piola_mesher_def def = piola_default_mesher_def();
  piola_shape *s = &def.shapes[0];
  s->center = (piola_vec3){0, 0, 0};
  double cell_size = 0;
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      usage(stdout);
      return 0;
    }
    int has_value = i + 1 < argc;
    const char *value = has_value ? argv[i + 1] : NULL;
    int ok = 1;
    if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      ok = has_value;
      out_path = value;
    } else if (strcmp(a, "--cell-size") == 0) {
      ok = has_value && cli_parse_double(value, &cell_size) && cell_size > 0;
    } else if (strcmp(a, "--refine") == 0) {
      double levels = -1;
      ok = has_value && cli_parse_double(value, &levels) && levels >= 0 && levels <= 6 && levels == floor(levels);
      def.refinement_levels = (int)levels;
    } else if (strcmp(a, "--radius") == 0) {
      ok = has_value && cli_parse_double(value, &s->radius);
    } else if (strcmp(a, "--minor-radius") == 0) {
      ok = has_value && cli_parse_double(value, &s->minor_radius);
    } else if (strcmp(a, "--half-length") == 0) {
      ok = has_value && cli_parse_double(value, &s->half_length);
    } else if (strcmp(a, "--half-extents") == 0) {
      ok = has_value && cli_parse_vec3(value, &s->half_extents);
    } else if (strcmp(a, "--center") == 0) {
      ok = has_value && cli_parse_vec3(value, &s->center);
    } else if (strcmp(a, "--axis") == 0) {
      ok = has_value && cli_parse_vec3(value, &s->axis);
    } else if (a[0] == '-' && a[1] != '\0') {
      fprintf(stderr, "piola mesh generate: unknown option '%s'\n", a);
      usage(stderr);
      return 2;
    } else {
      if (shape_arg) {
        fprintf(stderr, "piola mesh generate: more than one SHAPE ('%s' and '%s')\n", shape_arg, a);
        return 2;
      }
      shape_arg = a;
      continue;
    }
    if (!ok) {
      fprintf(stderr, "piola mesh generate: option %s needs a valid value%s%s\n", a,
              has_value ? ", got " : "", has_value ? value : "");
      return 2;
    }
    ++i;
  }
  if (!shape_arg || !out_path) {
    fprintf(stderr, "piola mesh generate: %s\n", !shape_arg ? "missing SHAPE" : "missing -o OUT");
    usage(stderr);
    return 2;
  }
  static const struct {
    const char *name;
    piola_shape_type type;
  } names[] = {{"sphere", PIOLA_SHAPE_SPHERE},     {"box", PIOLA_SHAPE_BOX},
               {"torus", PIOLA_SHAPE_TORUS},       {"cylinder", PIOLA_SHAPE_CYLINDER},
               {"capsule", PIOLA_SHAPE_CAPSULE}};
  piola_tri_mesh surface = {0};
  int found = 0;
  for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k)
    if (strcasecmp(shape_arg, names[k].name) == 0) {
      s->type = names[k].type;
      found = 1;
    }
  if (!found) {
    piola_status st = read_shape_surface(shape_arg, &surface);
    if (st != PIOLA_OK) {
      fprintf(stderr,
              "piola mesh generate: SHAPE '%s' is not a primitive name, a readable surface or a "
              "readable tet mesh: %s\n",
              shape_arg, piola_last_error());
      return st == PIOLA_ERROR_IO ? 1 : 2;
    }
    s->type = PIOLA_SHAPE_SURFACE;
    s->surface = &surface;
  }
  def.shape_count = 1;
  double size = shape_size(s);
  def.cell_size = cell_size > 0 ? cell_size : (isfinite(size) && size > 0 ? size / 20 : 0.1);
  piola_tet_mesh mesh = {0};
  piola_status st = piola_mesher_generate(&def, &mesh);
  int code = 0;
  if (st != PIOLA_OK) {
    fprintf(stderr, "piola mesh generate: %s\n", piola_last_error());
    code = st == PIOLA_ERROR_OUT_OF_MEMORY ? 1 : 2;
  } else {
    st = piola_tet_mesh_write(out_path, &mesh);
    if (st != PIOLA_OK) {
      fprintf(stderr, "piola mesh generate: %s\n", piola_last_error());
      code = st == PIOLA_ERROR_IO ? 1 : 2;
    } else {
      printf("wrote %s: %d tets, %d nodes (cell size %g m, %d refinement levels)\n", out_path,
             (int)mesh.tet_count, (int)mesh.vertex_count, def.cell_size, def.refinement_levels);
    }
  }
  piola_tet_mesh_free(&mesh);
  piola_tri_mesh_free(&surface);
  return code;
}
