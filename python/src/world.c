/* _piola.World: a world (piola/world.h), its bodies' state as NumPy views, and stepping with
 * the GIL released.
 *
 * Views: positions and velocities of every body (solid or shell) are writable arrays over
 * the world's own buffers (no copy); every other array (rest positions, masses, cells,
 * constraint flags) is a read-only view. A view holds a reference to the world object, so the
 * memory under it lives as long as the view: close() only ends the world for calls (ClosedError),
 * and the world is freed when the last view and the world object are gone.
 *
 * Writes through a view reach the solver through a snapshot: after every call that changes
 * the state the world object copies each body's positions and velocities; before the next
 * step (and before stats) it compares, and hands a changed body to piola_world_body_set_state,
 * which recomputes its forces. Untouched bodies are not touched, so stepping from Python gives
 * the same numbers as stepping from C. */
#include "pypiola.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* apply_view_writes' own refusal, told apart from the library's statuses */
#define VIEW_BAD_VELOCITY ((piola_status)-100)

typedef struct {
  piola_body_id id;
  double *x, *v; /* snapshots, 3n each */
  int32_t n;
} body_shadow;

typedef struct {
  PyObject_HEAD piola_world *world;
  PyObject *scene; /* the owning scene object (strong), or NULL for a world of our own */
  int closed;
  int busy;             /* a step is running with the GIL released */
  body_shadow *shadows; /* one per body, in the world's body order */
  int32_t shadow_count;
} world_object;

piola_world *pypiola_world_get(PyObject *obj) {
  if (!PyObject_TypeCheck(obj, &pypiola_world_type)) {
    PyErr_SetString(PyExc_TypeError, "expected a _piola.World");
    return NULL;
  }
  world_object *self = (world_object *)obj;
  if (self->closed || !self->world || (self->scene && pypiola_scene_closed(self->scene))) {
    PyErr_SetString(pypiola_closed_error, "the world has been closed");
    return NULL;
  }
  if (self->busy) {
    PyErr_SetString(PyExc_RuntimeError, "the world is stepping in another thread");
    return NULL;
  }
  return self->world;
}

static void free_shadows(world_object *self) {
  for (int32_t i = 0; i < self->shadow_count; ++i)
    free(self->shadows[i].x), free(self->shadows[i].v);
  free(self->shadows);
  self->shadows = NULL;
  self->shadow_count = 0;
}

/* Takes the snapshot of every body; a new body (the count changed) rebuilds the list, since
 * adding a solid moves the shells one place on. */
static int take_snapshots(world_object *self) {
  int32_t count = piola_world_body_count(self->world);
  if (count != self->shadow_count) {
    free_shadows(self);
    body_shadow *list = calloc((size_t)count + 1, sizeof *list);
    if (!list) return PyErr_NoMemory(), -1;
    self->shadows = list;
    self->shadow_count = count;
    for (int32_t i = 0; i < count; ++i) {
      list[i].id = piola_world_body_at(self->world, i);
      list[i].n = piola_world_body_node_count(self->world, list[i].id);
      list[i].x = malloc(3 * (size_t)list[i].n * sizeof(double) + 1);
      list[i].v = malloc(3 * (size_t)list[i].n * sizeof(double) + 1);
      if (!list[i].x || !list[i].v) {
        free_shadows(self);
        return PyErr_NoMemory(), -1;
      }
    }
  }
  for (int32_t i = 0; i < count; ++i) {
    body_shadow *s = &self->shadows[i];
    size_t bytes = 3 * (size_t)s->n * sizeof(double);
    memcpy(s->x, piola_world_body_positions(self->world, s->id), bytes);
    memcpy(s->v, piola_world_body_velocities(self->world, s->id), bytes);
  }
  return 0;
}

static int all_finite(const double *values, size_t count) {
  for (size_t i = 0; i < count; ++i)
    if (!isfinite(values[i])) return 0;
  return 1;
}

