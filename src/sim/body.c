/* The per-kind dispatch of the body operations (see body.h), and what every kind shares:
 * allocation and release of the per-node state.
 *
 * Adding a kind: a value in piola_body_kind, a case in every switch below (the compiler
 * names the ones missing), its add function and its own code in a file of its own. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "contact/bvh.h"
#include "force/elastic_body_internal.h"
#include "force/stiffness_matrix.h"
#include "shell/shell_stiffness.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

const char *piola__body_kind_name(piola_body_kind kind) {
  switch (kind) {
    case PIOLA_BODY_SOLID: return "solid";
    case PIOLA_BODY_SHELL: return "shell";
    case PIOLA_BODY_NONE: break;
  }
  return "none";
}

int32_t piola__body_element_count(const world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola_elastic_body_tet_count(b->solid);
    case PIOLA_BODY_SHELL: return piola_shell_body_triangle_count(b->shell);
    case PIOLA_BODY_NONE: break;
  }
  return 0;
}

piola_status piola__body_update_forces(world_body *b, double t) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola__solid_update_forces(b, t);
    case PIOLA_BODY_SHELL: return piola__shell_update_forces(b, t);
    case PIOLA_BODY_NONE: break;
  }
  return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "body of no kind");
}

void piola__body_damping_forces(const world_body *b, const double *v, double beta, double alpha,
                                double *out) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: piola_elastic_body_damping_forces(b->solid, v, beta, alpha, out); return;
    case PIOLA_BODY_SHELL: piola_shell_body_damping_forces(b->shell, v, beta, alpha, out); return;
    case PIOLA_BODY_NONE: break;
  }
}

int piola__body_undamped(const world_body *b, double beta, double alpha) {
  if (beta != 0 || alpha != 0) return 0;
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return 1;
    /* a shell with bending damping is damped even with zero in-plane viscosities */
    case PIOLA_BODY_SHELL: return piola_shell_body_bending_damping(b->shell) == 0;
    case PIOLA_BODY_NONE: break;
  }
  return 1;
}

void piola__body_damping_apply(const world_body *b, const double *p, double beta, double alpha,
                               double h, double *scratch, double *out) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      /* one pass: the damping's own chunk sum forms M p - h D p */
      piola__elastic_body_damping_operator(b->solid, p, beta, alpha, b->mass, h, out);
      return;
    case PIOLA_BODY_SHELL:
    case PIOLA_BODY_NONE: break;
  }
  piola__body_damping_forces(b, p, beta, alpha, scratch);
  for (int32_t i = 0; i < b->n; ++i)
    for (int k = 0; k < 3; ++k) out[3 * i + k] = b->mass[i] * p[3 * i + k] - h * scratch[3 * i + k];
}

int piola__body_damping_reusable(const world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return 1;
    case PIOLA_BODY_SHELL: return 0;
    case PIOLA_BODY_NONE: break;
  }
  return 0;
}

void piola__body_damping_prepare(world_body *b, double beta, double alpha) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: piola__elastic_body_damping_prepare(b->solid, beta, alpha); return;
    case PIOLA_BODY_SHELL: return;
    case PIOLA_BODY_NONE: return;
  }
}

uint64_t piola__body_damping_generation(const world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return b->solid->damping.generation;
    case PIOLA_BODY_SHELL: return 0;
    case PIOLA_BODY_NONE: break;
  }
  return 0;
}

void piola__body_damping_add_sparse(const world_body *b, const double *e, double beta,
                                    double alpha, double scale, double *out) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      piola__elastic_body_damping_forces_add_sparse(b->solid, e, beta, alpha, scale, out);
      return;
    case PIOLA_BODY_SHELL: return;
    case PIOLA_BODY_NONE: return;
  }
}

double piola__body_stable_dt(const piola_world *w, const world_body *b, double scale) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola__solid_stable_dt(w, b, scale);
    case PIOLA_BODY_SHELL: return piola__shell_stable_dt(w, b, scale);
    case PIOLA_BODY_NONE: break;
  }
  return INFINITY;
}

double piola__body_max_wave_speed(const world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola_elastic_body_max_wave_speed(b->solid);
    case PIOLA_BODY_SHELL: return piola_shell_body_max_wave_speed(b->shell);
    case PIOLA_BODY_NONE: break;
  }
  return 0;
}

