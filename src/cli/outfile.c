/* src/cli/outfile.c — output files that are either written completely or not at all, and
 * never written where they must not be.
 * SPDX-License-Identifier: MIT
 *
 * What a path names decides how it is written (docs/cli.md, "Output files"):
 *  - "-": standard output;
 *  - a regular file, or a name that does not exist yet: a temporary file beside it, renamed
 *    over it only when everything was written and closed (rename is atomic on POSIX file
 *    systems), so a crash, a full disk or a bad scene never leaves a truncated report;
 *  - a symbolic link: followed, and its final target written as above (the link stays);
 *  - a device, FIFO or socket (/dev/null, /dev/stdout, a pipe): written through as a
 *    stream; there is no file to replace;
 *  - a directory, a name ending in '/', or the scene being read (same device and inode,
 *    whatever the path; for the scene "-", the file standard input comes from): refused
 *    before any work (exit 2).
 * Every write, flush and close is checked; a failure is reported by the caller with exit
 * status CLI_EXIT_IO.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/cli.h"

enum { MAX_LINKS = 40 }; /* as the kernel's own limit on nested symbolic links */

/* The final target of path after following symbolic links (the target need not exist).
 * Returns a malloc'd path, or NULL with errno set. */
static char *follow_links(const char *path) {
  char *cur = strdup(path);
  for (int hop = 0; cur && hop <= MAX_LINKS; hop++) {
    struct stat st;
    if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode))
      return cur; /* not a link (or not there): this is the target */
    char link[PATH_MAX];
    ssize_t k = readlink(cur, link, sizeof link - 1);
    if (k < 0) {
      free(cur);
      return NULL;
    }
    link[k] = '\0';
    char *next;
    const char *slash = strrchr(cur, '/');
    if (link[0] == '/' || !slash) {
      next = strdup(link);
    } else { /* relative to the link's own directory */
      size_t dir = (size_t)(slash - cur) + 1;
      next = malloc(dir + (size_t)k + 1);
      if (next) {
        memcpy(next, cur, dir);
        memcpy(next + dir, link, (size_t)k + 1);
      }
    }
    free(cur);
    cur = next;
  }
  if (cur) {
    free(cur);
    errno = ELOOP;
  }
  return NULL;
}

static int fail(cli_outfile *o, const char *why) {
  fprintf(stderr, "calcvar: cannot write %s: %s\n", o->path, why);
  cli_outfile_abandon(o);
  return -1;
}

/* A device, FIFO or socket: stream into it (opening a FIFO waits for its reader). */
static int open_stream(cli_outfile *o, const char *path) {
  int fd = open(path, O_WRONLY | O_NOCTTY);
  if (fd < 0 || !(o->f = fdopen(fd, "w"))) {
    int e = errno;
    if (fd >= 0) close(fd);
    return fail(o, strerror(e));
  }
  o->stream = 1;
  return 0;
}