/* Hands bodies changed through their views to set_state. A refused state (NaN) is undone. */
static int apply_view_writes(world_object *self) {
  for (int32_t i = 0; i < self->shadow_count; ++i) {
    body_shadow *s = &self->shadows[i];
    size_t bytes = 3 * (size_t)s->n * sizeof(double);
    double *x = (double *)piola_world_body_positions(self->world, s->id);
    double *v = (double *)piola_world_body_velocities(self->world, s->id);
    int dx = memcmp(x, s->x, bytes) != 0, dv = memcmp(v, s->v, bytes) != 0;
    if (!dx && !dv) continue;
    double *copy = malloc(2 * bytes + 1);
    if (!copy) return PyErr_NoMemory(), -1;
    memcpy(copy, x, bytes);
    memcpy(copy + 3 * (size_t)s->n, v, bytes);
    /* set_state copies into the same buffers: give it a separate copy. It checks positions;
     * velocities are checked here. */
    piola_status st = all_finite(v, 3 * (size_t)s->n)
                          ? piola_world_body_set_state(self->world, s->id, dx ? copy : NULL,
                                                       dv ? copy + 3 * (size_t)s->n : NULL)
                          : VIEW_BAD_VELOCITY;
    free(copy);
    if (st != PIOLA_OK) {
      memcpy(x, s->x, bytes);
      memcpy(v, s->v, bytes);
      PyErr_Format(PyExc_ValueError,
                   "body '%s': the state written through its views was refused and undone: %s",
                   piola_world_body_name(self->world, s->id),
                   st == VIEW_BAD_VELOCITY ? "a velocity is not finite" : piola_last_error());
      return -1;
    }
    memcpy(s->x, x, bytes);
    memcpy(s->v, v, bytes);
  }
  return 0;
}

/* The world, ready for a call that reads derived state or steps. */
static piola_world *synced(world_object *self) {
  piola_world *w = pypiola_world_get((PyObject *)self);
  if (!w || apply_view_writes(self) < 0) return NULL;
  return w;
}

/* World(gravity (3 tracks), max_dt, cfl, cg_tolerance, cg_max_iterations, collision_interval) */
static int world_init(PyObject *self_obj, PyObject *args, PyObject *kwds) {
  world_object *self = (world_object *)self_obj;
  if (kwds && PyDict_Size(kwds) > 0) {
    PyErr_SetString(PyExc_TypeError, "World takes positional arguments");
    return -1;
  }
  if (self->world) {
    PyErr_SetString(PyExc_RuntimeError, "World is already initialized");
    return -1;
  }
  piola_world_def def = piola_default_world_def();
  if (!PyArg_ParseTuple(args, "(O&O&O&)dddid", pypiola_track_converter, &def.gravity[0],
                        pypiola_track_converter, &def.gravity[1], pypiola_track_converter,
                        &def.gravity[2], &def.max_dt, &def.cfl, &def.cg_tolerance,
                        &def.cg_max_iterations, &def.collision_interval))
    return -1;
  piola_status st = piola_world_create(&def, &self->world);
  if (st != PIOLA_OK) {
    self->world = NULL;
    pypiola_raise(PyExc_ValueError, st);
    return -1;
  }
  return 0;
}

PyObject *pypiola_world_from_scene(PyObject *scene, piola_world *world) {
  world_object *self = (world_object *)PyType_GenericNew(&pypiola_world_type, NULL, NULL);
  if (!self) return NULL;
  self->world = world;
  Py_INCREF(scene);
  self->scene = scene;
  if (take_snapshots(self) < 0) {
    Py_DECREF(self);
    return NULL;
  }
  return (PyObject *)self;
}

