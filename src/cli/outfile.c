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
 *  - one of the process's own descriptors (/dev/stdout, /dev/stderr, /dev/fd/N,
 *    /proc/self/fd/N, or a link to one), whatever file it is open on: written through that
 *    descriptor, where it stands (`>> log` keeps appending; the file is never replaced);
 *  - a directory, a name ending in '/', or a file being read (the scene, a batch table:
 *    same device and inode, whatever the path; for "-", the file standard input comes
 *    from): refused before any work (exit 2); so are two outputs that name one file.
 * Temporary files are registered (cli_signals.c) so that an interrupted run removes them.
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

/* Where the symbolic link cur points (relative targets taken from the link's directory):
 * a malloc'd path; NULL with errno 0 when cur is not a link (or not there), else errno. */
static char *link_target(const char *cur) {
  struct stat st;
  errno = 0;
  if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) {
    errno = 0;
    return NULL;
  }
  char link[PATH_MAX];
  ssize_t k = readlink(cur, link, sizeof link - 1);
  if (k < 0) return NULL;
  link[k] = '\0';
  const char *slash = strrchr(cur, '/');
  if (link[0] == '/' || !slash) return strdup(link);
  size_t dir = (size_t)(slash - cur) + 1;
  char *next = malloc(dir + (size_t)k + 1);
  if (next) {
    memcpy(next, cur, dir);
    memcpy(next + dir, link, (size_t)k + 1);
  }
  return next;
}

/* The final target of path after following symbolic links (the target need not exist).
 * Returns a malloc'd path, or NULL with errno set. */
static char *follow_links(const char *path) {
  char *cur = strdup(path);
  for (int hop = 0; cur && hop <= MAX_LINKS; hop++) {
    char *next = link_target(cur);
    if (!next && errno == 0) return cur; /* not a link: this is the target */
    free(cur);
    cur = next;
  }
  if (cur) {
    free(cur);
    errno = ELOOP;
  }
  return NULL;
}

/* The descriptor a path names when it is one of the process's own: /dev/stdin, /dev/stdout,
 * /dev/stderr, /dev/fd/N or /proc/self/fd/N; else -1. */
static int own_fd(const char *path) {
  static const char *const std[] = {"/dev/stdin", "/dev/stdout", "/dev/stderr"};
  for (int k = 0; k < 3; k++)
    if (strcmp(path, std[k]) == 0) return k;
  const char *num = strncmp(path, "/dev/fd/", 8) == 0          ? path + 8
                    : strncmp(path, "/proc/self/fd/", 14) == 0 ? path + 14
                                                               : NULL;
  if (!num || !*num) return -1;
  char *end;
  long fd = strtol(num, &end, 10);
  return *end || fd < 0 || fd > INT_MAX ? -1 : (int)fd;
}

/* own_fd of path or of any link on the way to its target (a link to /dev/stdout). */
static int own_fd_through_links(const char *path) {
  char *cur = strdup(path);
  int fd = -1;
  for (int hop = 0; cur && fd < 0 && hop <= MAX_LINKS; hop++) {
    fd = own_fd(cur);
    char *next = fd < 0 ? link_target(cur) : NULL;
    free(cur);
    cur = next;
  }
  free(cur);
  return fd;
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

/* Write through descriptor fd (a duplicate of it: closing ours leaves it open). */
static int open_own_fd(cli_outfile *o, int fd) {
  if (fcntl(fd, F_GETFL) < 0) return fail(o, "that descriptor is not open");
  int d = fcntl(fd, F_DUPFD_CLOEXEC, 3);
  if (d < 0 || !(o->f = fdopen(d, "w"))) {
    int e = errno;
    if (d >= 0) close(d);
    return fail(o, strerror(e));
  }
  o->stream = 1;
  return 0;
}

/* Is st the file that input names (for "-", the file standard input comes from)? */
static int is_input(const struct stat *st, const char *input) {
  struct stat si;
  if (!input || !S_ISREG(st->st_mode)) return 0;
  int have = strcmp(input, "-") == 0 ? fstat(STDIN_FILENO, &si) == 0 : stat(input, &si) == 0;
  return have && si.st_dev == st->st_dev && si.st_ino == st->st_ino;
}

/* Where o's file is, to tell two outputs that name one file: the file's device and inode,
 * or for a file not there yet its directory's and its own name. */
static void identify(cli_outfile *o, const struct stat *st, int exists) {
  struct stat sd;
  o->exists = exists;
  if (exists) {
    o->dev = st->st_dev, o->ino = st->st_ino;
    return;
  }
  const char *slash = strrchr(o->dest, '/');
  o->base = slash ? slash + 1 : o->dest;
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - o->dest) + 1 : 1, slash ? o->dest : ".");
  if (stat(dir, &sd) == 0) o->dev = sd.st_dev, o->ino = sd.st_ino;
}

