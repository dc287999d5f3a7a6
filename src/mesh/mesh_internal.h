/* Internal mesh helpers shared by the mesh core, the readers and the quality checks.
 *
 * Faces and tets are matched by their sorted vertex keys. Instead of a general sort or a
 * hash table we bucket keys by their smallest vertex (a counting sort, O(n)) and compare
 * within a bucket, which holds only the few faces around one vertex. This is linear in
 * practice, allocation-light and deterministic (no hash seeds, no unstable sort). */
#ifndef PIOLA_MESH_INTERNAL_H
#define PIOLA_MESH_INTERNAL_H

#include <stdint.h>

#include "piola/mesh.h"

/* Groups `count` keys of `width` (<= 4) sorted vertex ids by their first (smallest) id.
 * keys[width*i] is the smallest. On return order[] lists key indices so that equal keys
 * are adjacent (order is size count; start is size vertex_count+1 and bounds each bucket).
 * Returns 0, or -1 when out of memory. */
int piola__group_keys(const int32_t *keys, int32_t count, int width, int32_t vertex_count,
                      int32_t *order, int32_t *start);

/* Sorts small int32 arrays in place (insertion sort). */
void piola__sort_small(int32_t *v, int n);

/* The four faces of a tet, wound outward for a positively oriented tet. */
extern const int piola__tet_faces[4][3];

/* Checks a loaded tet mesh (names `source` in messages): finite positions, index ranges,
 * degenerate tets (zero volume relative to their size) and duplicated tets; then orients
 * all tets positively. Used by every reader. lines[t], when not NULL, is the line of tet t
 * in the file, for messages. */
piola_status piola__tet_mesh_finish(piola_tet_mesh *mesh, const char *source, const int32_t *lines);

#endif
