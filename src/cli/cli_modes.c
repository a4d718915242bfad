/* src/cli/cli_modes.c — `calcvar modes SCENE`: the equilibrium of a Lagrangian L(y, y') and
 * its small oscillations, for a person or as JSON (SCENES.md).
 * SPDX-License-Identifier: MIT
 *
 * The numbers come from scene_modes_new (src/scene/scene_mechanics.c, src/mech), the JSON from
 * the library (scene_mechanics_json.c, as cv_modes_json). Exit status: 0 modes
 * found; 1 no equilibrium from the guess, M not positive definite, or non-finite values
 * (nothing written); 2 bad input, including a scene whose integrand or a constraint
 * depends on the variable, or that has integral constraints (modes does not apply).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "scene/scene_mechanics.h"

static const double TWO_PI = 6.28318530717958647692;

static void usage(FILE *f) {
  fputs("usage: calcvar modes SCENE [--set name=value] [--json FILE] [--quiet]\n"
        "  finds an equilibrium dL/dy = 0 (y' = 0) from the guess at the start of the\n"
        "  interval, forms M = d2L/dy'dy' and K = -d2L/dydy there and prints each w^2 of\n"
        "  K v = w^2 M v: stable (period 2 pi/w), unstable (growth rate sqrt(-w^2)) or\n"
        "  neutral (w^2 = 0: a free translation or rotation), with its mode shape; with\n"
        "  gyroscopic terms (L_y'y not symmetric) also the motions of M y'' + G y' + K y = 0;\n"
        "  with [constraints] G(y) = 0 the equilibrium on them, the multipliers, and the\n"
        "  modes along them\n"
        "  --json FILE   the same as JSON ('-' for stdout)\n",
        f);
}

static const char *kind_name(mech_mode_kind k) { return scene_mode_kind_name(k); }

/* The JSON of the library (scene_mechanics_json.c, also cv_modes_json) and a newline. */
static int write_json(FILE *f, const scene *s, const mech_modes *md) {
  char *text = scene_modes_json(s, md);
  int rc = text && fputs(text, f) != EOF && fputc('\n', f) != EOF ? 0 : -1;
  free(text); /* from json_dumps: jansson's allocator */
  return rc;
}

static void print_matrix(FILE *f, const char *label, int n, const double *A) {
  for (int i = 0; i < n; i++) {
    fprintf(f, "  %-14s", i == 0 ? label : "");
    for (int j = 0; j < n; j++) fprintf(f, " %14.8g", A[i * n + j]);
    fprintf(f, "\n");
  }
}

static void write_text(FILE *f, const scene *s, const mech_modes *md) {
  int n = s->n;
  fprintf(f, "%s (%s)\n", s->title, s->file);
  fprintf(f, "  equilibrium ");
  for (int i = 0; i < n; i++)
    fprintf(f, " %s = %.15g%s", s->unknowns[i], md->equilibrium[i], i + 1 < n ? "," : "");
  fprintf(f,
          "\n               (Newton from the guess at %s = %.15g: %d iteration%s, "
          "max |dL/dy%s| = %.2g)\n",
          s->variable, s->a, md->iterations, md->iterations == 1 ? "" : "s",
          md->nc ? " + lambda.dG/dy|, |G" : "", md->residual);
  for (int c = 0; c < md->nc; c++)
    fprintf(f, "  %-12s lambda_%s = %.15g (multiplier of the constraint %s = 0)\n",
            c ? "" : "multipliers", s->cons[c].name, md->multipliers[c], s->cons[c].name);
  if (md->nc > 0)
    fprintf(f,
            "  %-12s %d mode%s on the constraints' tangent space (%d unknowns - %d "
            "constraint%s)\n",
            "constrained", md->nmodes, md->nmodes == 1 ? "" : "s", n, md->nc,
            md->nc == 1 ? "" : "s");
  print_matrix(f, "M = L_y'y'", n, md->mass);
  print_matrix(f, md->nc ? "K = -(L+l.G)_yy" : "K = -L_yy", n, md->stiffness);
  if (md->gyroscopic > 0)
    fprintf(f,
            "  note         L has gyroscopic terms (L_y'y not symmetric, max |G| = %.3g): "
            "the modes of K v = w^2 M v below leave them out; the motions with them follow\n",
            md->gyroscopic);
  fprintf(f, "\n  %-4s %-22s %-9s %-32s %s\n", "mode", "omega^2", "kind", "frequency or growth",
          "shape (v'Mv = 1)");
  for (int k = 0; k < md->nmodes; k++) {
    double w2 = md->omega2[k];
    char what[64];
    if (md->kind[k] == MECH_MODE_STABLE)
      snprintf(what, sizeof what, "omega %.6g, period %.6g", sqrt(w2), TWO_PI / sqrt(w2));
    else if (md->kind[k] == MECH_MODE_UNSTABLE)
      snprintf(what, sizeof what, "growth rate %.6g", sqrt(-w2));
    else
      snprintf(what, sizeof what, "free motion");
    fprintf(f, "  %-4d %-22.15g %-9s %-32s", k + 1, w2, kind_name(md->kind[k]), what);
    for (int i = 0; i < n; i++) fprintf(f, " %s %.6g", s->unknowns[i], md->shape[k * n + i]);
    fprintf(f, "\n");
  }
  if (md->ngyro == 0) return;
  fprintf(f, "\n  with the gyroscopic terms, M y'' + G y' + K y = 0 (G = L_y'y - L_y'y^T):\n");
  fprintf(f, "  %-4s %-9s %s\n", "", "kind", "frequency or growth");
  for (int k = 0; k < md->ngyro; k++) {
    double w = md->gyro_omega[k], r = md->gyro_growth[k];
    char what[96];
    if (md->gyro_kind[k] == MECH_MODE_STABLE)
      snprintf(what, sizeof what, "omega %.6g, period %.6g", w, TWO_PI / w);
    else if (md->gyro_kind[k] == MECH_MODE_UNSTABLE && w > 0)
      snprintf(what, sizeof what, "growth rate %.6g, oscillating with omega %.6g", r, w);
    else if (md->gyro_kind[k] == MECH_MODE_UNSTABLE)
      snprintf(what, sizeof what, "growth rate %.6g", r);
    else
      snprintf(what, sizeof what, "free motion");
    fprintf(f, "  %-4d %-9s %s\n", k + 1, kind_name(md->gyro_kind[k]), what);
  }
}

int cli_modes(int argc, char **argv) {
  cli_opts o;
  char err[SC_ERRLEN] = "";
  scene *s = NULL;
  mech_modes md;
  cli_outfile jf = {0};
  memset(&md, 0, sizeof md);
  int rc = cli_scene_command_start("modes", argc, argv, usage, &o, &s, &jf);
  if (rc >= 0) goto done;
  cv_status st = scene_modes_new(s, &md, err, sizeof err);
  if (st != CVAR_OK) {
    fprintf(stderr, "%s\n", err);
    rc = st == CVAR_EINVAL ? EXIT_BADINPUT : EXIT_UNSOLVED;
    goto done;
  }
  if (o.json) {
    if (cli_outfile_finish(&jf, write_json(jf.f, s, &md)) < 0) {
      fprintf(stderr, "calcvar modes: the JSON could not be written\n");
      rc = EXIT_IOERROR;
      goto done;
    }
  }
  if (!o.quiet && (!o.json || strcmp(o.json, "-") != 0)) write_text(stdout, s, &md);
  rc = EXIT_SOLVED;
done:
  cli_outfile_abandon(&jf);
  mech_modes_free(&md);
  scene_free(s);
  cli_opts_free(&o);
  return rc;
}
