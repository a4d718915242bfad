/* src/scene/scene_table.c — the [tables] section: read a CSV grid into a cv_table.
 * SPDX-License-Identifier: MIT
 *
 * The CSV (docs/scenes.md "[tables]"): a header of 2..4 column names (1..3 coordinates,
 * then the value), then one row per grid point, in any order, forming a full rectilinear
 * grid. Every fault is reported at the CSV's own FILE:LINE. Numbers are read by a fast
 * exact path (Clinger: at most 19 significant digits whose integer fits in 2^53, a power of
 * ten up to 22; both exact doubles, so one rounding) with strtod for everything else.
 * One pass over the mapped file, no array of parsed rows; a grid written in its own order
 * is read straight into the table's array of values (docs/scenes.md "Reading speed";
 * bench/bench_table). */
#define _DEFAULT_SOURCE /* MAP_POPULATE */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/cv_memory.h"
#include "core/cv_table_internal.h"
#include "scene/scene_internal.h"

enum { TB_MAXCOL = 4 };

static int is_sp(char c) { return c == ' ' || c == '\t'; }

/* Parse one number from s[0..len): the whole field must be the number. 0 or -1. */
static int parse_num(const char *s, size_t len, double *out) {
  static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  size_t i = 0;
  int neg = 0;
  if (i < len && (s[i] == '-' || s[i] == '+')) neg = s[i++] == '-';
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
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
      /* eight digits at once when they keep m within 19 significant digits (m != 0: all
       * eight count); the first byte is the most significant digit */
      if (m && nd <= 11 && len - i >= 8) {
        uint64_t w;
        memcpy(&w, s + i, 8);
        if ((w & 0xF0F0F0F0F0F0F0F0ull) == 0x3030303030303030ull &&
            ((w + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) == 0x3030303030303030ull) {
          w -= 0x3030303030303030ull;
          w = w * 10 + (w >> 8); /* pairs of digits in the even bytes */
          w = ((w & 0x000000FF000000FFull) * (100 + (1000000ull << 32)) +
               ((w >> 16) & 0x000000FF000000FFull) * (1 + (10000ull << 32))) >>
              32;
          m = m * 100000000u + (uint32_t)w;
          nd += 8, frac += 8, digits += 8, i += 8;
          continue;
        }
      }
#endif
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
    if (j < len && (s[j] == '-' || s[j] == '+')) eneg = s[j++] == '-';
    if (j >= len || s[j] < '0' || s[j] > '9') fast = 0;
    while (j < len && s[j] >= '0' && s[j] <= '9') {
      if (e < 10000) e = e * 10 + (s[j] - '0');
      j++;
    }
    if (eneg) e = -e;
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
      static const long double p10l[28] = {1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,
                                           1e8L,  1e9L,  1e10L, 1e11L, 1e12L, 1e13L, 1e14L, 1e15L,
                                           1e16L, 1e17L, 1e18L, 1e19L, 1e20L, 1e21L, 1e22L, 1e23L,
                                           1e24L, 1e25L, 1e26L, 1e27L}; /* exact: 5^27 < 2^64 */
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
  if (len == 0 || len >= sizeof buf) return -1;
  memcpy(buf, s, len);
  buf[len] = '\0';
  char *end;
  errno = 0;
  double v = strtod(buf, &end);
  if (end != buf + len) return -1;
  *out = v;
  return 0;
}

/* Split one line [p, q) at commas into at most TB_MAXCOL + 1 trimmed fields. Returns the
 * count (TB_MAXCOL + 1 means "more"). */
static int split(const char *p, const char *q, const char **fs, size_t *fl) {
  int n = 0;
  for (;;) {
    const char *c = memchr(p, ',', (size_t)(q - p));
    const char *end = c ? c : q;
    const char *a = p, *b = end;
    while (a < b && is_sp(*a)) a++;
    while (b > a && is_sp(b[-1])) b--;
    if (n <= TB_MAXCOL) {
      fs[n] = a;
      fl[n] = (size_t)(b - a);
    }
    n++;
    if (!c || n > TB_MAXCOL) return n > TB_MAXCOL ? TB_MAXCOL + 1 : n;
    p = c + 1;
  }
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The distinct texts of one coordinate column. Each new text is read once (parse_num) and
 * gets the next id; a row's coordinate is then found by its text, most often the very text
 * of the previous row (the slow coordinates of a grid written in order), else by hashing.
 * Texts that differ but read as one number ("0.5", "0.50", "-0", "0") share the grid index
 * later (rank), so the grid is that of the values, as before. */
typedef struct {
  const char **s; /* by id: the text (in the file's buffer), its length, value, hash */
  size_t *len;
  double *v;
  uint64_t *hash;
  uint32_t *slot; /* open addressing: id + 1, 0 = empty */
  size_t n, cap, nslot;
  const char *last; /* the previous row's text of this column and its id */
  size_t lastlen;
  uint32_t lastid;
  int unsorted; /* a new text's value was not above every earlier one */
} tcol;

static uint64_t text_hash(const char *s, size_t len) {
  uint64_t h = (uint64_t)len * 0x9E3779B97F4A7C15ull, w;
  for (; len >= 8; s += 8, len -= 8) {
    memcpy(&w, s, 8);
    h = (h ^ w) * 0xff51afd7ed558ccdull;
    h ^= h >> 29;
  }
  if (len) {
    w = 0;
    memcpy(&w, s, len);
    h = (h ^ w) * 0xff51afd7ed558ccdull;
  }
  return h ^ (h >> 32);
}

/* The id of the text s[0..len) with hash hh, or -1 when the column has not seen it. */
static long tcol_find(const tcol *c, const char *s, size_t len, uint64_t hh) {
  if (!c->nslot) return -1;
  size_t mask = c->nslot - 1;
  for (size_t i = (size_t)hh & mask; c->slot[i]; i = (i + 1) & mask) {
    uint32_t id = c->slot[i] - 1;
    if (c->hash[id] == hh && c->len[id] == len && memcmp(c->s[id], s, len) == 0) return (long)id;
  }
  return -1;
}

/* Add a new text with its value; its id, or -1 when out of memory. */
static long tcol_add(tcol *c, const char *s, size_t len, double v, uint64_t hh) {
  if (c->n == c->cap) {
    size_t ncap = c->cap ? c->cap * 2 : 64;
    const char **ns = cv_realloc(c->s, ncap * sizeof *ns);
    if (ns) c->s = ns;
    size_t *nl = ns ? cv_realloc(c->len, ncap * sizeof *nl) : NULL;
    if (nl) c->len = nl;
    double *nv = nl ? cv_realloc(c->v, ncap * sizeof *nv) : NULL;
    if (nv) c->v = nv;
    uint64_t *nh = nv ? cv_realloc(c->hash, ncap * sizeof *nh) : NULL;
    if (!nh) return -1;
    c->hash = nh;
    c->cap = ncap;
  }
  if ((c->n + 1) * 2 > c->nslot) {
    size_t ns = c->nslot ? c->nslot * 2 : 128, mask = ns - 1;
    uint32_t *sl = cv_calloc(ns, sizeof *sl);
    if (!sl) return -1;
    for (size_t id = 0; id < c->n; id++) {
      size_t i = (size_t)c->hash[id] & mask;
      while (sl[i]) i = (i + 1) & mask;
      sl[i] = (uint32_t)id + 1;
    }
    cv_free(c->slot);
    c->slot = sl;
    c->nslot = ns;
  }
  size_t mask = c->nslot - 1, i = (size_t)hh & mask;
  while (c->slot[i]) i = (i + 1) & mask;
  c->slot[i] = (uint32_t)c->n + 1;
  if (c->n && !(v > c->v[c->n - 1])) c->unsorted = 1;
  c->s[c->n] = s;
  c->len[c->n] = len;
  c->v[c->n] = v;
  c->hash[c->n] = hh;
  return (long)c->n++;
}

static void tcol_free(tcol *c) {
  cv_free(c->s);
  cv_free(c->len);
  cv_free(c->v);
  cv_free(c->hash);
  cv_free(c->slot);
}

/* Whether the coordinate ids t of a row follow p, the previous row's, in the row-major
 * enumeration of the ids (the last coordinate fastest), the radices rad (0 = not known
 * yet: the digit has not wrapped around) being learnt on the way. Known radices are
 * always those of the last coordinates (a digit wraps only when all after it do). */
static int order_next(int dim, const uint32_t *p, const uint32_t *t, uint32_t *rad) {
  int d = 0;
  while (d < dim && t[d] == p[d]) d++;
  if (d == dim || t[d] != p[d] + 1 || (rad[d] && t[d] >= rad[d])) return 0;
  for (int e = d + 1; e < dim; e++)
    if (t[e] != 0 || (rad[e] && p[e] + 1 != rad[e])) return 0;
  for (int e = d + 1; e < dim; e++)
    if (!rad[e]) rad[e] = p[e] + 1;
  return 1;
}

/* The ids of the rows 0 .. nrows-1 when they were the enumeration of order_next: row r
 * in mixed radix (an unknown radix takes what is left: the digits before it are 0). */
static void decode_ids(int dim, const uint32_t *rad, size_t nrows, uint32_t *ids) {
  for (size_t r = 0; r < nrows; r++) {
    size_t q = r;
    for (int e = dim - 1; e >= 0; e--) {
      if (rad[e]) {
        ids[r * (size_t)dim + (size_t)e] = (uint32_t)(q % rad[e]);
        q /= rad[e];
      } else {
        ids[r * (size_t)dim + (size_t)e] = (uint32_t)q;
        q = 0;
      }
    }
  }
}

/* Index of x in the sorted distinct values c[0..n) (present by construction). */
static int locate(const double *c, int n, double x) {
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

/* The line of the data row number r (0-based; blank lines are no rows), the first row
 * being on or after `line` at p. Used only to report a repeated grid point. */
static int row_line(const char *p, const char *end, int line, size_t r) {
  for (;;) {
    const char *nl = memchr(p, '\n', (size_t)(end - p));
    const char *q = nl ? nl : end;
    const char *a = p;
    while (a < q && (is_sp(*a) || *a == '\r')) a++;
    if (a < q && r-- == 0) return line;
    if (!nl) return line;
    p = nl + 1;
    line++;
  }
}

/* The file's bytes: mapped when it is a regular file (no copy; the page cache is read
 * in place), else read into a buffer grown by doubling. 0, or -1 with errno set (EIO for
 * a read error, ENOMEM). */
static int table_bytes(int fd, char **text, size_t *len, int *mapped) {
  struct stat sb;
  *mapped = 0;
  if (fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0 &&
      (uint64_t)sb.st_size < (uint64_t)SIZE_MAX / 2) {
    int flags = MAP_PRIVATE;
#ifdef MAP_POPULATE
    flags |= MAP_POPULATE; /* one call maps every page instead of a fault per page */
#endif
    void *m = mmap(NULL, (size_t)sb.st_size, PROT_READ, flags, fd, 0);
    if (m != MAP_FAILED) {
      (void)posix_madvise(m, (size_t)sb.st_size, POSIX_MADV_SEQUENTIAL);
      *text = m;
      *len = (size_t)sb.st_size;
      *mapped = 1;
      return 0;
    }
  }
  size_t n = 0, cap = 1 << 16;
  char *buf = cv_malloc(cap);
  for (;;) {
    if (!buf) {
      errno = ENOMEM;
      return -1;
    }
    ssize_t got = read(fd, buf + n, cap - n);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      cv_free(buf);
      errno = EIO;
      return -1;
    }
    if (got == 0) break;
    n += (size_t)got;
    if (n == cap) {
      char *nb = cv_realloc(buf, cap *= 2);
      if (!nb) cv_free(buf);
      buf = nb;
    }
  }
  *text = buf;
  *len = n;
  return 0;
}

/* Open a [tables] file as a scene is opened (scene_file.c): a regular file only (a FIFO
 * would block, /dev/zero never ends), of at most SC_MAX_TABLE_BYTES. A descriptor, or -1
 * with a message. */
static int table_open(const char *path, const char *shown, char *err, size_t errlen) {
  struct stat st;
  if (stat(path, &st) != 0) {
    sc_err(err, errlen, shown, 0, "cannot open the table: %s", strerror(errno));
    return -1;
  }
  int fd = S_ISREG(st.st_mode) ? open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK) : -1;
  if (fd >= 0 && (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))) { /* replaced since stat */
    close(fd);
    fd = -1;
  }
  if (fd < 0) {
    sc_err(err, errlen, shown, 0, "cannot read a table from %s; give a CSV file",
           S_ISREG(st.st_mode)    ? strerror(errno)
           : S_ISDIR(st.st_mode)  ? "a directory"
           : S_ISFIFO(st.st_mode) ? "a FIFO (named pipe)"
                                  : "a device or socket");
    return -1;
  }
  if ((long long)st.st_size > SC_MAX_TABLE_BYTES) {
    close(fd);
    sc_err(err, errlen, shown, 0, "the table is larger than 1 GiB, the most calcvar reads");
    return -1;
  }
  return fd;
}

