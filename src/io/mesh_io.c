/* Path-based mesh reading and writing: loads the file and dispatches on its extension. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>

#include "common/grow.h"
#include "common/input_path.h"
#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/mesh_writers.h"
#include "mesh/mesh_internal.h"
#include "piola/files.h"
#include "piola/mesh_io.h"

/* A whole input file, memory-mapped when possible: mapping skips the copy into a fresh
 * buffer and the zeroing of its pages, which cost as much as parsing for big files. */
typedef struct loaded_file {
  char *data;
  size_t size;
  int mapped;
} loaded_file;

static piola_status load_file(const char *path, loaded_file *f) {
  memset(f, 0, sizeof *f);
  FILE *stream;
  PIOLA_TRY(piola__open_input(path, &stream));
  struct stat st;
  if (fstat(fileno(stream), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fileno(stream), 0);
    if (p != MAP_FAILED) {
      fclose(stream);
      f->data = p;
      f->size = (size_t)st.st_size;
      f->mapped = 1;
      return PIOLA_OK;
    }
  }
  fclose(stream);
  return piola_read_file(path, 0, &f->data, &f->size);
}

static void unload_file(loaded_file *f) {
  if (f->mapped) munmap(f->data, f->size);
  else free(f->data);
  memset(f, 0, sizeof *f);
}

static const char *extension(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(path, '.');
  if (!dot || (slash && dot < slash)) return "";
  return dot;
}

/* TetGen: given a.node or a.ele, both a.node and a.ele are read. */
static piola_status read_tetgen(const char *path, piola_tet_mesh *out) {
  size_t n = strlen(path);
  char *node_path = malloc(n + 8), *ele_path = malloc(n + 8);
  loaded_file node = {0}, ele = {0};
  piola_status status = PIOLA_OK;
  if (!node_path || !ele_path) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
    goto done;
  }
  size_t stem = n - strlen(extension(path));
  memcpy(node_path, path, stem);
  memcpy(ele_path, path, stem);
  strcpy(node_path + stem, ".node");
  strcpy(ele_path + stem, ".ele");
  status = load_file(node_path, &node);
  if (status == PIOLA_OK) status = load_file(ele_path, &ele);
  if (status == PIOLA_OK)
    status = piola__read_tetgen_mem(node_path, node.data, node.size, ele_path, ele.data, ele.size, out);
done:
  free(node_path);
  free(ele_path);
  unload_file(&node);
  unload_file(&ele);
  return status;
}

piola_status piola_tet_mesh_read(const char *path, piola_tet_mesh *out) {
  if (!path || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh read: NULL argument");
  memset(out, 0, sizeof *out);
  const char *ext = extension(path);
  if (strcasecmp(ext, ".node") == 0 || strcasecmp(ext, ".ele") == 0) return read_tetgen(path, out);
  if (strcasecmp(ext, ".veg") == 0) {
    piola_vega_material *materials = NULL;
    int32_t count = 0;
    piola_status s = piola_vega_read(path, out, &materials, &count);
    free(materials);
    return s;
  }
  piola_status (*reader)(const char *, const char *, size_t, piola_tet_mesh *) = NULL;
  if (strcasecmp(ext, ".msh") == 0) reader = piola__read_gmsh_mem;
  else if (strcasecmp(ext, ".mesh") == 0) reader = piola__read_medit_mem;
  else if (strcasecmp(ext, ".vtu") == 0) reader = piola__read_vtu_mem;
  else if (strcasecmp(ext, ".obj") == 0 || strcasecmp(ext, ".off") == 0 || strcasecmp(ext, ".stl") == 0)
    /* a closed surface is the most common wrong input here: say how to get a tet mesh from it */
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "%s: '%s' is a surface, not a tet mesh; fill it with tets first: "
                      "piola mesh generate %s -o mesh.msh (docs/mesher.md)", path, ext, path);
  else
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "%s: unknown tet mesh extension '%s' (expected .node, .ele, .msh, .mesh, .veg, .vtu)", path,
                      ext);
  loaded_file f;
  PIOLA_TRY(load_file(path, &f));
  piola_status s = reader(path, f.data, f.size, out);
  unload_file(&f);
  return s;
}

