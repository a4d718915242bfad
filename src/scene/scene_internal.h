/* src/scene/scene_internal.h — private types of the scene loader: logical lines, raw entries.
 * SPDX-License-Identifier: MIT */
#ifndef CV_SCENE_INTERNAL_H
#define CV_SCENE_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>

#include "core/cv_memory.h"
#include "scene/scene.h"

/* Where a piece of a (possibly continued) value came from: the value's characters from
 * `off` on were read from physical line `line`, starting at 1-based column `col`. Used to
 * turn an expression error at "column C" of the joined value back into FILE:LINE. */
typedef struct {
  int off;
  int line;
  int col;
} sc_piece;

/* One `key = value` after the pre-pass: comments stripped, continuation lines joined by
 * one space, surrounding white space trimmed. */
typedef struct {
  char *key;
  char *value;
  int line; /* physical line of the key */
  int npieces;
  sc_piece *pieces;
} sc_entry;

typedef enum {
  SEC_SCENE,
  SEC_PARAMETERS,
  SEC_DEFINITIONS,
  SEC_BOUNDARY,
  SEC_GUESS,
  SEC_CONSTRAINTS,
  SEC_INTEGRALS,
  SEC_EXACT,
  SEC_REPORT,
  SEC_MESH,
  SEC_SOLVER,
  SEC_TABLES,
  SEC_PLOT,
  SEC_ENDS,
  SEC_COUNT
} sc_section;

/* A logical line: a section header or a key line (with its continuations). */
typedef struct {
  int is_section;
  int section; /* is_section: the sc_section */
  int line;    /* physical line where it starts */
  sc_entry entry;
} sc_lline;

typedef struct {
  int n;
  sc_lline *l;
} sc_llines;

/* Entries per section in file order, as inih delivered them. */
typedef struct {
  const char *file;
  sc_entry *e[SEC_COUNT];
  int ne[SEC_COUNT];
  int sec_line[SEC_COUNT]; /* line of the section header, 0 when absent */
} sc_raw;

