/* The part of a collision surface's state that outlives a call and changes what later calls
 * do: the shapes of its three trees and their age.
 *
 * Why there is any: a tree built in one call is refit, not rebuilt, by the calls after it
 * until it is REBUILD_PERIOD calls old (detection.c), and the order of its leaves fixes the
 * order of the candidate pairs, so of the impulses, which act one after the other. A surface
 * created anew builds its trees at its first call instead, and its impulses come in another
 * order. Everything else a call reads (boxes, candidates, contacts, zones, masses) it
 * computes itself.
 *
 * The history as bytes (for checkpoints, piola/checkpoint.h; little-endian as the machine
 * writes it): the tree age (i32: calls since the trees were built, 0 when never built), then
 * per tree (triangles, edges, vertices) its node count (i32), per node in preorder `first`
 * and `count` (i32 each: a leaf's first entry and size, or an inner node's right child and
 * 0), and the primitive order (one i32 per primitive). The node boxes are left out: every
 * call refits them to its own boxes before it uses a tree. */
#ifndef PIOLA_CONTACT_SURFACE_HISTORY_H
#define PIOLA_CONTACT_SURFACE_HISTORY_H

#include <stddef.h>

#include "piola/collision_surface.h"

/* Length in bytes of the surface's history. */
size_t piola__collision_surface_history_size(const piola_collision_surface *surface);

/* Writes the history into out (history_size bytes). */
void piola__collision_surface_history_save(const piola_collision_surface *surface,
                                           unsigned char *out);

/* Checks that bytes (length n) are a history this surface can take: the length, node counts
 * and indices in range, every node but the root the child of exactly one node, depth at most
 * 64 (what the tree walks allow); with store != 0 then puts it in place. Returns 0, -1 for a
 * history that does not fit (nothing stored), -2 out of memory. */
int piola__collision_surface_history_load(piola_collision_surface *surface,
                                          const unsigned char *bytes, size_t n, int store);

#endif
