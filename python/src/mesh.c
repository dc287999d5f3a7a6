/* Mesh files and the mesher (piola/mesh_io.h, piola/mesher.h). Arrays come back as fresh
 * NumPy arrays (float64 points, int32 indices) that the caller owns. */
#include "pypiola.h"

#include <stdlib.h>
#include <string.h>

/* A new array holding a copy of count * width values of `data`. */
static PyArrayObject *copy_out(int type_num, const void *data, npy_intp count, npy_intp width,
                               size_t item) {
  npy_intp dims[2] = {count, width};
  PyArrayObject *a = pypiola_new_array(type_num, width > 0 ? 2 : 1, dims);
  if (a && count > 0)
    memcpy(PyArray_DATA(a), data, (size_t)count * (size_t)(width > 0 ? width : 1) * item);
  return a;
}

static PyObject *read_tet_mesh(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *path_obj;
  if (!PyArg_ParseTuple(args, "O&", PyUnicode_FSConverter, &path_obj)) return NULL;
  piola_tet_mesh mesh = {0};
  piola_status st;
  const char *path = PyBytes_AS_STRING(path_obj);
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  st = piola_tet_mesh_read(path, &mesh);
  PyEval_RestoreThread(released);
  Py_DECREF(path_obj);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_mesh_error, st);
  PyArrayObject *points =
      copy_out(NPY_DOUBLE, mesh.positions, mesh.vertex_count, 3, sizeof(double));
  PyArrayObject *tets = copy_out(NPY_INT32, mesh.tets, mesh.tet_count, 4, sizeof(int32_t));
  PyObject *regions = mesh.tet_regions ? (PyObject *)copy_out(NPY_INT32, mesh.tet_regions,
                                                              mesh.tet_count, 0, sizeof(int32_t))
                                       : Py_NewRef(Py_None);
  PyObject *fibers = mesh.tet_fibers ? (PyObject *)copy_out(NPY_DOUBLE, mesh.tet_fibers,
                                                            mesh.tet_count, 3, sizeof(double))
                                     : Py_NewRef(Py_None);
  piola_tet_mesh_free(&mesh);
  if (!points || !tets || !regions || !fibers) {
    Py_XDECREF(points);
    Py_XDECREF(tets);
    Py_XDECREF(regions);
    Py_XDECREF(fibers);
    return NULL;
  }
  return Py_BuildValue("NNNN", points, tets, regions, fibers);
}

static PyObject *read_tri_mesh(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *path_obj;
  if (!PyArg_ParseTuple(args, "O&", PyUnicode_FSConverter, &path_obj)) return NULL;
  piola_tri_mesh mesh = {0};
  piola_status st;
  const char *path = PyBytes_AS_STRING(path_obj);
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  st = piola_tri_mesh_read(path, &mesh);
  PyEval_RestoreThread(released);
  Py_DECREF(path_obj);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_mesh_error, st);
  PyArrayObject *points =
      copy_out(NPY_DOUBLE, mesh.positions, mesh.vertex_count, 3, sizeof(double));
  PyArrayObject *tris =
      copy_out(NPY_INT32, mesh.triangles, mesh.triangle_count, 3, sizeof(int32_t));
  piola_tri_mesh_free(&mesh);
  if (!points || !tris) {
    Py_XDECREF(points);
    Py_XDECREF(tris);
    return NULL;
  }
  return Py_BuildValue("NN", points, tris);
}

