/* piola: writing a simulation's results to a folder.
 *
 * Layout of an output folder DIR:
 *   DIR/frames/frame_NNNN.vtu   every solid's tets: per-cell det_f, inverted (0/1),
 *                               energy_density (J/m^3) and solid (index); per-point velocity
 *                               (m/s) and displacement (m, from the rest position)
 *   DIR/surface/frame_NNNN.obj  the boundary surface of every solid
 *   DIR/stats.csv               one row per frame (see docs/cli.md for the columns)
 *   DIR/sim.pvd                 ParaView collection of the VTU frames with their times
 *   DIR/failure_report.txt      only when a run stops on a non-finite state
 * Every file is written whole or not at all (a temporary file renamed into place), and
 * stats.csv and sim.pvd are rewritten after each frame, so a stopped run leaves a
 * consistent folder of every good frame. */
#ifndef PIOLA_OUTPUT_H
#define PIOLA_OUTPUT_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_output piola_output;

/* Whether results may be written to dir, leaving it as it was: OK when dir does not exist
 * and can be created (its nearest existing ancestor is a writable folder), or is an empty
 * writable folder, or when force is set and dir is a writable folder (writability is tested
 * by creating and removing a probe file). Otherwise PIOLA_ERROR_INVALID_ARGUMENT with a
 * message saying why. */
PIOLA_API piola_status piola_output_check_folder(const char *dir, bool force);

/* Creates dir, dir/frames and dir/surface (after piola_output_check_folder), removing the
 * results of an earlier run there (only files piola writes) when force is set. */
PIOLA_API piola_status piola_output_open(const char *dir, bool force, const piola_world *world,
                                         piola_output **out);
PIOLA_API void piola_output_close(piola_output *output);

/* Reopens the folder of an earlier run to continue after frame `frame` (a resume from a
 * checkpoint, piola/checkpoint.h): frames 0..frame must be in place and listed in
 * stats.csv; later frames, their index rows and stray temporaries are removed, and both
 * indexes are rewritten to list exactly frames 0..frame. */
PIOLA_API piola_status piola_output_open_resume(const char *dir, int32_t frame,
                                                const piola_world *world, piola_output **out);

/* The output of one process of a split run (docs/mpi.md, "Output"): frames are written as
 * pieces, DIR/frames/frame_NNNN_pK.vtu by process K (piola_output_write_piece), tied by
 * DIR/frames/frame_NNNN.pvtu, which piece 0's piola_output_write_frame writes with the OBJ
 * and the indexes once every piece is in place; sim.pvd lists the .pvtu files. Piece 0
 * prepares the folder as piola_output_open does (resume_frame < 0), or reconciles it as
 * piola_output_open_resume does (resume_frame >= 0, the pieces of frames 0..resume_frame
 * included); the other pieces only write their own piece and must be opened after piece 0.
 * Shells and fracture are not written as pieces (PIOLA_ERROR_UNSUPPORTED). */
PIOLA_API piola_status piola_output_open_pieces(const char *dir, bool force, int32_t resume_frame,
                                                const piola_world *world, int32_t piece,
                                                int32_t piece_count, piola_output **out);

/* Writes this process's piece of frame `frame` of the world's current state, whole, under
 * its final name (no index lists it before piece 0's piola_output_write_frame). */
PIOLA_API piola_status piola_output_write_piece(piola_output *output, const piola_world *world,
                                                int32_t frame);

typedef struct piola_frame_info {
  int32_t frame;          /* frame number, 0 is the initial state */
  int32_t substeps;       /* steps taken since the previous frame */
  int32_t cg_iterations;  /* CG iterations since the previous frame */
  double wall_seconds;    /* wall time spent since the previous frame, s */
  int64_t contacts;       /* self-collision repulsion contacts since the previous frame */
  int64_t impacts;        /* self-collision impacts since the previous frame */
  int32_t impact_zones;   /* self-collision rigid impact zones since the previous frame */
  int32_t newton_iterations; /* implicit integrators: Newton iterations since the previous
                                frame (0 with Newmark) */
  int32_t linear_iterations; /* implicit integrators: CG iterations of the Newton systems */
  int32_t newton_failures;   /* implicit integrators: tries whose Newton did not converge,
                                retried at half the size or kept (time-stepping.md, "Failure") */
  int32_t step_retries;   /* steps redone at a smaller size since the previous frame */
  int32_t energy_redos;   /* Newmark steps redone at a smaller size since the previous frame
                             because their energy rose (docs/time-stepping.md) */
} piola_frame_info;

/* Writes the VTU and OBJ of the world's current state and appends a row to stats.csv and
 * an entry to sim.pvd. With pieces (piece 0 only): the .pvtu instead of the VTU, refused
 * (PIOLA_ERROR_IO) when a piece of the frame is not in place. */
PIOLA_API piola_status piola_output_write_frame(piola_output *output, const piola_world *world,
                                                const piola_frame_info *info);

/* Writes DIR/failure_report.txt: the message and the worst elements of each solid (smallest
 * det F, largest energy density) at the last good state. */
PIOLA_API piola_status piola_output_write_failure_report(piola_output *output,
                                                         const piola_world *world,
                                                         const char *message);

/* Writes DIR/warnings.txt: the world's warnings raised so far (piola_world_warning), one
 * per line; nothing when none has been raised. */
PIOLA_API piola_status piola_output_write_warnings(piola_output *output, const piola_world *world);

#ifdef __cplusplus
}
#endif

#endif
