/* Fracture state of a solid (fracture.c, fracture_surface.c): the virtual node algorithm
 * of Molino, Bao and Fedkiw 2004 for plane cuts. See docs/fracture.md.
 *
 * The solid's current mesh is made of copies of the tets of its original mesh. A copy that
 * is whole has fraction 1; a cut copy holds the material on one side of one plane. The
 * plane is kept as the signed distances (m, at the time of the cut, each at least `snap`
 * from zero) of the copy's four corners: inside the tet the crack is the zero set of their
 * linear interpolant, a polygon in barycentric coordinates. The copy's corners are in the
 * order of its original tet (positively oriented), so corner k of a copy and of its
 * original tet are the same material point.
 *
 * A tet can be cut again: a copy's material is then the part of its tet on its side of
 * each of up to three cuts, a convex cell (a cell of the planes' arrangement). Unlike
 * MBF04, whose pieces each keep the material near one of the tet's corners, a cell need
 * not hold a corner: where two cracks cross inside a tet, the wedge between them is a copy
 * of its own whose nodes are all virtual, joined to its neighbours through the faces it
 * touches like any copy. So a tet has at most 8 copies (three cuts deep). The first cut is
 * in event, dist and side; the others in more_event, more_dist and more_side. */
#ifndef PIOLA_SIM_FRACTURE_INTERNAL_H
#define PIOLA_SIM_FRACTURE_INTERNAL_H

#include <stdint.h>

#include "piola/mesh.h"
#include "piola/world_fracture.h"

enum {
  FRACTURE_MAX_CUTS = 3,   /* cuts through one copy */
  FRACTURE_MAX_COPIES = 8, /* copies of one original tet: two per cut, three deep */
  CELL_POLYGON_MAX = 12    /* points of one clipped polygon (a triangle or quadrilateral
                              clipped by up to three planes) */
};

typedef struct solid_fracture {
  /* scripted cuts, sorted by time, and the next one to apply */
  piola_fracture_cut *cuts;   /* a blade cut's blade points into blades */
  piola_tri_mesh *blades;     /* per scripted cut: its blade's copy (empty for a plane) */
  int32_t cut_count, next_cut, max_cuts_per_step, max_tets_per_step;
  /* per scripted cut, for moving blades (fracture_blade.c): the crack it grows (-1: not
   * started, or not a moving blade) and the time of the blade's position at its last cut, s */
  int32_t *sweep_crack;
  double *swept_to;
  int32_t events;             /* cracks started so far (plane and blade cuts, the criterion's
                                 cracks): the crack ids */
  int32_t grown_crack;        /* the id all the criterion's cracks share (-1: none yet): their
                                 values are one field, so two of them that meet join */
  piola_fracture_criterion criterion;
  double threshold;           /* Pa, or plastic log strain: a new crack starts past it */
  double growth_threshold;    /* same unit: a crack front grows past it (0: threshold) */
  double max_crack_speed;     /* m/s, 0: no limit (a front crosses every tet past the
                                 threshold in one pass) */
  /* the original mesh (after the elastic body's reorientation) and its face adjacency:
   * per tet and local face k (opposite corner k) the neighbour tet, or -1 on the boundary */
  int32_t tet_count;
  int32_t *tets;              /* 4 per original tet, original vertex ids */
  int32_t *neighbor;          /* 4 per original tet */
  /* per copy (element of the current mesh) */
  int32_t copy_count;
  int32_t *parent;            /* original tet */
  int32_t *event;             /* the crack it belongs to, -1: whole */
  double *dist;               /* 4 per copy: signed corner distances of that cut, m; the
                                 copy's material is where their interpolant has sign side */
  int8_t *side;               /* +1 or -1 */
  double *fraction;           /* material fraction in (0, 1] */
  int32_t *fragment;          /* connected piece of material */
  int32_t fragment_count;
  int32_t cut_tets;           /* original tets split so far */
  int32_t *copies;            /* FRACTURE_MAX_COPIES per original tet: its copies (-1 after
                                 the last) */
  /* per copy, its second and third cuts (FRACTURE_MAX_CUTS - 1 slots; event -1: none) */
  int32_t *more_event;
  double *more_dist;          /* 4 per slot */
  int8_t *more_side;
  double *last_strain;        /* per copy, plastic_strain criterion only (else NULL): its
                                 accumulated plastic strain at the last criterion pass */
  /* per original vertex: the crack that reached it first (-1: none) and that crack's value
   * there, m: a crack grows by continuing these values into the next tet */
  int32_t vertex_count;
  int32_t *vertex_crack;
  double *vertex_value;
  double *vertex_time;        /* s: when that value was set (the crack front reached it) */
} solid_fracture;

/* A point of a copy's polygons: corner lo when lo == hi, else the crossing of the cut at
 * lo + t (hi - lo) on the edge between corners lo and hi, lo the corner whose original
 * vertex id is smaller (so neighbouring copies compute the same t). */
