/* _piola.Obstacle: a rigid obstacle on its own (piola/obstacle.h), queried for signed
 * distances and poses, and the definition World.add_obstacle copies into a world. */
#include "pypiola.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
  PyObject_HEAD piola_obstacle_def def; /* def.mesh points at surface */
  piola_tri_mesh surface;               /* own copy for a mesh obstacle */
  piola_obstacle *obstacle;
} obstacle_object;

/* Obstacle((type, center, axis, radius, minor_radius, half_length, half_extents, tooth_count,
 *           tooth_depth, mesh_points or None, mesh_triangles or None, friction, motion)) */
static int obstacle_init(PyObject *self_obj, PyObject *args, PyObject *kwds) {
  obstacle_object *self = (obstacle_object *)self_obj;
  if (kwds && PyDict_Size(kwds) > 0) {
    PyErr_SetString(PyExc_TypeError, "Obstacle takes one definition tuple");
    return -1;
  }
  if (self->obstacle) {
    PyErr_SetString(PyExc_RuntimeError, "Obstacle is already initialized");
    return -1;
  }
  piola_obstacle_def def = piola_default_obstacle_def();
  int type = 0;
  PyObject *mp, *mt;
  if (!PyArg_ParseTuple(args, "(iO&O&dddO&idOOdO&)", &type, pypiola_vec3_converter, &def.center,
                        pypiola_vec3_converter, &def.axis, &def.radius, &def.minor_radius,
                        &def.half_length, pypiola_vec3_converter, &def.half_extents,
                        &def.tooth_count, &def.tooth_depth, &mp, &mt, &def.friction,
                        pypiola_motion_converter, &def.motion))
    return -1;
  if (type < 0 || type >= PIOLA_OBSTACLE_TYPE_COUNT) {
    PyErr_Format(PyExc_ValueError, "unknown obstacle type %d", type);
    return -1;
  }
  def.type = (piola_obstacle_type)type;
  if (def.type == PIOLA_OBSTACLE_MESH) {
    npy_intp pd[2] = {-1, 3}, td[2] = {-1, 3};
    PyArrayObject *p = pypiola_check_array(mp, "mesh points", NPY_DOUBLE, 2, pd, 0);
    PyArrayObject *t = p ? pypiola_check_array(mt, "mesh triangles", NPY_INT32, 2, td, 0) : NULL;
    if (!t) return -1;
    npy_intp n = PyArray_DIM(p, 0), m = PyArray_DIM(t, 0);
    const int32_t *idx = PyArray_DATA(t);
    for (npy_intp i = 0; i < 3 * m; ++i)
      if (idx[i] < 0 || idx[i] >= n) {
        PyErr_Format(PyExc_ValueError, "mesh triangles[%zd] has index %d outside 0..%zd",
                     (Py_ssize_t)(i / 3), (int)idx[i], (Py_ssize_t)n - 1);
        return -1;
      }
    piola_tri_mesh *s = &self->surface;
    s->vertex_count = (int32_t)n;
    s->triangle_count = (int32_t)m;
    s->positions = malloc(3 * (size_t)n * sizeof(double) + 1);
    s->triangles = malloc(3 * (size_t)m * sizeof(int32_t) + 1);
    if (!s->positions || !s->triangles) {
      piola_tri_mesh_free(s);
      PyErr_NoMemory();
      return -1;
    }
    memcpy(s->positions, PyArray_DATA(p), 3 * (size_t)n * sizeof(double));
    memcpy(s->triangles, idx, 3 * (size_t)m * sizeof(int32_t));
    def.mesh = s;
  }
  piola_status st = piola_obstacle_create(&def, &self->obstacle);
  if (st != PIOLA_OK) {
    piola_tri_mesh_free(&self->surface);
    pypiola_raise(PyExc_ValueError, st);
    return -1;
  }
  self->def = def;
  return 0;
}

static void obstacle_dealloc(PyObject *self_obj) {
  obstacle_object *self = (obstacle_object *)self_obj;
  piola_obstacle_destroy(self->obstacle);
  piola_tri_mesh_free(&self->surface);
  Py_TYPE(self_obj)->tp_free(self_obj);
}

