/* _piola.Scene: a scene file or JSON text loaded and built (piola/scene.h). Its world is a
 * _piola.World that keeps the scene alive; the scene keeps a plain back pointer to that
 * world object, which clears it when it goes, so there is only ever one. */
#include "pypiola.h"

#include <stdio.h>

typedef struct {
  PyObject_HEAD piola_scene *scene;
  PyObject *world; /* borrowed: the world object, or NULL */
  int closed;
} scene_object;

int pypiola_scene_closed(PyObject *obj) {
  scene_object *self = (scene_object *)obj;
  return self->closed || !self->scene;
}

void pypiola_scene_forget_world(PyObject *obj) { ((scene_object *)obj)->world = NULL; }

/* Scene(path, json or None, base_dir or None, label or None): loads a file (json None) or
 * JSON text. Raises SceneError with the library's key-path message. */
static int scene_init(PyObject *self_obj, PyObject *args, PyObject *kwds) {
  scene_object *self = (scene_object *)self_obj;
  if (kwds && PyDict_Size(kwds) > 0) {
    PyErr_SetString(PyExc_TypeError, "Scene takes positional arguments");
    return -1;
  }
  if (self->scene) {
    PyErr_SetString(PyExc_RuntimeError, "Scene is already initialized");
    return -1;
  }
  PyObject *path_obj = NULL;
  const char *json = NULL, *base = NULL, *label = NULL;
  if (!PyArg_ParseTuple(args, "O&zzz", PyUnicode_FSConverter, &path_obj, &json, &base, &label))
    return -1;
  const char *path = PyBytes_AS_STRING(path_obj);
  piola_status st;
  piola_scene *scene = NULL;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  st = json ? piola_scene_load_string(json, base, label, &scene) : piola_scene_load(path, &scene);
  PyEval_RestoreThread(released);
  char where[4096]; /* the name messages give the scene: its file's path, or a dict's label */
  snprintf(where, sizeof where, "%s", json ? (label ? label : "scene") : path);
  Py_DECREF(path_obj);
  if (st != PIOLA_OK) {
    pypiola_raise(pypiola_scene_error, st);
    return -1;
  }
  /* a cut gives a solid new arrays, which the NumPy views over the world's memory assume
   * never happens */
  const piola_world *world = piola_scene_world(scene);
  for (int32_t s = 0; s < piola_world_solid_count(world); ++s)
    if (piola_world_solid_has_fracture(world, s)) {
      PyErr_Format(pypiola_scene_error,
                   "%s: solids[%d] ('%s') has fracture, which the Python package "
                   "does not support (docs/fracture.md); run the scene with `piola run`",
                   where, (int)s, piola_world_solid_name(world, s));
      piola_scene_destroy(scene); /* after the message: it owns the name */
      return -1;
    }
  self->scene = scene;
  return 0;
}

static void scene_dealloc(PyObject *self_obj) {
  scene_object *self = (scene_object *)self_obj;
  piola_scene_destroy(self->scene);
  Py_TYPE(self_obj)->tp_free(self_obj);
}

static int usable(scene_object *self) {
  if (!pypiola_scene_closed((PyObject *)self)) return 1;
  PyErr_SetString(pypiola_closed_error, "the scene has been closed");
  return 0;
}

static PyObject *scene_info(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  scene_object *self = (scene_object *)self_obj;
  if (!usable(self)) return NULL;
  return Py_BuildValue("{s:d,s:i}", "fps", piola_scene_fps(self->scene), "frames",
                       (int)piola_scene_frames(self->scene));
}

static PyObject *scene_world(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  scene_object *self = (scene_object *)self_obj;
  if (!usable(self)) return NULL;
  if (self->world) return Py_NewRef(self->world);
  self->world = pypiola_world_from_scene(self_obj, piola_scene_world(self->scene));
  return self->world; /* the caller's reference; we keep a borrowed one */
}

static PyObject *scene_close(PyObject *self_obj, PyObject *unused) {
  (void)unused;
  scene_object *self = (scene_object *)self_obj;
  if (self->world && !pypiola_world_get(self->world)) {
    if (PyErr_ExceptionMatches(PyExc_RuntimeError)) return NULL; /* stepping elsewhere */
    PyErr_Clear();
  }
  self->closed = 1;
  Py_RETURN_NONE;
}

static PyObject *scene_get_closed(PyObject *self_obj, void *unused) {
  (void)unused;
  return PyBool_FromLong(pypiola_scene_closed(self_obj));
}

/* copy_resolved(scene_path, out_path): piola_scene_copy_resolved (a static method). */
static PyObject *scene_copy_resolved(PyObject *unused, PyObject *args) {
  (void)unused;
  PyObject *src, *dst;
  if (!PyArg_ParseTuple(args, "O&O&", PyUnicode_FSConverter, &src, PyUnicode_FSConverter, &dst))
    return NULL;
  piola_status st = piola_scene_copy_resolved(PyBytes_AS_STRING(src), PyBytes_AS_STRING(dst));
  Py_DECREF(src);
  Py_DECREF(dst);
  if (st != PIOLA_OK) return pypiola_raise(pypiola_error, st);
  Py_RETURN_NONE;
}

static PyMethodDef scene_methods[] = {
    {"copy_resolved", scene_copy_resolved, METH_VARARGS | METH_STATIC,
     "copy_resolved(scene_path, out_path): the scene file with absolute mesh paths"},
    {"info", scene_info, METH_NOARGS, "info() -> {fps, frames}"},
    {"world", scene_world, METH_NOARGS, "world() -> the scene's _piola.World"},
    {"close", scene_close, METH_NOARGS, "close(): later calls raise ClosedError"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef scene_getset[] = {
    {"closed", scene_get_closed, NULL, "whether the scene has been closed", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject pypiola_scene_type =
    PYPIOLA_TYPE("_piola.Scene", scene_object,
                 "A loaded scene (use piola.Scene).",
                 scene_methods, scene_getset, scene_init, scene_dealloc);
