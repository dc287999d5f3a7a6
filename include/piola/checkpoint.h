/* piola: checkpoints, the complete state of a world at a frame, so a killed run continues
 * where it stopped and writes the same bits as a run that never stopped.
 *
 * A checkpoint holds everything the next step reads that is not rebuilt from the scene:
 * the time, every body's positions and velocities, the elastic force and per-element state
 * of the last force update (the diagonalization, det F, the plastic Fp^-1, the shells'
 * dihedral angles), the damping operator the next step starts from and the last solve's
 * product it reuses, the plastic state (Fp^-1, hardening, bounds, refresh phase, control
 * logarithms), the cut state of solids with fracture (their copies, nodes, fractions and
 * cracks), the statistics of the last step, and what self-collision carries from step
 * to step (the shapes and age of the collision trees, which decide the order of its
 * impulses, and an open collision interval). Keyframe clocks and obstacle poses are
 * functions of the time, and the initial scramble's random numbers are used once at
 * creation, so the time covers them. The file layout is in docs/file-formats.md. */
#ifndef PIOLA_CHECKPOINT_H
#define PIOLA_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The checkpoint format this piola writes (docs/file-formats.md); it reads this one,
 * format 8 (without backward Euler solids' kept start), format 7 (without the solids'
 * self-collision waits either), format 6 (without the recent step bounds either), format 5
 * (without the step weights of cut plastic solids either) and format 4 (whose cut solids
 * have no tet cut twice either). */
#define PIOLA_CHECKPOINT_VERSION 9

/* 1 when checkpoints cover every part of the world's state; 0 with a reason in *why (a
 * static string) otherwise. why may be NULL. */
PIOLA_API int piola_world_checkpoint_supported(const piola_world *world, const char **why);

/* A 64-bit key (FNV-1a) naming the scene a world was built from: the scene file's bytes
 * (scene, length; NULL and 0 for none) and the rest state of every body (rest positions,
 * elements and masses, so a changed mesh file changes the key); a NULL world adds none. */
PIOLA_API uint64_t piola_world_scene_key(const piola_world *world, const void *scene,
                                         size_t length);

/* Writes the world's state at frame `frame` (>= 0: the frame whose end state it is, as
 * piola_world_checkpoint_read gives back; a negative one is refused with
 * PIOLA_ERROR_INVALID_ARGUMENT) to path, whole or not at all (a temporary renamed into
 * place). */
PIOLA_API piola_status piola_world_checkpoint_write(const piola_world *world, const char *path,
                                                    uint64_t scene_key, int32_t frame);

/* Reads a checkpoint into a world built from the same scene (as piola_world_scene_key says):
 * PIOLA_ERROR_PARSE for a file that is not a whole, intact checkpoint (bad magic, size or
 * checksum), PIOLA_ERROR_UNSUPPORTED for another format version or another scene, each
 * with a message. The world is changed only when the whole file was checked (a cut solid
 * takes the file's cut state while the rest is checked, and is put back as it was when the
 * file does not fit). *frame (frame may be NULL) receives the frame it was written at. */
PIOLA_API piola_status piola_world_checkpoint_read(piola_world *world, const char *path,
                                                   uint64_t scene_key, int32_t *frame);

#ifdef __cplusplus
}
#endif

#endif
