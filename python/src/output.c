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

/* write_frame(frame, substeps, cg_iterations, wall_seconds, contacts, impacts, impact_zones) */
static PyObject *output_write_frame(PyObject *self_obj, PyObject *args) {
  output_object *self = (output_object *)self_obj;
  piola_frame_info info = {0};
  long long contacts = 0, impacts = 0;
  int frame, substeps, cg, zones;
  if (!PyArg_ParseTuple(args, "iiidLLi", &frame, &substeps, &cg, &info.wall_seconds, &contacts,
                        &impacts, &zones))
    return NULL;
  piola_world *w = output_world(self);
  if (!w) return NULL;
  info.frame = frame, info.substeps = substeps, info.cg_iterations = cg, info.impact_zones = zones;
  info.contacts = contacts, info.impacts = impacts;
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
    {"write_frame", output_write_frame, METH_VARARGS,
     "write_frame(frame, substeps, cg, wall, contacts, impacts, zones)"},
    {"write_failure_report", output_write_failure_report, METH_VARARGS,
     "write_failure_report(message)"},
    {"close", output_close, METH_NOARGS, "close()"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject pypiola_output_type =
    PYPIOLA_TYPE("_piola.Output", output_object,
                 "A results folder (used by piola.Scene.run).",
                 output_methods, NULL, output_init, output_dealloc);