/* Points (n, 3) float64 and cells (m, width) int32 with every index in [0, n). */
static int check_cells(PyObject *pobj, PyObject *cobj, int width, const char *cell_name,
                       PyArrayObject **points, PyArrayObject **cells) {
  npy_intp pd[2] = {-1, 3}, cd[2] = {-1, width};
  if (!(*points = pypiola_check_array(pobj, "points", NPY_DOUBLE, 2, pd, 0))) return -1;
  if (!(*cells = pypiola_check_array(cobj, cell_name, NPY_INT32, 2, cd, 0))) return -1;
  npy_intp n = PyArray_DIM(*points, 0), count = PyArray_SIZE(*cells);
  if (n > INT32_MAX || PyArray_DIM(*cells, 0) > INT32_MAX) {
    PyErr_SetString(PyExc_ValueError, "mesh too large for 32-bit indices");
    return -1;
  }
  const int32_t *c = PyArray_DATA(*cells);
  for (npy_intp i = 0; i < count; ++i)
    if (c[i] < 0 || c[i] >= n) {
      PyErr_Format(PyExc_ValueError, "%s[%zd][%zd] = %d is not a point index (0..%zd)", cell_name,
                   (Py_ssize_t)(i / width), (Py_ssize_t)(i % width), (int)c[i], (Py_ssize_t)n - 1);
      return -1;
    }
  return 0;
}

/* write_tet_mesh(path, points, tets, regions or None, fibers or None). The GIL stays held:
 * the arrays are read in place and must not change while the file is written. */
static PyObject *write_tet_mesh(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *path_obj, *pobj, *tobj, *robj, *fobj;
  if (!PyArg_ParseTuple(args, "O&OOOO", PyUnicode_FSConverter, &path_obj, &pobj, &tobj, &robj,
                        &fobj))
    return NULL;
  PyArrayObject *points, *tets;
  piola_tet_mesh mesh = {0};
  if (check_cells(pobj, tobj, 4, "tets", &points, &tets) < 0) goto fail;
  mesh.vertex_count = (int32_t)PyArray_DIM(points, 0);
  mesh.positions = PyArray_DATA(points);
  mesh.tet_count = (int32_t)PyArray_DIM(tets, 0);
  mesh.tets = PyArray_DATA(tets);
  npy_intp m = mesh.tet_count;
  if (robj != Py_None) {
    PyArrayObject *r = pypiola_check_array(robj, "regions", NPY_INT32, 1, &m, 0);
    if (!r) goto fail;
    mesh.tet_regions = PyArray_DATA(r);
  }
  if (fobj != Py_None) {
    npy_intp fd[2] = {m, 3};
    PyArrayObject *f = pypiola_check_array(fobj, "fibers", NPY_DOUBLE, 2, fd, 0);
    if (!f) goto fail;
    mesh.tet_fibers = PyArray_DATA(f);
  }
  piola_status st = piola_tet_mesh_validate(&mesh);
  if (st == PIOLA_OK) st = piola_tet_mesh_write(PyBytes_AS_STRING(path_obj), &mesh);
  if (st != PIOLA_OK) {
    pypiola_raise(pypiola_mesh_error, st);
    goto fail;
  }
  Py_DECREF(path_obj);
  Py_RETURN_NONE;
fail:
  Py_DECREF(path_obj);
  return NULL;
}

static PyObject *write_tri_mesh(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *path_obj, *pobj, *tobj;
  if (!PyArg_ParseTuple(args, "O&OO", PyUnicode_FSConverter, &path_obj, &pobj, &tobj)) return NULL;
  PyArrayObject *points, *tris;
  if (check_cells(pobj, tobj, 3, "triangles", &points, &tris) < 0) {
    Py_DECREF(path_obj);
    return NULL;
  }
  piola_tri_mesh mesh = {(int32_t)PyArray_DIM(points, 0), PyArray_DATA(points),
                         (int32_t)PyArray_DIM(tris, 0), PyArray_DATA(tris)};
  piola_status st = piola_tri_mesh_write(PyBytes_AS_STRING(path_obj), &mesh);
  Py_DECREF(path_obj);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_mesh_error, st);
  Py_RETURN_NONE;
}

/* generate_mesh([(type, center, axis, radius, minor_radius, half_length, half_extents,
 *                 surface_points or None, surface_triangles or None), ...], cell_size, levels) */
