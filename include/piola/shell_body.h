/* piola: thin shells and cloth (paper section 8): a triangle mesh with in-plane elasticity,
 * dihedral-angle bending, damping and plasticity.
 *
 * In plane, each triangle has a 3x2 deformation gradient F = Ds Dm^-1 (Dm the 2x2 rest edge
 * matrix in the triangle's own rest frame), diagonalized as F = U Fhat V^T with U 3x2 with
 * orthonormal columns, Fhat 2x2 diagonal and V a 2x2 rotation. The stress is a membrane
 * version of the solids' models (piola_membrane_stress below), P = U Phat V^T, and the
 * nodal forces are G = -A0 h P Dm^-T (A0 the rest area, h the thickness). Triangles that
 * collapse to a line or a point keep finite, restoring forces (the inversion extension).
 * When reference normals are enabled, a triangle whose normal opposes its reference normal
 * is "inverted": its smaller entry of Fhat is taken negative, and the force flips it back.
 *
 * Out of plane, every interior edge is a hinge with the dihedral-angle bending of Bridson,
 * Marino and Fedkiw 2003 (BMF03): forces along their four directions u1..u4, which are the
 * gradient of the signed dihedral angle theta, with magnitude proportional to
 * sin(theta/2) - sin(theta0/2). The geometric weight |e|^2 / (|N1| + |N2|) is taken at rest,
 * which makes the force exactly -grad of the energy
 *     E = D w (Phi(theta) - Phi(theta0)),  w = 2 |e0|^2 / (A1 + A2),
 *     Phi(theta) = -2 cos(theta / 2) - theta sin(theta0 / 2),
 * with D the flexural rigidity (N m). For small angles E ~ D |e0|^2/(2 (A1+A2)) (theta -
 * theta0)^2; the factor 2 in w is calibrated so that an equilateral mesh bent into a
 * cylinder of curvature k in any direction has D k^2 / 2 per unit area, the plate energy
 * (tested). See docs/shells.md.
 *
 * Forces are computed in parallel with OpenMP and are bit-for-bit identical whatever the
 * number of threads (per-element buffers gathered per vertex in a fixed order).
 *
 *   piola_shell_body_def def = piola_default_shell_body_def();
 *   def.rest_mesh = &cloth; def.materials = &material; def.material_count = 1;
 *   def.thickness = 1e-3; def.density = 300; def.bending.stiffness = 1e-4;
 *   piola_shell_body *shell;
 *   if (piola_shell_body_create(&def, &shell) != PIOLA_OK) puts(piola_last_error());
 *   piola_shell_body_update(shell, x, 1.0, forces, NULL); */
#ifndef PIOLA_SHELL_BODY_H
#define PIOLA_SHELL_BODY_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The membrane models (piola_membrane_stress) are in piola/material.h. */

/* ------------------------------------------------------------------ sheet meshes */

/* A flat width x height rectangle (m) in the z = 0 plane, centred at the origin, with
 * nx x ny cells (>= 1 each) split into two triangles along alternating diagonals (so the
 * mesh has no preferred shear direction). Vertex (i, j) is j * (nx + 1) + i, at
 * x = -width/2 + i width/nx, y = -height/2 + j height/ny. Triangles wind counterclockwise
 * seen from +z. out is overwritten (free with piola_tri_mesh_free). */
PIOLA_API piola_status piola_tri_mesh_rectangle(double width, double height, int32_t nx,
                                                int32_t ny, piola_tri_mesh *out);

/* A flat disk of the given radius (m) in the z = 0 plane, centred at the origin: vertex 0
 * at the centre and `rings` (>= 1) concentric rings, ring k with 6 k vertices, so triangles
 * are nearly equilateral. Counterclockwise seen from +z. */
PIOLA_API piola_status piola_tri_mesh_disk(double radius, int32_t rings, piola_tri_mesh *out);

/* The surface of a torus around the z axis, centred at the origin: major radius R, tube
 * radius r < R (m), `around` (>= 3) segments along the ring and `tube` (>= 3) around the
 * tube. sweep_degrees in (0, 360]: 360 gives the closed torus, less an open piece of it
 * from angle 0 to the sweep (e.g. 180: half a torus, the paper's Figure 8), with
 * around + 1 vertex rings. Triangles wind so that normals point out of the tube. */