static int ready(obstacle_object *self) {
  if (self->obstacle) return 1;
  PyErr_SetString(PyExc_RuntimeError, "Obstacle is not initialized");
  return 0;
}

/* signed_distance(points (n, 3), t) -> (distance (n,), normal (n, 3), velocity (n, 3)) */
static PyObject *obstacle_signed_distance(PyObject *self_obj, PyObject *args) {
  obstacle_object *self = (obstacle_object *)self_obj;
  PyObject *pobj;
  double t;
  if (!ready(self) || !PyArg_ParseTuple(args, "Od", &pobj, &t)) return NULL;
  npy_intp pd[2] = {-1, 3};
  PyArrayObject *p = pypiola_check_array(pobj, "points", NPY_DOUBLE, 2, pd, 0);
  if (!p) return NULL;
  npy_intp n = PyArray_DIM(p, 0), d1[1] = {n}, d3[2] = {n, 3};
  PyArrayObject *d = pypiola_new_array(NPY_DOUBLE, 1, d1),
                *nr = pypiola_new_array(NPY_DOUBLE, 2, d3),
                *v = pypiola_new_array(NPY_DOUBLE, 2, d3);
  if (!d || !nr || !v) {
    Py_XDECREF(d);
    Py_XDECREF(nr);
    Py_XDECREF(v);
    return NULL;
  }
  const double *pp = PyArray_DATA(p);
  double *dp = PyArray_DATA(d), *np_ = PyArray_DATA(nr), *vp = PyArray_DATA(v);
  for (npy_intp i = 0; i < n; ++i) {
    piola_vec3 x = {pp[3 * i], pp[3 * i + 1], pp[3 * i + 2]}, nn = {0, 0, 0}, vv = {0, 0, 0};
    dp[i] = piola_obstacle_signed_distance(self->obstacle, t, x, &nn, &vv);
    np_[3 * i] = nn.x, np_[3 * i + 1] = nn.y, np_[3 * i + 2] = nn.z;
    vp[3 * i] = vv.x, vp[3 * i + 1] = vv.y, vp[3 * i + 2] = vv.z;
  }
  return Py_BuildValue("NNN", d, nr, v);
}

/* pose(t) -> (rotation (3, 3), translation (3,)): x(t) = R x0 + translation */
static PyObject *obstacle_pose(PyObject *self_obj, PyObject *args) {
  obstacle_object *self = (obstacle_object *)self_obj;
  double t;
  if (!ready(self) || !PyArg_ParseTuple(args, "d", &t)) return NULL;
  piola_mat3 r;
  piola_vec3 c;
  piola_rigid_motion_pose(&self->def.motion, t, &r, &c);
  npy_intp d33[2] = {3, 3}, d3[1] = {3};
  PyArrayObject *ra = pypiola_new_array(NPY_DOUBLE, 2, d33),
                *ca = pypiola_new_array(NPY_DOUBLE, 1, d3);
  if (!ra || !ca) {
    Py_XDECREF(ra);
    Py_XDECREF(ca);
    return NULL;
  }
  memcpy(PyArray_DATA(ra), r.m, sizeof r.m);
  double *cp = PyArray_DATA(ca);
  cp[0] = c.x, cp[1] = c.y, cp[2] = c.z;
  return Py_BuildValue("NN", ra, ca);
}

const piola_obstacle_def *pypiola_obstacle_def(PyObject *obj) {
  if (!PyObject_TypeCheck(obj, &pypiola_obstacle_type) || !((obstacle_object *)obj)->obstacle) {
    PyErr_SetString(PyExc_TypeError, "expected an initialized _piola.Obstacle");
    return NULL;
  }
  return &((obstacle_object *)obj)->def;
}

static PyMethodDef obstacle_methods[] = {
    {"signed_distance", obstacle_signed_distance, METH_VARARGS,
     "signed_distance(points, t) -> (distance m, outward normal, velocity m/s)"},
    {"pose", obstacle_pose, METH_VARARGS, "pose(t) -> (rotation, translation m)"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject pypiola_obstacle_type =
    PYPIOLA_TYPE("_piola.Obstacle", obstacle_object,
                 "A rigid obstacle built from a definition tuple (use piola.Obstacle).",
                 obstacle_methods, NULL, obstacle_init, obstacle_dealloc);
