/* `piola run SCENE.json -o DIR [--threads N] [--frames N] [--force | --resume]
 * [--checkpoint-every N]`: simulate a scene and write its frames. Uses only the public API.
 *
 * Everything that can be wrong with the input (arguments, the scene, its meshes, the output
 * folder) is checked before anything is written, so a bad run exits 2 and leaves the output
 * folder untouched. A state that turns NaN or Inf stops the run with exit code 1, keeping
 * every frame written so far and a failure report. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli_numbers.h"
#include "cli/commands.h"
#include "cli/run_budget.h"
#include "cli/run_checkpoints.h"
#include "cli/run_mpi.h"
#include "cli/run_split_checkpoints.h"
#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/output.h"
#include "piola/render.h"
#include "piola/threads.h"
#include "piola/scene.h"
#include "piola/world_shells.h"
#include "piola/world.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: piola run SCENE.json -o DIR [--threads N] [--frames N] [--force | --resume]\n"
          "                 [--checkpoint-every N] [--max-steps N] [--render]\n"
          "\n"
          "  -o, --output DIR   folder for frames/, surface/, stats.csv and sim.pvd\n"
          "  --threads N        worker threads, 1 to 1024 (default: all cores)\n"
          "  --frames N         write N frames after frame 0 instead of the scene's `frames`\n"
          "  --force            write into DIR even if it holds earlier results\n"
          "                     (the earlier run's frames, surfaces, stats.csv, sim.pvd,\n"
          "                     failure_report.txt, warnings.txt and checkpoints are removed\n"
          "                     first, nothing else)\n"
          "  --resume           continue the run in DIR from its newest checkpoint\n"
          "  --max-steps N      refuse a run estimated to take more than N steps (1e7)\n"
          "  --checkpoint-every N  a checkpoint every N frames (0: none; default: every 10\n"
          "                     frames or 5 minutes of wall time, whichever comes first)\n"
          "  --render           also render every frame to DIR/render/frame_NNNN.png\n"
          "                     (DIR/preview.png of the last frame is written by every\n"
          "                     run but one split under mpirun)\n"
          "  -h, --help         this text\n"
          "\n"
          "`piola check SCENE.json` validates a scene and estimates its run without writing.\n");
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void format_duration(double s, char *buf, size_t n) {
  if (!isfinite(s) || s < 0) {
    snprintf(buf, n, "--:--");
    return;
  }
  long t = (long)(s + 0.5);
  if (t >= 3600) snprintf(buf, n, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else snprintf(buf, n, "%02ld:%02ld", t / 60, t % 60);
}

/* Prints each warning the world raised since the last call once on stderr and rewrites
 * DIR/warnings.txt with all of them (docs/cli.md). */
static void report_warnings(piola_output *out, const piola_world *world, bool warned[],
                            bool tty) {
  if (!out) return; /* another MPI process than 0: process 0 reports */
  bool fresh = false;
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k) {
    const char *w = piola_world_warning(world, (piola_warning_kind)k);
    if (!w || warned[k]) continue;
    if (tty && !fresh) fputc('\n', stderr);
    fprintf(stderr, "piola run: warning: %s\n", w);
    warned[k] = fresh = true;
  }
  if (fresh && piola_output_write_warnings(out, world) != PIOLA_OK)
    fprintf(stderr, "piola run: warnings.txt: %s\n", piola_last_error());
}

/* What the warning handler needs to report a warning as it is raised. */
typedef struct warning_report {
  piola_output *out; /* NULL on MPI processes other than 0 */
  const piola_world *world;
  bool *warned;
  bool tty;
} warning_report;

/* The world's warning handler: a warning raised inside a frame is printed then, not when
 * the frame ends (a run stalled inside a frame by a tiny step said nothing of it). */
static void report_raised_warning(void *context, piola_warning_kind kind, const char *message) {
  (void)kind, (void)message;
  const warning_report *r = context;
  report_warnings(r->out, r->world, r->warned, r->tty);
}

