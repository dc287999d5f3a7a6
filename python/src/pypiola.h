/* The piola Python extension (_piola): shared declarations.
 *
 * The extension is thin: it checks that every array it is given is exactly what the C API
 * needs (dtype, shape, C order) and raises TypeError/ValueError otherwise; the friendly
 * conversions (lists to arrays, int64 indices to int32, dict keys to definitions) live in
 * the pure-Python package (python/piola). Every call that can take long (stepping, meshing,
 * file I/O, material evaluation on many F) runs with the GIL released. */
#ifndef PIOLA_PYTHON_PYPIOLA_H
#define PIOLA_PYTHON_PYPIOLA_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#define PY_ARRAY_UNIQUE_SYMBOL pypiola_ARRAY_API
#ifndef PYPIOLA_MODULE_FILE
#define NO_IMPORT_ARRAY
#endif
#include <numpy/arrayobject.h>

#include <piola/piola.h>
#include <piola/world_shells.h>

/* piola.Error and its subclasses, created by the module (module.c). */
extern PyObject *pypiola_error;            /* base of every piola failure */
extern PyObject *pypiola_scene_error;      /* a scene that does not load (message: key path) */
extern PyObject *pypiola_mesh_error;       /* a mesh file that cannot be read or written */
extern PyObject *pypiola_simulation_error; /* a step that fails (non-finite state) */
extern PyObject *pypiola_closed_error;     /* a call on a closed world or scene */

/* Raises `type` with piola_last_error() (or the status name when empty) and sets the
 * exception's `status` attribute to the status name. Returns NULL. */
PyObject *pypiola_raise(PyObject *type, piola_status status);

/* Checks that obj is a C-contiguous, aligned ndarray of `type_num` with `ndim` dimensions
 * whose sizes match dims (-1: any). writable also requires a writable array. Raises
 * TypeError or ValueError naming `what` and returns NULL when not; else obj, borrowed. */
PyArrayObject *pypiola_check_array(PyObject *obj, const char *what, int type_num, int ndim,
                                   const npy_intp *dims, int writable);

/* A new C-ordered array of `type_num` (uninitialized). */
PyArrayObject *pypiola_new_array(int type_num, int ndim, const npy_intp *dims);

/* Converters for PyArg_ParseTuple ("O&"): a sequence of 3 floats, a keyframe track
 * (a float, or a pair (times, values) of equal-length float sequences), a material
 * definition tuple, a rigid motion tuple. */
int pypiola_vec3_converter(PyObject *obj, void *out);     /* piola_vec3 */
int pypiola_track_converter(PyObject *obj, void *out);    /* piola_track */
int pypiola_material_converter(PyObject *obj, void *out); /* piola_material_def */
int pypiola_motion_converter(PyObject *obj, void *out);   /* piola_rigid_motion_def */

/* Module functions by file. */
extern PyMethodDef pypiola_material_methods[];
extern PyMethodDef pypiola_mesh_methods[];

/* The type object of a class of the module: instances of the C struct `object`, made by
 * `init` (after the generic tp_new) and freed by `dealloc`; methods and getset may be NULL. */
#define PYPIOLA_TYPE(name, object, doc, methods, getset, init, dealloc)                         \
  {                                                                                              \
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = (name), .tp_basicsize = sizeof(object),             \
    .tp_dealloc = (dealloc), .tp_flags = Py_TPFLAGS_DEFAULT, .tp_doc = (doc),                    \
    .tp_methods = (methods), .tp_getset = (getset), .tp_init = (init), .tp_new = PyType_GenericNew \
  }

/* Types. */
extern PyTypeObject pypiola_world_type;
extern PyTypeObject pypiola_scene_type;
extern PyTypeObject pypiola_obstacle_type;
extern PyTypeObject pypiola_output_type;

/* The world of a scene: a new world object that borrows the scene's world and keeps the
 * scene object alive (world.c). */
PyObject *pypiola_world_from_scene(PyObject *scene, piola_world *world);
/* Whether a scene object has been closed (scene.c). */
int pypiola_scene_closed(PyObject *scene);
/* The scene's world object clears its back pointer when it goes (scene.c). */
void pypiola_scene_forget_world(PyObject *scene);
/* The definition held by a _piola.Obstacle, or NULL with TypeError (obstacle.c). */
const piola_obstacle_def *pypiola_obstacle_def(PyObject *obj);
/* The world of a world object, or NULL with ClosedError/RuntimeError when it cannot be used
 * now (closed, or stepping in another thread) (world.c). */
piola_world *pypiola_world_get(PyObject *obj);

#endif
