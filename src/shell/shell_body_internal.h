/* The shell body's internal layout, shared by the rest state, the force loops, damping and
 * plasticity.
 *
 * Why it looks like this. A shell has two kinds of elements: triangles (in-plane forces,
 * three corners) and hinges (bending, four vertices: the two ends of an interior edge and
 * the two opposite corners). Each kind is a flat array of small fixed-size records, one
 * parallel loop per kind, and every element writes its nodal forces into its own slot of a
 * per-element buffer (9 doubles per triangle, 12 per hinge). A second pass gives every
 * vertex the sum of its triangle entries and then its hinge entries, read from two CSR
 * incidence lists sorted by element index, so every sum has a fixed order: forces are
 * bit-for-bit identical for any thread count, without atomics.
 *
 * Triangles keep the effective rest inverse Dm^-1 Fp^-1 (what the force loop needs) next to
 * the plain Dm^-1 and Fp^-1 (what plasticity needs), so the hot loop does one 2x2 product
 * less. The last update's U (3x2), V (2x2) and signed Fhat are kept for damping and
 * plasticity; hinges keep theta and grad theta (12 numbers) for bending damping, which runs
 * inside every conjugate-gradient iteration and should not redo the geometry.
 *
 * The per-triangle SVD is the robust public piola_diagonalize3x2 (few triangles compared
 * with a volumetric mesh's tets, and cloth degenerates often, so robustness wins here). */
#ifndef PIOLA_SHELL_BODY_INTERNAL_H
#define PIOLA_SHELL_BODY_INTERNAL_H

#include <stdint.h>

#include "piola/shell_body.h"

typedef struct shell_triangle {
  int32_t v[3];
  int32_t material;
  double dm_inv[4];      /* rest Dm^-1, row-major 2x2 */
  double fp_inv[4];      /* plastic Fp^-1, row-major 2x2 (identity without plasticity) */
  double dm_inv_eff[4];  /* Dm^-1 Fp^-1: F_elastic = Ds dm_inv_eff */
  double volume;         /* rest area times thickness, m^3 */
  double reference[3];   /* reference normal (world space, not normalized) */
  /* state of the last update */
  double u[6];           /* 3x2 row-major */
  double vrot[4];        /* 2x2 row-major */
  double fhat[2];        /* signed */
  double energy_density; /* J/m^3 */
} shell_triangle;

/* The shape-function gradients g_a of a triangle in its rest frame, from its effective
 * Dm^-1 (F = sum_a x_a g_a^T: g1, g2 its rows, g0 = -(g1 + g2)). */
static inline void shell_triangle_gradients(const shell_triangle *tri, double g[3][2]) {
  const double *d = tri->dm_inv_eff;
  g[0][0] = -(d[0] + d[2]), g[0][1] = -(d[1] + d[3]);
  g[1][0] = d[0], g[1][1] = d[1];
  g[2][0] = d[2], g[2][1] = d[3];
}

/* The implicit system matrix's pattern (shell_stiffness.h): row i lists the vertices that
 * share a triangle or a hinge with vertex i, increasing, in col[row_start[i] ..
 * row_start[i + 1]); triangle_slot[6 t + k] and hinge_slot[12 h + k] are the entries of the
 * element's ordered vertex pairs (a, b), a != b, in the order of shell_stiffness_matrix.c. */
typedef struct shell_matrix_pattern {
  int32_t *row_start, *col;
  int32_t *triangle_slot, *hinge_slot;
  int32_t entry_count;
} shell_matrix_pattern;

typedef struct shell_hinge {
  int32_t v[4];          /* x1, x2 opposite corners; x3 -> x4 the edge */
  double weight;         /* w = 2 |e0|^2 / (A1 + A2), dimensionless */
  double rest_angle;     /* theta0, rad */
  /* state of the last update */
  double angle;          /* theta, rad */
  double grad[12];       /* d theta / d x_i, 1/m, vertex i at 3 i */
} shell_hinge;

struct piola_shell_body {
  int32_t vertex_count;
  int32_t triangle_count;
  int32_t hinge_count;
  shell_triangle *triangles;
  shell_hinge *hinges;
  double *triangle_forces;   /* 9 per triangle */
  double *hinge_forces;      /* 12 per hinge */
  /* incidence lists: entries 3 t + corner and 4 h + slot, sorted */
  int32_t *tri_start, *tri_incidence;
  int32_t *hinge_start, *hinge_incidence;
  /* public AoS copies */
  int32_t *triangle_indices; /* 3 per triangle */
  int32_t *hinge_indices;    /* 4 per hinge */
  double *rest_angles, *angles, *fhat, *fp_inv;
  /* materials: the plane-stress (membrane) versions */
  piola_material *materials;
  int32_t material_count;
  /* parameters */
  double thickness, density;
  piola_shell_bending_def bending;
  piola_shell_plasticity_def plasticity;
  int use_reference_normals;
  /* cold */
  double *rest_positions;
  double *masses;
  double *inverse_sqrt_masses; /* 1 / sqrt(m_i), for the bending's step bound */
  double *vertex_rate2;        /* scratch of the bending's step bound, one per vertex */
  double min_rest_altitude, max_wave_speed, bending_time_scale;
  double last_stiffness_scale;
  shell_matrix_pattern *pattern; /* built on the first implicit step, NULL before */
};

/* Builds the rest state from def (rest_state.c). body must be zeroed. */
piola_status piola__shell_body_build(piola_shell_body *body, const piola_shell_body_def *def);
void piola__shell_body_free_arrays(piola_shell_body *body);

/* Signed dihedral angle of the hinge at positions p1..p4 (x3 -> x4 the edge) and, when grad
 * is not NULL, its gradient (12 numbers, 1/m). theta = atan2((n1 x n2) . e/|e|, n1 . n2)
 * with N1 = (x1 - x3) x (x1 - x4), N2 = (x2 - x4) x (x2 - x3) (BMF03); 0 for a flat hinge,
 * and 0 with a zero gradient when a triangle or the edge is degenerate. */
double piola__hinge_angle(const double *p1, const double *p2, const double *p3, const double *p4,
                          double grad[12]);

/* Bending energy potential Phi(theta) - Phi(theta0) (dimensionless) and its derivative
 * sin(theta/2) - sin(theta0/2). */
double piola__bending_potential(double theta, double theta0, double *derivative);

/* Sums the per-element buffers into per-vertex forces. */
void piola__shell_body_gather(const piola_shell_body *body, double *forces);

#endif