static void world_dealloc(PyObject *self_obj) {
  world_object *self = (world_object *)self_obj;
  free_shadows(self);
  if (self->scene) {
    pypiola_scene_forget_world(self->scene);
    Py_DECREF(self->scene); /* the scene frees its world */
  } else {
    piola_world_destroy(self->world);
  }
  Py_TYPE(self_obj)->tp_free(self_obj);
}

static PyObject *world_close(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  world_object *self = (world_object *)self_obj;
  if (self->busy) {
    PyErr_SetString(PyExc_RuntimeError, "the world is stepping in another thread");
    return NULL;
  }
  self->closed = 1;
  Py_RETURN_NONE;
}

static PyObject *world_get_closed(PyObject *self_obj, void *unused) {
  (void)unused;
  world_object *self = (world_object *)self_obj;
  return PyBool_FromLong(self->closed || (self->scene && pypiola_scene_closed(self->scene)));
}

static PyObject *stats_dict(const piola_step_stats *st) {
  return Py_BuildValue(
      "{s:i,s:i,s:i,s:d,s:L,s:L,s:i,s:i,s:i,s:i,s:i,s:i,s:i}", "substeps", (int)st->substeps,
      "cg_iterations", (int)st->cg_iterations, "colliding", (int)st->colliding, "last_dt",
      st->last_dt, "contacts", (long long)st->contacts, "impacts", (long long)st->impacts,
      "impact_zones", (int)st->impact_zones, "collision_steps", (int)st->collision_steps,
      "newton_iterations", (int)st->newton_iterations, "linear_iterations",
      (int)st->linear_iterations, "newton_failures", (int)st->newton_failures, "step_retries",
      (int)st->step_retries, "energy_redos", (int)st->energy_redos);
}

/* Runs advance_to (target >= 0) or one step (dt_limit) without the GIL. */
static PyObject *run_steps(world_object *self, int advance, double value) {
  piola_world *w = synced(self);
  if (!w) return NULL;
  if (!isfinite(value) && advance) {
    PyErr_SetString(PyExc_ValueError, "advance_to: the time must be finite");
    return NULL;
  }
  if (advance && value < piola_world_time(w)) {
    /* PyErr_Format has no %g */
    char text[160];
    snprintf(text, sizeof text, "advance_to: t = %g s is before the world's time %g s", value,
             piola_world_time(w));
    PyErr_SetString(PyExc_ValueError, text);
    return NULL;
  }
  piola_step_stats st = {0};
  piola_status status;
  self->busy = 1;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  status = advance ? piola_world_advance_to(w, value, &st) : piola_world_step(w, value, &st);
  PyEval_RestoreThread(released);
  self->busy = 0;
  if (take_snapshots(self) < 0) return NULL;
  if (status != PIOLA_OK)
    return pypiola_raise(
        status == PIOLA_ERROR_NOT_FINITE ? pypiola_simulation_error : pypiola_error, status);
  return stats_dict(&st);
}

static PyObject *world_advance_to(PyObject *self, PyObject *args) {
  double t;
  if (!PyArg_ParseTuple(args, "d", &t)) return NULL;
  return run_steps((world_object *)self, 1, t);
}

static PyObject *world_step(PyObject *self, PyObject *args) {
  double dt = INFINITY;
  if (!PyArg_ParseTuple(args, "|d", &dt)) return NULL;
  if (!(dt > 0)) {
    PyErr_SetString(PyExc_ValueError, "step: dt_limit must be > 0");
    return NULL;
  }
  return run_steps((world_object *)self, 0, dt);
}

static PyObject *world_info(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  piola_world *w = pypiola_world_get(self_obj);
  if (!w) return NULL;
  return Py_BuildValue("{s:d,s:d,s:i,s:i,s:i}", "time", piola_world_time(w), "stable_dt",
                       piola_world_stable_dt(w), "solids", (int)piola_world_solid_count(w),
                       "shells", (int)piola_world_shell_count(w), "obstacles",
                       (int)piola_world_obstacle_count(w));
}

