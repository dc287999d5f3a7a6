/* The exact triangle referee of the contact tests: counts intersecting triangle pairs with
 * the exact test of src/contact/triangle_intersection.c, behind a box sweep that only drops
 * pairs whose closed boxes are disjoint (such pairs cannot share a point), so it checks
 * every pair. Shared by test_contact_shells.c and test_collision_step.c; test_contact_cloth.c
 * and test_contact_solids.c test every pair of one set. */
#ifndef PIOLA_TEST_TRIANGLE_REFEREE_H
#define PIOLA_TEST_TRIANGLE_REFEREE_H

#include <stdint.h>

/* One triangle set to judge: positions (live pointer, m), count triangles over them; pairs
 * inside one set that share a vertex are exempt. */
typedef struct judged {
  const double *x;
  const int32_t *tris;
  int32_t count;
} judged;

/* Intersecting triangle pairs over all sets (within and across), except pairs of one set
 * that share a vertex. Fails the test if the exact test reports an error. */
long referee_count_intersections(const judged *sets, int set_count);
/* The same count over one set by testing every pair (no box sweep), so that every pair not
 * sharing a vertex also meets the exact test's error check (test_contact_cloth.c,
 * test_contact_solids.c). */
long referee_count_intersections_every_pair(judged set);

struct piola_world;
/* The triangles of shell `shell` of world w at its current positions. */
judged referee_shell_set(const struct piola_world *w, int32_t shell);

#endif
