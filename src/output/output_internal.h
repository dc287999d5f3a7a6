/* Shared between the output folder policy and the frame writer. */
#ifndef PIOLA_OUTPUT_OUTPUT_INTERNAL_H
#define PIOLA_OUTPUT_OUTPUT_INTERNAL_H

#include <stdbool.h>

#include "piola/output.h"

/* Checks the folder policy, creates DIR, DIR/frames and DIR/surface, and when forced
 * removes an earlier run's results. */
piola_status piola__output_prepare_folder(const char *dir, bool force);

#endif