static void progress(bool tty, int frame, int frames, double t, double elapsed, int substeps,
                     int inverted) {
  double eta = frame > 0 ? elapsed / frame * (frames - frame) : NAN;
  char eta_s[32], el_s[32];
  format_duration(eta, eta_s, sizeof eta_s);
  format_duration(elapsed, el_s, sizeof el_s);
  if (tty) {
    int width = 30, filled = frames > 0 ? width * frame / frames : width;
    char bar[64];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    fprintf(stderr, "\r[%s] frame %d/%d  t = %.3f s  elapsed %s  ETA %s  ", bar, frame, frames, t,
            el_s, eta_s);
    if (frame == frames) fputc('\n', stderr);
  } else {
    fprintf(stderr, "frame %d/%d t=%.4f s substeps=%d inverted=%d elapsed=%s eta=%s\n", frame,
            frames, t, substeps, inverted, el_s, eta_s);
  }
  fflush(stderr);
}

/* Writes a frame: process 0's VTU, or in a split run every process's piece and then, once
 * all are in place, process 0's .pvtu (docs/mpi.md); the OBJ and the indexes last, by
 * process 0. Collective; true when every process succeeded (a failure is printed where it
 * happened). */
static bool write_frame_everywhere(run_mpi *mpi, piola_output *out, const piola_world *world,
                                   const piola_frame_info *info) {
  const bool lead = mpi->rank == 0;
  if (mpi->size > 1) {
    bool ok = piola_output_write_piece(out, world, info->frame) == PIOLA_OK;
    if (!ok) fprintf(stderr, "piola run: MPI process %d: %s\n", mpi->rank, piola_last_error());
    if (!run_mpi_all(mpi, ok)) return false;
  }
  bool ok = !lead || piola_output_write_frame(out, world, info) == PIOLA_OK;
  if (!ok) fprintf(stderr, "piola run: %s\n", piola_last_error());
  return run_mpi_all(mpi, ok);
}

/* A checkpoint at frame: one file, or in a split run one file per process and process 0's
 * manifest (run_split_checkpoints.h). Collective. */
static int save_checkpoint(run_mpi *mpi, const char *dir, const piola_world *world, uint64_t key,
                           int32_t frame) {
  if (mpi->size > 1) return run_split_checkpoint_save(mpi, dir, world, key, frame);
  return run_checkpoint_save(dir, world, key, frame);
}