void piola__body_plastic_in_step(world_body *b, double dt) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return;
    case PIOLA_BODY_SHELL: piola_shell_body_plastic_flow(b->shell, dt); return;
    case PIOLA_BODY_NONE: return;
  }
}

void piola__body_plastic_after_step(world_body *b, double dt) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: piola__solid_plastic_update(b, dt); return;
    case PIOLA_BODY_SHELL: return;
    case PIOLA_BODY_NONE: return;
  }
}

int32_t piola__body_collide_in_step(piola_world *w, world_body *b, double t1, double dt,
                                    uint8_t mark, double *surface_velocity) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return 0;
    case PIOLA_BODY_SHELL:
      return b->collide_with_solids
                 ? piola__shell_collide_with_solids(w, b, t1, dt, mark, surface_velocity)
                 : 0;
    case PIOLA_BODY_NONE: break;
  }
  return 0;
}

piola_status piola__body_stiffness_init(world_body *b, piola__stiffness_matrix *matrix) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola__stiffness_matrix_init(matrix, b->solid);
    case PIOLA_BODY_SHELL: return piola__shell_stiffness_matrix_init(matrix, b->shell);
    case PIOLA_BODY_NONE: break;
  }
  return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "body of no kind");
}

void piola__body_stiffness_assemble(const world_body *b, piola__stiffness_matrix *matrix,
                                    double stiffness_weight, double damping_weight, double beta,
                                    double alpha, double mass_weight) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      /* a split's ghost tets at this update (collective: every process assembles) */
      piola__elastic_body_split_share_fhat(b->solid);
      piola__stiffness_matrix_assemble(matrix, b->solid, stiffness_weight, damping_weight, b->mass,
                                       mass_weight);
      return;
    case PIOLA_BODY_SHELL:
      piola__shell_stiffness_matrix_assemble(matrix, b->shell, stiffness_weight, damping_weight,
                                             beta, alpha, b->mass, mass_weight);
      return;
    case PIOLA_BODY_NONE: return;
  }
}

void piola__body_stiffness_set_mass_weight(const world_body *b, piola__stiffness_matrix *matrix,
                                           double stiffness_weight, double damping_weight,
                                           double beta, double alpha, double mass_weight) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      piola__stiffness_matrix_set_mass_weight(matrix, b->solid, b->mass, mass_weight);
      return;
    case PIOLA_BODY_SHELL:
      piola__body_stiffness_assemble(b, matrix, stiffness_weight, damping_weight, beta, alpha,
                                     mass_weight);
      return;
    case PIOLA_BODY_NONE: return;
  }
}

void piola__body_stiffness_apply(const world_body *b, const piola__stiffness_matrix *matrix,
                                 double mass_weight, const double *p, double *out) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      piola__stiffness_matrix_apply(matrix, b->solid, b->mass, mass_weight, p, out);
      return;
    case PIOLA_BODY_SHELL:
      piola__shell_stiffness_matrix_apply(matrix, b->shell, b->mass, mass_weight, p, out);
      return;
    case PIOLA_BODY_NONE: return;
  }
}

piola_status piola__body_collision_triangles(const world_body *b, piola_tri_mesh *out, int *owned) {
  memset(out, 0, sizeof *out);
  *owned = 0;
  switch (b->kind) {
    case PIOLA_BODY_SOLID: {
      /* the boundary of the tets (built here, freed by the caller) */
      piola_tet_mesh mesh = {.vertex_count = b->n,
                             .positions = b->x,
                             .tet_count = piola_elastic_body_tet_count(b->solid),
                             .tets = (int32_t *)piola_elastic_body_tets(b->solid)};
      *owned = 1;
      return piola_tet_mesh_boundary(&mesh, out);
    }
    case PIOLA_BODY_SHELL:
      /* the shell's own triangles, borrowed */
      out->triangle_count = piola_shell_body_triangle_count(b->shell);
      out->triangles = (int32_t *)piola_shell_body_triangles(b->shell);
      return PIOLA_OK;
    case PIOLA_BODY_NONE: break;
  }
  return PIOLA_OK;
}

