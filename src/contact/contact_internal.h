/* Internals of collision processing for deformable surfaces (BFA02).
 *
 * Why it is organised this way:
 * - Everything that touches a pair is expressed through one relative position,
 *   r = sum_k w_k x_k over the pair's four vertices (point minus the closest point of the
 *   triangle, or closest point of one edge minus that of the other). The weights sum to zero,
 *   so an impulse applied as dv_k = w_k J / m_k leaves linear momentum unchanged, and the same
 *   formula covers point-triangle and edge-edge pairs, unequal masses and pinned vertices
 *   (1 / m = 0). The change of relative velocity is J sum_k w_k^2 / m_k, so the impulse that
 *   produces a wanted change is a division by that sum.
 * - Detection (broad phase in a BVH, then the exact narrow test of each pair) is the
 *   expensive part, and the tree descent is the expensive part of that. So a call descends
 *   the trees once, at its start, with "reach" boxes per vertex: swept from x0 to the
 *   proposed x1 and padded by half the thickness. They hold the proximity boxes (x0 padded by
 *   half the thickness) and the swept boxes of the first detection pass as long as repulsion
 *   changes the velocities little against the thickness. The descent measures the distance
 *   of each pair it yields once: the contacts of the repulsion stage, and the candidates of
 *   the first detection pass (pairs that can collide while their vertices stay in their reach
 *   boxes), which that pass scans. A vertex whose swept box escapes its reach box makes its
 *   pairs uncertain: they are found by tree queries from that vertex, or, when most vertices
 *   escaped, the descent is redone with the swept boxes. Later passes test only pairs with a
 *   vertex whose velocity changed, by tree queries from those. Parallel work runs over fixed
 *   chunks (tree tasks or blocks of queries), each into its own list, joined in chunk order,
 *   so the result does not depend on the thread count. Impulses are then applied one pair
 *   after the other (Gauss-Seidel), in that order, so later pairs see the velocities earlier
 *   pairs left.
 * - Rigid impact zones use the linearised rigid motion v = v_cm + w x (x0 - c). Over the step
 *   this moves the zone by the affine map x -> x + s dt (v_cm + w x (x - c)), whose matrix
 *   I + s dt [w]x has singular values 1 and sqrt(1 + (s dt |w|)^2): it never shrinks a
 *   distance, so no pair inside a zone can come closer than it was at the start of the step. */
#ifndef PIOLA_CONTACT_INTERNAL_H
#define PIOLA_CONTACT_INTERNAL_H

#include <stdint.h>

#include "contact/bvh.h"
#include "math/mat3.h"
#include "piola/collision_surface.h"

/* Fraction of the pair thickness within which continuous detection calls two primitives
 * touching, and the gap it leaves them at the end of the step. */
#define PIOLA__CCD_TOLERANCE 1e-3
#define PIOLA__CCD_TARGET_GAP 1e-2

/* Tree queries per parallel block of a detection pass (the size of surface->blocks). */
#define PIOLA__QUERY_BLOCK 256

/* One pair and what is needed to push it apart. */
typedef struct piola__contact {
  int32_t v[4];      /* vertices: point then triangle, or edge then edge */
  double w[4];       /* relative position r = sum w[k] x[k] */
  vec3 normal;       /* unit; r has a non-negative component along it at the start */
  double gap;        /* m: r . normal at the start of the step */
  double thickness;  /* m: of the pair */
  double friction;   /* Coulomb coefficient of the pair */
  int32_t edge_edge; /* 1: edge (v[0], v[1]) against edge (v[2], v[3]); 0: point-triangle */
} piola__contact;

typedef struct piola__contact_list {
  piola__contact *items;
  int64_t count;
  size_t capacity; /* items (common/grow.h) */
} piola__contact_list;

int piola__contact_list_push(piola__contact_list *list, const piola__contact *c);

/* A candidate pair: vertex v[0] against triangle (v[1], v[2], v[3]), or edge (v[0], v[1])
 * against edge (v[2], v[3]). */
typedef struct piola__pair {
  int32_t v[4];
  int32_t edge_edge; /* 1 for an edge-edge pair */
  double separation; /* m: distance at x0 less twice the detection tolerance */
} piola__pair;