typedef struct cut_point {
  int8_t lo, hi;
  double t;
} cut_point;

/* The polygons of one cut copy: the part of each face (k opposite corner k, outward) that
 * holds material, the crack polygon (outward from the material) and the material fraction.
 * dist: the 4 corner distances (none zero), side: +1 or -1, ids: original vertex ids. */
typedef struct copy_polygons {
  cut_point face[4][4];
  int32_t face_size[4];
  cut_point crack[4];
  int32_t crack_size;
  double fraction;
} copy_polygons;

void piola__fracture_copy_polygons(const double dist[4], int side, const int32_t ids[4],
                                   copy_polygons *out);

/* The outward faces of a positively oriented tet: face k is opposite corner k. */
extern const int8_t piola__cut_tet_face[4][3];

/* One cut through a copy: its crack (event id), the copy's side of it (+1 or -1) and the
 * corner distances (m, none zero). */
typedef struct copy_cut {
  int32_t event;
  int8_t side;
  double dist[4];
} copy_cut;

/* The cuts through copy c (first one first); returns their count (0: whole). */
int32_t piola__fracture_copy_cuts(const solid_fracture *f, int32_t c, copy_cut out[FRACTURE_MAX_CUTS]);

/* A point of a copy cut by several planes: on the face (edge, corner) of its tet spanned by
 * the corners in mask `corners`, and on the copy's cuts in mask `cuts` (bit j: cut j), one
 * cut fewer than corners; w: its barycentric weights (0 outside `corners`). Its weights
 * are computed from the corners' distances alone, corners in order of original vertex id
 * and cuts in order of event id, so every copy that names the point alike gets the same
 * bits. */
typedef struct cell_point {
  uint8_t corners, cuts;
  double w[4];
} cell_point;

/* The polygons of a copy cut by n cuts (1 to FRACTURE_MAX_CUTS): each face (k opposite
 * corner k, outward) clipped to the copy's material, each cut's crack polygon clipped by
 * the other cuts (outward from the material), and the material fraction they enclose. */
typedef struct cell_polygons {
  cell_point face[4][CELL_POLYGON_MAX];
  int32_t face_size[4];
  cell_point crack[FRACTURE_MAX_CUTS][CELL_POLYGON_MAX];
  int32_t crack_size[FRACTURE_MAX_CUTS];
  double fraction;
} cell_polygons;

void piola__fracture_cell_polygons(const copy_cut *cuts, int32_t n, const int32_t ids[4],
                                   cell_polygons *out);

void piola__fracture_free(solid_fracture *f);

/* A vertex of a fragment surface: sum w[k] x[node[k]] over its nodes (a corner: one node,
 * a crack's crossing of an edge: two, where two cracks meet on a face: three, where three
 * meet inside a tet: four; unused slots node -1, weight 0; the weights sum to 1). */
typedef struct fracture_surface_point {
  int32_t node[4];
  double w[4];
} fracture_surface_point;

struct world_body;
struct piola_world;
/* Cuts solid b by a triangle surface (world space): every uncut copy it passes all the way
 * through. crack < 0: a new crack; else the cut continues that crack, taking its values at
 * the vertices that hold them (so the crack stays one zero set across steps). *cut_count:
 * copies split. */
piola_status piola__fracture_surface_cut(struct piola_world *w, struct world_body *b,
                                         const piola_tri_mesh *surface, int32_t crack,
                                         int32_t *cut_count);
/* A scripted cut that is a moving blade (end_time > time). */
int piola__fracture_cut_moves(const piola_fracture_cut *cut);
/* Refuses a cut's bad motion (non-finite, a moving plane, a velocity without end_time > time). */
piola_status piola__fracture_check_motion(const piola_fracture_cut *cut, const char *name, int32_t index);
/* Starts moving cut i of b (due now): a new crack and its first cut. */
piola_status piola__fracture_blade_start(struct piola_world *w, struct world_body *b, int32_t i);
/* Before a step: every started moving blade not done yet cuts once more (fracture_blade.c). */
piola_status piola__fracture_blades_sweep(struct piola_world *w, struct world_body *b);
/* The distance (m) from a cut's plane below which node distances are pushed away from it:
 * a share of the smallest rest altitude, and with self-collision up to half the thickness
 * (capped at 5% of that altitude), so the crack faces' collision surfaces fit inside. */
double piola__fracture_snap(const struct world_body *b);
/* The fragment surfaces of solid b (piola_world_solid_fracture_surface), with each crack
 * face moved into its copy's material by inset (m, below the cut's snap distance, so every
 * polygon keeps its shape; 0: the crack itself), and when where is given, each vertex as a
 * point between two nodes (*where, vertex_count entries, freed by the caller). */
piola_status piola__fracture_surface_build(const struct world_body *b, double inset,
                                           piola_fracture_surface *out,
                                           fracture_surface_point **where);

#endif
