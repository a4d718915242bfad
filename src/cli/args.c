/* src/cli/args.c — command-line options of `solve` (SCENES.md "Options of solve").
 * SPDX-License-Identifier: MIT
 *
 * Both "--opt VALUE" and "--opt=VALUE" are accepted. Every value is checked here, so a
 * bad flag is reported before any scene is read or any file is written.
 */
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli/cli.h"

static int bad(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static int bad(const char *cmd, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "calcvar %s: ", cmd);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n");
  va_end(ap);
  return EXIT_BADINPUT;
}

static int parse_int(const char *s, long lo, long hi, int *out) {
  char *end;
  if (!(*s >= '0' && *s <= '9') && *s != '+') return -1;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || *end || v < lo || v > hi) return -1;
  *out = (int)v;
  return 0;
}

static int parse_pos_double(const char *s, double *out) {
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (end == s || *end || !isfinite(v) || !(v > 0)) return -1;
  *out = v;
  return 0;
}

void cli_opts_free(cli_opts *o) { free(o->set); }

int cli_args_parse(const char *cmd, int argc, char **argv, cli_opts *o) {
  memset(o, 0, sizeof *o);
  o->method = -1;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i], *v = NULL;
    char name[32];
    if (strcmp(a, "--") == 0 || a[0] != '-' || strcmp(a, "-") == 0) {
      if (strcmp(a, "--") == 0 && ++i >= argc) break;
      if (o->scene_path)
        return bad(cmd, "one scene file only: '%s' and '%s'", o->scene_path, argv[i]);
      o->scene_path = argv[i];
      continue;
    }
    const char *eq = strchr(a, '=');
    size_t nl = eq ? (size_t)(eq - a) : strlen(a);
    if (nl >= sizeof name) return bad(cmd, "unknown option '%s'", a);
    memcpy(name, a, nl);
    name[nl] = '\0';
    int flag = strcmp(name, "--quiet") == 0 || strcmp(name, "--help") == 0 ||
               strcmp(name, "-h") == 0 || strcmp(name, "--all") == 0 ||
               strcmp(name, "--verbose") == 0 || strcmp(name, "-v") == 0;
    static const char *const valued[] = {
        "--elements",   "--degree",    "--method", "--tolerance", "--max-iterations",
        "--set",        "--adapt",     "--tol",    "--continue",  "--json",
        "--csv",        "--plot",      "--max",    "--work",      "--max-elements",
        "--time-limit", "--max-nodes", NULL};
    int known = flag;
    for (int k = 0; valued[k]; k++) known |= strcmp(name, valued[k]) == 0;
    if (!known) return bad(cmd, "unknown option '%s' (see calcvar --help)", name);
    if (flag) {
      if (eq) return bad(cmd, "%s takes no value", name);
      if (strcmp(name, "--quiet") == 0)
        o->quiet = 1;
      else if (strcmp(name, "--all") == 0)
        o->all = 1;
      else if (strcmp(name, "--verbose") == 0 || strcmp(name, "-v") == 0)
        o->verbose = 1;
      else
        o->help = 1;
      continue;
    }
    if (eq)
      v = eq + 1;
    else if (i + 1 < argc)
      v = argv[++i];
    else
      return bad(cmd, "%s needs a value", name);

    if (strcmp(name, "--elements") == 0) {
      /* INT_MAX / 9 keeps nodes = elements * degree + 1 an int at degree 8. */
      if (parse_int(v, 1, INT_MAX / 9, &o->elements) < 0)
        return bad(cmd, "--elements needs a whole number >= 1, got '%s'", v);
    } else if (strcmp(name, "--degree") == 0) {
      if (parse_int(v, 1, 8, &o->degree) < 0)
        return bad(cmd, "--degree needs a whole number from 1 to 8, got '%s'", v);
    } else if (strcmp(name, "--max") == 0) {
      if (parse_int(v, 1, 1000, &o->max_paths) < 0)
        return bad(cmd, "--max needs a whole number of paths from 1 to 1000, got '%s'", v);
    } else if (strcmp(name, "--work") == 0) {
      if (parse_pos_double(v, &o->work) < 0 || o->work < 1 || o->work > 1e6)
        return bad(cmd, "--work needs a factor from 1 to 1e6, got '%s'", v);
    } else if (strcmp(name, "--max-iterations") == 0) {
      if (parse_int(v, 1, INT_MAX, &o->max_iterations) < 0)
        return bad(cmd, "--max-iterations needs a whole number >= 1, got '%s'", v);
    } else if (strcmp(name, "--method") == 0) {
      cv_method m;
      if (cv_method_from_name(v, &m) != CVAR_OK)
        return bad(cmd,
                   "unknown method '%s' (known: newton, lbfgs, tnewton, mma, ccsaq, "
                   "slsqp, auglag)",
                   v);
      o->method = (int)m;
    } else if (strcmp(name, "--tolerance") == 0) {
      if (parse_pos_double(v, &o->tolerance) < 0 || o->tolerance < 10 * DBL_EPSILON ||
          o->tolerance >= 1)
        return bad(cmd,
                   "--tolerance needs a number from 2.2e-15 (10 eps) to below 1, "
                   "got '%s'",
                   v);
    } else if (strcmp(name, "--max-elements") == 0) {
      if (parse_int(v, 1, INT_MAX / 9, &o->max_elements) < 0)
        return bad(cmd, "--max-elements needs a whole number >= 1, got '%s'", v);
    } else if (strcmp(name, "--max-nodes") == 0) {
      if (parse_int(v, 2, INT_MAX / 9, &o->max_nodes) < 0)
        return bad(cmd, "--max-nodes needs a whole number >= 2, got '%s'", v);
    } else if (strcmp(name, "--adapt") == 0) {
      if (parse_pos_double(v, &o->adapt) < 0)
        return bad(cmd, "--adapt needs a target error > 0, got '%s'", v);
    } else if (strcmp(name, "--time-limit") == 0) {
      if (parse_pos_double(v, &o->time_limit) < 0 || o->time_limit > 1e9)
        return bad(cmd, "--time-limit needs a number of seconds > 0 (at most 1e9), got '%s'", v);
    } else if (strcmp(name, "--tol") == 0) {
      if (parse_pos_double(v, &o->tol) < 0)
        return bad(cmd, "--tol needs a target max nodal error > 0, got '%s'", v);
    } else if (strcmp(name, "--set") == 0) {
      const char *e = strchr(v, '=');
      if (!e || e == v || !e[1]) return bad(cmd, "--set needs name=value, got '%s'", v);
      sc_set *ns = realloc(o->set, (size_t)(o->nset + 1) * sizeof *ns);
      if (!ns) return bad(cmd, "out of memory");
      o->set = ns;
      /* Split in place: argv strings are writable (C11 5.1.2.2.1). */
      *(char *)e = '\0';
      o->set[o->nset].name = v;
      o->set[o->nset].value = e + 1;
      o->nset++;
    } else if (strcmp(name, "--continue") == 0) {
      const char *e = strchr(v, '='), *c = e ? strchr(e, ':') : NULL;
      char *end;
      if (!e || e == v || !c || c == e + 1 || !c[1])
        return bad(cmd, "--continue needs name=from:to, got '%s'", v);
      strtod(e + 1, &end);
      if (end != c) return bad(cmd, "--continue name=from:to: 'from' is not a number in '%s'", v);
      strtod(c + 1, &end);
      if (*end) return bad(cmd, "--continue name=from:to: 'to' is not a number in '%s'", v);
      o->cont = v;
    } else if (strcmp(name, "--json") == 0) {
      o->json = v;
    } else if (strcmp(name, "--csv") == 0) {
      o->csv = v;
    } else if (strcmp(name, "--plot") == 0) {
      size_t n = strlen(v);
      if (n < 5 || (strcmp(v + n - 4, ".png") != 0 && strcmp(v + n - 4, ".svg") != 0))
        return bad(cmd, "--plot FILE must end in .png or .svg, got '%s'", v);
      o->plot = v;
    }
    if (!*v) return bad(cmd, "%s needs a non-empty value", name);
  }
  if (o->help) return 0;
  if (!o->scene_path) return bad(cmd, "a scene file is missing: calcvar %s SCENE [options]", cmd);
  if (o->tol > 0 && o->adapt > 0)
    return bad(cmd, "--tol and --adapt cannot be combined (--tol chooses the mesh and the "
                    "degrees, --adapt the mesh at one degree)");
  if ((o->max_paths || o->work > 0) && !o->all)
    return bad(cmd, "--max and --work belong to --all; give --all too");
  if (o->json && o->csv && strcmp(o->json, "-") == 0 && strcmp(o->csv, "-") == 0)
    return bad(cmd, "--json - and --csv - cannot both write to stdout");
  if (o->json && o->csv && strcmp(o->json, "-") != 0 && cli_same_output(o->json, o->csv))
    return bad(cmd, "--json and --csv name the same file '%s'", o->json);
  return 0;
}

