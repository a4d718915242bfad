/* src/scene/scene_lines.c — the pre-pass: physical lines to logical lines with line numbers.
 * SPDX-License-Identifier: MIT
 *
 * Why a pre-pass before libinih: Debian's inih is built with INI_MAX_LINE 200 (a longer
 * line is split and its tail parsed as a line of its own), inline comments only with ';',
 * and INI_HANDLER_LINENO 0 (the handler never learns the line). SCENES.md allows '#'
 * comments after white space, values continued on indented lines and expressions of any
 * length, and every message must name its line. So this pass reads the text itself:
 * strips comments, joins continuations, records where each character came from, and
 * checks section headers (inih does not report empty sections to the handler). inih then
 * receives one short canonical line per logical line (scene_ini.c).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expr/expr.h"
#include "scene/scene_internal.h"

static const char *const section_names[SEC_COUNT] = {
    "scene", "parameters", "definitions", "boundary", "guess",  "constraints", "integrals",
    "exact", "report",     "mesh",        "solver",   "tables", "plot",        "ends"};

/* Longest key passed to inih: its reader hands out at most INI_MAX_LINE = 200 bytes per
 * line, and "KEY = @INDEX\n" must fit. No legitimate name comes close. */
enum { MAX_KEY = 100 };

const char *sc_section_name(int sec) {
  return sec >= 0 && sec < SEC_COUNT ? section_names[sec] : "?";
}

int sc_section_from_name(const char *name) {
  for (int i = 0; i < SEC_COUNT; i++)
    if (strcmp(name, section_names[i]) == 0) return i;
  return -1;
}

static int is_ws(char c) { return c == ' ' || c == '\t'; }

void sc_entry_free(sc_entry *e) {
  cv_free(e->key);
  cv_free(e->value);
  cv_free(e->pieces);
  memset(e, 0, sizeof *e);
}

void sc_llines_free(sc_llines *ll) {
  for (int i = 0; i < ll->n; i++) sc_entry_free(&ll->l[i].entry);
  cv_free(ll->l);
  ll->l = NULL;
  ll->n = 0;
}

void sc_entry_locate(const sc_entry *e, int off, int *line, int *col) {
  *line = e->line;
  *col = 0;
  for (int i = 0; i < e->npieces; i++)
    if (e->pieces[i].off <= off) {
      *line = e->pieces[i].line;
      *col = e->pieces[i].col + (off - e->pieces[i].off);
    }
}

/* Show at most 40 characters of a bad line in a message. */
static void excerpt(char *dst, size_t cap, const char *s, size_t n) {
  size_t k = n < cap - 4 ? n : cap - 4;
  memcpy(dst, s, k);
  if (k < n)
    memcpy(dst + k, "...", 4);
  else
    dst[k] = '\0';
}

static sc_lline *push(sc_llines *ll, int *cap) {
  if (ll->n == *cap) {
    int nc = *cap ? 2 * *cap : 16;
    sc_lline *l = cv_realloc(ll->l, (size_t)nc * sizeof *l);
    if (!l) return NULL;
    ll->l = l;
    *cap = nc;
  }
  sc_lline *r = &ll->l[ll->n++];
  memset(r, 0, sizeof *r);
  return r;
}

/* Append a continuation piece (text t of length n, read at line/col) to entry e. */
static int append_piece(sc_entry *e, const char *t, size_t n, int line, int col) {
  size_t old = strlen(e->value);
  char *v = cv_realloc(e->value, old + n + 2);
  sc_piece *p = cv_realloc(e->pieces, (size_t)(e->npieces + 1) * sizeof *p);
  if (v) e->value = v;
  if (p) e->pieces = p;
  if (!v || !p) return -1;
  size_t off = old;
  if (old > 0) v[off++] = ' ';
  memcpy(v + off, t, n);
  v[off + n] = '\0';
  e->pieces[e->npieces].off = (int)off;
  e->pieces[e->npieces].line = line;
  e->pieces[e->npieces].col = col;
  e->npieces++;
  return 0;
}

