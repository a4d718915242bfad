/* src/cli/cli_batch.c — `calcvar batch SCENE TABLE.csv [--out FILE] [--threads N]
 * [--warm] [solve options]`: one solve per table row on one compiled scene (docs/cli.md).
 * SPDX-License-Identifier: MIT
 *
 * Two passes over the table. The first checks all of it (header, every row's count and
 * numbers, and that each row's values make a valid scene) before anything is written, so
 * bad input is exit 2 with the table's FILE:LINE and no output. The second streams it:
 * windows of rows are solved (threads inside a window, MPI ranks sharing it in blocks)
 * and written in input order; memory depends on the window, not on the number of rows.
 */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT, getline */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_batch.h"
#include "scene/scene_batch.h"

/* window = threads x this (x ranks under MPI): the threads meet once a window (and the
 * ranks, to gather it), so a window is many rows; memory depends on it only. */
enum { ROWS_PER_THREAD = 1024 };

static void usage(FILE *f) {
  fputs("usage: calcvar batch SCENE TABLE.csv [options]\n"
        "  TABLE.csv            header of parameter names, one row of values per problem\n"
        "  --out FILE           the result table (default stdout)\n"
        "  --threads N          rows solved at once (default: the cores available)\n"
        "  --warm               start each row from the previous row's solution\n"
        "  --elements N, --degree P, --method M, --tolerance T, --max-iterations K,\n"
        "  --set name=value, --adapt TOL, --tol T, --time-limit S, --max-nodes N\n"
        "                       as for calcvar solve, for every row\n"
        "Output: the input columns, status, action, iterations, time_s, morse_index,\n"
        "error_max_nodal (with [exact]), error_estimate (without [exact], always with --tol),\n"
        "one column per [report] entry and integral multiplier (mu_NAME), message.\n"
        "exit status: 0 every row converged, 1 some did not, 2 bad input, 3 the output\n"
        "could not be written\n",
        f);
}

int cli_cores_available(void) {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  long c = sysconf(_SC_NPROCESSORS_ONLN);
  return c > 0 ? (int)c : 1;
}

/* ---- the table ---------------------------------------------------------------------- */

/* The table is opened once and read twice (check, then solve) through one stream: a
 * regular file is rewound; standard input ("-", or a path to the same file such as
 * /dev/stdin) that is a pipe is first copied into an unlinked scratch file. Like a scene,
 * a table must be a regular file or standard input (a FIFO would block, /dev/zero never
 * ends) of at most SC_MAX_TABLE_BYTES, its lines at most MAX_LINE bytes of text. */
enum { MAX_LINE = 1 << 20 };

typedef struct {
  const char *path;
  FILE *f;
  char *line;
  size_t cap;
  int lineno;
  int ncols;
  char **names;  /* header */
  char **field;  /* fields of the current row (point into line) */
  char why[160]; /* next_line's reason for -2 */
} table;

static const char *kind_of(mode_t m) {
  return S_ISDIR(m)    ? "a directory"
         : S_ISCHR(m)  ? "a character device"
         : S_ISBLK(m)  ? "a block device"
         : S_ISFIFO(m) ? "a FIFO (named pipe)"
         : S_ISSOCK(m) ? "a socket"
                       : "not a regular file";
}

/* Does path name the file standard input is open on ("-", /dev/stdin, /dev/fd/0)? */
static int is_stdin(const char *path) {
  struct stat a, b;
  if (strcmp(path, "-") == 0) return 1;
  return stat(path, &a) == 0 && fstat(STDIN_FILENO, &b) == 0 && a.st_dev == b.st_dev &&
         a.st_ino == b.st_ino;
}

/* Bytes a table's text may not hold: NUL and the control characters but tab and CR. */
static int bad_byte(const char *p, size_t n) {
  for (size_t i = 0; i < n; i++) {
    unsigned char c = (unsigned char)p[i];
    if ((c < 0x20 && c != '\t' && c != '\r' && c != '\n') || c == 0x7f) return 1 + (int)i;
  }
  return 0;
}

/* Standard input that is not a regular file, copied into an unlinked scratch file (at
 * most SC_MAX_TABLE_BYTES). The stream, or NULL after a message. */
static FILE *spool_stdin(const char *path) {
  const char *dir = getenv("TMPDIR");
  char name[4096];
  snprintf(name, sizeof name, "%s/calcvar-table.XXXXXX", dir && dir[0] ? dir : "/tmp");
  int fd = mkstemp(name);
  if (fd < 0) {
    fprintf(stderr, "%s: cannot keep standard input for the second pass: %s: %s\n", path, name,
            strerror(errno));
    return NULL;
  }
  unlink(name); /* gone with the descriptor, whatever happens */
  FILE *f = fdopen(fd, "w+");
  if (!f) close(fd);
  char buf[65536];
  long long total = 0;
  ssize_t k = 0;
  while (f && (k = read(STDIN_FILENO, buf, sizeof buf)) != 0) {
    if (k < 0 && errno == EINTR) continue;
    /* a stream that is not text ends here, not after 1 GiB of it is kept */
    const char *why = k < 0                      ? strerror(errno)
                      : bad_byte(buf, (size_t)k) ? "it is not a text table"
                      : (total += k) > SC_MAX_TABLE_BYTES
                          ? "larger than 1 GiB, the most calcvar reads"
                      : fwrite(buf, 1, (size_t)k, f) != (size_t)k ? strerror(errno)
                                                                  : NULL;
    if (why) {
      fprintf(stderr, "%s: cannot read the table: %s\n", path, why);
      fclose(f);
      return NULL;
    }
  }
  if (!f || fflush(f) != 0 || fseek(f, 0, SEEK_SET) != 0) {
    fprintf(stderr, "%s: cannot keep standard input for the second pass: %s\n", path,
            strerror(errno));
    if (f) fclose(f);
    return NULL;
  }
  return f;
}

