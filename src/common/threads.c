/* The thread count piola's parallel loops use (piola/threads.h). Results never depend
 * on it; only speed does. */
#include "piola/threads.h"

#include <omp.h>

static int requested_threads = 0;

void piola_set_thread_count(int threads) { requested_threads = threads > 0 ? threads : 0; }

int piola_thread_count(void) {
  return requested_threads > 0 ? requested_threads : omp_get_max_threads();
}