static PyObject *generate_mesh(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *list;
  piola_mesher_def def = piola_default_mesher_def();
  if (!PyArg_ParseTuple(args, "O!di", &PyList_Type, &list, &def.cell_size, &def.refinement_levels))
    return NULL;
  Py_ssize_t count = PyList_GET_SIZE(list);
  if (count < 1 || count > PIOLA_MESHER_MAX_SHAPES) {
    PyErr_Format(PyExc_ValueError, "the mesher takes 1 to %d shapes, got %zd",
                 PIOLA_MESHER_MAX_SHAPES, count);
    return NULL;
  }
  piola_tri_mesh surfaces[PIOLA_MESHER_MAX_SHAPES];
  memset(surfaces, 0, sizeof surfaces);
  PyObject *result = NULL;
  for (Py_ssize_t i = 0; i < count; ++i) {
    piola_shape *s = &def.shapes[i];
    int type = 0;
    PyObject *sp, *st;
    if (!PyArg_ParseTuple(PyList_GET_ITEM(list, i), "iO&O&dddO&OO;bad shape tuple", &type,
                          pypiola_vec3_converter, &s->center, pypiola_vec3_converter, &s->axis,
                          &s->radius, &s->minor_radius, &s->half_length, pypiola_vec3_converter,
                          &s->half_extents, &sp, &st))
      goto done;
    if (type < PIOLA_SHAPE_SPHERE || type > PIOLA_SHAPE_SURFACE) {
      PyErr_Format(PyExc_ValueError, "shape %zd: unknown type %d", i, type);
      goto done;
    }
    s->type = (piola_shape_type)type;
    if (s->type == PIOLA_SHAPE_SURFACE) {
      PyArrayObject *points, *tris;
      if (check_cells(sp, st, 3, "surface triangles", &points, &tris) < 0) goto done;
      piola_tri_mesh *m = &surfaces[i];
      m->vertex_count = (int32_t)PyArray_DIM(points, 0);
      m->triangle_count = (int32_t)PyArray_DIM(tris, 0);
      m->positions = malloc(3 * (size_t)m->vertex_count * sizeof(double) + 1);
      m->triangles = malloc(3 * (size_t)m->triangle_count * sizeof(int32_t) + 1);
      if (!m->positions || !m->triangles) {
        PyErr_NoMemory();
        goto done;
      }
      memcpy(m->positions, PyArray_DATA(points), 3 * (size_t)m->vertex_count * sizeof(double));
      memcpy(m->triangles, PyArray_DATA(tris), 3 * (size_t)m->triangle_count * sizeof(int32_t));
      s->surface = m;
    }
  }
  def.shape_count = (int)count;
  piola_tet_mesh mesh = {0};
  piola_status status;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  status = piola_mesher_generate(&def, &mesh);
  PyEval_RestoreThread(released);
  if (status != PIOLA_OK) {
    pypiola_raise(pypiola_mesh_error, status);
    goto done;
  }
  PyArrayObject *points =
      copy_out(NPY_DOUBLE, mesh.positions, mesh.vertex_count, 3, sizeof(double));
  PyArrayObject *tets = copy_out(NPY_INT32, mesh.tets, mesh.tet_count, 4, sizeof(int32_t));
  piola_tet_mesh_free(&mesh);
  if (points && tets) {
    result = Py_BuildValue("NN", points, tets);
  } else {
    Py_XDECREF(points);
    Py_XDECREF(tets);
  }
done:
  for (int i = 0; i < PIOLA_MESHER_MAX_SHAPES; ++i) piola_tri_mesh_free(&surfaces[i]);
  return result;
}

