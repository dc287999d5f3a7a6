/* Per-phase step timers; see step_profile.h. */
#define _POSIX_C_SOURCE 200809L
#include "sim/step_profile.h"

#include <string.h>
#include <time.h>

const char *const piola__step_phase_names[STEP_PHASE_COUNT] = {
    "setup", "prepare", "solve 1", "collide", "rhs 2", "update", "solve 2", "friction", "check", "world",
    "assemble", "linear solve"};

static double seconds_of(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void piola__step_profile_reset(step_profile *p, int enabled) {
  memset(p, 0, sizeof *p);
  p->enabled = enabled;
}

void piola__step_profile_start(step_profile *p) {
  if (!p->enabled) return;
  p->last_wall = seconds_of(CLOCK_MONOTONIC);
  p->last_thread_cpu = seconds_of(CLOCK_THREAD_CPUTIME_ID);
  p->last_cpu = seconds_of(CLOCK_PROCESS_CPUTIME_ID);
}

void piola__step_profile_mark(step_profile *p, step_phase phase) {
  if (!p->enabled) return;
  double wall = seconds_of(CLOCK_MONOTONIC), tcpu = seconds_of(CLOCK_THREAD_CPUTIME_ID);
  double cpu = seconds_of(CLOCK_PROCESS_CPUTIME_ID);
  p->wall[phase] += wall - p->last_wall;
  p->thread_cpu[phase] += tcpu - p->last_thread_cpu;
  p->cpu[phase] += cpu - p->last_cpu;
  p->last_wall = wall, p->last_thread_cpu = tcpu, p->last_cpu = cpu;
}

void piola__step_profile_apply(step_profile *p, int begin) {
  if (!p->enabled) return;
  double wall = seconds_of(CLOCK_MONOTONIC), tcpu = seconds_of(CLOCK_THREAD_CPUTIME_ID);
  double cpu = seconds_of(CLOCK_PROCESS_CPUTIME_ID);
  if (begin) {
    p->apply_start_wall = wall, p->apply_start_thread_cpu = tcpu, p->apply_start_cpu = cpu;
    return;
  }
  p->applies++;
  p->apply_wall += wall - p->apply_start_wall;
  p->apply_thread_cpu += tcpu - p->apply_start_thread_cpu;
  p->apply_cpu += cpu - p->apply_start_cpu;
}
