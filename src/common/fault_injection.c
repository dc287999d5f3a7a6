#include "common/fault_injection.h"

#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

/* -1: not read yet; 0: off; otherwise the call number (from 1) that faults. */
typedef struct countdown {
  const char *variable;
  long target;
  long calls;
} countdown;

static int due(countdown *c) {
  if (c->target < 0) {
    const char *s = getenv(c->variable);
    char *end;
    long k = s ? strtol(s, &end, 10) : 0;
    c->target = s && *s && !*end && k > 0 ? k : 0;
  }
  return c->target > 0 && ++c->calls == c->target;
}

void piola__fault_before_rename(void) {
  static countdown kill_at = {"PIOLA_FAULT_KILL_AT_RENAME", -1, 0};
  if (due(&kill_at)) raise(SIGKILL);
}

void piola__fault_during_write(FILE *stream) {
  static countdown kill_at = {"PIOLA_FAULT_KILL_IN_WRITE", -1, 0};
  if (!due(&kill_at)) return;
  const long written = fflush(stream) == 0 ? ftell(stream) : 0;
  const int cut = written > 0 ? ftruncate(fileno(stream), written / 2) : 0;
  (void)cut; /* killed either way */
  raise(SIGKILL);
}

int piola__fault_write_fails(void) {
  static countdown fail_at = {"PIOLA_FAULT_FAIL_WRITE_AT", -1, 0};
  return due(&fail_at);
}