/* Open the table for reading (see above): 0, or EXIT_BADINPUT after a message. */
static int table_source(table *t, const char *path, int ranks) {
  struct stat st;
  if (is_stdin(path)) {
    if (ranks > 1) {
      fprintf(stderr,
              "%s: under MPI the table must be a file (only rank 0 has standard "
              "input)\n",
              path);
      return EXIT_BADINPUT;
    }
    if (fstat(STDIN_FILENO, &st) != 0 || S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ||
        S_ISDIR(st.st_mode)) { /* /dev/zero never ends; a terminal is no table */
      fprintf(stderr, "%s: cannot read a table from standard input: it is %s\n", path,
              kind_of(st.st_mode));
      return EXIT_BADINPUT;
    }
    int fd = S_ISREG(st.st_mode) ? dup(STDIN_FILENO) : -1;
    t->f = fd >= 0 ? fdopen(fd, "r") : spool_stdin(path);
    if (fd >= 0 && !t->f) close(fd);
    if (!t->f) return EXIT_BADINPUT;
  } else {
    if (stat(path, &st) != 0) {
      fprintf(stderr, "%s: cannot open: %s\n", path, strerror(errno));
      return EXIT_BADINPUT;
    }
    int fd = S_ISREG(st.st_mode) ? open(path, O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC) : -1;
    if (fd >= 0 && (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))) { /* replaced since stat */
      close(fd);
      fd = -1;
    }
    if (fd < 0) {
      fprintf(stderr,
              "%s: cannot read a table from %s; give a CSV file, or '-' for standard "
              "input\n",
              path, S_ISREG(st.st_mode) ? strerror(errno) : kind_of(st.st_mode));
      return EXIT_BADINPUT;
    }
    if (!(t->f = fdopen(fd, "r"))) {
      close(fd);
      fprintf(stderr, "%s: cannot open: %s\n", path, strerror(errno));
      return EXIT_BADINPUT;
    }
  }
  if (fstat(fileno(t->f), &st) == 0 && st.st_size > SC_MAX_TABLE_BYTES) {
    fprintf(stderr, "%s: the table is larger than 1 GiB, the most calcvar reads\n", path);
    return EXIT_BADINPUT;
  }
  return 0;
}

/* Next non-blank line split at commas into t->field; returns the field count, 0 at the
 * end, -1 on a read error, -2 for a line that is not text (t->why says why). Fields are
 * trimmed of blanks; the line's end is removed. */
static int next_line(table *t, int maxf) {
  for (;;) {
    ssize_t len = getline(&t->line, &t->cap, t->f);
    if (len < 0) return ferror(t->f) ? -1 : 0;
    t->lineno++;
    int bad = bad_byte(t->line, (size_t)len);
    if (len > MAX_LINE || bad) {
      if (len > MAX_LINE)
        snprintf(t->why, sizeof t->why, "the line is longer than %d bytes", MAX_LINE);
      else
        snprintf(t->why, sizeof t->why, "byte %d of the line is 0x%02x, not text", bad,
                 (unsigned char)t->line[bad - 1]);
      return -2;
    }
    while (len > 0 && (t->line[len - 1] == '\n' || t->line[len - 1] == '\r')) t->line[--len] = '\0';
    char *p = t->line;
    while (*p == ' ' || *p == '\t') p++;
    if (!*p) continue; /* blank lines are skipped */
    int k = 0;
    for (;;) {
      char *c = strchr(p, ',');
      if (c) *c = '\0';
      while (*p == ' ' || *p == '\t') p++;
      char *e = p + strlen(p);
      while (e > p && (e[-1] == ' ' || e[-1] == '\t')) *--e = '\0';
      if (k < maxf) t->field[k] = p;
      k++;
      if (!c) break;
      p = c + 1;
    }
    return k;
  }
}

static void table_close(table *t) {
  if (t->f) fclose(t->f);
  for (int c = 0; t->names && c < t->ncols; c++) free(t->names[c]);
  free(t->names);
  free(t->field);
  free(t->line);
  memset(t, 0, sizeof *t);
}

/* Open the table and read its header; its names become the batch's columns. 0, or
 * EXIT_BADINPUT after a message. */
