/* The _piola module: exceptions, array checks, argument converters and module setup. */
#define PYPIOLA_MODULE_FILE
#include "pypiola.h"

#include <string.h>

PyObject *pypiola_error, *pypiola_scene_error, *pypiola_mesh_error, *pypiola_simulation_error,
    *pypiola_closed_error;

PyObject *pypiola_raise(PyObject *type, piola_status status) {
  const char *message = piola_last_error();
  if (!message || !message[0]) message = piola_status_name(status);
  PyObject *exc = PyObject_CallFunction(type, "s", message);
  if (!exc) return NULL;
  PyObject *name = PyUnicode_FromString(piola_status_name(status));
  if (name) {
    PyObject_SetAttrString(exc, "status", name);
    Py_DECREF(name);
  }
  PyErr_SetObject(type, exc);
  Py_DECREF(exc);
  return NULL;
}

PyArrayObject *pypiola_check_array(PyObject *obj, const char *what, int type_num, int ndim,
                                   const npy_intp *dims, int writable) {
  if (!PyArray_Check(obj)) {
    PyErr_Format(PyExc_TypeError, "%s must be a numpy array", what);
    return NULL;
  }
  PyArrayObject *a = (PyArrayObject *)obj;
  if (PyArray_TYPE(a) != type_num) {
    PyArray_Descr *want = PyArray_DescrFromType(type_num);
    PyErr_Format(PyExc_TypeError, "%s must have dtype %S, got %S", what, (PyObject *)want,
                 (PyObject *)PyArray_DESCR(a));
    Py_XDECREF(want);
    return NULL;
  }
  if (PyArray_NDIM(a) != ndim) {
    PyErr_Format(PyExc_ValueError, "%s must have %d dimensions, got %d", what, ndim,
                 PyArray_NDIM(a));
    return NULL;
  }
  for (int i = 0; i < ndim; ++i)
    if (dims[i] >= 0 && PyArray_DIM(a, i) != dims[i]) {
      PyErr_Format(PyExc_ValueError, "%s: dimension %d must be %zd, got %zd", what, i,
                   (Py_ssize_t)dims[i], (Py_ssize_t)PyArray_DIM(a, i));
      return NULL;
    }
  if (!PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISALIGNED(a)) {
    PyErr_Format(PyExc_ValueError, "%s must be C-contiguous and aligned", what);
    return NULL;
  }
  if (writable && !PyArray_ISWRITEABLE(a)) {
    PyErr_Format(PyExc_ValueError, "%s must be writable", what);
    return NULL;
  }
  return a;
}

PyArrayObject *pypiola_new_array(int type_num, int ndim, const npy_intp *dims) {
  return (PyArrayObject *)PyArray_SimpleNew(ndim, (npy_intp *)dims, type_num);
}

int pypiola_vec3_converter(PyObject *obj, void *out) {
  piola_vec3 *v = out;
  if (!PyArg_ParseTuple(obj, "ddd;expected 3 floats", &v->x, &v->y, &v->z)) return 0;
  return 1;
}