static int run(int argc, char **argv, run_mpi *mpi) {
  const char *scene_path = NULL, *out_dir = NULL;
  long threads = 0, frames_override = -1, checkpoint_every = -1; /* -1: the default */
  double max_steps = 1e7; /* the time-budget guard (see budget_ok) */
  bool force = false, render_frames = false, resume = false;
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      usage(stdout);
      return 0;
    } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (++i >= argc) return fprintf(stderr, "piola run: %s needs a folder\n", a), 2;
      out_dir = argv[i];
    } else if (strcmp(a, "--threads") == 0) {
      if (++i >= argc || !cli_parse_long(argv[i], 1, 1024, &threads))
        return fprintf(stderr, "piola run: --threads needs an integer in [1, 1024]\n"), 2;
    } else if (strcmp(a, "--frames") == 0) {
      if (++i >= argc || !cli_parse_long(argv[i], 0, 1000000, &frames_override))
        return fprintf(stderr, "piola run: --frames needs an integer in [0, 1000000]\n"), 2;
    } else if (strcmp(a, "--force") == 0) {
      force = true;
    } else if (strcmp(a, "--max-steps") == 0) {
      if (++i >= argc || !cli_parse_double(argv[i], &max_steps) || !(max_steps >= 1) ||
          max_steps > 1e18)
        return fprintf(stderr, "piola run: --max-steps needs a number in [1, 1e18]\n"), 2;
    } else if (strcmp(a, "--resume") == 0) {
      resume = true;
    } else if (strcmp(a, "--checkpoint-every") == 0) {
      if (++i >= argc || !cli_parse_long(argv[i], 0, 1000000, &checkpoint_every))
        return fprintf(stderr, "piola run: --checkpoint-every needs an integer in [0, 1000000]\n"), 2;
    } else if (strcmp(a, "--render") == 0) {
      render_frames = true;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "piola run: unknown option '%s'\n", a);
      usage(stderr);
      return 2;
    } else if (!scene_path) {
      scene_path = a;
    } else {
      fprintf(stderr, "piola run: more than one scene given ('%s' and '%s')\n", scene_path, a);
      return 2;
    }
  }
  if (!scene_path || !out_dir) {
    fprintf(stderr, "piola run: %s\n", !scene_path ? "no scene file given" : "no output folder given (-o DIR)");
    usage(stderr);
    return 2;
  }
  if (force && resume) {
    fprintf(stderr, "piola run: --force and --resume exclude each other (start over, or continue)\n");
    return 2;
  }
  const bool lead = mpi->rank == 0; /* the process that writes and reports */
  if (!run_mpi_all(mpi, piola_output_check_folder(out_dir, force || resume) == PIOLA_OK)) {
    if (lead) fprintf(stderr, "piola run: %s\n", piola_last_error());
    return 2;
  }
  if (threads > 0) piola_set_thread_count((int)threads); /* every parallel loop of piola */
  double t_start = now_seconds();
  piola_scene *scene = NULL;
  if (!run_mpi_all(mpi, run_mpi_load(mpi, scene_path, &scene) == PIOLA_OK)) {
    if (lead) fprintf(stderr, "piola run: %s\n", scene ? "another MPI process could not load the scene" : piola_last_error());
    piola_scene_destroy(scene);
    return 2;
  }
  piola_world *world = piola_scene_world(scene);
  if (!run_mpi_split(mpi, world)) {
    piola_scene_destroy(scene);
    return 2;
  }
  int frames = frames_override >= 0 ? (int)frames_override : (int)piola_scene_frames(scene);
  double fps = piola_scene_fps(scene);
  if (!run_budget_ok("piola run", scene_path, world, frames, fps, max_steps, !lead)) {
    piola_scene_destroy(scene);
    return 2;
  }
  /* checkpoints: on by default where they cover the whole state */
  const char *why = NULL;
  uint64_t scene_key = 0;
  if (!piola_world_checkpoint_supported(world, &why)) {
    if (resume || checkpoint_every > 0) {
      if (lead) fprintf(stderr, "piola run: %s: %s\n", resume ? "--resume" : "--checkpoint-every", why);
      piola_scene_destroy(scene);
      return 2;
    }
    if (checkpoint_every < 0 && lead) fprintf(stderr, "piola run: no checkpoints: %s\n", why);
    checkpoint_every = 0;
  }
  if ((checkpoint_every != 0 || resume) && !run_scene_key(scene_path, world, &scene_key)) {
    piola_scene_destroy(scene);
    return 2;
  }
  int32_t resume_frame = -1;
  if (resume) {
    /* a split run resumes from one file per process, on as many processes (docs/mpi.md) */
    int found = mpi->size > 1 ? run_split_checkpoint_resume(mpi, out_dir, world, scene_key, &resume_frame)
                              : run_checkpoint_resume(out_dir, world, scene_key, &resume_frame);
    int listed = found == 1 ? run_listed_frames(out_dir) : 0;
    if (found == 2 || listed > 1) {
      if (found == 1 && lead)
        fprintf(stderr, "piola run: cannot resume: %s holds frames 0..%d but no checkpoint "
                        "(checkpoint_NNNN.bin); use --force to start over\n", out_dir, listed - 1);
      piola_scene_destroy(scene);
      return 2;
    }
    if (found == 1) {
      /* no checkpoint and at most frame 0: a missing or empty folder, or a run killed
       * before its first checkpoint; starting over loses nothing */
      if (lead) fprintf(stderr, "piola run: no checkpoint in %s, starting from frame 0\n", out_dir);
      force = true;
    }
  }
  /* a split run writes its frames as pieces, one per process (docs/mpi.md, "Output"):
   * process 0 prepares the folder first, then the others open their pieces */
  const int32_t pieces = mpi->size > 1 ? mpi->size : 0;
  piola_output *out = NULL;
  piola_status opened = !lead ? PIOLA_OK
                        : pieces ? piola_output_open_pieces(out_dir, force, resume_frame, world, 0, pieces, &out)
                        : resume_frame >= 0 ? piola_output_open_resume(out_dir, resume_frame, world, &out)
                                            : piola_output_open(out_dir, force, world, &out);
  bool open_ok = run_mpi_all(mpi, opened == PIOLA_OK);
  if (open_ok && pieces && !lead) {
    opened = piola_output_open_pieces(out_dir, force, resume_frame, world, mpi->rank, pieces, &out);
    if (opened != PIOLA_OK)
      fprintf(stderr, "piola run: MPI process %d: %s\n", mpi->rank, piola_last_error());
  }
  if (open_ok && pieces) open_ok = run_mpi_all(mpi, opened == PIOLA_OK);
  if (!open_ok) {
    if (lead) fprintf(stderr, "piola run: %s\n", opened == PIOLA_OK ? "another MPI process could not open its piece" : piola_last_error());
    piola_output_close(out);
    piola_scene_destroy(scene);
    return opened == PIOLA_ERROR_INVALID_ARGUMENT ? 2 : 1;
  }
  if (resume_frame >= 0 && lead)
    fprintf(stderr, "piola run: resuming after frame %d (t = %.9g s) from %s/checkpoint_%04d.%s\n",
            (int)resume_frame, piola_world_time(world), out_dir, (int)resume_frame,
            pieces ? "manifest and one file per MPI process" : "bin");
  if (resume_frame >= frames && lead)
    fprintf(stderr,
            "piola run: nothing to simulate: the run in %s already reaches frame %d, and this "
            "one ends at frame %d (--frames or the scene's frames); its frames are kept\n",
            out_dir, (int)resume_frame, frames);
  const double checkpoint_wall = 300; /* s: the default's time bound */
  int32_t last_checkpoint = resume_frame >= 0 ? resume_frame : 0;
  double last_checkpoint_time = now_seconds();
  bool tty = lead && isatty(STDERR_FILENO);
  bool warned[PIOLA_WARNING_KIND_COUNT] = {false};
  report_warnings(lead ? out : NULL, world, warned, false);
  warning_report raised = {lead ? out : NULL, world, warned, tty};
  piola_world_set_warning_handler(world, report_raised_warning, &raised);
  const double first_dt = piola_world_stable_dt(world); /* collective when split: all ask */
  if (lead)
    fprintf(stderr, "piola run: %s -> %s: %d frames at %g fps, %d solids, %d shells, %d obstacles, first dt %.3g s%s\n",
            scene_path, out_dir, frames, fps, (int)piola_world_solid_count(world),
            (int)piola_world_shell_count(world), (int)piola_world_obstacle_count(world),
            first_dt, mpi->size > 1 ? ", on MPI processes" : "");
  /* previews (src/render): DIR/scene.json, DIR/preview.png and, with --render, every frame */
  piola_preview *preview = NULL;
  if (lead && pieces)
    fprintf(stderr, "piola run: no preview%s: the frames of a split run are pieces; `piola render "
                    "%s` draws their surfaces afterwards (docs/mpi.md)\n",
            render_frames ? " and no --render" : "", out_dir);
  else if (lead && piola_preview_open(out_dir, scene_path, render_frames, &preview) != PIOLA_OK)
    fprintf(stderr, "piola run: no preview: %s\n", piola_last_error());
  int rc = 0;
  long long total_steps = 0, total_cg = 0, total_newton = 0, total_linear = 0, total_failures = 0;
  int max_inverted = 0;
  double sim_start = now_seconds();
  piola_frame_info info = {0};
  if (resume_frame < 0) run_mpi_collect(mpi, world); /* process 0 writes frame 0 */
  if (resume_frame >= 0) {
    /* frames up to resume_frame are on disk already */
  } else if (!write_frame_everywhere(mpi, out, world, &info)) {
    rc = 1;
  } else {
    if (preview && piola_preview_frame_written(preview, 0, piola_world_time(world)) != PIOLA_OK)
      fprintf(stderr, "piola run: preview: %s\n", piola_last_error());
    if (checkpoint_every != 0 && !save_checkpoint(mpi, out_dir, world, scene_key, 0)) rc = 1;
  }
  if (!run_mpi_all(mpi, rc == 0)) rc = 1;
  int frame = 0, frames_written = 0;
  int first = resume_frame >= 0 ? resume_frame + 1 : 1;
  for (frame = first; rc == 0 && frame <= frames; ++frame) {
    double t0 = now_seconds();
    piola_step_stats st = {0};
    const piola_status advanced = piola_world_advance_to(world, frame / fps, &st);
    if (advanced != PIOLA_OK) {
      /* every MPI process fails the same step: their node states are the same bits */
      rc = 1;
      run_mpi_collect(mpi, world); /* for the failure report */
      if (!lead) break;
      char message[1024];
      /* a failure the library left without a message still says what it was */
      snprintf(message, sizeof message, "%s",
               piola_last_error()[0] ? piola_last_error() : piola_status_name(advanced));
      if (tty) fputc('\n', stderr);
      report_warnings(lead ? out : NULL, world, warned, false);
      fprintf(stderr, "piola run: stopped at frame %d: %s\n", frame, message);
      if (piola_output_write_failure_report(out, world, message) == PIOLA_OK)
        fprintf(stderr, "piola run: frames 0..%d are kept; see %s/failure_report.txt\n", frame - 1, out_dir);
      else
        fprintf(stderr, "piola run: could not write the failure report: %s\n", piola_last_error());
      rc = 1;
      break;
    }
    info.frame = frame;
    info.substeps = st.substeps;
    info.cg_iterations = st.cg_iterations;
    info.contacts = st.contacts;
    info.impacts = st.impacts;
    info.impact_zones = st.impact_zones;
    info.step_retries = st.step_retries;
    info.energy_redos = st.energy_redos;
    info.newton_iterations = st.newton_iterations;
    info.linear_iterations = st.linear_iterations;
    info.newton_failures = st.newton_failures;
    total_newton += st.newton_iterations;
    total_linear += st.linear_iterations;
    total_failures += st.newton_failures;
    info.wall_seconds = now_seconds() - t0;
    total_steps += st.substeps;
    total_cg += st.cg_iterations;
    int inverted = 0;
    run_mpi_collect(mpi, world); /* process 0 alone reads the per-tet state, from here on */
    for (int32_t s = 0; lead && s < piola_world_solid_count(world); ++s)
      inverted += piola_world_solid_stats(world, s).inverted_count;
    if (inverted > max_inverted) max_inverted = inverted;
    if (!write_frame_everywhere(mpi, out, world, &info)) {
      rc = 1;
      break;
    }
    frames_written++;
    if (preview && piola_preview_frame_written(preview, frame, piola_world_time(world)) != PIOLA_OK)
      fprintf(stderr, "piola run: preview: %s\n", piola_last_error());
    /* after the frame's commit, so a checkpoint's frames are all on disk */
    bool due = checkpoint_every > 0 ? frame - last_checkpoint >= checkpoint_every
                                    : frame - last_checkpoint >= 10 ||
                                          now_seconds() - last_checkpoint_time >= checkpoint_wall;
    due = run_mpi_from_lead(mpi, due); /* process 0's clock decides for all */
    if (checkpoint_every != 0 && (due || frame == frames)) {
      if (!save_checkpoint(mpi, out_dir, world, scene_key, frame)) {
        rc = 1;
        break;
      }
      last_checkpoint = frame;
      last_checkpoint_time = now_seconds();
    }
    report_warnings(lead ? out : NULL, world, warned, tty);
    if (lead) progress(tty, frame, frames, piola_world_time(world), now_seconds() - sim_start, st.substeps, inverted);
  }
  piola_world_set_warning_handler(world, NULL, NULL); /* `raised` ends with this function */
  double wall = now_seconds() - t_start;
  double sim_wall = now_seconds() - sim_start;
  int written = frames_written;
  run_mpi_report(mpi);
  /* the hints name only files that are there: a run stopped by a failed write may have none */
  char pvd[4200], png[4200];
  snprintf(pvd, sizeof pvd, "%s/sim.pvd", out_dir);
  snprintf(png, sizeof png, "%s/preview.png", out_dir);
  const bool have_pvd = access(pvd, F_OK) == 0;
  if (lead)
    fprintf(stderr,
            "piola run: %s. %d frames (%.3f s simulated) in %.2f s wall (%.2f frames/s), %lld "
            "steps, %lld CG iterations, %lld Newton iterations, %lld linear iterations, %lld "
            "failed Newton steps, at most %d inverted tets in a frame.%s%s%s\n",
            rc == 0 ? "done" : "stopped", written, written / fps, wall,
            sim_wall > 0 ? written / sim_wall : 0.0, total_steps, total_cg, total_newton,
            total_linear, total_failures, max_inverted, have_pvd ? " Open " : "",
            have_pvd ? pvd : "", have_pvd ? " in ParaView." : "");
  if (preview && piola_preview_close(preview) != PIOLA_OK)
    fprintf(stderr, "piola run: preview.png: %s\n", piola_last_error());
  else if (preview && access(png, F_OK) == 0)
    fprintf(stderr, "piola run: preview of the last frame: %s\n", png);
  piola_output_close(out);
  piola_scene_destroy(scene);
  return rc;
}

int cli_run(int argc, char **argv) {
  run_mpi mpi;
  if (!run_mpi_start(&mpi)) return 1;
  int rc = run(argc, argv, &mpi);
  run_mpi_finish(&mpi, NULL); /* the world is gone: the split only drops its own arrays */
  return rc;
}