/* Read the text into logical lines. Returns 0, or -1 with a message in err. */
int sc_llines_read(sc_llines *ll, const char *text, size_t len, const char *file, char *err,
                   size_t errlen) {
  int cap = 0, line = 0, seen[SEC_COUNT] = {0};
  sc_lline *cur_key = NULL; /* the key line that indented lines continue */
  char buf[48];
  size_t pos = 0;

  ll->n = 0;
  ll->l = NULL;
  if (len >= 3 && (unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB &&
      (unsigned char)text[2] == 0xBF)
    pos = 3; /* UTF-8 byte order mark, as inih skips it */

  while (pos < len) {
    line++;
    const char *s = text + pos;
    const char *nl = memchr(s, '\n', len - pos);
    size_t n = nl ? (size_t)(nl - s) : len - pos;
    pos += n + (nl ? 1 : 0);
    if (memchr(s, '\0', n)) {
      sc_err(err, errlen, file, line, "a NUL byte: this is not a text file");
      goto fail;
    }
    if (n > 0 && s[n - 1] == '\r') n--; /* CRLF line ends */

    /* A comment starts at '#' or ';' at the start of the line or after white space. */
    for (size_t i = 0; i < n; i++)
      if ((s[i] == '#' || s[i] == ';') && (i == 0 || is_ws(s[i - 1]))) {
        n = i;
        break;
      }
    size_t lead = 0;
    while (lead < n && is_ws(s[lead])) lead++;
    while (n > lead && is_ws(s[n - 1])) n--;
    if (lead == n) continue; /* blank or comment: does not end a continued value (as in inih) */
    const char *t = s + lead;
    size_t tn = n - lead;

    if (lead > 0 && cur_key) {
      if (append_piece(&cur_key->entry, t, tn, line, (int)lead + 1) < 0) goto nomem;
      continue;
    }
    cur_key = NULL;
    if (t[0] == '[') {
      const char *close = memchr(t, ']', tn);
      if (!close || close != t + tn - 1) {
        excerpt(buf, sizeof buf, t, tn);
        sc_err(err, errlen, file, line,
               close ? "text after the section header '%s'"
                     : "a section header needs a "
                       "closing ']': '%s'",
               buf);
        goto fail;
      }
      size_t a = 1, b = tn - 1;
      while (a < b && is_ws(t[a])) a++;
      while (b > a && is_ws(t[b - 1])) b--;
      char name[32];
      int sec = -1;
      if (b - a < sizeof name) {
        memcpy(name, t + a, b - a);
        name[b - a] = '\0';
        sec = sc_section_from_name(name);
      }
      if (sec < 0) { /* the known sections, the nearest first if one is a slip away */
        char known[256] = "", hint[64] = "";
        size_t kl = 0;
        ex_nearest nr = {NULL, 0};
        for (int k = 0; k < SEC_COUNT; k++) {
          kl += (size_t)snprintf(known + kl, sizeof known - kl, "%s%s", k ? ", " : "",
                                 section_names[k]);
          if (b - a < sizeof name) ex_name_consider(&nr, name, section_names[k]);
        }
        if (nr.best) snprintf(hint, sizeof hint, "did you mean [%s]? ", nr.best);
        excerpt(buf, sizeof buf, t + a, b - a);
        sc_err(err, errlen, file, line, "unknown section [%s] (%sknown: %s)", buf, hint, known);
        goto fail;
      }
      if (seen[sec]) {
        sc_err(err, errlen, file, line, "section [%s] is given twice (first at line %d)", name,
               seen[sec]);
        goto fail;
      }
      seen[sec] = line;
      sc_lline *l = push(ll, &cap);
      if (!l) goto nomem;
      l->is_section = 1;
      l->section = sec;
      l->line = line;
      continue;
    }
    const char *eq = memchr(t, '=', tn);
    if (!eq) {
      excerpt(buf, sizeof buf, t, tn);
      sc_err(err, errlen, file, line, "expected 'name = value' or '[section]', got '%s'", buf);
      goto fail;
    }
    size_t kn = (size_t)(eq - t);
    while (kn > 0 && is_ws(t[kn - 1])) kn--;
    if (kn == 0) {
      sc_err(err, errlen, file, line, "a name is missing before '='");
      goto fail;
    }
    if (kn > MAX_KEY) {
      sc_err(err, errlen, file, line, "a name of %zu characters is too long", kn);
      goto fail;
    }
    const char *v = eq + 1;
    while (v < t + tn && is_ws(*v)) v++;
    sc_lline *l = push(ll, &cap);
    if (!l) goto nomem;
    l->line = line;
    l->entry.line = line;
    l->entry.key = sc_strndup(t, kn);
    l->entry.value = sc_strdup("");
    if (!l->entry.key || !l->entry.value) goto nomem;
    if (append_piece(&l->entry, v, (size_t)(t + tn - v), line, (int)(v - s) + 1) < 0) goto nomem;
    cur_key = l;
  }
  return 0;

nomem:
  sc_err(err, errlen, file, line, "out of memory");
fail:
  sc_llines_free(ll);
  return -1;
}
