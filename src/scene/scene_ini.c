/* src/scene/scene_ini.c — feed the logical lines through libinih, collect entries per section.
 * SPDX-License-Identifier: MIT
 *
 * inih reads through ini_parse_stream with our reader, which hands out one canonical line
 * per logical line: "[section]" or "KEY = @INDEX". The value itself stays in the logical
 * line (any length: INI_MAX_LINE never cuts it) and the handler fetches it by INDEX. inih
 * processes each line right after reading it, so the reader's current index is also the
 * handler's line (Debian's inih passes no line number: INI_HANDLER_LINENO is 0). inih
 * decides what is a section and what is a key; the handler rejects keys outside a
 * section and keys given twice.
 */
#include <ini.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

typedef struct {
  sc_llines *ll;
  sc_raw *raw;
  int next; /* next logical line the reader hands out */
  int cur;  /* the logical line inih is processing */
  char *err;
  size_t errlen;
  int failed;
  int cap[SEC_COUNT];         /* room in raw->e[sec] (grown by doubling) */
  sc_namemap keys[SEC_COUNT]; /* the keys of each section so far: key -> index */
} feed;

static char *reader(char *str, int num, void *stream) {
  feed *f = stream;
  if (f->next >= f->ll->n) return NULL;
  f->cur = f->next++;
  const sc_lline *l = &f->ll->l[f->cur];
  if (l->is_section)
    snprintf(str, (size_t)num, "[%s]\n", sc_section_name(l->section));
  else
    snprintf(str, (size_t)num, "%s = @%d\n", l->entry.key, f->cur);
  return str;
}

static int handler(void *user, const char *section, const char *name, const char *value) {
  feed *f = user;
  sc_lline *l = &f->ll->l[f->cur];
  const char *file = f->raw->file;
  char *end;
  long idx = value[0] == '@' ? strtol(value + 1, &end, 10) : -1;

  if (l->is_section || idx != f->cur || *end || strcmp(name, l->entry.key) != 0) {
    /* inih split the line somewhere else than at our '=' (it also accepts ':'). */
    sc_err(f->err, f->errlen, file, l->line, "expected 'name = value', got a ':' in '%s'",
           l->is_section ? "" : l->entry.key);
    f->failed = 1;
    return 0;
  }
  int sec = sc_section_from_name(section);
  if (sec < 0) {
    sc_err(f->err, f->errlen, file, l->line, "'%s' is outside any section (start with [scene])",
           name);
    f->failed = 1;
    return 0;
  }
  sc_raw *raw = f->raw;
  int first = sc_namemap_get(&f->keys[sec], name);
  if (first >= 0) {
    sc_err(f->err, f->errlen, file, l->line, "'%s' is given twice in [%s] (first at line %d)", name,
           section, raw->e[sec][first].line);
    f->failed = 1;
    return 0;
  }
  if (raw->ne[sec] == f->cap[sec]) {
    int ncap = f->cap[sec] ? 2 * f->cap[sec] : 16;
    sc_entry *e = cv_realloc(raw->e[sec], (size_t)ncap * sizeof *e);
    if (!e) {
      sc_err(f->err, f->errlen, file, l->line, "out of memory");
      f->failed = 1;
      return 0;
    }
    raw->e[sec] = e;
    f->cap[sec] = ncap;
  }
  if (sc_namemap_put(&f->keys[sec], l->entry.key, raw->ne[sec]) < 0) {
    sc_err(f->err, f->errlen, file, l->line, "out of memory");
    f->failed = 1;
    return 0;
  }
  raw->e[sec][raw->ne[sec]++] = l->entry; /* ownership moves to raw */
  memset(&l->entry, 0, sizeof l->entry);
  return 1;
}

void sc_raw_free(sc_raw *raw) {
  for (int s = 0; s < SEC_COUNT; s++) {
    for (int i = 0; i < raw->ne[s]; i++) sc_entry_free(&raw->e[s][i]);
    cv_free(raw->e[s]);
    raw->e[s] = NULL;
    raw->ne[s] = 0;
  }
}

int sc_raw_read(sc_raw *raw, const char *text, size_t len, const char *file, char *err,
                size_t errlen) {
  sc_llines ll;
  memset(raw, 0, sizeof *raw);
  raw->file = file;
  if (sc_llines_read(&ll, text, len, file, err, errlen) < 0) return -1;
  for (int i = 0; i < ll.n; i++)
    if (ll.l[i].is_section) raw->sec_line[ll.l[i].section] = ll.l[i].line;

  feed f = {&ll, raw, 0, 0, err, errlen, 0, {0}, {{0}}};
  int r = ini_parse_stream(reader, &f, handler, &f);
  for (int k = 0; k < SEC_COUNT; k++) sc_namemap_free(&f.keys[k]);
  if (r != 0 && !f.failed) {
    /* inih found a syntax error the pre-pass let through: r is the canonical line. */
    int line = r > 0 && r <= ll.n ? ll.l[r - 1].line : 0;
    sc_err(err, errlen, file, line, "syntax error");
  }
  sc_llines_free(&ll);
  if (r != 0) {
    sc_raw_free(raw);
    return -1;
  }
  return 0;
}