static int table_open(table *t, const char *path, cv_batch *b, int ranks) {
  char err[512];
  memset(t, 0, sizeof *t);
  t->path = path;
  if (table_source(t, path, ranks) != 0) return EXIT_BADINPUT;
  int np = cv_batch_num_parameters(b), maxf = np + 1;
  t->field = malloc((size_t)maxf * sizeof *t->field);
  if (!t->field) {
    fprintf(stderr, "calcvar batch: out of memory\n");
    return EXIT_BADINPUT;
  }
  int k = next_line(t, maxf);
  if (k <= 0) {
    fprintf(stderr, "%s:%d: %s\n", path, t->lineno > 0 ? t->lineno : 1,
            k == -2 ? t->why
            : k < 0 ? "read error"
                    : "the table is empty (it needs a header of parameter names)");
    return EXIT_BADINPUT;
  }
  if (k > np) {
    fprintf(stderr, "%s:%d: the header has %d columns but %s has %d parameter%s\n", path, t->lineno,
            k, scene_batch_scene(b)->file, np, np == 1 ? "" : "s");
    return EXIT_BADINPUT;
  }
  t->names = calloc((size_t)k, sizeof *t->names);
  if (!t->names) return EXIT_BADINPUT;
  t->ncols = k;
  for (int c = 0; c < k; c++)
    if (!(t->names[c] = strdup(t->field[c]))) return EXIT_BADINPUT;
  if (cv_batch_set_columns(b, k, (const char *const *)t->names, err, sizeof err) != CVAR_OK) {
    fprintf(stderr, "%s:%d: %s\n", path, t->lineno, err[0] ? err : "out of memory");
    return EXIT_BADINPUT;
  }
  return 0;
}

/* Back to the first row for the second pass (the header is read again and skipped). */
static int table_rewind(table *t) {
  t->lineno = 0;
  if (fseek(t->f, 0, SEEK_SET) != 0 || next_line(t, t->ncols) != t->ncols) {
    fprintf(stderr, "%s: the table changed while it was read\n", t->path);
    return -1;
  }
  return 0;
}

/* ---- windows of rows ---------------------------------------------------------------- */

/* Rows read from the table and not yet solved: their fields' text (copied: the line
 * buffer is reused) and line numbers. */
typedef struct {
  int n, cap, ncols;
  char *store;
  size_t slen, scap;
  size_t *off; /* off[r * ncols + c]: field c of row r in store */
  int *line;
} window;

static void window_free(window *w) {
  free(w->store);
  free(w->off);
  free(w->line);
  memset(w, 0, sizeof *w);
}

/* The current line's fields as row w->n of the window. 0, or -1 out of memory. */
static int window_add(window *w, const table *t) {
  if (w->n == w->cap) {
    int ncap = w->cap ? 2 * w->cap : 256;
    size_t *no = realloc(w->off, (size_t)ncap * (size_t)(w->ncols + 1) * sizeof *no);
    if (!no) return -1;
    w->off = no;
    int *nl = realloc(w->line, (size_t)ncap * sizeof *nl);
    if (!nl) return -1;
    w->line = nl;
    w->cap = ncap;
  }
  for (int c = 0; c < w->ncols; c++) {
    size_t l = strlen(t->field[c]) + 1;
    if (w->slen + l > w->scap) {
      size_t ncap = w->scap ? 2 * w->scap : 4096;
      while (ncap < w->slen + l) ncap *= 2;
      char *ns = realloc(w->store, ncap);
      if (!ns) return -1;
      w->store = ns, w->scap = ncap;
    }
    memcpy(w->store + w->slen, t->field[c], l);
    w->off[(size_t)w->n * w->ncols + c] = w->slen;
    w->slen += l;
  }
  w->line[w->n++] = t->lineno;
  return 0;
}

static const char *window_field(const window *w, int r, int c) {
  return w->store + w->off[(size_t)r * w->ncols + c];
}

/* Row r's numbers into vals: 0, or 1 + the first column that is not a finite number. */
static int window_values(const window *w, int r, double *vals) {
  for (int c = 0; c < w->ncols; c++) {
    const char *f = window_field(w, r, c);
    char *end;
    vals[c] = strtod(f, &end);
    if (end == f || *end || !isfinite(vals[c])) return 1 + c;
  }
  return 0;
}

/* The next line of the table as fields: 1, 0 at the end, or -EXIT_BADINPUT with the
 * message in msg (read error, wrong number of fields). The numbers are read by the
 * workers. */
static int table_fields(table *t, char *msg, size_t len) {
  int k = next_line(t, t->ncols);
  if (k == 0) return 0;
  if (k < 0) {
    snprintf(msg, len, "%s:%d: %s", t->path, t->lineno, k == -2 ? t->why : "read error");
    return -EXIT_BADINPUT;
  }
  if (k != t->ncols) {
    snprintf(msg, len, "%s:%d: %d value%s, but the header has %d column%s", t->path, t->lineno, k,
             k == 1 ? "" : "s", t->ncols, t->ncols == 1 ? "" : "s");
    return -EXIT_BADINPUT;
  }
  return 1;
}

/* Per-thread arrays of k doubles each, one after the other: a thread's slice starts at
 * t * stride(k), a multiple of 8 doubles (a cache line) with a line to spare, so two
 * threads never write into one line (false sharing costs more than the row's text). */
static size_t stride(int k) { return ((size_t)k + 7) / 8 * 8 + 8; }

