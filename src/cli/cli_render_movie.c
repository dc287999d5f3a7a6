/* The movie of `piola render`: ffmpeg over the rendered PNGs. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli/render_cli.h"

bool render_cli_find_in_path(const char *program) {
  const char *path = getenv("PATH");
  if (!path) return false;
  char buf[4096];
  for (const char *p = path; *p;) {
    const char *colon = strchr(p, ':');
    size_t len = colon ? (size_t)(colon - p) : strlen(p);
    snprintf(buf, sizeof buf, "%.*s/%s", (int)len, len ? p : ".", program);
    if (access(buf, X_OK) == 0) return true;
    if (!colon) break;
    p = colon + 1;
  }
  return false;
}

/* Runs argv in `cwd`, output to log; returns its exit status (-1: not run). */
static int run_in(const char *cwd, char *const argv[], const char *log) {
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    FILE *l = fopen(log, "w");
    if (l) {
      dup2(fileno(l), STDOUT_FILENO);
      dup2(fileno(l), STDERR_FILENO);
    }
    if (chdir(cwd) != 0) _exit(127);
    execvp(argv[0], argv);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The rendered PNGs, linked as a gap-free sequence (ffmpeg's image reader needs one) in a
 * folder of this call's own (mkdtemp), are encoded with H.264 (yuv420p, the format every
 * player takes), or MPEG-4 part 2 when this ffmpeg has no libx264. Everything made there is
 * removed again; nothing else is. */
int render_cli_make_movie(const char *render_dir, const int *frames, int count, double fps,
                          const char **encoder) {
  char seq[4300], path[4400], target[64], fps_s[32], log[4400], tmp[4400], final_path[4400];
  snprintf(seq, sizeof seq, "%s/.movie_XXXXXX", render_dir);
  snprintf(log, sizeof log, "%s/ffmpeg.log", render_dir);
  snprintf(final_path, sizeof final_path, "%s/movie.mp4", render_dir);
  if (!mkdtemp(seq)) return -1;
  snprintf(tmp, sizeof tmp, "%s/movie.partial.mp4", seq);
  int rc = 0, linked = 0;
  for (int i = 0; i < count && rc == 0; ++i) {
    snprintf(path, sizeof path, "%s/img_%06d.png", seq, i);
    snprintf(target, sizeof target, "../frame_%04d.png", frames[i]);
    if (symlink(target, path) != 0) rc = -1;
    else ++linked;
  }
  snprintf(fps_s, sizeof fps_s, "%g", fps);
  static const char *const encoders[2][6] = {{"libx264", "-preset", "medium", "-crf", "20", NULL},
                                             {"mpeg4", "-q:v", "3", NULL, NULL, NULL}};
  bool made = false;
  for (int e = 0; e < 2 && rc == 0 && !made; ++e) {
    char *argv[32];
    int a = 0;
    argv[a++] = "ffmpeg", argv[a++] = "-nostdin", argv[a++] = "-y", argv[a++] = "-loglevel";
    argv[a++] = "error", argv[a++] = "-framerate", argv[a++] = fps_s, argv[a++] = "-i";
    argv[a++] = "img_%06d.png", argv[a++] = "-vf", argv[a++] = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
    argv[a++] = "-c:v";
    for (int k = 0; encoders[e][k]; ++k) argv[a++] = (char *)encoders[e][k];
    argv[a++] = "-pix_fmt", argv[a++] = "yuv420p", argv[a++] = "-f", argv[a++] = "mp4";
    argv[a++] = "movie.partial.mp4", argv[a] = NULL;
    if (run_in(seq, argv, log) == 0 && rename(tmp, final_path) == 0) {
      *encoder = encoders[e][0];
      made = true;
    }
  }
  unlink(tmp);
  for (int i = 0; i < linked; ++i) {
    snprintf(path, sizeof path, "%s/img_%06d.png", seq, i);
    unlink(path);
  }
  rmdir(seq);
  return made ? 0 : -1;
}
