/* Shared between the output folder policy and the frame writer. */
#ifndef PIOLA_OUTPUT_OUTPUT_INTERNAL_H
#define PIOLA_OUTPUT_OUTPUT_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "piola/mesh.h"
#include "piola/output.h"
#include "piola/world.h"

/* Checks the folder policy, creates DIR, DIR/frames and DIR/surface, and when forced
 * removes an earlier run's results. */
piola_status piola__output_prepare_folder(const char *dir, bool force);

/* output_reconcile.c: removes stray temporaries from dir, dir/frames and dir/surface and,
 * with drop_after >= 0, the frames numbered above it. */
void piola__output_remove_strays(const char *dir, long drop_after);
/* For a resume from frame last_frame: checks that frames 0..last_frame are in place (with
 * piece_count > 0: each frame's .pvtu and its pieces) and stats.csv lists them, removes
 * strays and later frames, and returns stats.csv's rows for frames 0..last_frame (no
 * header; malloc'ed, *rows owned by the caller). */
piola_status piola__output_reconcile(const char *dir, int32_t last_frame, int32_t piece_count,
                                     char **rows, size_t *length);

/* The per-body layout of the OBJ surface frames (obj_frame.c): the OBJ's vertices (indices
 * into the frame's points), grouped by body, and its faces (1-based OBJ indices). */
typedef struct obj_layout {
  int32_t body_count;
  int32_t *vertices;          /* point index of each OBJ vertex */
  int32_t *faces;             /* 3 per face */
  int32_t *body_vertex_start; /* body_count + 1 */
  int32_t *body_face_start;   /* body_count + 1 */
  char (*names)[128];         /* per body: the object name (blanks made '_') */
} obj_layout;

/* Bodies own the points [body_first_vertex[b], body_first_vertex[b + 1]) (body_count + 1
 * entries); a surface triangle belongs to the body of its first vertex. */
piola_status piola__obj_layout_build(const piola_tri_mesh *surface, const int32_t *body_first_vertex,
                                     int32_t body_count, const char *const *names,
                                     int32_t vertex_count, obj_layout *layout);
/* Writes one frame (positions: 3 per point), whole or not at all. */
piola_status piola__obj_layout_write(const obj_layout *layout, const char *path,
                                     const double *positions);
void piola__obj_layout_free(obj_layout *layout);
/* As piola__obj_layout_write, but a solid with fracture state is written as one object
 * per fragment, `o <name>_<fragment>`, its closed surface with the crack faces. */
piola_status piola__obj_write_fragments(const obj_layout *layout, const char *path,
                                        const double *positions, const piola_world *world);

/* A frame as pieces, one per process of a split run (frame_pieces.c): this process's piece,
 * its points and cells (indices into the whole frame) and the arrays of its VTU. */
typedef struct piece_layout {
  int32_t piece, piece_count;
  int32_t *points, *cells;
  piola_tet_mesh tets; /* the piece's numbering; positions refreshed per frame */
  double *velocity, *displacement, *point_id, *det_f, *inverted, *energy, *solid, *cell_id;
  int fractures;               /* a solid has fracture state: the layout is built again for
                                  every frame, cells get fragment and material_fraction */
  double *fragment, *fraction; /* per cell, when fractures */
} piece_layout;

piola_status piola__piece_layout_build(piece_layout *layout, const piola_world *world,
                                       int32_t piece, int32_t piece_count);
void piola__piece_layout_free(piece_layout *layout);
/* "DIR/frames/frame_NNNN_pK.vtu" */
void piola__piece_name(char *out, size_t size, const char *dir, int32_t frame, int32_t piece);
/* Writes and renames into place this process's piece of frame (a data file no index lists
 * until process 0's .pvtu and indexes are committed). */
piola_status piola__piece_write(piece_layout *layout, const piola_world *world, const char *dir,
                                int32_t frame);
struct frame_commit;
/* Checks that every piece of frame is in place and queues the frame's .pvtu (a data file of
 * the frame's commit, written under a temporary name). */
piola_status piola__pvtu_stage(struct frame_commit *commit, const char *dir, int32_t frame,
                               int32_t piece_count, int fractures);
/* The frame number of a file of DIR/frames piola writes (frame_NNNN.vtu, frame_NNNN.pvtu,
 * frame_NNNN_pK.vtu), or -1. */
long piola__frame_file_number(const char *name);

#endif