/* scene_error.c */
void sc_err(char *err, size_t errlen, const char *file, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
char *sc_strdup(const char *s);
char *sc_strndup(const char *s, size_t n);

/* scene_lines.c: the pre-pass (physical lines -> logical lines). */
const char *sc_section_name(int sec);
int sc_section_from_name(const char *name);
int sc_llines_read(sc_llines *ll, const char *text, size_t len, const char *file, char *err,
                   size_t errlen);
void sc_llines_free(sc_llines *ll);

/* scene_ini.c: feed the logical lines through libinih, collect entries per section. */
int sc_raw_read(sc_raw *raw, const char *text, size_t len, const char *file, char *err,
                size_t errlen);
void sc_raw_free(sc_raw *raw);
void sc_entry_free(sc_entry *e);

/* Map a 0-based offset in an entry's value to a physical line and 1-based column. */
void sc_entry_locate(const sc_entry *e, int off, int *line, int *col);

/* scene_names.c: the names a scene may not define (the grammar's reserved names and free). */
int sc_is_reserved(const char *s);
/* Whether s is UTF-8 text (a title goes into the JSON report). */
int sc_is_utf8(const char *s);
/* The most unknowns a scene may have (the compiled integrand's own limit). */
enum { SC_MAX_UNKNOWNS = 1000 };

/* scene_namemap.c: names (borrowed) to non-negative integers, found in constant time. */
typedef struct {
  const char **key; /* NULL: an empty bucket */
  int *val;
  size_t cap, n;
} sc_namemap;
/* The value of name, or -1. */
int sc_namemap_get(const sc_namemap *m, const char *name);
/* Add name (or give it a new value): 0, or -1 out of memory. */
int sc_namemap_put(sc_namemap *m, const char *name, int val);
void sc_namemap_free(sc_namemap *m);

/* The loader's state while it interprets the entries (scene_load.c and friends). */
typedef enum { SC_R_PARAM, SC_R_FULL } sc_rmode;
typedef struct {
  scene *s;
  sc_raw raw;
  const char *file;
  char *err;
  size_t errlen;
  sc_rmode mode;    /* what names resolve: parameters only, or everything */
  int limit;        /* parameters (SC_R_PARAM) or definitions (SC_R_FULL) usable: index < limit */
  int second;       /* the value being parsed may use y'' (sc_parse) */
  sc_namemap names; /* every name defined so far: SC_NAME_CODE(kind, index) */
} sc_loader;

/* The kinds of names in sc_loader.names, and their codes there. */
enum { SC_NAME_VARIABLE, SC_NAME_UNKNOWN, SC_NAME_PARAMETER, SC_NAME_DEFINITION, SC_NAME_KINDS };
#define SC_NAME_CODE(kind, index) ((index)*SC_NAME_KINDS + (kind))
/* The index of name if it is of the given kind, else -1. */
int sc_name_find(const sc_loader *L, const char *name, int kind);
/* Record a name that sc_check_new_name accepted: 0, or -1 (with a message) out of memory. */
int sc_name_add(sc_loader *L, int line, const char *name, int kind, int index);

/* scene_parse.c */
ex_id sc_parse(sc_loader *L, const sc_entry *e, int off, const char *text, const char *what);
int sc_parse_const(sc_loader *L, const sc_entry *e, int off, const char *text, const char *what,
                   double *value);
/* The same, also giving the expression (an expression of the parameters when they are
 * inputs; node may be NULL). */
/* The core's smoothing hook for an integrand compiled with its jumps smoothable: the width
 * is its last input (theory HC-4; scene_problem.c). */
void sc_set_smoothing_width(void *user, double w);
int sc_parse_const_node(sc_loader *L, const sc_entry *e, int off, const char *text,
                        const char *what, double *value, ex_id *node);
/* Value of a constant expression of the parameters at their current values (0, or -1 on
 * allocation failure). */
int sc_eval_params(const scene *s, ex_id e, double *value);
const char *sc_slot_name(const scene *s, int slot, char *buf, size_t cap);
int sc_first_slot(const scene *s, ex_id e, int from, int to);

/* scene_order2.c: which unknowns are second order; slope lines checked against them. */
int sc_load_order2(sc_loader *L);
/* A slope line `y' = a, b` of [boundary] (entry e, unknown k): parsed into s->sbc[k]. */
int sc_load_slope_line(sc_loader *L, const sc_entry *e, int k);
/* Whether e reads some y''; the first such unknown's index in *which (may be NULL). */
int sc_uses_second(const scene *s, ex_id e, int *which);

/* scene_load.c: a new name (identifier, not reserved, not taken; `role` for the message). */
int sc_check_new_name(sc_loader *L, int line, const char *name, const char *role);

/* scene_table.c: the [tables] section, and one CSV grid read into a table (`shown` names
 * the file in messages "FILE:LINE: ..."; NULL with the message in err). */
int sc_load_tables(sc_loader *L);
struct cv_table *sc_table_read(const char *path, const char *shown, char *err, size_t errlen);

/* scene_eval.c */
/* The same with y'' (d2y[i*m + k]; NULL where no expression reads it). */
int sc_eval_exprs2(const scene *s, int nout, const ex_id *outs, int m, const double *x,
                   const double *y, const double *dy, const double *d2y, double *out);
int sc_eval_exprs(const scene *s, int nout, const ex_id *outs, int m, const double *x,
                  const double *y, const double *dy, double *out);

/* Every key of a fixed-key section must be one of `keys` (NULL-terminated); `list` names
 * them for the message. Returns 0, or -1 with FILE:LINE in L->err. */
int sc_check_keys(sc_loader *L, int sec, const char *const *keys, const char *list);

/* The opaque public handle of calcvar.h (cv_scene.c, cv_mechanics.c): a loaded scene. */
struct cv_scene {
  scene *s;
};

#endif /* CV_SCENE_INTERNAL_H */