/* Per-thread state of pass 2, padded to keep the threads' lines apart (as above). */
typedef struct {
  cli_buf tb;          /* the thread's formatted rows of the window */
  cv_batch_result res; /* the row being solved */
  long fails;
  char pad[64];
} thread_state;

/* Pass 1 on the workers: bad[r] = 0, or 1 when row r of the window is not a row of
 * numbers or not a valid scene. */
typedef struct {
  const window *w;
  double *vals; /* ncols per thread */
  unsigned char *bad;
} check_job;

static int check_item(cv_batch *b, int t, int r, void *user) {
  check_job *j = user;
  double *v = j->vals + (size_t)t * stride(j->w->ncols);
  char err[8];
  j->bad[r] =
      window_values(j->w, r, v) != 0 || scene_batch_check_row(b, t, v, err, sizeof err) != CVAR_OK;
  return 0;
}

/* Row r's message into msg, found again on this thread (the first bad row only). */
static void bad_row_message(cv_batch *b, const table *t, const window *w, int r, double *vals,
                            char *msg, size_t len) {
  char err[SC_ERRLEN];
  int c = window_values(w, r, vals);
  if (c > 0)
    snprintf(msg, len, "%s:%d: column '%s': '%s' is not a finite number", t->path, w->line[r],
             t->names[c - 1], window_field(w, r, c - 1));
  else if (cv_batch_check_row(b, vals, err, sizeof err) != CVAR_OK)
    /* the scene's message names the scene; the row is where the values came from */
    snprintf(msg, len, "%s:%d: %s", t->path, w->line[r], err);
}

/* Pass 2 on the workers: read, solve and format row r of the window into the thread's
 * buffer; where[r] = its text's thread, offset and length. */
typedef struct {
  const window *w;
  const cli_batch_cols *cols;
  long first;          /* number of the window's first row in the table */
  double *vals, *outs; /* per thread (stride) */
  thread_state *ts;
  size_t (*where)[3];
} solve_job;

static void format_row(cli_buf *o, const cli_batch_cols *cols, const window *w, int row,
                       const cv_batch_result *r);

static int solve_item(cv_batch *b, int t, int r, void *user) {
  solve_job *j = user;
  double *v = j->vals + (size_t)t * stride(j->w->ncols);
  thread_state *ts = &j->ts[t];
  cv_batch_result *res = &ts->res;
  res->outputs = j->outs + (size_t)t * stride(j->cols->nout);
  if (window_values(j->w, r, v) != 0) return -1; /* checked in pass 1 */
  scene_batch_solve_row(b, t, (int)(j->first + r), v, res);
  size_t at = ts->tb.len;
  format_row(&ts->tb, j->cols, j->w, r, res);
  j->where[r][0] = (size_t)t, j->where[r][1] = at, j->where[r][2] = ts->tb.len - at;
  ts->fails += res->status != CVAR_OK;
  return 0;
}

/* ---- one output row ----------------------------------------------------------------- */

/* ",v" with v in fmt (one conversion), nothing after the comma when v is not finite.
 * strfromd formats the number directly: printf's machinery costs several times more per
 * call (with the printf hooks some linked libraries register, every call takes glibc's
 * slow positional path). */
static void num(cli_buf *o, double v, const char *fmt) {
  cli_buf_put(o, ",", 1);
  if (!isfinite(v)) return;
  char d[64];
  int k = strfromd(d, sizeof d, fmt, v);
  if (k > 0 && (size_t)k < sizeof d) cli_buf_put(o, d, (size_t)k);
}

/* A non-negative integer in decimal (no printf: a row has several). */
static void integer(cli_buf *o, long v) {
  char d[24];
  int k = (int)sizeof d;
  unsigned long u = v < 0 ? 0UL - (unsigned long)v : (unsigned long)v;
  do d[--k] = (char)('0' + u % 10);
  while ((u /= 10) > 0);
  if (v < 0) d[--k] = '-';
  cli_buf_put(o, d + k, sizeof d - (size_t)k);
}

/* The row's output line (input fields as given) appended to o. Strings and integers are
 * copied and only the real numbers go through printf (a row's text costs about as much
 * as its LDL^T otherwise: docs/performance.md). */
static void format_row(cli_buf *o, const cli_batch_cols *cols, const window *w, int row,
                       const cv_batch_result *r) {
  for (int c = 0; c < cols->ncols; c++) {
    const char *in = window_field(w, row, c);
    if (c) cli_buf_put(o, ",", 1);
    cli_buf_put(o, in, strlen(in));
  }
  if (cols->ncols) cli_buf_put(o, ",", 1);
  const char *st = cli_status_string(r->status);
  cli_buf_put(o, st, strlen(st));
  num(o, r->has_result ? r->action : NAN, "%.17g");
  cli_buf_put(o, ",", 1);
  integer(o, r->iterations);
  num(o, r->time_s, "%.6f");
  cli_buf_put(o, ",", 1);
  if (r->has_result && r->morse_index >= 0) integer(o, r->morse_index);
  if (cols->err_nodal) num(o, r->has_result ? r->error_max_nodal : NAN, "%.3e");
  if (cols->err_est) num(o, r->has_result ? r->error_estimate : NAN, "%.3e");
  for (int k = 0; k < cols->nout; k++) num(o, r->has_result ? r->outputs[k] : NAN, "%.17g");
  /* the message as one quoted CSV field: quotes doubled, line ends dropped */
  cli_buf_put(o, ",\"", 2);
  const char *m = r->message;
  while (*m) {
    size_t run = strcspn(m, "\"\n\r");
    cli_buf_put(o, m, run);
    m += run;
    if (*m == '"') cli_buf_put(o, "\"\"", 2);
    if (*m) m++;
  }
  cli_buf_put(o, "\"\n", 2);
}

