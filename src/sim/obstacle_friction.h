/* Coulomb friction of a node against the obstacles, as both integrators apply it once the
 * normal velocity change of a contact is known (docs/contact.md). */
#ifndef PIOLA_SIM_OBSTACLE_FRICTION_H
#define PIOLA_SIM_OBSTACLE_FRICTION_H

#include "piola/obstacle.h"

/* The obstacle a node at p touches at time t, taken as the nearest one (|signed distance|):
 * its friction coefficient mu and its surface velocity at p (m/s). mu = 0 and a zero
 * velocity when there is no obstacle. */
void piola__nearest_obstacle_motion(piola_obstacle *const *obstacles, int32_t count, double t,
                                    piola_vec3 p, double *mu, piola_vec3 *velocity);

/* vT <- max(0, 1 - mu dvn / |vT|) vT for the velocity v relative to the surface velocity vo,
 * vT its part tangential to the unit normal n, dvn > 0 the normal velocity change of the
 * contact (m/s). Returns 0 (v unchanged) when mu or |vT| is zero, 2 when friction stops the
 * tangential motion (mu dvn >= |vT|: vT becomes 0), else 1 (slowed). */
int piola__coulomb_limit(double v[3], piola_vec3 vo, const double n[3], double mu, double dvn);

#endif