PIOLA_API piola_status piola_tri_mesh_torus(double major_radius, double minor_radius,
                                            int32_t around, int32_t tube, double sweep_degrees,
                                            piola_tri_mesh *out);

/* ------------------------------------------------------------------ the shell body */

typedef struct piola_shell_body piola_shell_body;

/* Bending (BMF03) of the hinges at interior edges. */
typedef struct piola_shell_bending_def {
  double stiffness;      /* flexural rigidity D, N m (= J), >= 0; 0 turns bending off. For a
                            plate, D = E h^3 / (12 (1 - nu^2)). Default 0 */
  double damping;        /* bending viscosity, N m s, >= 0: damping / stiffness is the
                            relaxation time of a bent hinge (s). Default 0 */
  double yield_angle;    /* rad, >= 0: plastic bending starts when |theta - theta0| exceeds
                            it. INFINITY (default) turns plastic bending off */
  double plastic_rate;   /* 1/s, > 0: the excess flows into theta0 at this rate
                            (fraction 1 - exp(-rate dt) per step); INFINITY = at once.
                            Default INFINITY */
} piola_shell_bending_def;

/* In-plane plasticity, F = Fe Fp with Fp a 2x2 per triangle. */
typedef struct piola_shell_plasticity_def {
  double yield_strain;        /* dimensionless log-stretch: a principal |ln fhat_e| above it
                                 flows. INFINITY (default) turns plasticity off */
  double rate;                /* 1/s, > 0: fraction 1 - exp(-rate dt) of the excess flows per
                                 step; INFINITY = at once. Default INFINITY */
  double max_plastic_stretch; /* dimensionless, > 1: singular values of Fp stay within
                                 [1/max, max]. Default 4 */
} piola_shell_plasticity_def;

typedef struct piola_shell_body_def {
  const piola_tri_mesh *rest_mesh;   /* rest positions (m) and triangles; copied. A
                                        degenerate rest triangle is an error naming it */
  const piola_material *materials;   /* material_count validated materials (their Young's
                                        modulus and Poisson ratio are the sheet's) */
  int32_t material_count;
  const int32_t *triangle_materials; /* triangle_count indices, or NULL: all use 0 */
  double thickness;                  /* m, > 0. Default 1e-3 */
  double density;                    /* kg/m^3, > 0. Default 1000 */
  piola_shell_bending_def bending;
  piola_shell_plasticity_def plasticity;
  bool use_reference_normals;        /* treat triangles whose normal opposes the reference
                                        as inverted. Default false */
  const double *reference_normals;   /* 3 * triangle_count world-space directions (need not
                                        be unit), or NULL: the rest normals. Copied; change
                                        them later with piola_shell_body_set_reference_normals */
} piola_shell_body_def;

PIOLA_API piola_shell_body_def piola_default_shell_body_def(void);

PIOLA_API piola_status piola_shell_body_create(const piola_shell_body_def *def,
                                               piola_shell_body **out);
PIOLA_API void piola_shell_body_destroy(piola_shell_body *body);

PIOLA_API int32_t piola_shell_body_vertex_count(const piola_shell_body *body);
PIOLA_API int32_t piola_shell_body_triangle_count(const piola_shell_body *body);
/* 3 * triangle_count vertex indices. */
PIOLA_API const int32_t *piola_shell_body_triangles(const piola_shell_body *body);
/* 3 * vertex_count rest positions, m. */
PIOLA_API const double *piola_shell_body_rest_positions(const piola_shell_body *body);
/* vertex_count lumped masses, kg: a third of density * thickness * area of each incident
 * rest triangle. */
PIOLA_API const double *piola_shell_body_masses(const piola_shell_body *body);
/* Smallest rest altitude over all triangles, m (the CFL length); with in-plane plasticity
 * divided by max_plastic_stretch, the most plastic flow can shrink it. */
PIOLA_API double piola_shell_body_min_rest_altitude(const piola_shell_body *body);
/* Largest in-plane wave speed sqrt((lambda* + 2 mu) / density) over the materials, m/s. */
PIOLA_API double piola_shell_body_max_wave_speed(const piola_shell_body *body);
/* Bending time scale 1 / omega, s, with omega^2 a Gershgorin bound on the largest
 * eigenvalue of M^-1 K for the hinges' rest stiffness K = sum (D w / 2) grad theta grad
 * theta^T (w the hinge weight below). Explicit bending is stable for steps below about
 * 2 / omega; INFINITY without bending. */