/* The messages of the warnings raised so far, in the order of their kinds. */
static PyObject *world_warnings(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  piola_world *w = pypiola_world_get(self_obj);
  if (!w) return NULL;
  PyObject *list = PyList_New(0);
  for (int k = 0; list && k < PIOLA_WARNING_KIND_COUNT; ++k) {
    const char *text = piola_world_warning(w, (piola_warning_kind)k);
    if (!text) continue;
    PyObject *item = PyUnicode_DecodeUTF8(text, (Py_ssize_t)strlen(text), "replace");
    if (!item || PyList_Append(list, item) < 0) Py_CLEAR(list);
    Py_XDECREF(item);
  }
  return list;
}

/* kind: 0 solid, 1 shell. Checks the index. */
static piola_world *body_world(PyObject *self, int kind, int index) {
  piola_world *w = pypiola_world_get(self);
  if (!w) return NULL;
  int count = kind == 0 ? piola_world_solid_count(w) : piola_world_shell_count(w);
  if (kind != 0 && kind != 1) {
    PyErr_SetString(PyExc_ValueError, "body kind must be 0 (solid) or 1 (shell)");
    return NULL;
  }
  if (index < 0 || index >= count) {
    PyErr_Format(PyExc_IndexError, "no %s %d (the world has %d)", kind == 0 ? "solid" : "shell",
                 index, count);
    return NULL;
  }
  return w;
}

static PyObject *world_body_name(PyObject *self, PyObject *args) {
  int kind, index;
  if (!PyArg_ParseTuple(args, "ii", &kind, &index)) return NULL;
  piola_world *w = body_world(self, kind, index);
  if (!w) return NULL;
  return PyUnicode_FromString(kind == 0 ? piola_world_solid_name(w, index)
                                        : piola_world_shell_name(w, index));
}

/* A view of `data` (rows x width of type_num) owned by the world object. */
static PyObject *make_view(PyObject *self, const void *data, npy_intp rows, npy_intp width,
                           int type_num, int writable) {
  npy_intp dims[2] = {rows, width};
  PyObject *a = PyArray_SimpleNewFromData(width > 0 ? 2 : 1, dims, type_num, (void *)data);
  if (!a) return NULL;
  Py_INCREF(self);
  if (PyArray_SetBaseObject((PyArrayObject *)a, self) < 0) {
    Py_DECREF(a);
    return NULL;
  }
  if (!writable) PyArray_CLEARFLAGS((PyArrayObject *)a, NPY_ARRAY_WRITEABLE);
  return a;
}

/* body_array(kind, index, name): positions, velocities (writable for solids), rest_positions,
 * masses, cells (tets or triangles), flags. */
static PyObject *world_body_array(PyObject *self, PyObject *args) {
  int kind, index;
  const char *name;
  if (!PyArg_ParseTuple(args, "iis", &kind, &index, &name)) return NULL;
  piola_world *w = body_world(self, kind, index);
  if (!w) return NULL;
  const piola_elastic_body *eb = kind == 0 ? piola_world_solid_body(w, index) : NULL;
  const piola_shell_body *sb = kind == 1 ? piola_world_shell_body(w, index) : NULL;
  npy_intp n = eb ? piola_elastic_body_vertex_count(eb) : piola_shell_body_vertex_count(sb);
  if (strcmp(name, "positions") == 0)
    return make_view(
        self, eb ? piola_world_solid_positions(w, index) : piola_world_shell_positions(w, index), n,
        3, NPY_DOUBLE, 1);
  if (strcmp(name, "velocities") == 0)
    return make_view(
        self, eb ? piola_world_solid_velocities(w, index) : piola_world_shell_velocities(w, index),
        n, 3, NPY_DOUBLE, 1);
  if (strcmp(name, "rest_positions") == 0)
    return make_view(
        self, eb ? piola_elastic_body_rest_positions(eb) : piola_shell_body_rest_positions(sb), n,
        3, NPY_DOUBLE, 0);
  if (strcmp(name, "masses") == 0)
    return make_view(self, eb ? piola_elastic_body_masses(eb) : piola_shell_body_masses(sb), n, 0,
                     NPY_DOUBLE, 0);
  if (strcmp(name, "cells") == 0)
    return eb ? make_view(self, piola_elastic_body_tets(eb), piola_elastic_body_tet_count(eb), 4,
                          NPY_INT32, 0)
              : make_view(self, piola_shell_body_triangles(sb), piola_shell_body_triangle_count(sb),
                          3, NPY_INT32, 0);
  if (strcmp(name, "flags") == 0)
    return make_view(self,
                     eb ? piola_world_solid_constraint_flags(w, index)
                        : piola_world_shell_constraint_flags(w, index),
                     n, 0, NPY_UINT8, 0);
  PyErr_Format(PyExc_ValueError, "no body array '%s'", name);
  return NULL;
}