piola_body_stats piola__body_stats(world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID: return piola__solid_stats(b);
    case PIOLA_BODY_SHELL: return piola__shell_stats(b);
    case PIOLA_BODY_NONE: break;
  }
  piola_body_stats none;
  memset(&none, 0, sizeof none);
  return none;
}

void piola__body_free_kind(world_body *b) {
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      piola_plastic_state_destroy(b->plastic);
      piola_elastic_body_destroy(b->solid);
      if (b->boundary) piola_tri_mesh_free(b->boundary);
      free(b->boundary);
      if (b->boundary_tree) piola__bvh_free(b->boundary_tree);
      free(b->boundary_tree), free(b->boundary_boxes);
      piola__fracture_free(b->fracture);
      return;
    case PIOLA_BODY_SHELL: piola_shell_body_destroy(b->shell); return;
    case PIOLA_BODY_NONE: return;
  }
}

/* ------------------------------------------------------------------ every kind */

piola_status piola__body_allocate(world_body *b, int32_t n, const char *name, int32_t index,
                                  const double *rest, const double *mass) {
  const char *kind = piola__body_kind_name(b->kind);
  b->n = n;
  size_t v3 = 3 * (size_t)n * sizeof(double);
  char fallback[32];
  snprintf(fallback, sizeof fallback, "%s%d", kind, (int)index);
  if (!name) name = fallback;
  b->name = malloc(strlen(name) + 1);
  b->x = malloc(v3), b->v = malloc(v3), b->force = malloc(v3), b->start = malloc(v3);
  b->mass = malloc((size_t)n * sizeof(double));
  b->inverse_mass = malloc((size_t)n * sizeof(double));
  b->flags = calloc((size_t)n, 1);
  b->motion_of = malloc((size_t)n * sizeof(int32_t));
  b->x_old = malloc(v3), b->v_old = malloc(v3), b->force_old = malloc(v3), b->rhs = malloc(v3);
  b->tmp = malloc(v3), b->work = malloc(4 * v3) /* CG's 3 vectors + the first solve's A x0 */;
  b->normals = malloc(v3);
  b->friction_spent = malloc((size_t)n * sizeof(double));
  b->av_product = malloc(v3), b->v_product = malloc(v3);
  b->colliding = calloc((size_t)n, 1);
  if (!b->av_product || !b->v_product || !b->name || !b->x || !b->v || !b->force || !b->start ||
      !b->mass || !b->inverse_mass || !b->flags || !b->motion_of || !b->x_old || !b->v_old ||
      !b->force_old || !b->rhs || !b->tmp || !b->work || !b->normals || !b->colliding ||
      !b->friction_spent)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s %d: out of memory", kind, (int)index);
  strcpy(b->name, name);
  memcpy(b->mass, mass, (size_t)n * sizeof(double));
  memcpy(b->start, rest, v3);
  for (int32_t i = 0; i < n; ++i) b->motion_of[i] = -1;
  return PIOLA_OK;
}

void piola__body_finish_masses(world_body *b) {
  for (int32_t i = 0; i < b->n; ++i) {
    b->inverse_mass[i] = b->mass[i] > 0 ? 1.0 / b->mass[i] : 0.0;
    if (!(b->mass[i] > 0)) b->flags[i] = NODE_FIXED; /* a node in no element cannot move */
  }
}

void piola__body_restore_step(world_body *b, double t) {
  size_t v3 = 3 * (size_t)b->n * sizeof(double);
  b->product_valid = 0;
  memcpy(b->x, b->x_old, v3);
  memcpy(b->v, b->v_old, v3);
  memcpy(b->force, b->force_old, v3);
  (void)piola__body_update_forces(b, t);
}

void piola__body_free(world_body *b) {
  piola__body_free_kind(b);
  free(b->name);
  free(b->x), free(b->v), free(b->mass), free(b->inverse_mass), free(b->force), free(b->start);
  free(b->flags), free(b->motion_of), free(b->motions);
  free(b->x_old), free(b->v_old), free(b->force_old), free(b->rhs), free(b->work), free(b->tmp);
  free(b->av_product), free(b->v_product);
  free(b->colliding), free(b->normals), free(b->friction_spent), free(b->solid_surface_v);
  piola__implicit_state_free(b->implicit);
  memset(b, 0, sizeof *b);
}