PIOLA_API double piola_shell_body_bending_time_scale(const piola_shell_body *body);

/* The bending damping (viscosity) of the definition, N m s. */
PIOLA_API double piola_shell_body_bending_damping(const piola_shell_body *body);

/* Hinges (interior edges shared by exactly two triangles; other edges do not bend). */
PIOLA_API int32_t piola_shell_body_hinge_count(const piola_shell_body *body);
/* 4 * hinge_count vertices (x1, x2, x3, x4) per hinge: x3 -> x4 is the shared edge, x1 and
 * x2 the opposite corners. */
PIOLA_API const int32_t *piola_shell_body_hinges(const piola_shell_body *body);
/* hinge_count rest angles theta0 (rad, in (-pi, pi]); plastic bending changes them. */
PIOLA_API const double *piola_shell_body_rest_angles(const piola_shell_body *body);
/* hinge_count dihedral angles theta (rad) at the last update. */
PIOLA_API const double *piola_shell_body_angles(const piola_shell_body *body);
/* Sets all rest angles (hinge_count values, rad); e.g. for a pre-bent shape. */
PIOLA_API piola_status piola_shell_body_set_rest_angles(piola_shell_body *body,
                                                        const double *angles);

/* Replaces the reference normals (3 * triangle_count, world space) used when
 * use_reference_normals is on; e.g. the normals of the surface the shell approximates. */
PIOLA_API piola_status piola_shell_body_set_reference_normals(piola_shell_body *body,
                                                              const double *normals);

typedef struct piola_shell_stats {
  double membrane_energy;   /* J */
  double bending_energy;    /* J */
  int32_t inverted_count;   /* triangles opposing their reference normal (0 without them) */
  int32_t degenerate_count; /* triangles with a signed fhat[1] below 1e-3 (collapsed) */
  double min_fhat;          /* smallest signed fhat[1] over the triangles */
} piola_shell_stats;

/* Computes F, its diagonalization, the dihedral angles and the elastic forces (in-plane plus
 * bending) at positions x (3 * vertex_count, m). forces (3 * vertex_count, N) is
 * overwritten. stiffness_scale (>= 0) multiplies the in-plane stress and the bending
 * stiffness. stats may be NULL. Non-finite positions return PIOLA_ERROR_NOT_FINITE and
 * leave forces unchanged. */
PIOLA_API piola_status piola_shell_body_update(piola_shell_body *body, const double *x,
                                               double stiffness_scale, double *forces,
                                               piola_shell_stats *stats);

/* Damping forces at velocities v (3 * vertex_count, m/s), with the rotations and hinge
 * gradients of the last update: in-plane, Phat = beta (A + A^T) + alpha tr(A) I with
 * A = U^T Fdot V (2x2; shear viscosity beta and bulk viscosity alpha in Pa s), and for
 * each hinge -(damping * w / 2) (grad theta . v) grad theta with the hinge's rest weight
 * w = 2 |e0|^2 / (A1 + A2). Linear in v, symmetric, dissipative. forces (N) overwritten. */
PIOLA_API void piola_shell_body_damping_forces(const piola_shell_body *body, const double *v,
                                               double shear_viscosity, double bulk_viscosity,
                                               double *forces);

/* Plastic flow over a step of dt (s), from the state of the last update: in-plane (Fp) and
 * bending (theta0). The next update uses the new rest state. Returns the number of
 * triangles plus hinges that flowed. */
PIOLA_API int32_t piola_shell_body_plastic_flow(piola_shell_body *body, double dt);

/* Signed Fhat of the last update, 2 per triangle (fhat[1] < 0 for a triangle inverted with
 * respect to its reference normal). */
PIOLA_API const double *piola_shell_body_fhat(const piola_shell_body *body);
/* Plastic deformation Fp^-1 per triangle (4 per triangle, row-major 2x2). */
PIOLA_API const double *piola_shell_body_fp_inverse(const piola_shell_body *body);

#ifdef __cplusplus
}
#endif

#endif
