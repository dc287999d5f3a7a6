/* Materials on arrays of deformation gradients: the constitutive models alone, without a
 * world (piola/material.h, piola/diagonalize.h). */
#include "pypiola.h"

#include <math.h>

static int init_material(const piola_material_def *def, piola_material *mat) {
  piola_status st = piola_material_init(def, mat);
  if (st != PIOLA_OK) {
    pypiola_raise(PyExc_ValueError, st);
    return -1;
  }
  return 0;
}

static PyObject *material_check(PyObject *self, PyObject *args) {
  (void)self;
  piola_material_def def;
  if (!PyArg_ParseTuple(args, "O&", pypiola_material_converter, &def)) return NULL;
  piola_material mat;
  if (init_material(&def, &mat) < 0) return NULL;
  /* threshold and mode as resolved: a def left at "default" gets the model's own */
  return Py_BuildValue("{s:d,s:d,s:d,s:d,s:s}", "mu", mat.mu, "lambda", mat.lambda,
                       "fiber_modulus", mat.fiber_modulus, "threshold", mat.threshold,
                       "inversion_mode", piola_inversion_mode_name(mat.inversion_mode));
}

/* out = U diag-or-full(phat) V^T */
static void rotate_back(const piola_mat3 *u, double phat[3][3], const piola_mat3 *v, double *out) {
  double t[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += u->m[i][k] * phat[k][j];
      t[i][j] = s;
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += t[i][k] * v->m[j][k];
      out[3 * i + j] = s;
    }
}

static PyObject *diagonalize(PyObject *self, PyObject *args) {
  (void)self;
  PyObject *fobj;
  if (!PyArg_ParseTuple(args, "O", &fobj)) return NULL;
  npy_intp dims[3] = {-1, 3, 3};
  PyArrayObject *f = pypiola_check_array(fobj, "F", NPY_DOUBLE, 3, dims, 0);
  if (!f) return NULL;
  npy_intp n = PyArray_DIM(f, 0);
  npy_intp d33[3] = {n, 3, 3}, d3[2] = {n, 3};
  PyArrayObject *u = pypiola_new_array(NPY_DOUBLE, 3, d33),
                *v = pypiola_new_array(NPY_DOUBLE, 3, d33),
                *fhat = pypiola_new_array(NPY_DOUBLE, 2, d3);
  if (!u || !v || !fhat) goto fail;
  const double *fp = PyArray_DATA(f);
  double *up = PyArray_DATA(u), *vp = PyArray_DATA(v), *hp = PyArray_DATA(fhat);
  npy_intp bad = -1;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  for (npy_intp i = 0; i < n; ++i) {
    piola_mat3 fm, um, vm;
    piola_vec3 h;
    for (int k = 0; k < 9; ++k) fm.m[k / 3][k % 3] = fp[9 * i + k];
    if (piola_diagonalize3(&fm, &um, &h, &vm) != PIOLA_OK && bad < 0) bad = i;
    for (int k = 0; k < 9; ++k)
      up[9 * i + k] = um.m[k / 3][k % 3], vp[9 * i + k] = vm.m[k / 3][k % 3];
    hp[3 * i] = h.x, hp[3 * i + 1] = h.y, hp[3 * i + 2] = h.z;
  }
  PyEval_RestoreThread(released);
  if (bad >= 0) {
    PyErr_Format(PyExc_ValueError, "F[%zd] is not finite (or too large to diagonalize)",
                 (Py_ssize_t)bad);
    goto fail;
  }
  return Py_BuildValue("NNN", u, fhat, v);
fail:
  Py_XDECREF(u);
  Py_XDECREF(v);
  Py_XDECREF(fhat);
  return NULL;
}