/* The directory of path (the part before its last '/', or ".") into *st; 0 when it cannot
 * be read. *base: the name after the last '/'. */
static int dir_of(const char *path, struct stat *st, const char **base) {
  const char *slash = strrchr(path, '/');
  char dir[4096];
  size_t ld = slash ? (size_t)(slash - path) : 0;
  if (ld >= sizeof dir) return 0;
  memcpy(dir, path, ld);
  dir[ld] = '\0';
  *base = slash ? slash + 1 : path;
  return stat(slash ? (ld ? dir : "/") : ".", st) == 0;
}

int cli_same_output(const char *a, const char *b) {
  struct stat sa, sb;
  int ha = stat(a, &sa) == 0, hb = stat(b, &sb) == 0;
  /* a device (/dev/null) or a pipe is written, not replaced: two outputs may share it */
  if (ha && !S_ISREG(sa.st_mode) && !S_ISDIR(sa.st_mode)) return 0;
  if (strcmp(a, b) == 0) return 1;
  if (ha && hb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino; /* ./f and f */
  struct stat da, db; /* not written yet: the same directory and name */
  const char *na, *nb;
  return dir_of(a, &da, &na) && dir_of(b, &db, &nb) && da.st_dev == db.st_dev &&
         da.st_ino == db.st_ino && strcmp(na, nb) == 0;
}

/* For commands that only read a scene (equations, modes): reject solve-only options. */
int cli_scene_command_start(const char *cmd, int argc, char **argv, void (*usage)(FILE *),
                            cli_opts *o, scene **s, cli_outfile *jf) {
  char err[SC_ERRLEN] = "";
  *s = NULL;
  int rc = cli_args_parse(cmd, argc, argv, o);
  if (rc != 0 || o->help) {
    if (o->help) usage(stdout);
    return rc;
  }
  if ((rc = cli_only_scene_options(cmd, o)) != 0) return rc;
  if (!(*s = scene_load_file(o->scene_path, o->nset, o->set, err, sizeof err))) {
    fprintf(stderr, "%s\n", err);
    return EXIT_BADINPUT;
  }
  /* Output files are opened before the work: an unwritable path is bad input. */
  if (o->json && cli_outfile_open(jf, o->json, o->scene_path) < 0) return EXIT_BADINPUT;
  return -1;
}

int cli_apply_accuracy(const cli_opts *o, scene *s) {
  if ((o->tol > 0 && s->adapt > 0) || (o->adapt > 0 && s->tol > 0)) {
    fprintf(stderr, "%s:%d: [mesh] %s cannot be combined with %s\n", s->file,
            s->tol > 0 ? s->tol_line : s->adapt_line, s->tol > 0 ? "tol" : "adapt",
            s->tol > 0 ? "--adapt" : "--tol");
    return EXIT_BADINPUT;
  }
  if (o->adapt > 0) s->adapt = o->adapt;
  double tol = o->tol > 0 ? o->tol : s->tol;
  if (o->time_limit > 0) {
    if (!(tol > 0 || s->adapt > 0)) {
      fprintf(stderr, "calcvar: --time-limit caps the rounds of automatic accuracy only (--tol "
                      "T, --adapt TOL, or [mesh] tol / adapt in the scene)\n");
      return EXIT_BADINPUT;
    }
    s->time_limit = o->time_limit;
  }
  if (o->max_nodes && !(tol > 0)) {
    fprintf(stderr, "calcvar: --max-nodes caps the nodes of --tol only (--tol T or [mesh] tol in "
                    "the scene; --adapt has --max-elements)\n");
    return EXIT_BADINPUT;
  }
  if (tol > 0) { /* automatic accuracy: the scene's or the flags' mesh is only the start */
    s->tol = tol;
    if (o->max_nodes) s->tol_max_nodes = o->max_nodes;
    if (o->elements) s->elements_line = -1; /* given by the flags: a start of its own */
    if (o->degree) s->degree_line = -1;
    scene_tol_start(s);
  }
  return 0;
}

void cli_apply_solver_options(const cli_opts *o, scene *s) {
  if (o->method >= 0) s->method = (cv_method)o->method;
  if (o->tolerance > 0) s->tolerance = o->tolerance;
  if (o->max_iterations) s->max_iterations = o->max_iterations;
}

int cli_only_scene_options(const char *cmd, const cli_opts *o) {
  if (o->csv || o->plot || o->adapt > 0 || o->tol > 0 || o->cont || o->elements || o->degree ||
      o->method >= 0 || o->tolerance > 0 || o->max_iterations || o->all || o->max_elements ||
      o->verbose || o->time_limit > 0 || o->max_nodes) {
    fprintf(stderr, "calcvar %s: only --set, --json and --quiet apply to %s\n", cmd, cmd);
    return EXIT_BADINPUT;
  }
  return 0;
}