/* body_stats(kind, index) -> dict */
static PyObject *world_body_stats(PyObject *self, PyObject *args) {
  int kind, index;
  if (!PyArg_ParseTuple(args, "ii", &kind, &index)) return NULL;
  if (!body_world(self, kind, index) || !synced((world_object *)self)) return NULL;
  piola_world *w = ((world_object *)self)->world;
  if (kind == 0) {
    piola_solid_stats s = piola_world_solid_stats(w, index);
    return Py_BuildValue("{s:d,s:d,s:i,s:d}", "kinetic_energy", s.kinetic_energy, "elastic_energy",
                         s.elastic_energy, "inverted_count", (int)s.inverted_count, "min_det_f",
                         s.min_det_f);
  }
  piola_world_shell_stats s = piola_world_shell_get_stats(w, index);
  return Py_BuildValue("{s:d,s:d,s:d,s:i,s:i}", "kinetic_energy", s.kinetic_energy,
                       "membrane_energy", s.membrane_energy, "bending_energy", s.bending_energy,
                       "inverted_count", (int)s.inverted_count, "degenerate_count",
                       (int)s.degenerate_count);
}

/* set_body_state(kind, index, positions or None, velocities or None): copies. */
static PyObject *world_set_body_state(PyObject *self_obj, PyObject *args) {
  world_object *self = (world_object *)self_obj;
  int kind, index;
  PyObject *pobj, *vobj;
  if (!PyArg_ParseTuple(args, "iiOO", &kind, &index, &pobj, &vobj)) return NULL;
  if (!body_world(self_obj, kind, index) || !synced(self)) return NULL;
  piola_body_id id = piola_world_body_of(self->world, (piola_body_kind)kind, index);
  npy_intp dims[2] = {piola_world_body_node_count(self->world, id), 3};
  const double *p = NULL, *v = NULL;
  if (pobj != Py_None) {
    PyArrayObject *a = pypiola_check_array(pobj, "positions", NPY_DOUBLE, 2, dims, 0);
    if (!a) return NULL;
    p = PyArray_DATA(a);
  }
  if (vobj != Py_None) {
    PyArrayObject *a = pypiola_check_array(vobj, "velocities", NPY_DOUBLE, 2, dims, 0);
    if (!a) return NULL;
    v = PyArray_DATA(a);
    if (!all_finite(v, 3 * (size_t)dims[0])) {
      PyErr_SetString(PyExc_ValueError, "set_state: a velocity is not finite");
      return NULL;
    }
  }
  /* the arrays may be the world's own views: copy before handing them over */
  size_t bytes = 3 * (size_t)dims[0] * sizeof(double);
  double *copy = malloc(2 * bytes + 1);
  if (!copy) return PyErr_NoMemory();
  if (p) memcpy(copy, p, bytes);
  if (v) memcpy(copy + 3 * (size_t)dims[0], v, bytes);
  piola_status st = piola_world_body_set_state(self->world, id, p ? copy : NULL,
                                               v ? copy + 3 * (size_t)dims[0] : NULL);
  free(copy);
  if (take_snapshots(self) < 0) return NULL;
  if (st != PIOLA_OK) return pypiola_raise(PyExc_ValueError, st);
  Py_RETURN_NONE;
}

