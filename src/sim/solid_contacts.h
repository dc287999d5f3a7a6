/* Contact between solids inside an implicit step (solid_contacts.c; docs/time-stepping.md,
 * "Solids against each other inside the solve"). */
#ifndef PIOLA_SIM_SOLID_CONTACTS_H
#define PIOLA_SIM_SOLID_CONTACTS_H

#include "sim/world_internal.h"

/* Puts every free node of solid s that is inside, or closer than the pair's thickness to,
 * the boundary surface of another solid (both with self_collision, whole on this process,
 * uncut) a little beyond that distance outside it, marks it `mark` with the surface's
 * outward normal in s->normals, the surface's velocity there in surface_velocity (3n, m/s)
 * and the pair's friction coefficient in surface_mu (n). Returns how many nodes it put. */
/* A body's implicit solve begins: the other solids' positions may have changed since the last
 * one, so their boundary trees are built again when next needed. Within a solve the other
 * solids stand still, and each tree is built once. */
void piola__solid_contacts_solve_begins(piola_world *w);
void piola__solid_contacts_free(piola_world *w);

int32_t piola__solid_contacts_with_solids(piola_world *w, world_body *s, uint8_t mark,
                                          double *surface_velocity, double *surface_mu);

#endif