typedef struct piola__pair_list {
  piola__pair *items;
  int64_t count;
  size_t capacity; /* items (common/grow.h) */
} piola__pair_list;

typedef enum piola__detect_mode { PIOLA__DETECT_PROXIMITY, PIOLA__DETECT_CCD } piola__detect_mode;

/* Where the last call's time went, in CPU seconds of the calling thread (with one thread,
 * all of it), and how much detection work it did: read by bench/bench_contact.c. */
typedef struct piola__contact_profile {
  double collect;      /* boxes, trees and the tree descent at the start of the call */
  double repulsion;    /* stage 1 */
  double detection;    /* stage 2 and 3 detection passes (with any collection they redo) */
  double impulses;     /* stage 2 impacts */
  double zones;        /* stage 3 zone velocities */
  int64_t candidates;  /* pairs collected at the start of the call */
  int32_t collections; /* tree descents (1 + collections redone) */
  int32_t escaped;     /* vertex escapes summed over detection passes */
} piola__contact_profile;

struct piola_collision_surface {
  int32_t vertex_count, triangle_count, edge_count, body_count;
  int32_t *triangles; /* 3 per triangle */
  int32_t *edges;     /* 2 per edge, lower index first, sorted */
  int32_t *vertex_body;
  piola_collision_body_def *bodies;
  /* Workspace, sized at creation and reused by every call. */
  double *inverse_mass;
  double *vertex_thickness;
  piola__box *vertex_boxes, *triangle_boxes, *edge_boxes;
  piola__bvh triangle_tree, edge_tree, vertex_tree;
  int32_t *queries;    /* query primitives of a detection pass */
  int32_t block_count; /* capacity of blocks */
  piola__contact_list *blocks;
  piola__contact_list found;
  int32_t *zone_parent;
  uint8_t *in_zone;
  uint8_t *dirty;          /* velocity changed since the last detection pass */
  uint8_t *on_surface;     /* vertex of at least one triangle */
  int32_t zone_misfit;     /* a zone could not follow its pinned vertices (this call) */
  int32_t tree_age;        /* calls since the trees were last built (0: never built) */
  int32_t *zone_order;     /* vertices grouped by zone */
  piola__box *reach_boxes; /* per vertex: the boxes the candidates were collected with */
  uint8_t *escaped;        /* swept box outside its reach box (this detection pass) */
  double *reach_radius;    /* per vertex: farthest point of its reach box from x0 */
  /* Per tree task of the last collection (task_count lists each, in task order, kept with
   * their memory from call to call; task_capacity lists allocated): */
  int32_t task_count, task_capacity;
  piola__pair_list *candidates;    /* pairs that can collide while in their reach boxes */
  piola__contact_list *near;       /* contacts at x0 */
  piola__contact_list *task_found; /* what a detection pass found among the candidates */
  int64_t candidate_count;         /* sum over the tasks */
  int32_t near_valid;              /* near holds the contacts at x0 (reach boxes were used) */
  piola__contact_profile profile;
  double *vertex_slabs, *triangle_slabs, *edge_slabs; /* 12 per primitive (detection.c) */
  /* Embedded vertices (node_count > 0; embedding.c): per vertex four nodes and weights (an
   * unused slot: node -1, weight 0), per node the vertices that use it (CSR). During a call
   * the stages work on the vertices' positions and velocities (vertex_x0, vertex_v, computed
   * from the nodes'), and every impulse goes to the nodes (node_v: the caller's v) and from
   * them back to their vertices; rigid impact zones are zones of nodes. */
  int32_t node_count;
  int32_t *embed_nodes;
  double *embed_weights;
  int32_t *node_vertex_start, *node_vertices;
  double *vertex_x0, *vertex_v;
  double *node_v;            /* the caller's velocities, during a call */
  const double *node_x0;     /* the caller's positions, during a call */
  double *node_inverse_mass;
  double *vertex_inverse_node_mass; /* per vertex, 1 / sum_j e_j m_j over its unpinned nodes
                                       (0: all pinned), during a call */
  int32_t *node_zone_parent, *node_zone_order;
  uint8_t *node_in_zone, *node_dirty;
};