/* Room for `more` bytes after the text of o. 0, or -1 (o->failed) out of memory. */
static int reserve(cli_buf *o, size_t more) {
  if (o->failed) return -1;
  if (o->data && o->cap - o->len > more) return 0;
  size_t ncap = o->cap ? o->cap : 1024;
  while (ncap - o->len <= more) ncap *= 2;
  char *nd = realloc(o->data, ncap);
  if (!nd) {
    o->failed = 1;
    return -1;
  }
  o->data = nd;
  o->cap = ncap;
  return 0;
}

int cli_buf_put(cli_buf *o, const char *s, size_t len) {
  if (reserve(o, len) < 0) return -1;
  memcpy(o->data + o->len, s, len);
  o->len += len;
  o->data[o->len] = '\0';
  return 0;
}

int cli_buf_printf(cli_buf *o, const char *fmt, ...) {
  va_list ap;
  for (int pass = 0; pass < 2; pass++) { /* into the room left; else grow to fit, once */
    size_t room = o->data ? o->cap - o->len : 0;
    va_start(ap, fmt);
    int k = vsnprintf(room ? o->data + o->len : NULL, room, fmt, ap);
    va_end(ap);
    if (k < 0) {
      o->failed = 1;
      return -1;
    }
    if ((size_t)k < room) {
      o->len += (size_t)k;
      return 0;
    }
    if (reserve(o, (size_t)k) < 0) return -1;
  }
  return -1; /* not reached: reserve left room for k bytes and the '\0' */
}

/* ---- the command -------------------------------------------------------------------- */

static double wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Take batch's own options out of argv (the rest goes to the solve option parser).
 * Returns 0, or EXIT_BADINPUT after a message. */
static int own_args(int argc, char **argv, char **rest, int *nrest, const char **table_path,
                    const char **out, int *threads, int *warm, int *help) {
  int npos = 0;
  *nrest = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (strcmp(a, "--warm") == 0) {
      *warm = 1;
    } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      *help = 1;
    } else if (strncmp(a, "--out", 5) == 0 && (a[5] == '\0' || a[5] == '=')) {
      if (!a[5] && i + 1 >= argc) {
        fprintf(stderr, "calcvar batch: --out needs a value\n");
        return EXIT_BADINPUT;
      }
      *out = a[5] ? a + 6 : argv[++i];
    } else if (strncmp(a, "--threads", 9) == 0 && (a[9] == '\0' || a[9] == '=')) {
      const char *v = a[9] ? a + 10 : (i + 1 < argc ? argv[++i] : NULL);
      char *end;
      long t = v ? strtol(v, &end, 10) : 0;
      if (!v || !*v || *end || t < 1 || t > 1024) {
        fprintf(stderr,
                "calcvar batch: --threads needs a whole number from 1 to 1024, got "
                "'%s'\n",
                v ? v : "");
        return EXIT_BADINPUT;
      }
      *threads = (int)t;
    } else if (a[0] != '-' || strcmp(a, "-") == 0) {
      if (npos++ == 1)
        *table_path = a; /* the second positional argument; the first is the scene */
      else
        rest[(*nrest)++] = argv[i];
    } else {
      rest[(*nrest)++] = argv[i];
      /* a valued solve option: keep its value with it */
      if (!strchr(a, '=') && i + 1 < argc && strcmp(a, "--quiet") != 0 &&
          strcmp(a, "--verbose") != 0 && strcmp(a, "-v") != 0 && strcmp(a, "--all") != 0)
        rest[(*nrest)++] = argv[++i];
    }
  }
  return 0;
}