piola_status piola_vega_read(const char *path, piola_tet_mesh *mesh, piola_vega_material **materials,
                             int32_t *material_count) {
  if (!path || !mesh || !materials || !material_count)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "vega read: NULL argument");
  memset(mesh, 0, sizeof *mesh);
  *materials = NULL;
  *material_count = 0;
  loaded_file f;
  PIOLA_TRY(load_file(path, &f));
  piola_status s = piola__read_vega_mem(path, f.data, f.size, mesh, materials, material_count);
  unload_file(&f);
  return s;
}

piola_status piola_tri_mesh_read(const char *path, piola_tri_mesh *out) {
  if (!path || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tri mesh read: NULL argument");
  memset(out, 0, sizeof *out);
  const char *ext = extension(path);
  piola_status (*reader)(const char *, const char *, size_t, piola_tri_mesh *) = NULL;
  if (strcasecmp(ext, ".obj") == 0) reader = piola__read_obj_mem;
  else if (strcasecmp(ext, ".off") == 0) reader = piola__read_off_mem;
  else if (strcasecmp(ext, ".stl") == 0) reader = piola__read_stl_mem;
  else
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: unknown surface extension '%s' (expected .obj, .off, .stl)",
                      path, ext);
  loaded_file f;
  PIOLA_TRY(load_file(path, &f));
  piola_status s = reader(path, f.data, f.size, out);
  unload_file(&f);
  return s;
}

piola_status piola_tet_mesh_write(const char *path, const piola_tet_mesh *mesh) {
  if (!path || !mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh write: NULL argument");
  PIOLA_TRY(piola_tet_mesh_validate(mesh));
  const char *ext = extension(path);
  if (strcasecmp(ext, ".msh") == 0) return piola__write_gmsh41(path, mesh);
  if (strcasecmp(ext, ".vtu") == 0) {
    piola_vtu_frame frame = {0};
    frame.tets = mesh;
    piola_vtu_field fields[2];
    double *values = NULL;
    if (mesh->tet_regions) {
      values = malloc((size_t)mesh->tet_count * sizeof(double) + 1);
      if (!values) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
      for (int32_t t = 0; t < mesh->tet_count; ++t) values[t] = mesh->tet_regions[t];
      fields[frame.cell_field_count++] = (piola_vtu_field){"region", 1, values};
    }
    if (mesh->tet_fibers) fields[frame.cell_field_count++] = (piola_vtu_field){"fiber", 3, mesh->tet_fibers};
    frame.cell_fields = fields;
    piola_status s = piola_vtu_write(path, &frame);
    free(values);
    return s;
  }
  if (strcasecmp(ext, ".node") == 0 || strcasecmp(ext, ".ele") == 0) return piola__write_tetgen(path, mesh);
  if (strcasecmp(ext, ".mesh") == 0) return piola__write_medit(path, mesh);
  if (strcasecmp(ext, ".obj") == 0 || strcasecmp(ext, ".off") == 0 || strcasecmp(ext, ".stl") == 0) {
    piola_tri_mesh boundary;
    PIOLA_TRY(piola_tet_mesh_boundary(mesh, &boundary));
    piola_status s = piola__tri_mesh_compact(&boundary);
    if (s == PIOLA_OK) s = piola_tri_mesh_write(path, &boundary);
    piola_tri_mesh_free(&boundary);
    return s;
  }
  return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                    "%s: cannot write tet meshes as '%s' (expected .msh, .vtu, .node, .mesh, .obj, .off, .stl)", path,
                    ext);
}

piola_status piola_tri_mesh_write(const char *path, const piola_tri_mesh *mesh) {
  if (!path || !mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tri mesh write: NULL argument");
  for (int32_t t = 0; t < 3 * mesh->triangle_count; ++t)
    if (mesh->triangles[t] < 0 || mesh->triangles[t] >= mesh->vertex_count)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: triangle %d has a vertex index out of range", path,
                        (int)(t / 3));
  const char *ext = extension(path);
  if (strcasecmp(ext, ".obj") == 0) return piola__write_obj(path, mesh);
  if (strcasecmp(ext, ".off") == 0) return piola__write_off(path, mesh);
  if (strcasecmp(ext, ".stl") == 0) return piola__write_stl(path, mesh);
  return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: cannot write surfaces as '%s' (expected .obj, .off, .stl)", path,
                    ext);
}
