/* src/cli/cli_equations.c — `calcvar equations SCENE`: momenta, Euler–Lagrange equations,
 * Hamiltonian and conservation laws of a scene's integrand, for a person or as JSON.
 * SPDX-License-Identifier: MIT
 *
 * The expressions come from scene_equations_new (src/scene/scene_mechanics.c, src/mech). They are
 * printed in the scene grammar, with parameters as numbers, by the library
 * (scene_mechanics_json.c), which also builds the JSON, so `--json` and the public
 * cv_equations_json give the same bytes (docs/mechanics.md).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "scene/scene_mechanics.h"

static void usage(FILE *f) {
  fputs("usage: calcvar equations SCENE [--set name=value] [--json FILE] [--quiet]\n"
        "  prints, for each unknown y, the momentum p = dF/dy', the Euler-Lagrange\n"
        "  equation d/dx dF/dy' - dF/dy = 0 expanded with y'', the Hamiltonian\n"
        "  H = sum y' dF/dy' - F, the cyclic unknowns and whether F depends on the variable\n"
        "  --json FILE   the same as JSON ('-' for stdout)\n",
        f);
}

/* The JSON of the library (scene_mechanics_json.c, also cv_equations_json) and a newline. */
static int write_json(FILE *f, const scene *s, const mech_equations *eq, const scene_eq_texts *t) {
  char *text = scene_equations_json(s, eq, t);
  int rc = text && fputs(text, f) != EOF && fputc('\n', f) != EOF ? 0 : -1;
  free(text); /* from json_dumps: jansson's allocator */
  return rc;
}

/* The shortest decimal that reads back as v (as the expressions print their numbers). */
static const char *shortest(double v, char *buf, size_t len) {
  for (int prec = 1; prec <= 17; prec++) {
    snprintf(buf, len, "%.*g", prec, v);
    if (strtod(buf, NULL) == v) break;
  }
  return buf;
}

static void write_text(FILE *f, const scene *s, const mech_equations *eq, const scene_eq_texts *t) {
  int n = s->n, ncyc = 0;
  char num[32];
  fprintf(f, "%s (%s)\n", s->title, s->file);
  fprintf(f, "  F(%s, y, y'%s) = %s\n", s->variable, t->mom2 ? ", y''" : "", t->F);
  if (s->nparams > 0) {
    fprintf(f, "  parameters   substituted as numbers:");
    for (int k = 0; k < s->nparams; k++)
      fprintf(f, "%s %s = %s", k ? "," : "", s->params[k].name,
              shortest(s->params[k].value, num, sizeof num));
    fprintf(f, "\n");
  }
  for (int i = 0; i < n; i++) {
    const char *u = s->unknowns[i];
    fprintf(f, "\n  %s\n", u);
    if (t->mom2) { /* Ostrogradsky's momenta of a second-order Lagrangian (theory P-14) */
      fprintf(f, "    momentum         p_%s = dF/d%s' - d/dx dF/d%s'' = %s\n", u, u, u, t->mom[i]);
      fprintf(f, "    second momentum  q_%s = dF/d%s'' = %s\n", u, u, t->mom2[i]);
    } else {
      fprintf(f, "    momentum         p_%s = dF/d%s' = %s\n", u, u, t->mom[i]);
    }
    fprintf(f, "    Euler-Lagrange   %s = 0\n", t->el[i]);
    if (eq->cyclic[i]) ncyc++;
  }
  if (s->ncons + s->nints > 0) {
    fprintf(f, "\n  multipliers  the equations are those of F");
    for (int c = 0; c < s->ncons; c++)
      fprintf(f, " + %s*(%s constraint)", eq->names[1 + 3 * n + c], s->cons[c].name);
    for (int r = 0; r < s->nints; r++)
      fprintf(f, " + %s*(%s integrand)", eq->names[1 + 3 * n + s->ncons + r], s->ints[r].name);
    fprintf(f, "\n");
  }
  fprintf(f, "\n  Hamiltonian  H = %s\n", t->H);
  fprintf(f, "  autonomous   %s\n",
          eq->autonomous
              ? "yes: F has no explicit dependence on the variable, so H is conserved"
              : "no: F depends explicitly on the variable, so H is not conserved in general");
  fprintf(f, "  cyclic      ");
  for (int i = 0; i < n; i++)
    if (eq->cyclic[i]) fprintf(f, " %s", s->unknowns[i]);
  fprintf(f, "%s\n", ncyc ? " (F does not depend on them: their momenta are conserved)" : " none");
  if ((ncyc || eq->autonomous) && s->ncons + s->nints > 0)
    fprintf(f,
            "               (for F alone: constraints that involve %s or the unknowns can "
            "break these conservation laws)\n",
            s->variable);
}

int cli_equations(int argc, char **argv) {
  cli_opts o;
  char err[SC_ERRLEN] = "";
  scene *s = NULL;
  mech_equations eq;
  scene_eq_texts t;
  cli_outfile jf = {0};
  memset(&eq, 0, sizeof eq);
  memset(&t, 0, sizeof t);
  int rc = cli_scene_command_start("equations", argc, argv, usage, &o, &s, &jf);
  if (rc >= 0) goto done;
  if (scene_equations_new(s, &eq, err, sizeof err) != CVAR_OK ||
      scene_eq_texts_make(&t, s, &eq) < 0) {
    fprintf(stderr, "%s\n", err[0] ? err : "calcvar equations: out of memory");
    rc = EXIT_UNSOLVED;
    goto done;
  }
  if (o.json) {
    if (cli_outfile_finish(&jf, write_json(jf.f, s, &eq, &t)) < 0) {
      fprintf(stderr, "calcvar equations: the JSON could not be written\n");
      rc = EXIT_IOERROR;
      goto done;
    }
  }
  if (!o.quiet && (!o.json || strcmp(o.json, "-") != 0)) write_text(stdout, s, &eq, &t);
  rc = EXIT_SOLVED;
done:
  cli_outfile_abandon(&jf);
  scene_eq_texts_free(&t);
  mech_equations_free(&eq);
  scene_free(s);
  cli_opts_free(&o);
  return rc;
}
