/* Section 9 collision processing against rigid obstacles.
 *
 * For every node (interior nodes included, so small obstacles cannot slip between surface
 * nodes) and every obstacle with phi(x) < 0:
 *   x  <- x - phi n                         (project to the surface; dxN = -phi)
 *   v_rel = v - v_obstacle(x), vn = v_rel . n
 *   if vn < 0: vn <- 0, dvN = -vn_old       (take the obstacle's normal velocity)
 *   else:      dvN = 0                      (already separating: keep it)
 *   vT <- max(0, 1 - mu (dvN + dxN / dt) / |vT|) vT     (Coulomb friction, paper eq. in 9)
 *   v  <- v_obstacle + vn n + vT
 * Obstacles are processed in the order given. A node pushed out of one obstacle into another
 * is handled by sweeping over all obstacles again, up to COLLISION_SWEEPS times, until no
 * obstacle contains it; when obstacles overlap so that no point satisfies all of them, the
 * last obstacle in the order wins. The stored normal is that of the last projection.
 *
 * Each node is independent, so the loop is parallel over nodes with a result that does not
 * depend on the thread count. Obstacle poses are computed once per call, and a bounding
 * sphere per obstacle skips the distance for nodes that are far from it. */
#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "piola/threads.h"
#include "sim/obstacle_internal.h"

#define COLLISION_SWEEPS 4
/* Projection iterations per contact; one suffices for an exact distance (all shapes here),
 * the extra ones correct floating-point residue near corners. */
#define PROJECTION_ITERATIONS 3

/* Projects one node out of one obstacle and applies the velocity rules. Returns false when
 * the node is not inside. */
static bool collide_node(const piola_obstacle *o, const piola__rigid_state *state, double dt,
                         vec3 *x, vec3 *v, vec3 *normal_out) {
  if (!piola__obstacle_may_contain(o, state, *x)) return false;
  vec3 n;
  double phi = piola__obstacle_distance_posed(o, state, *x, &n, NULL);
  if (!(phi < 0)) return false;
  vec3 start = *x;
  vec3 p = vec3_sub(*x, vec3_scale(n, phi));
  for (int it = 1; it < PROJECTION_ITERATIONS; ++it) {
    vec3 n2;
    double phi2 = piola__obstacle_distance_posed(o, state, p, &n2, NULL);
    if (!(phi2 < 0)) break;
    p = vec3_sub(p, vec3_scale(n2, phi2));
  }
  double dxn = vec3_dot(vec3_sub(p, start), n); /* = -phi for an exact distance */
  *x = p;
  vec3 vo = piola__rigid_state_velocity(state, p);
  vec3 rel = vec3_sub(*v, vo);
  double vn = vec3_dot(rel, n);
  vec3 vt = vec3_sub(rel, vec3_scale(n, vn));
  double dvn = 0;
  if (vn < 0) {
    dvn = -vn;
    vn = 0;
  }
  double mu = o->friction;
  double vt_len = vec3_norm(vt);
  if (mu > 0 && vt_len > 0) {
    double impulse = dvn + (dt > 0 ? dxn / dt : 0);
    double scale = 1.0 - mu * impulse / vt_len;
    vt = vec3_scale(vt, scale > 0 ? scale : 0);
  }
  *v = vec3_add(vo, vec3_add(vec3_scale(n, vn), vt));
  *normal_out = n;
  return true;
}

int32_t piola_obstacles_collide(piola_obstacle *const *obstacles, int32_t obstacle_count, double t,
                                double dt, int32_t node_count, double *x, double *v,
                                uint8_t *colliding, double *normals) {
  if (node_count <= 0) return 0;
  if (obstacle_count <= 0 || !obstacles) {
    if (colliding)
      for (int32_t i = 0; i < node_count; ++i) colliding[i] = 0;
    return 0;
  }
  piola__rigid_state states_small[8];
  piola__rigid_state *states = obstacle_count <= 8
                                   ? states_small
                                   : malloc(sizeof(piola__rigid_state) * (size_t)obstacle_count);
  if (!states) {
    (void)PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision poses for %d obstacles",
                     (int)obstacle_count);
    return -1;
  }
  for (int32_t k = 0; k < obstacle_count; ++k)
    if (obstacles[k]) piola__rigid_motion_state(&obstacles[k]->motion, t, &states[k]);

  int32_t count = 0;
  /* Below a few thousand nodes a parallel region costs more than it saves (and far more on a
   * loaded machine, where a descheduled thread stalls the barrier). */
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) reduction(+ : count) \
    if (node_count >= 4096)
  for (int32_t i = 0; i < node_count; ++i) {
    vec3 xi = vec3_load(x + 3 * i), vi = vec3_load(v + 3 * i), ni = vec3_make(0, 0, 0);
    bool hit = false;
    for (int sweep = 0; sweep < COLLISION_SWEEPS; ++sweep) {
      bool any = false;
      for (int32_t k = 0; k < obstacle_count; ++k)
        if (obstacles[k] && collide_node(obstacles[k], &states[k], dt, &xi, &vi, &ni)) any = true;
      if (!any) break;
      hit = true;
    }
    if (hit) {
      vec3_store(x + 3 * i, xi);
      vec3_store(v + 3 * i, vi);
      if (normals) vec3_store(normals + 3 * i, ni);
      ++count;
    }
    if (colliding) colliding[i] = hit ? 1 : 0;
  }
  if (states != states_small) free(states);
  return count;
}