/* tet_mesh_boundary(points, tets) -> triangles (k, 3) int32, outward, same numbering. */
static PyObject *tet_mesh_boundary(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *pobj, *tobj;
  if (!PyArg_ParseTuple(args, "OO", &pobj, &tobj)) return NULL;
  PyArrayObject *points, *tets;
  if (check_cells(pobj, tobj, 4, "tets", &points, &tets) < 0) return NULL;
  piola_tet_mesh mesh = {(int32_t)PyArray_DIM(points, 0),
                         PyArray_DATA(points),
                         (int32_t)PyArray_DIM(tets, 0),
                         PyArray_DATA(tets),
                         NULL,
                         NULL};
  piola_tri_mesh out = {0};
  piola_status st = piola_tet_mesh_boundary(&mesh, &out);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_mesh_error, st);
  PyObject *tris =
      (PyObject *)copy_out(NPY_INT32, out.triangles, out.triangle_count, 3, sizeof(int32_t));
  piola_tri_mesh_free(&out);
  return tris;
}

/* {name: (count, components) array} of VTU fields. */
static PyObject *fields_dict(const piola_vtu_array *fields, int32_t count, int32_t rows) {
  PyObject *d = PyDict_New();
  for (int32_t i = 0; d && i < count; ++i) {
    const piola_vtu_array *f = &fields[i];
    PyArrayObject *a = f->components == 1
                           ? copy_out(NPY_DOUBLE, f->values, rows, 0, sizeof(double))
                           : copy_out(NPY_DOUBLE, f->values, rows, f->components, sizeof(double));
    if (!a || PyDict_SetItemString(d, f->name, (PyObject *)a) < 0) Py_CLEAR(d);
    Py_XDECREF(a);
  }
  return d;
}

/* read_vtu(path) -> (points, tets, triangles, point_fields, cell_fields, tet_cells,
 * triangle_cells) */
static PyObject *read_vtu(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *path_obj;
  if (!PyArg_ParseTuple(args, "O&", PyUnicode_FSConverter, &path_obj)) return NULL;
  piola_vtu_data data = {0};
  piola_status st;
  const char *path = PyBytes_AS_STRING(path_obj);
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  st = piola_vtu_read(path, &data);
  PyEval_RestoreThread(released);
  Py_DECREF(path_obj);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_mesh_error, st);
  PyObject *result = Py_BuildValue(
      "NNNNNNN", copy_out(NPY_DOUBLE, data.positions, data.point_count, 3, sizeof(double)),
      copy_out(NPY_INT32, data.tets, data.tet_count, 4, sizeof(int32_t)),
      copy_out(NPY_INT32, data.triangles, data.triangle_count, 3, sizeof(int32_t)),
      fields_dict(data.point_fields, data.point_field_count, data.point_count),
      fields_dict(data.cell_fields, data.cell_field_count, data.cell_count),
      copy_out(NPY_INT32, data.tet_cells, data.tet_count, 0, sizeof(int32_t)),
      copy_out(NPY_INT32, data.triangle_cells, data.triangle_count, 0, sizeof(int32_t)));
  piola_vtu_data_free(&data);
  return result;
}

PyMethodDef pypiola_mesh_methods[] = {
    {"read_vtu", read_vtu, METH_VARARGS,
     "read_vtu(path) -> (points, tets, triangles, point_fields, cell_fields, tet_cells, "
     "triangle_cells)"},
    {"read_tet_mesh", read_tet_mesh, METH_VARARGS,
     "read_tet_mesh(path) -> (points, tets, regions, fibers)"},
    {"read_tri_mesh", read_tri_mesh, METH_VARARGS, "read_tri_mesh(path) -> (points, triangles)"},
    {"write_tet_mesh", write_tet_mesh, METH_VARARGS,
     "write_tet_mesh(path, points, tets, regions, fibers)"},
    {"write_tri_mesh", write_tri_mesh, METH_VARARGS, "write_tri_mesh(path, points, triangles)"},
    {"generate_mesh", generate_mesh, METH_VARARGS,
     "generate_mesh(shapes, cell_size, levels) -> (points, tets)"},
    {"tet_mesh_boundary", tet_mesh_boundary, METH_VARARGS,
     "tet_mesh_boundary(points, tets) -> triangles"},
    {NULL, NULL, 0, NULL},
};
