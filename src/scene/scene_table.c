/* src/scene/scene_table.c — the [tables] section: read a CSV grid into a cv_table.
 * SPDX-License-Identifier: MIT
 *
 * The CSV (docs/scenes.md "[tables]"): a header of 2..4 column names (1..3 coordinates,
 * then the value), then one row per grid point, in any order, forming a full rectilinear
 * grid. Every fault is reported at the CSV's own FILE:LINE. Numbers are read by a fast
 * exact path (Clinger: at most 19 significant digits whose integer fits in 2^53, a power of
 * ten up to 22; both exact doubles, so one rounding) with strtod for everything else, so a
 * 200^3 grid reads in well under a second (bench/bench_table). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/cv_memory.h"
#include "core/cv_table_internal.h"
#include "scene/scene_internal.h"

enum { TB_MAXCOL = 4 };

static int is_sp(char c) { return c == ' ' || c == '\t'; }

/* Parse one number from s[0..len): the whole field must be the number. 0 or -1. */
static int parse_num(const char *s, size_t len, double *out)
{
  static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  size_t i = 0;
  int neg = 0;
  if (i < len && (s[i] == '-' || s[i] == '+'))
    neg = s[i++] == '-';
  uint64_t m = 0;
  int nd = 0, frac = 0, digits = 0;
  while (i < len && s[i] >= '0' && s[i] <= '9') {
    if (nd < 19) {
      m = m * 10 + (uint64_t)(s[i] - '0');
      if (m) nd++;
    } else
      nd = 99; /* too many digits for the fast path */
    i++, digits++;
  }
  if (i < len && s[i] == '.') {
    i++;
    while (i < len && s[i] >= '0' && s[i] <= '9') {
      if (nd < 19) {
        m = m * 10 + (uint64_t)(s[i] - '0');
        if (m) nd++;
        frac++;
      } else
        nd = 99;
      i++, digits++;
    }
  }
  int e = 0, fast = digits > 0 && nd <= 19;
  if (digits && i < len && (s[i] == 'e' || s[i] == 'E')) {
    size_t j = i + 1;
    int eneg = 0;
    if (j < len && (s[j] == '-' || s[j] == '+'))
      eneg = s[j++] == '-';
    if (j >= len || s[j] < '0' || s[j] > '9')
      fast = 0;
    while (j < len && s[j] >= '0' && s[j] <= '9') {
      if (e < 10000)
        e = e * 10 + (s[j] - '0');
      j++;
    }
    if (eneg)
      e = -e;
    i = j;
  }
  if (fast && i == len && m < ((uint64_t)1 << 53)) {
    int ex = e - frac;
    if (ex >= -22 && ex <= 22) {
      double v = (double)m;
      v = ex < 0 ? v / p10[-ex] : v * p10[ex];
      *out = neg ? -v : v;
      return 0;
    }
  }
#if LDBL_MANT_DIG == 64 && defined(__x86_64__)
  /* Up to 19 digits (17-digit output of %.17g included): m and 10^|ex| (|ex| <= 27) are
   * exact in the 64-bit significand of long double, so m * 10^ex is rounded once there;
   * rounding that to double is then correct unless the long double lies on or next to a
   * midpoint between two doubles (low 11 bits 0x3ff..0x401), which goes to strtod. */
  if (fast && i == len && m != 0) {
    int ex = e - frac;
    if (ex >= -27 && ex <= 27) {
      static const long double p10l[28] = {
          1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,
          1e10L, 1e11L, 1e12L, 1e13L, 1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L,
          1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L}; /* exact: 5^27 < 2^64 */
      long double L = ex < 0 ? (long double)m / p10l[-ex] : (long double)m * p10l[ex];
      uint64_t bits; /* x87 extended: the explicit 64-bit significand comes first */
      memcpy(&bits, &L, sizeof bits);
      unsigned low = (unsigned)(bits & 0x7ff);
      if (low < 0x3ff || low > 0x401) {
        double v = (double)L;
        *out = neg ? -v : v;
        return 0;
      }
    }
  }
#endif
  /* everything else (and every malformed field) through strtod on a copy */
  char buf[128];
  if (len == 0 || len >= sizeof buf)
    return -1;
  memcpy(buf, s, len);
  buf[len] = '\0';
  char *end;
  errno = 0;
  double v = strtod(buf, &end);
  if (end != buf + len)
    return -1;
  *out = v;
  return 0;
}

/* Split one line [p, q) at commas into at most TB_MAXCOL + 1 trimmed fields. Returns the
 * count (TB_MAXCOL + 1 means "more"). */