/* material_eval(material, F (n,3,3), fibers (n,3) or None, activation) -> (P, psi) */
static PyObject *material_eval(PyObject *self, PyObject *args) {
  (void)self;
  piola_material_def def;
  PyObject *fobj, *fibobj;
  double activation;
  if (!PyArg_ParseTuple(args, "O&OOd", pypiola_material_converter, &def, &fobj, &fibobj,
                        &activation))
    return NULL;
  piola_material mat;
  if (init_material(&def, &mat) < 0) return NULL;
  npy_intp dims[3] = {-1, 3, 3};
  PyArrayObject *f = pypiola_check_array(fobj, "F", NPY_DOUBLE, 3, dims, 0);
  if (!f) return NULL;
  npy_intp n = PyArray_DIM(f, 0);
  const double *fib = NULL;
  if (fibobj != Py_None) {
    npy_intp fd[2] = {n, 3};
    PyArrayObject *fa = pypiola_check_array(fibobj, "fibers", NPY_DOUBLE, 2, fd, 0);
    if (!fa) return NULL;
    if (def.model != PIOLA_MODEL_MUSCLE && def.model != PIOLA_MODEL_HGO) {
      PyErr_SetString(PyExc_ValueError, "fibers need the muscle or the hgo model");
      return NULL;
    }
    fib = PyArray_DATA(fa);
    if (def.model == PIOLA_MODEL_HGO) /* every fibre must give a plane for the two families */
      for (npy_intp i = 0; i < n; ++i) {
        double fam[6];
        if (piola_material_hgo_families(&mat, fib + 3 * i, fam) != PIOLA_OK) {
          PyErr_Format(PyExc_ValueError, "fibers[%zd]: %s", (Py_ssize_t)i, piola_last_error());
          return NULL;
        }
      }
  }
  npy_intp d33[3] = {n, 3, 3}, d1[1] = {n};
  PyArrayObject *p = pypiola_new_array(NPY_DOUBLE, 3, d33),
                *psi = pypiola_new_array(NPY_DOUBLE, 1, d1);
  if (!p || !psi) {
    Py_XDECREF(p);
    Py_XDECREF(psi);
    return NULL;
  }
  const double *fp = PyArray_DATA(f);
  double *pp = PyArray_DATA(p), *ep = PyArray_DATA(psi);
  npy_intp bad = -1;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  for (npy_intp i = 0; i < n; ++i) {
    piola_mat3 fm, um, vm;
    piola_vec3 h;
    for (int k = 0; k < 9; ++k) fm.m[k / 3][k % 3] = fp[9 * i + k];
    if (piola_diagonalize3(&fm, &um, &h, &vm) != PIOLA_OK) {
      if (bad < 0) bad = i;
      continue;
    }
    double fhat[3] = {h.x, h.y, h.z}, phat[3][3] = {{0}};
    if (fib && mat.model == PIOLA_MODEL_HGO) {
      /* the matrix through the diagonalization, the fibres on the full F */
      double d[3], fam[6], pf[9];
      piola_material_stress(&mat, fhat, d);
      for (int r = 0; r < 3; ++r) phat[r][r] = d[r];
      (void)piola_material_hgo_families(&mat, fib + 3 * i, fam); /* checked above */
      piola_material_hgo_fiber_stress(&mat, fp + 9 * i, fam, pf);
      ep[i] = piola_material_energy_density(&mat, fhat) +
              piola_material_hgo_fiber_energy_density(&mat, fp + 9 * i, fam);
      rotate_back(&um, phat, &vm, pp + 9 * i);
      for (int k = 0; k < 9; ++k) pp[9 * i + k] += pf[k];
      continue;
    }
    if (fib) {
      const double *a = fib + 3 * i;
      double ahat[3];
      for (int r = 0; r < 3; ++r)
        ahat[r] = vm.m[0][r] * a[0] + vm.m[1][r] * a[1] + vm.m[2][r] * a[2];
      piola_material_muscle_stress(&mat, fhat, ahat, activation, phat);
      ep[i] = piola_material_muscle_energy_density(&mat, fhat, ahat, activation);
    } else {
      double d[3];
      piola_material_stress(&mat, fhat, d);
      for (int r = 0; r < 3; ++r) phat[r][r] = d[r];
      ep[i] = piola_material_energy_density(&mat, fhat);
    }
    rotate_back(&um, phat, &vm, pp + 9 * i);
  }
  PyEval_RestoreThread(released);
  if (bad >= 0) {
    Py_DECREF(p);
    Py_DECREF(psi);
    PyErr_Format(PyExc_ValueError, "F[%zd] is not finite (or too large to diagonalize)",
                 (Py_ssize_t)bad);
    return NULL;
  }
  return Py_BuildValue("NN", p, psi);
}

/* material_eval_hat(material, fhat (n,3)) -> (phat (n,3), psi (n,), dphat (n,3,3)) */
static PyObject *material_eval_hat(PyObject *self, PyObject *args) {
  (void)self;
  piola_material_def def;
  PyObject *hobj;
  if (!PyArg_ParseTuple(args, "O&O", pypiola_material_converter, &def, &hobj)) return NULL;
  piola_material mat;
  if (init_material(&def, &mat) < 0) return NULL;
  npy_intp dims[2] = {-1, 3};
  PyArrayObject *h = pypiola_check_array(hobj, "fhat", NPY_DOUBLE, 2, dims, 0);
  if (!h) return NULL;
  npy_intp n = PyArray_DIM(h, 0);
  npy_intp d3[2] = {n, 3}, d1[1] = {n}, d33[3] = {n, 3, 3};
  PyArrayObject *p = pypiola_new_array(NPY_DOUBLE, 2, d3),
                *psi = pypiola_new_array(NPY_DOUBLE, 1, d1),
                *dp = pypiola_new_array(NPY_DOUBLE, 3, d33);
  if (!p || !psi || !dp) {
    Py_XDECREF(p);
    Py_XDECREF(psi);
    Py_XDECREF(dp);
    return NULL;
  }
  const double *hp = PyArray_DATA(h);
  double *pp = PyArray_DATA(p), *ep = PyArray_DATA(psi), *dpp = PyArray_DATA(dp);
  npy_intp bad = -1;
  PyThreadState *released = PyEval_SaveThread(); /* the GIL */
  for (npy_intp i = 0; i < n; ++i) {
    const double *fh = hp + 3 * i;
    if (!isfinite(fh[0]) || !isfinite(fh[1]) || !isfinite(fh[2])) {
      if (bad < 0) bad = i;
      continue;
    }
    double d[3][3];
    piola_material_stress(&mat, fh, pp + 3 * i);
    ep[i] = piola_material_energy_density(&mat, fh);
    piola_material_stress_derivative(&mat, fh, d);
    for (int k = 0; k < 9; ++k) dpp[9 * i + k] = d[k / 3][k % 3];
  }
  PyEval_RestoreThread(released);
  if (bad >= 0) {
    Py_DECREF(p);
    Py_DECREF(psi);
    Py_DECREF(dp);
    PyErr_Format(PyExc_ValueError, "fhat[%zd] is not finite", (Py_ssize_t)bad);
    return NULL;
  }
  return Py_BuildValue("NNN", p, psi, dp);
}

PyMethodDef pypiola_material_methods[] = {
    {"material_check", material_check, METH_VARARGS, "material_check(def) -> dict"},
    {"material_eval", material_eval, METH_VARARGS,
     "material_eval(def, F, fibers, activation) -> (P, psi)"},
    {"material_eval_hat", material_eval_hat, METH_VARARGS,
     "material_eval_hat(def, fhat) -> (phat, psi, dphat)"},
    {"diagonalize", diagonalize, METH_VARARGS, "diagonalize(F) -> (U, fhat, V)"},
    {NULL, NULL, 0, NULL},
};
