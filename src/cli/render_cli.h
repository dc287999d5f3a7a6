/* The pieces of `piola render DIR` (src/cli/cli_render*.c): where its frames come from and
 * how its movie is made. Internal to the `piola` program. */
#ifndef PIOLA_CLI_RENDER_CLI_H
#define PIOLA_CLI_RENDER_CLI_H

#include <stdbool.h>

#include "piola/mesh_io.h"
#include "piola/render.h"

/* ---- frames (cli_render_frames.c) */

/* Frame numbers of folder/frame_NNNN<suffix>, sorted; returns the count (-1: no memory). */
int render_cli_list_frames(const char *folder, const char *suffix, int **out);

/* A whole text file, or NULL. */
char *render_cli_read_text(const char *path);

/* Time (s) of a frame from the text of DIR/sim.pvd (may be NULL), or NAN. */
double render_cli_frame_time(const char *pvd, int frame);

/* Materials of the scene's solids, when stresses are computed from the frames. */
typedef struct render_cli_stress {
  piola_material_def materials[256];
  int32_t count; /* 0: the frames are not given a stress field */
} render_cli_stress;

typedef struct render_cli_frame {
  piola_render_frame *vtu; /* or */
  piola_tri_mesh obj;
  piola_render_mesh mesh;
} render_cli_frame;

/* Loads frame f of DIR (VTU, or the OBJ surface when vtu is false) and its mesh with the
 * value field (may be NULL), computing the von_mises_stress field first when stress has
 * materials. Prints the error and returns -1 on failure. */
int render_cli_load_frame(const char *dir, bool vtu, int f, const char *field, double time,
                          const render_cli_stress *stress, render_cli_frame *out);
void render_cli_frame_free(render_cli_frame *frame);

/* ---- movie (cli_render_movie.c) */

bool render_cli_find_in_path(const char *program);

/* Encodes render_dir/frame_NNNN.png of `frames` into render_dir/movie.mp4 at fps with
 * ffmpeg (H.264, else MPEG-4 part 2); *encoder receives the one used. Returns 0 on success;
 * an earlier movie.mp4 is replaced only by a finished new one. */
int render_cli_make_movie(const char *render_dir, const int *frames, int count, double fps,
                          const char **encoder);

#endif