static int split(const char *p, const char *q, const char **fs, size_t *fl)
{
  int n = 0;
  for (;;) {
    const char *c = memchr(p, ',', (size_t)(q - p));
    const char *end = c ? c : q;
    const char *a = p, *b = end;
    while (a < b && is_sp(*a))
      a++;
    while (b > a && is_sp(b[-1]))
      b--;
    if (n <= TB_MAXCOL) {
      fs[n] = a;
      fl[n] = (size_t)(b - a);
    }
    n++;
    if (!c || n > TB_MAXCOL)
      return n > TB_MAXCOL ? TB_MAXCOL + 1 : n;
    p = c + 1;
  }
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Distinct values of one coordinate column, as a growing open-addressing hash set. */
typedef struct {
  double *v;
  unsigned char *used;
  size_t cap, n;
} dset;

static int dset_add(dset *s, double x)
{
  if (x == 0)
    x = 0.0; /* -0 and 0 are one coordinate */
  if ((s->n + 1) * 2 > s->cap) {
    size_t ncap = s->cap ? s->cap * 2 : 64;
    double *nv = cv_malloc(ncap * sizeof *nv);
    unsigned char *nu = cv_calloc(ncap, 1);
    if (!nv || !nu) {
      cv_free(nv);
      cv_free(nu);
      return -1;
    }
    for (size_t i = 0; i < s->cap; i++)
      if (s->used[i]) {
        uint64_t b;
        memcpy(&b, &s->v[i], sizeof b);
        size_t h = (size_t)((b * 0x9E3779B97F4A7C15ull) >> 20) & (ncap - 1);
        while (nu[h])
          h = (h + 1) & (ncap - 1);
        nu[h] = 1;
        nv[h] = s->v[i];
      }
    cv_free(s->v);
    cv_free(s->used);
    s->v = nv;
    s->used = nu;
    s->cap = ncap;
  }
  uint64_t b;
  memcpy(&b, &x, sizeof b);
  size_t h = (size_t)((b * 0x9E3779B97F4A7C15ull) >> 20) & (s->cap - 1);
  while (s->used[h]) {
    if (s->v[h] == x)
      return 0;
    h = (h + 1) & (s->cap - 1);
  }
  s->used[h] = 1;
  s->v[h] = x;
  s->n++;
  return 0;
}

/* Index of x in the sorted distinct values c[0..n) (present by construction). */
static int locate(const double *c, int n, double x)
{
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (c[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

cv_table *sc_table_read(const char *path, const char *shown, char *err, size_t errlen)
{
  cv_table *t = NULL;
  char *text = NULL;
  double *rows = NULL, *vals = NULL, *coords[3] = {NULL, NULL, NULL};
  int *rowline = NULL, *where = NULL;
  dset ds[3];
  memset(ds, 0, sizeof ds);
  size_t nrows = 0, caprows = 0;

  FILE *f = fopen(path, "rb");
  if (!f) {
    sc_err(err, errlen, shown, 0, "cannot open the table: %s", strerror(errno));
    return NULL;
  }
  /* one buffer of the file's size (a regular file); grown by doubling otherwise */
  size_t len = 0, cap = 1 << 16;
  struct stat sb;
  if (fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0)
    cap = (size_t)sb.st_size + 1; /* + 1: reaching cap means more data may follow */
  text = cv_malloc(cap + 1);
  while (text) {
    len += fread(text + len, 1, cap - len, f);
    if (len < cap)
      break;
    char *nt = cv_realloc(text, (cap *= 2) + 1);
    if (!nt) {
      cv_free(text);
      text = NULL;
    } else
      text = nt;
  }
  int bad = ferror(f);
  fclose(f);
  if (!text || bad) {
    sc_err(err, errlen, shown, 0, bad ? "read error" : "out of memory");
    goto done;
  }
  text[len] = '\0';

  /* the header */
  const char *p = text, *end = text + len, *fs[TB_MAXCOL + 1];
  size_t fl[TB_MAXCOL + 1];
  int line = 1;
  const char *nl = memchr(p, '\n', (size_t)(end - p));
  const char *q = nl ? nl : end;
  if (q > p && q[-1] == '\r')
    q--;
  if (memchr(text, '\0', len)) {
    sc_err(err, errlen, shown, 0, "the table contains a NUL byte (not a text file)");
    goto done;
  }
  int ncol = p == q ? 0 : split(p, q, fs, fl);
  if (ncol < 2 || ncol > TB_MAXCOL) {
    sc_err(err, errlen, shown, 1,
           "the header must name 2 to 4 columns (1 to 3 coordinates, then the value), "
           "found %s%d", ncol > TB_MAXCOL ? "more than " : "", ncol > TB_MAXCOL ? TB_MAXCOL : ncol);
    goto done;
  }
  for (int c = 0; c < ncol; c++) {
    double dummy;
    if (fl[c] == 0 || parse_num(fs[c], fl[c], &dummy) == 0) {
      sc_err(err, errlen, shown, 1,
             "the header must name every column (column %d is %s)", c + 1,
             fl[c] ? "a number: is the header line missing?" : "empty");
      goto done;
    }
  }
  char names[TB_MAXCOL][64];
  for (int c = 0; c < ncol; c++)
    snprintf(names[c], sizeof names[c], "%.*s", (int)(fl[c] < 60 ? fl[c] : 60), fs[c]);
  int dim = ncol - 1;

  /* the rows: room for one per remaining line, allocated once (a 200^3 grid is 8e6 rows;
   * growing by doubling cost a third of the reading time in copies and page faults) */
  p = nl ? nl + 1 : end;
  for (const char *r = p; r < end; r++) {
    r = memchr(r, '\n', (size_t)(end - r));
    caprows++;
    if (!r)
      break;
  }
  if (caprows) {
    rows = cv_malloc(caprows * (size_t)ncol * sizeof *rows);
    rowline = cv_malloc(caprows * sizeof *rowline);
    if (!rows || !rowline) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
  }
  while (p < end) {
    line++;
    nl = memchr(p, '\n', (size_t)(end - p));
    q = nl ? nl : end;
    const char *r = q;
    if (r > p && r[-1] == '\r')
      r--;
    const char *a = p;
    while (a < r && is_sp(*a))
      a++;
    if (a == r) { /* blank line */
      p = nl ? nl + 1 : end;
      continue;
    }
    int n = split(p, r, fs, fl);
    if (n != ncol) {
      sc_err(err, errlen, shown, line, "%s%d value%s in this row, the header has %d columns",
             n > TB_MAXCOL ? "more than " : "", n > TB_MAXCOL ? TB_MAXCOL : n,
             n == 1 ? "" : "s", ncol);
      goto done;
    }
    if (nrows == caprows) {
      caprows = caprows ? caprows * 2 : 1024;
      double *nr = cv_realloc(rows, caprows * (size_t)ncol * sizeof *nr);
      int *nlines = cv_realloc(rowline, caprows * sizeof *nlines);
      if (nr)
        rows = nr;
      if (nlines)
        rowline = nlines;
      if (!nr || !nlines) {
        sc_err(err, errlen, shown, line, "out of memory");
        goto done;
      }
    }
    double *row = rows + nrows * (size_t)ncol;
    for (int c = 0; c < ncol; c++) {
      if (parse_num(fs[c], fl[c], &row[c]) != 0) {
        sc_err(err, errlen, shown, line, "column '%s': '%.*s' is not a number", names[c],
               (int)(fl[c] < 40 ? fl[c] : 40), fs[c]);
        goto done;
      }
      if (!isfinite(row[c])) {
        sc_err(err, errlen, shown, line, "column '%s': %.*s is not a finite number",
               names[c], (int)(fl[c] < 40 ? fl[c] : 40), fs[c]);
        goto done;
      }
      if (c < dim && dset_add(&ds[c], row[c]) != 0) {
        sc_err(err, errlen, shown, line, "out of memory");
        goto done;
      }
    }
    rowline[nrows++] = line;
    p = nl ? nl + 1 : end;
  }
  if (nrows == 0) {
    sc_err(err, errlen, shown, 1, "the table has a header but no rows");
    goto done;
  }

  /* the grid: distinct coordinate values, sorted */
  int n[3] = {1, 1, 1};
  size_t size = 1;
  for (int k = 0; k < dim; k++) {
    if (ds[k].n < 4) {
      sc_err(err, errlen, shown, 1,
             "coordinate '%s' has %zu distinct value%s; a cubic spline needs at least 4",
             names[k], ds[k].n, ds[k].n == 1 ? "" : "s");
      goto done;
    }
    coords[k] = cv_malloc(ds[k].n * sizeof *coords[k]);
    if (!coords[k]) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
    size_t m = 0;
    for (size_t i = 0; i < ds[k].cap; i++)
      if (ds[k].used[i])
        coords[k][m++] = ds[k].v[i];
    qsort(coords[k], m, sizeof *coords[k], cmp_double);
    n[k] = (int)m;
    size *= m;
  }
  vals = cv_malloc(size * sizeof *vals);
  where = cv_calloc(size, sizeof *where); /* line of the row holding each point, 0 = none */
  if (!vals || !where) {
    sc_err(err, errlen, shown, 0, "out of memory");
    goto done;
  }
  for (size_t r = 0; r < nrows; r++) {
    const double *row = rows + r * (size_t)ncol;
    size_t idx = 0;
    for (int k = 0; k < dim; k++)
      idx = idx * (size_t)n[k] + (size_t)locate(coords[k], n[k], row[k] == 0 ? 0.0 : row[k]);
    if (where[idx]) {
      sc_err(err, errlen, shown, rowline[r], "repeated grid point (also on line %d)",
             where[idx]);
      goto done;
    }
    where[idx] = rowline[r];
    vals[idx] = row[dim];
  }
  if (nrows != size) {
    size_t miss = 0;
    while (where[miss])
      miss++;
    size_t rest = miss;
    double u[3] = {0, 0, 0};
    for (int k = dim - 1; k >= 0; k--) {
      u[k] = coords[k][rest % (size_t)n[k]];
      rest /= (size_t)n[k];
    }
    char at[200];
    int o = 0;
    for (int k = 0; k < dim; k++)
      o += snprintf(at + o, sizeof at - (size_t)o, "%s%s = %.17g", k ? ", " : "", names[k],
                    u[k]);
    sc_err(err, errlen, shown, rowline[nrows - 1],
           "the grid is not complete: %zu of %zu points are missing, e.g. %s (every "
           "combination of the coordinate values must have a row)", size - nrows, size, at);
    goto done;
  }
  cv_status why;
  char msg[200];
  t = cv_table_new_msg(dim, n, (const double *const *)coords, vals, &why, msg, sizeof msg);
  if (!t)
    sc_err(err, errlen, shown, 0, "%s", msg);
done:
  cv_free(text);
  cv_free(rows);
  cv_free(rowline);
  cv_free(vals);
  cv_free(where);
  for (int k = 0; k < 3; k++) {
    cv_free(coords[k]);
    cv_free(ds[k].v);
    cv_free(ds[k].used);
  }
  return t;
}

/* [tables]: `name = file.csv`, a path relative to the scene's directory (the current one
 * for a scene without a file, e.g. standard input) or absolute. Loaded before every other
 * name, so parameters and definitions may not reuse a table's name and every expression
 * may call it. */
int sc_load_tables(sc_loader *L)
{
  scene *s = L->s;
  const char *file = s->file;
  const char *slash = strrchr(file, '/');
  int from_file = strcmp(file, "<stdin>") != 0 && strncmp(file, "gallery:", 8) != 0;
  size_t dirlen = from_file && slash ? (size_t)(slash - file) + 1 : 0;
  for (int i = 0; i < L->raw.ne[SEC_TABLES]; i++) {
    const sc_entry *e = &L->raw.e[SEC_TABLES][i];
    if (sc_check_new_name(L, e->line, e->key, "a table") < 0)
      return -1;
    if (!e->value[0]) {
      sc_err(L->err, L->errlen, L->file, e->line, "table '%s' needs a file name", e->key);
      return -1;
    }
    size_t vl = strlen(e->value);
    char *path = cv_malloc(dirlen + vl + 1);
    if (!path) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
    size_t pre = e->value[0] == '/' ? 0 : dirlen;
    memcpy(path, file, pre);
    memcpy(path + pre, e->value, vl + 1);
    char msg[SC_ERRLEN];
    msg[0] = '\0';
    cv_table *t = sc_table_read(path, path, msg, sizeof msg);
    if (!t) {
      /* a file that cannot be opened has no line of its own: point at the scene's */
      if (strncmp(msg, path, strlen(path)) == 0 && msg[strlen(path)] == ':' &&
          msg[strlen(path) + 1] == ' ')
        sc_err(L->err, L->errlen, L->file, e->line, "table '%s': %s", e->key, msg);
      else
        snprintf(L->err, L->errlen, "%s", msg); /* the CSV's own FILE:LINE */
      cv_free(path);
      return -1;
    }
    cv_free(path);
    int idx = ex_dag_add_table(s->dag, e->key, t);
    cv_table_free(t); /* the DAG holds its own reference */
    if (idx < 0) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
  }
  return 0;
}