int cli_batch(int argc, char **argv) {
  cli_opts o;
  memset(&o, 0, sizeof o);
  char **rest = malloc(((size_t)argc + 1) * sizeof *rest);
  const char *table_path = NULL, *out_path = NULL;
  int threads = 0, warm = 0, help = 0, nrest = 0, rc;
  if (!rest) return EXIT_BADINPUT;
  cli_mpi mpi;
  cli_mpi_init(&mpi);
  rc = own_args(argc, argv, rest, &nrest, &table_path, &out_path, &threads, &warm, &help);
  if (rc == 0 && !help) rc = cli_args_parse("batch", nrest, rest, &o); /* --help needs no scene */
  free(rest);
  if (rc != 0 || help || o.help) {
    if (rc == 0 && mpi.rank == 0) usage(stdout);
    cli_opts_free(&o);
    cli_mpi_finish(&mpi);
    return rc;
  }
  if (!o.scene_path || !table_path) {
    fprintf(stderr, "calcvar batch: needs a scene and a table: calcvar batch SCENE "
                    "TABLE.csv [options]\n");
    cli_opts_free(&o);
    cli_mpi_finish(&mpi);
    return EXIT_BADINPUT;
  }
  if (o.verbose) {
    /* rows are solved on several threads (and ranks): per-iteration lines would interleave */
    fprintf(stderr, "calcvar batch: --verbose is not available for batch yet; run calcvar "
                    "solve --verbose --set ... on a row to see its iterations\n");
    cli_opts_free(&o);
    cli_mpi_finish(&mpi);
    return EXIT_BADINPUT;
  }
  if (o.cont || o.json || o.csv || o.plot || o.all || o.max_paths || o.work > 0 ||
      o.max_elements > 0) {
    fprintf(stderr, "calcvar batch: --%s is an option of calcvar solve, not of batch\n",
            o.cont        ? "continue"
            : o.json      ? "json"
            : o.csv       ? "csv"
            : o.plot      ? "plot"
            : o.all       ? "all"
            : o.max_paths ? "max"
            : o.work > 0  ? "work"
                          : "max-elements");
    cli_opts_free(&o);
    cli_mpi_finish(&mpi);
    return EXIT_BADINPUT;
  }
  rc = cli_batch_run(&o, table_path, out_path, threads, warm, &mpi);
  cli_opts_free(&o);
  cli_mpi_finish(&mpi);
  return rc;
}

/* ---- the run: scene, check, output, solve, finish ------------------------------------ */

/* What the steps of one run share. Under MPI every rank runs every step; where one rank
 * alone can fail (rank 0 opens and writes the output) the ranks agree on the outcome
 * (agree), so that none is left waiting for the others in a collective call. */
typedef struct {
  const cli_opts *o;
  cli_mpi *mpi;
  const char *out_path;
  cv_batch *b;
  table t;
  cli_outfile of;
  FILE *f;             /* rank 0: the output (of.f or stdout); NULL on the other ranks */
  int threads, W, wsz; /* rows per window per rank (W), and over all ranks */
  long nrows;
  double *vals, *outs;
  window wd;
  cli_buf buf;
  thread_state *ts;
  unsigned char *bad;
  size_t (*where)[3];
  cli_batch_cols cols;
} batch_run;

/* Whether any rank says bad (every rank gets the answer). */
static int agree(cli_mpi *mpi, int bad) { return cli_mpi_min_long(mpi, bad ? -1 : 0) < 0; }

/* The scene with the command's options, compiled once as a batch. 0, or EXIT_BADINPUT. */
static int batch_scene(const cli_opts *o, cv_batch **bp) {
  char err[SC_ERRLEN];
  scene *s = scene_load_file_inputs(o->scene_path, o->nset, o->set, err, sizeof err);
  if (!s) {
    fprintf(stderr, "%s\n", err);
    return EXIT_BADINPUT;
  }
  if (o->elements) s->elements = o->elements;
  if (o->degree) s->degree = o->degree;
  cli_apply_solver_options(o, s);
  if (cli_apply_accuracy(o, s) != 0) {
    scene_free(s);
    return EXIT_BADINPUT;
  }
  if ((s->method == CVAR_METHOD_LBFGS || s->method == CVAR_METHOD_TNEWTON) &&
      (s->ncons > 0 || s->nints > 0)) {
    fprintf(stderr,
            "calcvar batch: method %s cannot impose constraints; use mma, ccsaq, "
            "slsqp, auglag or newton\n",
            cv_method_name(s->method));
    scene_free(s);
    return EXIT_BADINPUT;
  }
  if (!(*bp = scene_batch_new(s, err, sizeof err))) { /* it owns s from here */
    fprintf(stderr, "%s\n", err);
    return EXIT_BADINPUT;
  }
  return 0;
}

/* Windows and per-thread buffers. 0, or -1 after a message. */
static int batch_alloc(batch_run *r) {
  int nc = r->t.ncols, threads = r->threads;
  /* Windows: W rows per rank (threads x ROWS_PER_THREAD), under MPI the ranks take
   * consecutive blocks of one window of W * size rows. */
  r->W = threads * ROWS_PER_THREAD;
  r->wsz = r->W * r->mpi->size;
  r->vals = malloc((size_t)threads * stride(nc) * sizeof *r->vals);
  r->wd.ncols = nc;
  r->ts = calloc((size_t)threads, sizeof *r->ts);
  r->outs = malloc((size_t)threads * stride(cv_batch_num_outputs(r->b)) * sizeof *r->outs);
  r->bad = malloc((size_t)r->W + 1);
  r->where = malloc(((size_t)r->W + 1) * sizeof *r->where);
  if (r->vals && r->ts && r->outs && r->bad && r->where) return 0;
  fprintf(stderr, "calcvar batch: out of memory\n");
  return -1;
}

/* Pass 1: the whole table is checked before anything is written. Lines are read and
 * counted here; the numbers and the scene each row makes are checked by the workers
 * (each rank its blocks); the first bad row over all ranks is reported. 0, or
 * EXIT_BADINPUT after a message. */