static int matrix9_converter(PyObject *obj, void *out) {
  piola_mat3 *m = out;
  double *d = &m->m[0][0];
  return PyArg_ParseTuple(obj, "ddddddddd;expected 9 floats (row-major 3x3)", d, d + 1, d + 2,
                          d + 3, d + 4, d + 5, d + 6, d + 7, d + 8) != 0;
}

/* One (selector, driven, motion or None) constraint; selector (kind, box_min, box_max, center,
 * radius, indices int32 or None). indices point into the tuple's array (kept alive by args). */
static int parse_constraint(PyObject *obj, piola_constraint_def *c) {
  int kind = 0, driven = 0;
  PyObject *indices, *motion;
  piola_selector *s = &c->selector;
  if (!PyArg_ParseTuple(obj, "(iO&O&O&dO)pO;bad constraint tuple", &kind, pypiola_vec3_converter,
                        &s->box_min, pypiola_vec3_converter, &s->box_max, pypiola_vec3_converter,
                        &s->center, &s->radius, &indices, &driven, &motion))
    return -1;
  if (kind < PIOLA_SELECT_BOX || kind > PIOLA_SELECT_INDICES) {
    PyErr_Format(PyExc_ValueError, "unknown selector kind %d", kind);
    return -1;
  }
  s->type = (piola_selector_type)kind;
  if (kind == PIOLA_SELECT_INDICES) {
    npy_intp d[1] = {-1};
    PyArrayObject *a = pypiola_check_array(indices, "indices", NPY_INT32, 1, d, 0);
    if (!a) return -1;
    s->indices = PyArray_DATA(a);
    s->index_count = (int32_t)PyArray_DIM(a, 0);
  }
  c->driven = driven != 0;
  c->motion = piola_default_rigid_motion_def();
  if (driven && !pypiola_motion_converter(motion, &c->motion)) return -1;
  return 0;
}

/* add_solid((name or None, points, tets, material, stiffness_scale, density, shear, bulk,
 *            velocity, constraints, initial_matrix, scramble_radius, scramble_seed,
 *            (self_collision, thickness, friction), fibers or None, activation)) -> index */