int cli_outfile_open(cli_outfile *o, const char *path, const char *input) {
  memset(o, 0, sizeof *o);
  o->path = path;
  if (strcmp(path, "-") == 0) {
    o->f = stdout;
    return 0;
  }
  size_t n = strlen(path);
  if (n == 0) return fail(o, "empty file name");
  if (path[n - 1] == '/') return fail(o, "the name ends in '/' (a directory); give a file name");
  struct stat st, si;
  /* What the kernel reaches through the path (links, and /proc's "magic" links such as
   * /dev/stdout on a pipe, which readlink cannot name): a device, FIFO or socket is a
   * stream, whatever the path looks like. */
  if (stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
    return open_stream(o, path);
  if (!(o->dest = follow_links(path))) return fail(o, strerror(errno));
  int exists = stat(o->dest, &st) == 0;
  if (!exists && errno != ENOENT) return fail(o, strerror(errno));
  if (exists && S_ISDIR(st.st_mode)) return fail(o, "it is a directory; give a file name");
  int have_in =
      input && (strcmp(input, "-") == 0 ? fstat(STDIN_FILENO, &si) == 0 : stat(input, &si) == 0);
  if (exists && have_in && si.st_dev == st.st_dev && si.st_ino == st.st_ino && S_ISREG(st.st_mode))
    return fail(o, "it is the scene being read (the report would destroy it)");
  if (exists && !S_ISREG(st.st_mode)) return open_stream(o, o->dest);
  size_t dn = strlen(o->dest);
  if (!(o->tmp = malloc(dn + 16))) return fail(o, "out of memory");
  memcpy(o->tmp, o->dest, dn);
  memcpy(o->tmp + dn, ".tmp.XXXXXX", 12);
  int fd = mkstemp(o->tmp);
  if (fd < 0) {
    int e = errno;
    free(o->tmp);
    o->tmp = NULL; /* nothing was created */
    return fail(o, strerror(e));
  }
  /* mkstemp makes the file 0600: a replaced file keeps its permissions, a new one gets
   * those a plain fopen would give. */
  mode_t mask = umask(0);
  umask(mask);
  (void)fchmod(fd, exists ? st.st_mode & 07777 : 0666 & ~mask);
  if (!(o->f = fdopen(fd, "w"))) {
    int e = errno;
    close(fd);
    return fail(o, strerror(e));
  }
  return 0;
}

/* Flush and close the stream; 0, or -1 with errno. */
static int close_checked(FILE *f) {
  int bad = fflush(f) != 0 || ferror(f);
  int e = errno;
  if (fclose(f) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  errno = e ? e : EIO;
  return bad ? -1 : 0;
}

int cli_outfile_commit(cli_outfile *o) {
  if (!o->f) return 0;
  if (o->f == stdout) {
    o->f = NULL;
    if (fflush(stdout) != 0 || ferror(stdout)) {
      fprintf(stderr, "calcvar: cannot write standard output: %s\n", strerror(errno));
      clearerr(stdout); /* said once: the final check of stdout need not repeat it */
      return -1;
    }
    return 0;
  }
  FILE *f = o->f;
  o->f = NULL;
  if (close_checked(f) != 0) return fail(o, strerror(errno));
  if (o->tmp && rename(o->tmp, o->dest) != 0) return fail(o, strerror(errno));
  free(o->tmp);
  o->tmp = NULL;
  cli_outfile_abandon(o); /* nothing left to remove: frees the names */
  return 0;
}

int cli_outfile_finish(cli_outfile *o, int wrote) {
  if (wrote >= 0) return cli_outfile_commit(o);
  int e = errno;
  if (o->f && o->f != stdout && ferror(o->f)) return fail(o, strerror(e ? e : EIO));
  if (o->f == stdout && ferror(stdout)) {
    fprintf(stderr, "calcvar: cannot write standard output: %s\n", strerror(e ? e : EIO));
    clearerr(stdout);
  }
  cli_outfile_abandon(o); /* a report half formed is not put in place */
  return -1;
}

int cli_outfile_render_name(cli_outfile *o, const char **name) {
  *name = NULL;
  if (!o->f || o->f == stdout) return -1;
  if (!o->stream) {
    /* the library writes the temporary file by name: close our handle on it */
    FILE *f = o->f;
    o->f = NULL;
    if (fclose(f) != 0) return fail(o, strerror(errno));
    *name = o->tmp;
    return 0;
  }
  const char *dir = getenv("TMPDIR");
  if (!dir || !dir[0]) dir = "/tmp";
  size_t n = strlen(dir);
  if (!(o->scratch = malloc(n + 24))) return fail(o, "out of memory");
  snprintf(o->scratch, n + 24, "%s/calcvar-out.XXXXXX", dir);
  int fd = mkstemp(o->scratch);
  if (fd < 0) {
    int e = errno;
    free(o->scratch);
    o->scratch = NULL;
    return fail(o, strerror(e));
  }
  close(fd);
  *name = o->scratch;
  return 0;
}

int cli_outfile_commit_rendered(cli_outfile *o) {
  if (!o->stream) {
    if (!o->tmp || access(o->tmp, F_OK) != 0) return fail(o, "the plotting library wrote nothing");
    if (rename(o->tmp, o->dest) != 0) return fail(o, strerror(errno));
    free(o->tmp);
    o->tmp = NULL;
    cli_outfile_abandon(o);
    return 0;
  }
  FILE *in = o->scratch ? fopen(o->scratch, "rb") : NULL;
  if (!in) return fail(o, "the plotting library wrote nothing");
  char buf[65536];
  size_t k;
  int bad = 0;
  while (!bad && (k = fread(buf, 1, sizeof buf, in)) > 0) bad = fwrite(buf, 1, k, o->f) != k;
  bad |= ferror(in);
  int e = errno;
  fclose(in);
  if (bad) return fail(o, strerror(e ? e : EIO));
  return cli_outfile_commit(o);
}

void cli_outfile_abandon(cli_outfile *o) {
  if (o->f && o->f != stdout) fclose(o->f);
  if (o->tmp) unlink(o->tmp);
  if (o->scratch) unlink(o->scratch);
  free(o->tmp);
  free(o->scratch);
  free(o->dest);
  memset(o, 0, sizeof *o);
}