static int batch_check(batch_run *r) {
  cli_mpi *mpi = r->mpi;
  long first_bad = LONG_MAX;
  int kind = 0, nomem = 0; /* of this rank's first bad row: 1 a value, 2 the line itself */
  char badmsg[2 * SC_ERRLEN] = "";
  for (int at_end = 0; !at_end && first_bad == LONG_MAX && !nomem;) {
    long w0 = r->nrows, m0 = w0 + (long)mpi->rank * r->W;
    r->wd.n = 0, r->wd.slen = 0;
    for (long i = w0; i < w0 + r->wsz; i++) {
      int k = table_fields(&r->t, badmsg, sizeof badmsg);
      if (k == 0) {
        at_end = 1;
        break;
      }
      if (k < 0) { /* every rank sees it; rank 0 says so */
        first_bad = i, kind = 2, at_end = 1;
        break;
      }
      r->nrows++;
      if (i >= m0 && i < m0 + r->W && window_add(&r->wd, &r->t) < 0) nomem = 1;
    }
    check_job cj = {&r->wd, r->vals, r->bad};
    if (!nomem && scene_batch_for_each(r->b, r->wd.n, scene_batch_block(r->b, r->wd.n), check_item,
                                       &cj) != CVAR_OK)
      nomem = 1;
    for (int i = 0; i < r->wd.n && !nomem; i++)
      if (r->bad[i] && m0 + i < first_bad) {
        first_bad = m0 + i, kind = 1;
        bad_row_message(r->b, &r->t, &r->wd, i, r->vals, badmsg, sizeof badmsg);
        break;
      }
  }
  if (nomem) fprintf(stderr, "calcvar batch: out of memory\n");
  if (agree(mpi, nomem)) return EXIT_BADINPUT;
  long global_bad = cli_mpi_min_long(mpi, first_bad);
  if (global_bad != LONG_MAX) { /* said once: by the rank whose row it is */
    if (first_bad == global_bad && (kind == 1 || mpi->rank == 0)) fprintf(stderr, "%s\n", badmsg);
    return EXIT_BADINPUT;
  }
  if (r->nrows > INT_MAX / 2) {
    fprintf(stderr, "%s: more than %d rows\n", r->t.path, INT_MAX / 2);
    return EXIT_BADINPUT;
  }
  return 0;
}

/* Rank 0 opens the output (never the scene or the table, by any name) and writes the
 * header. 0, or EXIT_BADINPUT on every rank when rank 0 could not open it. */
static int batch_output(batch_run *r, const char *table_path) {
  const char *inputs[2] = {r->o->scene_path, table_path};
  int bad = r->mpi->rank == 0 && r->out_path &&
            cli_outfile_open_inputs(&r->of, r->out_path, inputs, 2) < 0;
  if (agree(r->mpi, bad)) return EXIT_BADINPUT;
  r->f = r->mpi->rank == 0 ? (r->out_path ? r->of.f : stdout) : NULL;
  cli_batch_cols cols = {r->t.ncols, 0, 0, cv_batch_num_outputs(r->b)};
  const scene *sc = scene_batch_scene(r->b);
  for (int i = 0; i < sc->n; i++) cols.err_nodal |= sc->exact[i] >= 0;
  /* the figure `solve` reports for the row: the estimate without [exact], and with --tol
   * always (its target) */
  cols.err_est = !cols.err_nodal || sc->tol > 0;
  r->cols = cols;
  FILE *f = r->f;
  if (f) {
    for (int c = 0; c < r->t.ncols; c++) fprintf(f, "%s,", r->t.names[c]);
    fprintf(f, "status,action,iterations,time_s,morse_index");
    if (cols.err_nodal) fprintf(f, ",error_max_nodal");
    if (cols.err_est) fprintf(f, ",error_estimate");
    for (int k = 0; k < cols.nout; k++) fprintf(f, ",%s", cv_batch_output_name(r->b, k));
    fprintf(f, ",message\n");
  }
  return 0;
}

/* One window of pass 2 on this rank: read, solve, format, and write (rank 0, through the
 * gather). 0; -1 when the output could not be written; -2 for anything else (after a
 * message). Every rank returns the same. */
static int batch_window(batch_run *r, long w0, long wn) {
  char badmsg[2 * SC_ERRLEN];
  long m0 = w0 + (long)r->mpi->rank * r->W;
  int bad = 0;
  r->wd.n = 0, r->wd.slen = 0;
  for (long i = w0; i < w0 + wn && !bad; i++) {
    if (table_fields(&r->t, badmsg, sizeof badmsg) <= 0) { /* the file changed since pass 1 */
      fprintf(stderr, "%s: the table changed while it was read\n", r->t.path);
      bad = 1;
    } else if (i >= m0 && i < m0 + r->W && window_add(&r->wd, &r->t) < 0) {
      bad = 2;
    }
  }
  for (int k = 0; k < r->threads; k++) r->ts[k].tb.len = 0;
  solve_job sj = {&r->wd, &r->cols, m0, r->vals, r->outs, r->ts, r->where};
  if (!bad && scene_batch_for_each(r->b, r->wd.n, scene_batch_block(r->b, r->wd.n), solve_item,
                                   &sj) != CVAR_OK)
    bad = 2;
  r->buf.len = 0;
  for (int i = 0; i < r->wd.n && !bad; i++)
    cli_buf_put(&r->buf, r->ts[r->where[i][0]].tb.data + r->where[i][1], r->where[i][2]);
  for (int k = 0; k < r->threads; k++) bad |= r->ts[k].tb.failed ? 2 : 0;
  bad |= r->buf.failed ? 2 : 0;
  if (bad & 2) fprintf(stderr, "calcvar batch: out of memory\n");
  if (agree(r->mpi, bad)) return -2;
  if (cli_mpi_gather_write(r->mpi, r->f, &r->buf) < 0) {
    if (r->f)
      fprintf(stderr, "calcvar batch: cannot write %s: %s\n",
              r->out_path ? r->out_path : "standard output", strerror(errno));
    return -1;
  }
  return 0;
}