cv_table *sc_table_read(const char *path, const char *shown, char *err, size_t errlen) {
  cv_table *t = NULL;
  char *text = NULL;
  size_t len = 0;
  int mapped = 0;
  double *vals = NULL, *grid = NULL, *coords[3] = {NULL, NULL, NULL};
  uint32_t *ids = NULL, *rank[3] = {NULL, NULL, NULL};
  unsigned char *seen = NULL;
  tcol tc[3];
  memset(tc, 0, sizeof tc);
  for (int k = 0; k < 3; k++) tc[k].lastlen = SIZE_MAX; /* matches no field */
  size_t nrows = 0, caprows = 0;

  int fd = table_open(path, shown, err, errlen);
  if (fd < 0) return NULL;
  int bad = table_bytes(fd, &text, &len, &mapped);
  int why_bad = errno;
  close(fd);
  if (bad) {
    text = NULL;
    sc_err(err, errlen, shown, 0, why_bad == ENOMEM ? "out of memory" : "read error");
    goto done;
  }

  /* the header */
  const char *p = text, *end = text + len, *fs[TB_MAXCOL + 1];
  size_t fl[TB_MAXCOL + 1];
  int line = 1;
  const char *nl = len ? memchr(p, '\n', len) : NULL;
  const char *q = nl ? nl : end;
  if (q > p && q[-1] == '\r') q--;
  if (len && memchr(text, '\0', len)) {
    sc_err(err, errlen, shown, 0, "the table contains a NUL byte (not a text file)");
    goto done;
  }
  int ncol = p == q ? 0 : split(p, q, fs, fl);
  if (ncol < 2 || ncol > TB_MAXCOL) {
    sc_err(err, errlen, shown, 1,
           "the header must name 2 to 4 columns (1 to 3 coordinates, then the value), "
           "found %s%d",
           ncol > TB_MAXCOL ? "more than " : "", ncol > TB_MAXCOL ? TB_MAXCOL : ncol);
    goto done;
  }
  for (int c = 0; c < ncol; c++) {
    double dummy;
    if (fl[c] == 0 || parse_num(fs[c], fl[c], &dummy) == 0) {
      sc_err(err, errlen, shown, 1, "the header must name every column (column %d is %s)", c + 1,
             fl[c] ? "a number: is the header line missing?" : "empty");
      goto done;
    }
  }
  char names[TB_MAXCOL][64];
  for (int c = 0; c < ncol; c++)
    snprintf(names[c], sizeof names[c], "%.*s", (int)(fl[c] < 60 ? fl[c] : 60), fs[c]);
  int dim = ncol - 1;

  /* the rows, in one pass: each coordinate becomes the id of its text (read once per
   * distinct text), each value is read into vals in row order. Rows of a grid written in
   * order (the last coordinate fastest, each increasing) are already the grid: vals then
   * becomes the table's array without a copy. */
  const char *body = nl ? nl + 1 : end;
  p = body;
  int lastline = 0, inorder = 1;
  uint32_t prev[3] = {0, 0, 0}, rad[3] = {0, 0, 0};
  while (p < end) {
    line++;
    nl = memchr(p, '\n', (size_t)(end - p));
    q = nl ? nl : end;
    const char *r = q;
    if (r > p && r[-1] == '\r') r--;
    const char *a = p;
    while (a < r && is_sp(*a)) a++;
    if (a == r) { /* blank line */
      p = nl ? nl + 1 : end;
      continue;
    }
    int n = split(p, r, fs, fl);
    if (n != ncol) {
      sc_err(err, errlen, shown, line, "%s%d value%s in this row, the header has %d columns",
             n > TB_MAXCOL ? "more than " : "", n > TB_MAXCOL ? TB_MAXCOL : n, n == 1 ? "" : "s",
             ncol);
      goto done;
    }
    if (nrows == caprows) {
      /* a first guess from the file's size (about 40 bytes a row), then doubling */
      size_t ncap = caprows ? caprows * 2 : len / 32 + 1024;
      if (ncap > UINT32_MAX) ncap = UINT32_MAX;
      if (nrows == ncap) {
        sc_err(err, errlen, shown, line, "too many rows (at most %lu)", (unsigned long)UINT32_MAX);
        goto done;
      }
      double *nv = cv_realloc(vals, ncap * sizeof *nv);
      if (nv) vals = nv;
      uint32_t *ni = nv && ids ? cv_realloc(ids, ncap * (size_t)dim * sizeof *ni) : NULL;
      if (!nv || (ids && !ni)) {
        sc_err(err, errlen, shown, line, "out of memory");
        goto done;
      }
      if (ni) ids = ni;
      caprows = ncap;
    }
    uint32_t rid[3];
    for (int c = 0; c < dim; c++) {
      tcol *T = &tc[c];
      if (fl[c] == T->lastlen && memcmp(fs[c], T->last, fl[c]) == 0) {
        rid[c] = T->lastid;
        continue;
      }
      /* next most likely (a fast coordinate of a grid in order): the text after the
       * previous one, or the first again */
      uint32_t guess = T->lastid + 1 < T->n ? T->lastid + 1 : 0;
      if (T->n && fl[c] == T->len[guess] && memcmp(fs[c], T->s[guess], fl[c]) == 0) {
        rid[c] = T->lastid = guess;
        T->last = fs[c];
        T->lastlen = fl[c];
        continue;
      }
      uint64_t hh = text_hash(fs[c], fl[c]);
      long id = tcol_find(T, fs[c], fl[c], hh);
      if (id < 0) {
        double x;
        if (parse_num(fs[c], fl[c], &x) != 0) {
          sc_err(err, errlen, shown, line, "column '%s': '%.*s' is not a number", names[c],
                 (int)(fl[c] < 40 ? fl[c] : 40), fs[c]);
          goto done;
        }
        if (!isfinite(x)) {
          sc_err(err, errlen, shown, line, "column '%s': %.*s is not a finite number", names[c],
                 (int)(fl[c] < 40 ? fl[c] : 40), fs[c]);
          goto done;
        }
        id = tcol_add(T, fs[c], fl[c], x == 0 ? 0.0 : x, hh); /* -0 and 0: one coordinate */
        if (id < 0) {
          sc_err(err, errlen, shown, line, "out of memory");
          goto done;
        }
      }
      rid[c] = (uint32_t)id;
      T->last = fs[c];
      T->lastlen = fl[c];
      T->lastid = (uint32_t)id;
    }
    if (parse_num(fs[dim], fl[dim], &vals[nrows]) != 0) {
      sc_err(err, errlen, shown, line, "column '%s': '%.*s' is not a number", names[dim],
             (int)(fl[dim] < 40 ? fl[dim] : 40), fs[dim]);
      goto done;
    }
    if (!isfinite(vals[nrows])) {
      sc_err(err, errlen, shown, line, "column '%s': %.*s is not a finite number", names[dim],
             (int)(fl[dim] < 40 ? fl[dim] : 40), fs[dim]);
      goto done;
    }
    /* rows in the order of the grid need no ids: they follow from the row number */
    if (inorder && nrows && !order_next(dim, prev, rid, rad)) {
      inorder = 0;
      ids = cv_malloc(caprows * (size_t)dim * sizeof *ids);
      if (!ids) {
        sc_err(err, errlen, shown, line, "out of memory");
        goto done;
      }
      decode_ids(dim, rad, nrows, ids);
    }
    if (inorder)
      memcpy(prev, rid, sizeof prev);
    else
      memcpy(ids + nrows * (size_t)dim, rid, (size_t)dim * sizeof *rid);
    nrows++;
    lastline = line;
    p = nl ? nl + 1 : end;
  }
  if (nrows == 0) {
    sc_err(err, errlen, shown, 1, "the table has a header but no rows");
    goto done;
  }

  /* the grid: distinct coordinate values, sorted; each text's id -> its index there */
  int n[3] = {1, 1, 1};
  size_t size = 1, stride[3] = {0, 0, 0};
  for (int k = 0; k < dim; k++) {
    coords[k] = cv_malloc(tc[k].n * sizeof *coords[k]);
    if (!coords[k]) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
    memcpy(coords[k], tc[k].v, tc[k].n * sizeof *coords[k]);
    qsort(coords[k], tc[k].n, sizeof *coords[k], cmp_double);
    size_t m = 0;
    for (size_t i = 0; i < tc[k].n; i++)
      if (m == 0 || coords[k][i] != coords[k][m - 1]) coords[k][m++] = coords[k][i];
    if (m < 4) {
      sc_err(err, errlen, shown, 1,
             "coordinate '%s' has %zu distinct value%s; a cubic spline needs at least 4", names[k],
             m, m == 1 ? "" : "s");
      goto done;
    }
    rank[k] = cv_malloc(tc[k].n * sizeof *rank[k]);
    if (!rank[k]) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
    for (size_t i = 0; i < tc[k].n; i++)
      rank[k][i] = (uint32_t)locate(coords[k], (int)m, tc[k].v[i]);
    n[k] = (int)m;
    size *= m;
  }
  stride[dim - 1] = 1;
  for (int k = dim - 2; k >= 0; k--) stride[k] = stride[k + 1] * (size_t)n[k + 1];
#define TB_INDEX(r)                                                                                \
  (dim == 1   ? (size_t)rank[0][ids[(r)]]                                                          \
   : dim == 2 ? (size_t)rank[0][ids[2 * (r)]] * stride[0] + rank[1][ids[2 * (r) + 1]]              \
              : (size_t)rank[0][ids[3 * (r)]] * stride[0] +                                        \
                    (size_t)rank[1][ids[3 * (r) + 1]] * stride[1] + rank[2][ids[3 * (r) + 2]])
  /* In the order of the grid: the ids are the enumeration of order_next, complete (as
   * many rows as points), and each coordinate's values came in increasing order (an
   * id is then the index in the sorted values). Otherwise the ids are needed. */
  int identity = inorder && nrows == size;
  for (int k = 0; k < dim; k++)
    if (tc[k].unsorted || tc[k].n != (size_t)n[k]) identity = 0;
  if (inorder && !identity) {
    ids = cv_malloc(nrows * (size_t)dim * sizeof *ids);
    if (!ids) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
    decode_ids(dim, rad, nrows, ids);
  }
  if (identity) { /* the values are the grid */
    grid = vals;
    vals = NULL;
    if (caprows > size) { /* give back the unused tail */
      double *g = cv_realloc(grid, size * sizeof *g);
      if (g) grid = g;
    }
  } else {
    grid = cv_malloc(size * sizeof *grid);
    seen = cv_calloc(size / 8 + 1, 1);
    if (!grid || !seen) {
      sc_err(err, errlen, shown, 0, "out of memory");
      goto done;
    }
    for (size_t r = 0; r < nrows; r++) {
      size_t idx = TB_INDEX(r);
      if (seen[idx >> 3] & (1u << (idx & 7))) {
        size_t first = 0;
        while (TB_INDEX(first) != idx) first++;
        sc_err(err, errlen, shown, row_line(body, end, 2, r),
               "repeated grid point (also on line %d)", row_line(body, end, 2, first));
        goto done;
      }
      seen[idx >> 3] |= (unsigned char)(1u << (idx & 7));
      grid[idx] = vals[r];
    }
  }
#undef TB_INDEX
  if (nrows != size) {
    size_t miss = 0;
    while (seen[miss >> 3] & (1u << (miss & 7))) miss++;
    size_t rest = miss;
    double u[3] = {0, 0, 0};
    for (int k = dim - 1; k >= 0; k--) {
      u[k] = coords[k][rest % (size_t)n[k]];
      rest /= (size_t)n[k];
    }
    char at[200];
    int o = 0;
    for (int k = 0; k < dim; k++)
      o += snprintf(at + o, sizeof at - (size_t)o, "%s%s = %.17g", k ? ", " : "", names[k], u[k]);
    sc_err(err, errlen, shown, lastline,
           "the grid is not complete: %zu of %zu points are missing, e.g. %s (every "
           "combination of the coordinate values must have a row)",
           size - nrows, size, at);
    goto done;
  }
  /* the table takes grid as its own array of values (freed by it on failure too) */
  cv_free(vals);
  vals = NULL;
  cv_free(ids);
  ids = NULL;
  cv_status why;
  char msg[200];
  t = cv_table_new_owned(dim, n, (const double *const *)coords, grid, &why, msg, sizeof msg);
  grid = NULL;
  if (!t) sc_err(err, errlen, shown, 0, "%s", msg);
done:
  if (mapped)
    munmap(text, len);
  else
    cv_free(text);
  cv_free(vals);
  cv_free(grid);
  cv_free(ids);
  cv_free(seen);
  for (int k = 0; k < 3; k++) {
    cv_free(coords[k]);
    cv_free(rank[k]);
    tcol_free(&tc[k]);
  }
  return t;
}

/* [tables]: `name = file.csv`, a path relative to the scene's directory (the current one
 * for a scene without a file, e.g. standard input) or absolute. Loaded before every other
 * name, so parameters and definitions may not reuse a table's name and every expression
 * may call it. */
int sc_load_tables(sc_loader *L) {
  scene *s = L->s;
  const char *file = s->file;
  const char *slash = strrchr(file, '/');
  int from_file = strcmp(file, "<stdin>") != 0 && strncmp(file, "gallery:", 8) != 0;
  size_t dirlen = from_file && slash ? (size_t)(slash - file) + 1 : 0;
  for (int i = 0; i < L->raw.ne[SEC_TABLES]; i++) {
    const sc_entry *e = &L->raw.e[SEC_TABLES][i];
    if (sc_check_new_name(L, e->line, e->key, "a table") < 0) return -1;
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