static PyObject *world_add_solid(PyObject *self_obj, PyObject *args) {
  world_object *self = (world_object *)self_obj;
  piola_world *w = synced(self);
  if (!w) return NULL;
  piola_solid_def def = piola_default_solid_def();
  PyObject *pobj, *tobj, *cons, *fobj;
  int collide = 0;
  unsigned long long seed = 1;
  if (!PyArg_ParseTuple(args, "(zOOO&O&dO&O&O&O!O&dK(pdd)OO&)", &def.name, &pobj, &tobj,
                        pypiola_material_converter, &def.material, pypiola_track_converter,
                        &def.stiffness_scale, &def.density, pypiola_track_converter,
                        &def.shear_viscosity, pypiola_track_converter, &def.bulk_viscosity,
                        pypiola_vec3_converter, &def.velocity, &PyList_Type, &cons,
                        matrix9_converter, &def.initial_matrix, &def.scramble_radius, &seed,
                        &collide, &def.self_collision.thickness, &def.self_collision.friction,
                        &fobj, pypiola_track_converter, &def.activation))
    return NULL;
  def.scramble_seed = seed;
  def.self_collision.enabled = collide != 0;
  npy_intp pd[2] = {-1, 3}, td[2] = {-1, 4};
  PyArrayObject *points = pypiola_check_array(pobj, "points", NPY_DOUBLE, 2, pd, 0);
  PyArrayObject *tets = points ? pypiola_check_array(tobj, "tets", NPY_INT32, 2, td, 0) : NULL;
  if (!tets) return NULL;
  if (PyArray_DIM(points, 0) > INT32_MAX || PyArray_DIM(tets, 0) > INT32_MAX) {
    PyErr_SetString(PyExc_ValueError, "mesh too large for 32-bit indices");
    return NULL;
  }
  piola_tet_mesh mesh = {(int32_t)PyArray_DIM(points, 0),
                         PyArray_DATA(points),
                         (int32_t)PyArray_DIM(tets, 0),
                         PyArray_DATA(tets),
                         NULL,
                         NULL};
  if (fobj != Py_None) {
    npy_intp fd[2] = {mesh.tet_count, 3};
    PyArrayObject *f = pypiola_check_array(fobj, "fibers", NPY_DOUBLE, 2, fd, 0);
    if (!f) return NULL;
    def.fiber_directions = PyArray_DATA(f);
  }
  piola_status st = piola_tet_mesh_validate(&mesh);
  if (st != PIOLA_OK) return pypiola_raise(PyExc_ValueError, st);
  def.mesh = &mesh;
  Py_ssize_t count = PyList_GET_SIZE(cons);
  piola_constraint_def *c = calloc((size_t)count + 1, sizeof *c);
  if (!c) return PyErr_NoMemory();
  for (Py_ssize_t i = 0; i < count; ++i)
    if (parse_constraint(PyList_GET_ITEM(cons, i), &c[i]) < 0) {
      free(c);
      return NULL;
    }
  def.constraints = c;
  def.constraint_count = (int32_t)count;
  int32_t index = -1;
  st = piola_world_add_solid(w, &def, &index);
  free(c);
  if (st != PIOLA_OK) return pypiola_raise(PyExc_ValueError, st);
  if (take_snapshots(self) < 0) return NULL;
  return PyLong_FromLong(index);
}

static PyObject *world_add_obstacle(PyObject *self_obj, PyObject *obstacle) {
  piola_world *w = synced((world_object *)self_obj);
  if (!w) return NULL;
  const piola_obstacle_def *def = pypiola_obstacle_def(obstacle);
  if (!def) return NULL;
  int32_t index = -1;
  piola_status st = piola_world_add_obstacle(w, def, &index);
  if (st != PIOLA_OK) return pypiola_raise(PyExc_ValueError, st);
  return PyLong_FromLong(index);
}

static PyMethodDef world_methods[] = {
    {"close", world_close, METH_NOARGS, "close(): later calls raise ClosedError"},
    {"info", world_info, METH_NOARGS, "info() -> {time, stable_dt, solids, shells, obstacles}"},
    {"warnings", world_warnings, METH_NOARGS, "warnings() -> the messages raised so far"},
    {"advance_to", world_advance_to, METH_VARARGS, "advance_to(t) -> step stats"},
    {"step", world_step, METH_VARARGS, "step(dt_limit=inf) -> step stats"},
    {"body_name", world_body_name, METH_VARARGS, "body_name(kind, index)"},
    {"body_array", world_body_array, METH_VARARGS, "body_array(kind, index, name) -> view"},
    {"body_stats", world_body_stats, METH_VARARGS, "body_stats(kind, index) -> dict"},
    {"set_body_state", world_set_body_state, METH_VARARGS, "set_body_state(kind, index, x, v)"},
    {"add_solid", world_add_solid, METH_VARARGS, "add_solid(definition tuple) -> index"},
    {"add_obstacle", world_add_obstacle, METH_O, "add_obstacle(_piola.Obstacle) -> index"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef world_getset[] = {
    {"closed", world_get_closed, NULL, "whether the world (or its scene) has been closed", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pypiola_world_type =
    PYPIOLA_TYPE("_piola.World", world_object,
                 "A piola world (use piola.World).",
                 world_methods, world_getset, world_init, world_dealloc);