int cli_outfile_clash(const cli_outfile *a, const cli_outfile *b, const char *what_a,
                      const char *what_b) {
  if (!a->f || !b->f || a->stream || b->stream || a->f == stdout || b->f == stdout) return 0;
  int same = a->exists == b->exists && a->dev == b->dev && a->ino == b->ino &&
             (a->exists || strcmp(a->base, b->base) == 0);
  if (!same) return 0;
  fprintf(stderr,
          "calcvar: %s %s and %s %s name the same file: one report would replace the "
          "other\n",
          what_a, a->path, what_b, b->path);
  return -1;
}

int cli_outfile_open(cli_outfile *o, const char *path, const char *input) {
  const char *inputs[1] = {input};
  return cli_outfile_open_inputs(o, path, inputs, 1);
}

int cli_outfile_open_inputs(cli_outfile *o, const char *path, const char *const *inputs,
                            int ninputs) {
  memset(o, 0, sizeof *o);
  o->path = path;
  if (strcmp(path, "-") == 0) {
    o->f = stdout;
    return 0;
  }
  size_t n = strlen(path);
  if (n == 0) return fail(o, "empty file name");
  if (path[n - 1] == '/') return fail(o, "the name ends in '/' (a directory); give a file name");
  struct stat st;
  int fd_named = own_fd_through_links(path);
  if (fd_named >= 0) return open_own_fd(o, fd_named);
  /* What the kernel reaches through the path (links, and /proc's "magic" links such as
   * /dev/stdout on a pipe, which readlink cannot name): a device, FIFO or socket is a
   * stream, whatever the path looks like. */
  if (stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
    return open_stream(o, path);
  if (!(o->dest = follow_links(path))) return fail(o, strerror(errno));
  int exists = stat(o->dest, &st) == 0;
  if (!exists && errno != ENOENT) return fail(o, strerror(errno));
  if (exists && S_ISDIR(st.st_mode)) return fail(o, "it is a directory; give a file name");
  for (int k = 0; exists && k < ninputs; k++)
    if (is_input(&st, inputs[k]))
      return fail(o, k == 0 ? "it is the scene being read (the report would destroy it)"
                            : "it is a file being read (the output would destroy it)");
  if (exists && !S_ISREG(st.st_mode)) return open_stream(o, o->dest);
  identify(o, &st, exists);
  size_t dn = strlen(o->dest);
  if (!(o->tmp = malloc(dn + 24))) return fail(o, "out of memory");
  /* NAME.tmp.XXXXXX beside the target; for a name within 11 bytes of the file system's
   * limit on a name (255), a shorter one in the same directory */
  const char *slash = strrchr(o->dest, '/');
  size_t base = strlen(slash ? slash + 1 : o->dest), dir = dn - base;
  memcpy(o->tmp, o->dest, dn);
  if (base + 11 > 255)
    memcpy(o->tmp + dir, ".calcvar.tmp.XXXXXX", 20);
  else
    memcpy(o->tmp + dn, ".tmp.XXXXXX", 12);
  int fd = cli_mkstemp(o->tmp);
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

static int stdout_reported; /* a failure of standard output was said once */
int cli_stdout_reported(void) { return stdout_reported; }
void cli_stdout_set_reported(void) { stdout_reported = 1; }

/* Say that standard output could not be written, once a run. */
static void stdout_failed(int e) {
  if (!stdout_reported)
    fprintf(stderr, "calcvar: cannot write standard output: %s\n", strerror(e ? e : EIO));
  stdout_reported = 1;
}

int cli_outfile_commit(cli_outfile *o) {
  if (!o->f) return 0;
  if (o->f == stdout) {
    o->f = NULL;
    if (fflush(stdout) != 0 || ferror(stdout)) {
      stdout_failed(errno);
      return -1;
    }
    return 0;
  }
  FILE *f = o->f;
  o->f = NULL;
  if (close_checked(f) != 0) return fail(o, strerror(errno));
  if (o->tmp && rename(o->tmp, o->dest) != 0) return fail(o, strerror(errno));
  cli_temp_forget(o->tmp);
  free(o->tmp);
  o->tmp = NULL;
  cli_outfile_abandon(o); /* nothing left to remove: frees the names */
  return 0;
}

int cli_outfile_finish(cli_outfile *o, int wrote) {
  if (wrote >= 0) return cli_outfile_commit(o);
  int e = errno;
  if (o->f && o->f != stdout && ferror(o->f)) return fail(o, strerror(e ? e : EIO));
  if (o->f == stdout && ferror(stdout)) stdout_failed(e);
  cli_outfile_abandon(o); /* a report half formed is not put in place */
  return -1;
}

int cli_outfile_render_name(cli_outfile *o, const char **name) {
  *name = NULL;
  if (!o->f || o->f == stdout) return -1;
  /* The library writes by name and checks nothing: it draws into a scratch file, which is
   * checked to be a whole picture and then copied into o->f with every write checked
   * (a full disk at the target is then a write error, not a truncated picture). */
  const char *dir = getenv("TMPDIR");
  if (!dir || !dir[0]) dir = "/tmp";
  size_t n = strlen(dir);
  const char *ext = strrchr(o->path, '.');
  if (!ext || strlen(ext) > 4) ext = "";
  if (!(o->scratch = malloc(n + 32))) return fail(o, "out of memory");
  snprintf(o->scratch, n + 32, "%s/calcvar-out.XXXXXX", dir);
  int fd = cli_mkstemp(o->scratch);
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

/* Is the file at f (read from the start) a whole picture: a PNG that ends with its IEND
 * chunk, or an SVG that ends with </svg>? A library that ran out of room or memory
 * leaves a file cut short. */
static int picture_complete(FILE *f, int svg) {
  char tail[16] = "";
  if (fseek(f, 0, SEEK_END) != 0) return 0;
  long size = ftell(f);
  if (size < (long)sizeof tail || fseek(f, size - (long)sizeof tail, SEEK_SET) != 0 ||
      fread(tail, 1, sizeof tail, f) != sizeof tail || fseek(f, 0, SEEK_SET) != 0)
    return 0;
  if (!svg) return memcmp(tail + 8, "IEND\xae\x42\x60\x82", 8) == 0;
  int end = (int)sizeof tail;
  while (end > 0 && (tail[end - 1] == '\n' || tail[end - 1] == ' ' || tail[end - 1] == '\r')) end--;
  return end >= 6 && memcmp(tail + end - 6, "</svg>", 6) == 0;
}

int cli_outfile_commit_rendered(cli_outfile *o, int svg) {
  FILE *in = o->scratch ? fopen(o->scratch, "rb") : NULL;
  if (!in) return fail(o, "the plotting library wrote nothing");
  if (!picture_complete(in, svg)) {
    fclose(in);
    return fail(o, "the plotting library left an incomplete picture (a full disk in "
                   "$TMPDIR, or out of memory?)");
  }
  char buf[65536];
  size_t k;
  int bad = 0;
  errno = 0;
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
  cli_temp_forget(o->tmp);
  cli_temp_forget(o->scratch);
  free(o->tmp);
  free(o->scratch);
  free(o->dest);
  memset(o, 0, sizeof *o);
}
