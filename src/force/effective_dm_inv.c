/* Accessors of the plasticity hook (see effective_dm_inv.h). */
#include "force/effective_dm_inv.h"

#include "force/elastic_body_internal.h"

void piola__elastic_body_get_dm_inv(const piola_elastic_body *body, int32_t t, double out[9]) {
  for (int k = 0; k < 9; ++k) out[k] = body->dm_inv[k][t];
}

void piola__elastic_body_set_dm_inv(piola_elastic_body *body, int32_t t, const double m[9]) {
  for (int k = 0; k < 9; ++k) body->dm_inv[k][t] = m[k];
}

const double *piola__elastic_body_rest_volumes(const piola_elastic_body *body) {
  return body->rest_volume;
}

void piola__elastic_body_get_rotations(const piola_elastic_body *body, int32_t t, double u[9],
                                       double v[9]) {
  for (int k = 0; k < 9; ++k) {
    if (u) u[k] = body->u[k][t];
    if (v) v[k] = body->v[k][t];
  }
}

void piola__elastic_body_plastic_lanes(piola_elastic_body *body, double *dm_inv[9], const double *v[9],
                                       int32_t *padded_tet_count) {
  for (int k = 0; k < 9; ++k) {
    dm_inv[k] = body->dm_inv[k];
    v[k] = body->v[k];
  }
  *padded_tet_count = body->padded_tet_count;
}
