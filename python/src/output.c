/* _piola.Output: a results folder written frame by frame (piola/output.h), for Scene.run. */
#include "pypiola.h"

typedef struct {
  PyObject_HEAD piola_output *output;
  PyObject *world; /* strong: the world whose frames are written */
} output_object;

/* Output(dir, force, world) */
static int output_init(PyObject *self_obj, PyObject *args, PyObject *kwds) {
  output_object *self = (output_object *)self_obj;
  if ((kwds && PyDict_Size(kwds) > 0) || self->output) {
    PyErr_SetString(PyExc_TypeError, "Output(dir, force, world), once");
    return -1;
  }
  PyObject *dir_obj, *world_obj;
  int force = 0;
  if (!PyArg_ParseTuple(args, "O&pO", PyUnicode_FSConverter, &dir_obj, &force, &world_obj))
    return -1;
  piola_world *w = pypiola_world_get(world_obj);
  piola_status st = PIOLA_OK;
  if (w) {
    st = piola_output_check_folder(PyBytes_AS_STRING(dir_obj), force != 0);
    if (st == PIOLA_OK)
      st = piola_output_open(PyBytes_AS_STRING(dir_obj), force != 0, w, &self->output);
  }
  Py_DECREF(dir_obj);
  if (!w) return -1;
  if (st != PIOLA_OK) {
    self->output = NULL;
    pypiola_raise(st == PIOLA_ERROR_INVALID_ARGUMENT ? PyExc_ValueError : pypiola_error, st);
    return -1;
  }
  Py_INCREF(world_obj);
  self->world = world_obj;
  return 0;
}

static void output_dealloc(PyObject *self_obj) {
  output_object *self = (output_object *)self_obj;
  piola_output_close(self->output);
  Py_XDECREF(self->world);
  Py_TYPE(self_obj)->tp_free(self_obj);
}

static piola_world *output_world(output_object *self) {
  if (!self->output) {
    PyErr_SetString(pypiola_closed_error, "the output has been closed");
    return NULL;
  }
  return pypiola_world_get(self->world);
}

/* One entry of a step-stats dict (world.c's stats_dict) as an integer; 0 when absent (frame 0
 * has no steps). Returns -1 with a Python error set. */
static int stats_entry(PyObject *stats, const char *key, long long *value) {
  *value = 0;
  if (stats == Py_None) return 0;
  PyObject *item = PyDict_GetItemString(stats, key); /* borrowed */
  if (!item) return 0;
  *value = PyLong_AsLongLong(item);
  return *value == -1 && PyErr_Occurred() ? -1 : 0;
}

/* write_frame(frame, wall_seconds, stats): stats is the dict advance_to returned for the
 * frame (None for frame 0); its counters become the frame's stats.csv row, as piola run
 * writes them. */
static PyObject *output_write_frame(PyObject *self_obj, PyObject *args) {
  output_object *self = (output_object *)self_obj;
  piola_frame_info info = {0};
  int frame;
  PyObject *stats;
  if (!PyArg_ParseTuple(args, "idO", &frame, &info.wall_seconds, &stats)) return NULL;
  if (stats != Py_None && !PyDict_Check(stats)) {
    PyErr_SetString(PyExc_TypeError, "write_frame: stats must be a dict or None");
    return NULL;
  }
  long long substeps, cg, contacts, impacts, zones, newton, linear, failures, retries, redos;
  if (stats_entry(stats, "substeps", &substeps) || stats_entry(stats, "cg_iterations", &cg) ||
      stats_entry(stats, "contacts", &contacts) || stats_entry(stats, "impacts", &impacts) ||
      stats_entry(stats, "impact_zones", &zones) ||
      stats_entry(stats, "newton_iterations", &newton) ||
      stats_entry(stats, "linear_iterations", &linear) ||
      stats_entry(stats, "newton_failures", &failures) ||
      stats_entry(stats, "step_retries", &retries) || stats_entry(stats, "energy_redos", &redos))
    return NULL;
  piola_world *w = output_world(self);
  if (!w) return NULL;
  info.frame = frame, info.substeps = (int32_t)substeps, info.cg_iterations = (int32_t)cg;
  info.contacts = contacts, info.impacts = impacts, info.impact_zones = (int32_t)zones;
  info.newton_iterations = (int32_t)newton, info.linear_iterations = (int32_t)linear;
  info.newton_failures = (int32_t)failures, info.step_retries = (int32_t)retries;
  info.energy_redos = (int32_t)redos;
  /* with the GIL held: no other thread can step the world while its frame is written */
  piola_status st = piola_output_write_frame(self->output, w, &info);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_error, st);
  Py_RETURN_NONE;
}

static PyObject *output_write_failure_report(PyObject *self_obj, PyObject *args) {
  output_object *self = (output_object *)self_obj;
  const char *message;
  if (!PyArg_ParseTuple(args, "s", &message)) return NULL;
  piola_world *w = output_world(self);
  if (!w) return NULL;
  piola_status st = piola_output_write_failure_report(self->output, w, message);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_error, st);
  Py_RETURN_NONE;
}

static PyObject *output_close(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  output_object *self = (output_object *)self_obj;
  piola_output_close(self->output);
  self->output = NULL;
  Py_RETURN_NONE;
}

static PyMethodDef output_methods[] = {
    {"write_frame", output_write_frame, METH_VARARGS, "write_frame(frame, wall_seconds, stats)"},
    {"write_failure_report", output_write_failure_report, METH_VARARGS,
     "write_failure_report(message)"},
    {"close", output_close, METH_NOARGS, "close()"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject pypiola_output_type =
    PYPIOLA_TYPE("_piola.Output", output_object,
                 "A results folder (used by piola.Scene.run).",
                 output_methods, NULL, output_init, output_dealloc);
