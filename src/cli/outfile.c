/* src/cli/outfile.c — all-or-nothing output files: write a temporary file beside the
 * target and rename it over the target only when everything was written.
 * SPDX-License-Identifier: MIT
 *
 * Why: users' scripts test for the report file; a crash, a full disk or a bad scene must
 * never leave a truncated JSON or CSV behind (rename is atomic on POSIX file systems).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/cli.h"

/* Open o for path ("-" is stdout). Returns 0, or -1 after printing why. */
int cli_outfile_open(cli_outfile *o, const char *path)
{
  memset(o, 0, sizeof *o);
  o->path = path;
  if (strcmp(path, "-") == 0) {
    o->f = stdout;
    return 0;
  }
  size_t n = strlen(path);
  o->tmp = malloc(n + 16);
  if (!o->tmp) {
    fprintf(stderr, "calcvar: %s: out of memory\n", path);
    return -1;
  }
  memcpy(o->tmp, path, n);
  memcpy(o->tmp + n, ".tmp.XXXXXX", 12);
  int fd = mkstemp(o->tmp);
  if (fd >= 0) {
    /* mkstemp makes the file 0600; give the report the permissions a plain fopen would. */
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, 0666 & ~mask);
  }
  if (fd < 0 || !(o->f = fdopen(fd, "w"))) {
    fprintf(stderr, "calcvar: cannot write %s: %s\n", path, strerror(errno));
    if (fd >= 0) {
      close(fd);
      unlink(o->tmp);
    }
    free(o->tmp);
    o->tmp = NULL;
    return -1;
  }
  return 0;
}

int cli_outfile_publish(cli_outfile *o, int failed, int give_reason)
{
  if (failed || rename(o->tmp, o->path) != 0) {
    if (give_reason)
      fprintf(stderr, "calcvar: cannot write %s: %s\n", o->path,
              failed ? "write error" : strerror(errno));
    else
      fprintf(stderr, "calcvar: cannot write %s\n", o->path);
    unlink(o->tmp);
    free(o->tmp);
    o->tmp = NULL;
    return -1;
  }
  free(o->tmp);
  o->tmp = NULL;
  return 0;
}

/* Close and move into place. Returns 0, or -1 after printing why (nothing is left). */
int cli_outfile_commit(cli_outfile *o)
{
  if (!o->f)
    return 0;
  if (o->f == stdout) {
    o->f = NULL;
    return fflush(stdout) == 0 ? 0 : -1;
  }
  int bad = ferror(o->f);
  bad |= fclose(o->f) != 0;
  o->f = NULL;
  return cli_outfile_publish(o, bad, 1);
}

void cli_outfile_abandon(cli_outfile *o)
{
  if (o->f && o->f != stdout)
    fclose(o->f);
  if (o->tmp) {
    unlink(o->tmp);
    free(o->tmp);
  }
  memset(o, 0, sizeof *o);
}