int pypiola_track_converter(PyObject *obj, void *out) {
  piola_track *track = out;
  if (PyFloat_Check(obj) || PyLong_Check(obj)) {
    double value = PyFloat_AsDouble(obj);
    if (value == -1.0 && PyErr_Occurred()) return 0;
    *track = piola_track_constant(value);
    return 1;
  }
  PyObject *times = NULL, *values = NULL;
  if (!PyArg_ParseTuple(obj, "OO;a track is a float or a pair (times, values)", &times, &values))
    return 0;
  PyObject *t = PySequence_Fast(times, "track times must be a sequence");
  if (!t) return 0;
  PyObject *v = PySequence_Fast(values, "track values must be a sequence");
  if (!v) {
    Py_DECREF(t);
    return 0;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(t);
  int ok = 0;
  if (n != PySequence_Fast_GET_SIZE(v) || n < 1 || n > PIOLA_MAX_KEYS) {
    PyErr_Format(PyExc_ValueError, "a track needs 1 to %d keys with as many times as values",
                 PIOLA_MAX_KEYS);
  } else {
    double tt[PIOLA_MAX_KEYS], vv[PIOLA_MAX_KEYS];
    ok = 1;
    for (Py_ssize_t i = 0; ok && i < n; ++i) {
      tt[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(t, i));
      vv[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(v, i));
      if (PyErr_Occurred()) ok = 0;
    }
    piola_status st;
    if (ok && (st = piola_track_from_keys(tt, vv, (int32_t)n, track)) != PIOLA_OK) {
      pypiola_raise(PyExc_ValueError, st);
      ok = 0;
    }
  }
  Py_DECREF(t);
  Py_DECREF(v);
  return ok;
}

/* A tuple of 1..PIOLA_OGDEN_MAX_TERMS numbers into out; the count, or -1 with an error set. */
static int ogden_terms(PyObject *seq, const char *what, double *out) {
  if (!PyTuple_Check(seq) || PyTuple_GET_SIZE(seq) < 1 || PyTuple_GET_SIZE(seq) > PIOLA_OGDEN_MAX_TERMS) {
    PyErr_Format(PyExc_ValueError, "ogden.%s must be 1 to %d numbers", what, PIOLA_OGDEN_MAX_TERMS);
    return -1;
  }
  const int n = (int)PyTuple_GET_SIZE(seq);
  for (int i = 0; i < n; ++i) {
    out[i] = PyFloat_AsDouble(PyTuple_GET_ITEM(seq, i));
    if (out[i] == -1.0 && PyErr_Occurred()) return -1;
  }
  return n;
}

/* (model, E, nu, threshold, mode, (spline 3), (muscle 5), ((ogden mu...), (ogden alpha...)),
 * (mooney_rivlin c10, c01), (hgo mu, k1, k2, kappa, fiber_angle_degrees, (axis 3),
 * fiber_stretch_limit)) */
int pypiola_material_converter(PyObject *obj, void *out) {
  piola_material_def *def = out;
  *def = piola_default_material_def();
  const char *model = NULL, *mode = NULL;
  piola_spline_def *sp = &def->spline;
  piola_muscle_def *mu = &def->muscle;
  piola_hgo_def *h = &def->hgo;
  PyObject *omu = NULL, *oalpha = NULL;
  if (!PyArg_ParseTuple(obj, "sddds(ddd)(ddddd)(OO)(dd)(ddddd(ddd)d);bad material tuple", &model,
                        &def->youngs_modulus, &def->poisson_ratio, &def->inversion_threshold, &mode,
                        &sp->compression_stretch, &sp->elongation_stretch, &sp->stiffening,
                        &mu->passive_stiffness, &mu->passive_toe_stretch, &mu->max_active_stress,
                        &mu->optimal_stretch, &mu->active_width, &omu, &oalpha,
                        &def->mooney_rivlin.c10, &def->mooney_rivlin.c01, &h->mu, &h->k1, &h->k2,
                        &h->kappa, &h->fiber_angle_degrees, &h->axis[0], &h->axis[1], &h->axis[2],
                        &h->fiber_stretch_limit))
    return 0;
  const int nm = ogden_terms(omu, "mu", def->ogden.mu), na = ogden_terms(oalpha, "alpha", def->ogden.alpha);
  if (nm < 0 || na < 0) return 0;
  if (nm != na) {
    PyErr_Format(PyExc_ValueError, "ogden.mu has %d terms and ogden.alpha %d: they must match", nm, na);
    return 0;
  }
  def->ogden.term_count = nm;
  if (!piola_material_model_from_name(model, &def->model)) {
    PyErr_Format(PyExc_ValueError, "unknown material model '%s'", model);
    return 0;
  }
  if (!piola_inversion_mode_from_name(mode, &def->inversion_mode)) {
    PyErr_Format(PyExc_ValueError, "unknown inversion mode '%s' (default, linear, clamp or energy)", mode);
    return 0;
  }
  return 1;
}

/* (kind, pivot, axis, (vx, vy, vz), angular_speed, (tx, ty, tz), angle) */
int pypiola_motion_converter(PyObject *obj, void *out) {
  piola_rigid_motion_def *m = out;
  *m = piola_default_rigid_motion_def();
  int kind = 0;
  if (!PyArg_ParseTuple(
          obj, "iO&O&(O&O&O&)O&(O&O&O&)O&;bad motion tuple", &kind, pypiola_vec3_converter,
          &m->pivot, pypiola_vec3_converter, &m->axis, pypiola_track_converter, &m->velocity[0],
          pypiola_track_converter, &m->velocity[1], pypiola_track_converter, &m->velocity[2],
          pypiola_track_converter, &m->angular_speed, pypiola_track_converter, &m->translation[0],
          pypiola_track_converter, &m->translation[1], pypiola_track_converter, &m->translation[2],
          pypiola_track_converter, &m->angle))
    return 0;
  if (kind != PIOLA_MOTION_VELOCITY && kind != PIOLA_MOTION_POSE) {
    PyErr_SetString(PyExc_ValueError, "motion kind must be 0 (velocity) or 1 (pose)");
    return 0;
  }
  m->kind = (piola_motion_kind)kind;
  return 1;
}

static PyObject *set_thread_count(PyObject *self, PyObject *args) {
  (void)self;
  int threads = 0;
  if (!PyArg_ParseTuple(args, "i", &threads)) return NULL;
  if (threads < 0) {
    PyErr_SetString(PyExc_ValueError, "threads must be >= 0 (0: OpenMP's default)");
    return NULL;
  }
  piola_set_thread_count(threads);
  Py_RETURN_NONE;
}

/* The C library's defaults, so the Python layer never restates them. */
static PyObject *defaults(PyObject *self, PyObject *unused) {
  (void)self, (void)unused;
  piola_material_def m = piola_default_material_def();
  piola_world_def w = piola_default_world_def();
  piola_solid_def s = piola_default_solid_def();
  piola_mesher_def g = piola_default_mesher_def();
  PyObject *omu = PyTuple_New(m.ogden.term_count), *oalpha = PyTuple_New(m.ogden.term_count);
  if (!omu || !oalpha) {
    Py_XDECREF(omu), Py_XDECREF(oalpha);
    return NULL;
  }
  for (int i = 0; i < m.ogden.term_count; ++i) {
    PyTuple_SET_ITEM(omu, i, PyFloat_FromDouble(m.ogden.mu[i]));
    PyTuple_SET_ITEM(oalpha, i, PyFloat_FromDouble(m.ogden.alpha[i]));
  }
  return Py_BuildValue(
      "{s:(sddds(ddd)(ddddd)(NN)(dd)(ddddd(ddd)d)),s:{s:(ddd),s:d,s:d,s:d,s:i,s:d},s:{s:d,s:d,s:d,s:d,"
      "s:K,s:(idd)},s:{s:i}}",
      "material", piola_material_model_name(m.model), m.youngs_modulus, m.poisson_ratio,
      m.inversion_threshold, piola_inversion_mode_name(m.inversion_mode),
      m.spline.compression_stretch, m.spline.elongation_stretch, m.spline.stiffening,
      m.muscle.passive_stiffness, m.muscle.passive_toe_stretch, m.muscle.max_active_stress,
      m.muscle.optimal_stretch, m.muscle.active_width, omu, oalpha, m.mooney_rivlin.c10,
      m.mooney_rivlin.c01, m.hgo.mu, m.hgo.k1, m.hgo.k2, m.hgo.kappa, m.hgo.fiber_angle_degrees,
      m.hgo.axis[0], m.hgo.axis[1], m.hgo.axis[2], m.hgo.fiber_stretch_limit, "world", "gravity", w.gravity[0].value,
      w.gravity[1].value, w.gravity[2].value, "max_dt", w.max_dt, "cfl", w.cfl, "cg_tolerance",
      w.cg_tolerance, "cg_max_iterations", (int)w.cg_max_iterations, "collision_interval",
      w.collision_interval, "solid", "density", s.density, "stiffness_scale",
      s.stiffness_scale.value, "scramble_radius", s.scramble_radius, "activation",
      s.activation.value, "scramble_seed", (unsigned long long)s.scramble_seed, "self_collision",
      (int)s.self_collision.enabled, s.self_collision.thickness, s.self_collision.friction,
      "mesher", "refinement_levels", g.refinement_levels);
}

static PyMethodDef module_methods[] = {
    {"defaults", defaults, METH_NOARGS, "defaults() -> the C library's default definitions"},
    {"set_thread_count", set_thread_count, METH_VARARGS,
     "set_thread_count(n): threads of piola's parallel loops (0: OpenMP's default)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT,
    "_piola",
    "piola's C extension; use the piola package instead.",
    -1,
    module_methods,
    NULL,
    NULL,
    NULL,
    NULL,
};

static int add_methods(PyObject *module, PyMethodDef *methods) {
  PyObject *name = PyModule_GetNameObject(module);
  if (!name) return -1;
  for (PyMethodDef *m = methods; m->ml_name; ++m) {
    PyObject *f = PyCFunction_NewEx(m, NULL, name);
    if (!f || PyModule_AddObject(module, m->ml_name, f) < 0) {
      Py_XDECREF(f);
      Py_DECREF(name);
      return -1;
    }
  }
  Py_DECREF(name);
  return 0;
}

static int add_type(PyObject *module, PyTypeObject *type, const char *name) {
  if (PyType_Ready(type) < 0) return -1;
  Py_INCREF(type);
  if (PyModule_AddObject(module, name, (PyObject *)type) < 0) {
    Py_DECREF(type);
    return -1;
  }
  return 0;
}

static int add_exception(PyObject *module, PyObject **slot, const char *name, PyObject *bases,
                         const char *doc) {
  *slot = PyErr_NewExceptionWithDoc(name, doc, bases, NULL);
  if (!*slot) return -1;
  Py_INCREF(*slot);
  if (PyModule_AddObject(module, strrchr(name, '.') + 1, *slot) < 0) {
    Py_DECREF(*slot);
    return -1;
  }
  return 0;
}

static int add_int_dict(PyObject *module, const char *name, const char *const *keys,
                        const int *values, int count) {
  PyObject *d = PyDict_New();
  if (!d) return -1;
  for (int i = 0; i < count; ++i) {
    PyObject *v = PyLong_FromLong(values[i]);
    if (!v || PyDict_SetItemString(d, keys[i], v) < 0) {
      Py_XDECREF(v);
      Py_DECREF(d);
      return -1;
    }
    Py_DECREF(v);
  }
  if (PyModule_AddObject(module, name, d) < 0) {
    Py_DECREF(d);
    return -1;
  }
  return 0;
}

PyMODINIT_FUNC PyInit__piola(void);
PyMODINIT_FUNC PyInit__piola(void) {
  import_array();
  PyObject *m = PyModule_Create(&module_def);
  if (!m) return NULL;
  if (add_methods(m, pypiola_material_methods) < 0 || add_methods(m, pypiola_mesh_methods) < 0)
    goto fail;
  if (add_exception(m, &pypiola_error, "piola.Error", PyExc_RuntimeError,
                    "A failure reported by the piola C library; `status` names its kind.") < 0)
    goto fail;
  PyObject *scene_bases = PyTuple_Pack(2, pypiola_error, PyExc_ValueError);
  PyObject *closed_bases = PyTuple_Pack(2, pypiola_error, PyExc_ValueError);
  int bad = !scene_bases || !closed_bases ||
            add_exception(m, &pypiola_scene_error, "piola.SceneError", scene_bases,
                          "A scene that does not load; the message names the key path.") < 0 ||
            add_exception(m, &pypiola_mesh_error, "piola.MeshError", pypiola_error,
                          "A mesh that cannot be read, written or generated.") < 0 ||
            add_exception(m, &pypiola_simulation_error, "piola.SimulationError", pypiola_error,
                          "A step that failed (non-finite state); the world is left at the "
                          "state before the failing step.") < 0 ||
            add_exception(m, &pypiola_closed_error, "piola.ClosedError", closed_bases,
                          "A call on a world or scene that has been closed.") < 0;
  Py_XDECREF(scene_bases);
  Py_XDECREF(closed_bases);
  if (bad) goto fail;
  if (add_type(m, &pypiola_world_type, "World") < 0 ||
      add_type(m, &pypiola_scene_type, "Scene") < 0 ||
      add_type(m, &pypiola_obstacle_type, "Obstacle") < 0 ||
      add_type(m, &pypiola_output_type, "Output") < 0)
    goto fail;
  static const char *const obstacle_names[] = {"plane",   "sphere", "box",  "cylinder",
                                               "capsule", "torus",  "gear", "mesh"};
  static const int obstacle_values[] = {
      PIOLA_OBSTACLE_PLANE,   PIOLA_OBSTACLE_SPHERE, PIOLA_OBSTACLE_BOX,  PIOLA_OBSTACLE_CYLINDER,
      PIOLA_OBSTACLE_CAPSULE, PIOLA_OBSTACLE_TORUS,  PIOLA_OBSTACLE_GEAR, PIOLA_OBSTACLE_MESH};
  static const char *const shape_names[] = {"sphere",   "box",     "torus",
                                            "cylinder", "capsule", "surface"};
  static const int shape_values[] = {PIOLA_SHAPE_SPHERE,  PIOLA_SHAPE_BOX,
                                     PIOLA_SHAPE_TORUS,   PIOLA_SHAPE_CYLINDER,
                                     PIOLA_SHAPE_CAPSULE, PIOLA_SHAPE_SURFACE};
  if (PyModule_AddStringConstant(m, "__version__", PIOLA_VERSION_STRING) < 0) goto fail;
  if (add_int_dict(m, "OBSTACLE_TYPES", obstacle_names, obstacle_values, 8) < 0 ||
      add_int_dict(m, "SHAPE_TYPES", shape_names, shape_values, 6) < 0)
    goto fail;
  return m;
fail:
  Py_DECREF(m);
  return NULL;
}