/* Pass 2: each window is read here, solved and formatted by the workers (each into its
 * own buffer), put together in input order and written (under MPI: rank 0 gathers).
 * 0, -1 (the output could not be written) or -2. */
static int batch_solve(batch_run *r) {
  long done_rows = 0;
  int tty = r->mpi->rank == 0 && isatty(2), rc = 0;
  double t0 = wall();
  while (done_rows < r->nrows && rc == 0) {
    long wn = r->nrows - done_rows < r->wsz ? r->nrows - done_rows : r->wsz;
    if ((rc = batch_window(r, done_rows, wn)) != 0) break;
    done_rows += wn;
    if (tty) {
      long failures = 0;
      for (int k = 0; k < r->threads; k++) failures += r->ts[k].fails;
      double el = wall() - t0;
      fprintf(stderr, "\rcalcvar batch: %ld/%ld rows, %.1f rows/s, %ld failed", done_rows, r->nrows,
              el > 0 ? done_rows / el : 0.0, failures);
    }
  }
  if (tty) fputc('\n', stderr);
  return rc;
}

/* Rank 0 puts the output in place (or flushes standard output); every rank learns whether
 * that worked. 0, or -1 (after rank 0's message). */
static int batch_commit(batch_run *r) {
  int bad = 0;
  if (r->f && r->out_path) {
    bad = cli_outfile_commit(&r->of) < 0; /* it says why */
  } else if (r->f && (fflush(stdout) != 0 || ferror(stdout))) {
    if (!cli_stdout_reported())
      fprintf(stderr, "calcvar: cannot write standard output: %s\n", strerror(errno));
    cli_stdout_set_reported();
    bad = 1;
  }
  return agree(r->mpi, bad) ? -1 : 0;
}

static void batch_run_free(batch_run *r) {
  cli_outfile_abandon(&r->of);
  free(r->buf.data);
  for (int k = 0; r->ts && k < r->threads; k++) free(r->ts[k].tb.data);
  free(r->ts);
  free(r->outs);
  free(r->bad);
  free(r->where);
  free(r->vals);
  window_free(&r->wd);
  table_close(&r->t);
  cv_batch_free(r->b);
}

int cli_batch_run(const cli_opts *o, const char *table_path, const char *out_path, int threads,
                  int warm, cli_mpi *mpi) {
  batch_run r;
  memset(&r, 0, sizeof r);
  r.o = o, r.mpi = mpi, r.out_path = out_path;
  int rc = batch_scene(o, &r.b);
  if (rc == 0) rc = table_open(&r.t, table_path, r.b, mpi->size);
  int settings_line = r.b ? scene_batch_scene(r.b)->settings_line : 0;
  if (rc == 0 && settings_line && r.t.ncols > 0) {
    /* a [mesh]/[solver] number computed from a parameter: it would have to follow the
     * row, which this build does not do (docs/cli.md) */
    fprintf(stderr,
            "%s:%d: a [mesh] or [solver] value uses a parameter; calcvar batch "
            "keeps one mesh and solver setting for every row\n",
            o->scene_path, settings_line > 0 ? settings_line : 0);
    rc = EXIT_BADINPUT;
  }
  if (rc == 0) {
    r.threads = threads ? threads : cli_cores_available();
    cv_batch_set_threads(r.b, r.threads);
    cv_batch_set_warm_start(r.b, warm);
    if (agree(mpi, batch_alloc(&r) < 0)) rc = EXIT_BADINPUT;
  }
  if (rc == 0) rc = batch_check(&r);
  if (rc == 0 && agree(mpi, table_rewind(&r.t) < 0)) rc = EXIT_BADINPUT;
  if (rc == 0) rc = batch_output(&r, table_path);
  if (rc == 0) {
    int solved = batch_solve(&r);
    rc = solved == -1 ? EXIT_IOERROR : solved < 0 ? EXIT_UNSOLVED : 0;
  }
  if (rc == 0 && batch_commit(&r) < 0) rc = EXIT_IOERROR;
  if (rc == 0) {
    long failures = 0;
    for (int k = 0; k < r.threads; k++) failures += r.ts[k].fails;
    rc = cli_mpi_reduce_failures(mpi, failures) == 0 ? EXIT_SOLVED : EXIT_UNSOLVED;
  }
  batch_run_free(&r);
  return rc;
}
