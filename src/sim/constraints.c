/* Constraints: nodes fixed in place or driven by a keyframed rigid motion, chosen by a box,
 * a sphere or an index list over the rest positions. Later constraints override earlier
 * ones on nodes they both select. */
#include <stdlib.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "sim/world_internal.h"

int piola__selector_contains(const piola_selector *sel, const double *p) {
  switch (sel->type) {
    case PIOLA_SELECT_BOX:
      return p[0] >= sel->box_min.x && p[0] <= sel->box_max.x && p[1] >= sel->box_min.y &&
             p[1] <= sel->box_max.y && p[2] >= sel->box_min.z && p[2] <= sel->box_max.z;
    case PIOLA_SELECT_SPHERE:
      return vec3_norm2(vec3_sub(vec3_load(p), sel->center)) <= sel->radius * sel->radius;
    case PIOLA_SELECT_INDICES:
      return 0;
  }
  return 0;
}

piola_status piola__body_apply_constraints(world_body *s, const double *rest,
                                            const piola_constraint_def *constraints,
                                            int32_t count) {
  if (count < 0 || (count > 0 && !constraints))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s '%s': constraints: bad count %d",
                      piola__body_kind_name(s->kind), s->name, (int)count);
  int32_t driven = 0;
  for (int32_t c = 0; c < count; ++c) driven += constraints[c].driven ? 1 : 0;
  if (driven) {
    s->motions = calloc((size_t)driven, sizeof *s->motions);
    if (!s->motions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "constraints: out of memory");
  }
  for (int32_t c = 0; c < count; ++c) {
    const piola_constraint_def *con = &constraints[c];
    const piola_selector *sel = &con->selector;
    if (sel->type == PIOLA_SELECT_SPHERE && !(sel->radius >= 0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "%s '%s': constraints[%d]: sphere radius must be >= 0 m",
                        piola__body_kind_name(s->kind), s->name, (int)c);
    /* as the scene files say: an inverted box would select nothing, silently */
    if (sel->type == PIOLA_SELECT_BOX &&
        !(sel->box_min.x <= sel->box_max.x && sel->box_min.y <= sel->box_max.y &&
          sel->box_min.z <= sel->box_max.z))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "%s '%s': constraints[%d]: box_min must be <= box_max in every "
                        "coordinate (m)",
                        piola__body_kind_name(s->kind), s->name, (int)c);
    uint8_t flag = con->driven ? NODE_DRIVEN : NODE_FIXED;
    int32_t motion = -1;
    if (con->driven) {
      motion = s->motion_count++;
      s->motions[motion] = con->motion;
    }
    if (sel->type == PIOLA_SELECT_INDICES) {
      if (sel->index_count > 0 && !sel->indices)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s '%s': constraints[%d]: indices missing",
                          piola__body_kind_name(s->kind), s->name, (int)c);
      for (int32_t k = 0; k < sel->index_count; ++k) {
        int32_t i = sel->indices[k];
        if (i < 0 || i >= s->n)
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                            "%s '%s': constraints[%d].indices[%d]: vertex %d is out of range "
                            "[0, %d)",
                            piola__body_kind_name(s->kind), s->name, (int)c, (int)k, (int)i,
                            (int)s->n);
        s->flags[i] = flag;
        s->motion_of[i] = motion;
      }
    } else {
      for (int32_t i = 0; i < s->n; ++i)
        if (piola__selector_contains(sel, rest + 3 * i)) {
          s->flags[i] = flag;
          s->motion_of[i] = motion;
        }
    }
  }
  return PIOLA_OK;
}

void piola__world_check_selections(piola_world *w, const world_body *s, const double *rest,
                                   const piola_constraint_def *constraints, int32_t count,
                                   int32_t index) {
  int32_t of_kind[2] = {0, 0}; /* fixed, driven: the scene keys number each list from 0 */
  for (int32_t c = 0; c < count; ++c) {
    const piola_selector *sel = &constraints[c].selector;
    const int driven = constraints[c].driven ? 1 : 0;
    const int32_t k = of_kind[driven]++;
    int32_t selected = sel->type == PIOLA_SELECT_INDICES ? sel->index_count : 0;
    for (int32_t i = 0; i < s->n && sel->type != PIOLA_SELECT_INDICES && !selected; ++i)
      selected = piola__selector_contains(sel, rest + 3 * i);
    if (selected) continue;
    const char *kind = piola__body_kind_name(s->kind);
    piola__world_warn(w, PIOLA_WARNING_EMPTY_SELECTION,
                      "%s '%s': %ss[%d].%s[%d] selects no node (no rest position, after "
                      "transform, lies in its %s): it constrains nothing",
                      kind, s->name, kind, (int)index, driven ? "driven" : "fixed", (int)k,
                      sel->type == PIOLA_SELECT_BOX ? "box" : sel->type == PIOLA_SELECT_SPHERE ? "sphere" : "index list");
    return; /* the warning names the first one */
  }
}

void piola__body_constrained_state(const world_body *s, int32_t i, double t, double x[3],
                                   double v[3]) {
  const double *p0 = s->start + 3 * i;
  if (s->flags[i] != NODE_DRIVEN) {
    x[0] = p0[0], x[1] = p0[1], x[2] = p0[2];
    v[0] = v[1] = v[2] = 0;
    return;
  }
  const piola_rigid_motion_def *m = &s->motions[s->motion_of[i]];
  piola_mat3 r;
  piola_vec3 c;
  piola_rigid_motion_pose(m, t, &r, &c);
  vec3 p = vec3_add(mat3_mul_vec(r, vec3_load(p0)), c);
  vec3_store(x, p);
  vec3_store(v, piola_rigid_motion_velocity(m, t, p));
}