/* Embedded surfaces (embedding.c). */
/* Validates the embedding of def and copies it into s (with its CSR); 0, or -1 out of
 * memory; -2 (with *message) for a bad embedding. */
int piola__embedding_create(piola_collision_surface *s, const piola_collision_surface_def *def,
                            const char **message);
void piola__embedding_free(piola_collision_surface *s);
/* The vertices' x0 and v (and vertex inverse masses: sum of weight^2 / node mass, 0 when
 * every node is pinned) from the nodes'. */
void piola__embedding_gather(piola_collision_surface *s, const double *node_x0, double *node_v,
                             const double *node_mass);
/* The pair's nodes, their weights in its relative position (nodes of several of its
 * vertices merged) and their effective inverse masses in it (1 / the mass of the vertex
 * they belong to, embedding.c); returns how many (<= 16). */
int piola__pair_nodes(const piola_collision_surface *s, const int32_t v[4], const double w[4],
                      int32_t node[16], double weight[16], double inverse_mass[16]);
/* Adds the velocity change weight * inverse_mass * impulse to each node of the pair and
 * brings the velocities of their vertices (vertex_v) up to date, marking them dirty. */
void piola__embedding_apply(piola_collision_surface *s, int n, const int32_t node[16],
                            const double weight[16], const double inverse_mass[16], vec3 impulse);
/* 1 when a vertex of one side of the pair (the point, or the first edge) shares a node with
 * one of the other side (the pair takes no part, as a vertex and a triangle that contains it
 * do not). */
int piola__pair_shares_node(const piola_collision_surface *s, const int32_t v[4], int edge_edge);
/* Rigid impact zones of nodes for an embedded surface (see piola__impact_zones_apply). */
int32_t piola__embedded_zones_apply(piola_collision_surface *s, const piola__contact_list *hits,
                                    int32_t *zone_vertices);
/* Whether every node of the pair is in one zone (embedded surfaces). */
int piola__embedded_same_zone(piola_collision_surface *s, const piola__contact *c);

/* Collects the candidate pairs of a call (into surface->candidates): reach boxes from x0 and
 * the velocities v, the trees fit to them (built when *tree_built is 0 and the trees are old
 * or new; see detection.c), one descent of tree against tree. Returns 0, or -1 out of memory. */
int piola__collect_candidates(piola_collision_surface *surface, const double *x0, const double *v,
                              double dt, int *tree_built);

/* All contacts (proximity at x0) or collisions (continuous detection over the step with
 * velocities v) into surface->found, in an order that does not depend on the thread count.
 * With dirty given, only pairs with a vertex marked there are tested (continuous detection
 * then queries the trees from those vertices; without, it scans the candidates). Needs the
 * candidates of this call (piola__collect_candidates), which it collects again, for some
 * vertices or all, when velocities left their reach boxes. Returns 0, or -1 out of memory. */
int piola__detect(piola_collision_surface *surface, const double *x0, const double *v, double dt,
                  piola__detect_mode mode, const uint8_t *dirty, int *tree_built);

/* The same by testing every pair (O(n^2)): the reference that tests compare with. Pairs come
 * vertex-triangle first (by vertex, then triangle), then edge-edge (lower edge index first).
 * Returns 0, or -1 out of memory. */
int piola__detect_all_pairs(const piola_collision_surface *surface, const double *x0,
                            const double *v, double dt, piola__detect_mode mode,
                            piola__contact_list *out);

/* Velocity field of rigid impact zones: merges the vertices of every contact in `hits` into
 * zones (union-find in surface->zone_parent), then gives every vertex of every zone the rigid
 * velocity that keeps the zone's linear and angular momentum about its centre of mass at x0.
 * Pinned vertices keep their velocity; a zone holding some moves with the rigid motion that
 * fits the pinned vertices best. Returns the number of zones, or -1 out of memory. */
int32_t piola__impact_zones_apply(piola_collision_surface *surface, const piola__contact_list *hits,
                                  const double *x0, double *v, int32_t *zone_vertices);

#endif
