/* src/cli/cli_check.c — `calcvar check SCENE`: parse, show the degrees of freedom and what
 * the method needs, and compare the symbolic partials with finite differences.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

/* Sample points for the derivative check: interior abscissae (ends may be singular, as
 * the brachistochrone's 1/sqrt(y) at y = 0). */
enum { NSAMPLE = 7 };

/* A relative difference above this between the symbolic partials and central differences
 * (error ~ eps^(2/3) ~ 1e-11 for first, ~1e-7 for second partials) means a wrong
 * derivative, not round-off. */
static const double CHECK_TOL = 1e-5;

static void print_end(const sc_boundary *bc, int end) {
  if (bc->free_end[end])
    printf("free (natural)");
  else
    printf("%.15g", bc->value[end]);
}

/* Second derivatives: the C^1 discretisation the scene's mesh gives (theory H-2): values
 * and slopes at E r + 1 nodes, r = (p - 1)/2, less the fixed end values and slopes. */
static void print_c1_dofs(const scene *s) {
  int n = s->n, p = s->degree == 1 ? 3 : s->degree, r = (p - 1) / 2, fixed = 0;
  long nodes = (long)s->elements * r + 1;
  for (int i = 0; i < n; i++)
    for (int end = 0; end < 2; end++) {
      fixed += !s->bc[i].free_end[end];
      fixed += s->sbc && s->sbc[i].line && !s->sbc[i].free_end[end];
    }
  if (p % 2 == 0 || p > 7) {
    printf("  discrete     degree %d: the C1 elements of y'' have degree 3, 5 or 7\n", p);
    return;
  }
  printf("  discrete     C1 elements: %d of degree %d, %ld nodes with a value and a slope of "
         "each unknown: %ld values + %ld slopes - %d fixed at the ends = %ld unknowns\n",
         s->elements, p, nodes, nodes * n, nodes * n, fixed, 2 * nodes * n - fixed);
}

/* The partials of a second-order integrand along the guess, y'' by central second
 * differences (step ~ eps^(1/4)); rc of the check. */
static int check_c1(const scene *s, const cv_problem *p, const double *x, const double *y,
                    const double *dy, cv_derivcheck *dc, cv_status *st) {
  int n = s->n;
  double h = 1.2e-4 * (s->b - s->a), xs[2 * NSAMPLE];
  double *d2 = malloc(3 * (size_t)n * NSAMPLE * sizeof *d2), *yy = d2 + (size_t)n * NSAMPLE;
  if (!d2) return -1;
  for (int k = 0; k < NSAMPLE; k++) xs[k] = x[k] + h, xs[NSAMPLE + k] = x[k] - h;
  if (scene_eval_guess(s, 2 * NSAMPLE, xs, yy) < 0) {
    free(d2);
    return -1;
  }
  for (int i = 0; i < n; i++)
    for (int k = 0; k < NSAMPLE; k++) {
      const double *yi = yy + (size_t)i * 2 * NSAMPLE;
      d2[i * NSAMPLE + k] = (yi[k] - 2 * y[i * NSAMPLE + k] + yi[NSAMPLE + k]) / (h * h);
    }
  *st = cv_problem_check_derivatives2(p, NSAMPLE, x, y, dy, d2, dc);
  free(d2);
  return 0;
}

int cli_check(int argc, char **argv) {
  cli_opts o;
  char err[SC_ERRLEN];
  int rc = cli_args_parse("check", argc, argv, &o);
  if (rc != 0 || o.help) {
    if (o.help) printf("usage: calcvar check SCENE [--set name=value] [--method M]\n");
    cli_opts_free(&o);
    return rc;
  }
  if (o.json || o.csv || o.plot || o.adapt > 0 || o.tol > 0 || o.cont || o.elements || o.degree ||
      o.time_limit > 0 || o.max_nodes) {
    fprintf(stderr, "calcvar check: only --set and --method apply to check\n");
    cli_opts_free(&o);
    return EXIT_BADINPUT;
  }
  scene *s = scene_load_file(o.scene_path, o.nset, o.set, err, sizeof err);
  cv_problem *p = NULL;
  if (!s) {
    fprintf(stderr, "%s\n", err);
    cli_opts_free(&o);
    return EXIT_BADINPUT;
  }
  if (o.method >= 0) s->method = (cv_method)o.method;
  int n = s->n;
  printf("%s (%s)\n", s->title, s->file);
  printf("  variable     %s on [%.15g, %.15g]\n", s->variable, s->a, s->b);
  printf("  unknowns    ");
  for (int i = 0; i < n; i++) printf(" %s", s->unknowns[i]);
  printf("\n  constraints  %d pointwise, %d integral\n", s->ncons, s->nints);
  printf("  freedom      %d unknown function%s - %d pointwise constraint%s = %d degree%s of "
         "freedom\n",
         n, n == 1 ? "" : "s", s->ncons, s->ncons == 1 ? "" : "s", n - s->ncons,
         n - s->ncons == 1 ? "" : "s");
  for (int i = 0; i < n; i++) {
    printf("  boundary     %s: ", s->unknowns[i]);
    print_end(&s->bc[i], 0);
    printf(" at %s = %.15g, ", s->variable, s->a);
    print_end(&s->bc[i], 1);
    printf(" at %s = %.15g\n", s->variable, s->b);
    if (s->c1 && s->order2[i]) { /* the slope line (missing: both slopes free) */
      static const sc_boundary both_free = {{0, 0}, {1, 1}, 0, {-1, -1}, 0, 0.0};
      const sc_boundary *sb = s->sbc && s->sbc[i].line ? &s->sbc[i] : &both_free;
      printf("  slope        %s': ", s->unknowns[i]);
      print_end(sb, 0);
      printf(" at %s = %.15g, ", s->variable, s->a);
      print_end(sb, 1);
      printf(" at %s = %.15g\n", s->variable, s->b);
    }
  }
  if (s->c1) print_c1_dofs(s);
  printf("  integrand    %s explicit %s", scene_F_depends_on_variable(s) ? "depends on" : "has no",
         s->variable);
  if (!scene_F_depends_on_variable(s))
    printf(s->c1 ? " (Ostrogradsky's energy H = y'.p + y''.dF/dy'' - F is conserved)"
                 : " (energy H = y'.dF/dy' - F is conserved)");
  printf("\n  cyclic      ");
  int ncyc = 0;
  for (int i = 0; i < n; i++)
    if (!scene_F_depends_on_unknown(s, i)) printf(" %s", s->unknowns[i]), ncyc++;
  printf("%s\n", !ncyc   ? " none"
                 : s->c1 ? " (their momenta p = dF/dy' - d/dx dF/dy'' are conserved)"
                         : " (their momenta dF/dy' are conserved)");
  if ((ncyc || !scene_F_depends_on_variable(s)) && s->ncons + s->nints > 0)
    printf("               (these conservation laws hold for F alone: constraints that "
           "involve %s or the unknowns can break them)\n",
           s->variable);
  unsigned need = scene_method_need(s->method);
  if (s->c1)
    printf("  method       %s needs F, dF/dy, dF/dy', dF/dy''%s\n", cv_method_name(s->method),
           need & CVAR_NEED_HESS ? " and the second partials in (y, y', y'')" : "");
  else
    printf("  method       %s needs F, dF/dy, dF/dy'%s\n", cv_method_name(s->method),
           need & CVAR_NEED_HESS ? " and the second partials (y,y), (y,y'), (y',y')" : "");

  if (!(p = scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err))) {
    fprintf(stderr, "%s\n", err);
    rc = EXIT_BADINPUT;
    goto done;
  }
  double x[NSAMPLE], xp[NSAMPLE], xm[NSAMPLE];
  double *y = malloc(3 * (size_t)n * NSAMPLE * sizeof *y);
  if (!y) {
    rc = EXIT_UNSOLVED;
    goto done;
  }
  double *yp = y + (size_t)n * NSAMPLE, *dy = yp + (size_t)n * NSAMPLE;
  /* y from the guess, y' by central differences of the guess, step h ~ eps^(1/3) (b - a). */
  double h = 6e-6 * (s->b - s->a);
  for (int k = 0; k < NSAMPLE; k++) {
    x[k] = s->a + (s->b - s->a) * (k + 0.5) / NSAMPLE;
    xp[k] = x[k] + h;
    xm[k] = x[k] - h;
  }
  if (scene_eval_guess(s, NSAMPLE, xp, yp) < 0 || scene_eval_guess(s, NSAMPLE, xm, dy) < 0 ||
      scene_eval_guess(s, NSAMPLE, x, y) < 0) {
    free(y);
    rc = EXIT_UNSOLVED;
    goto done;
  }
  for (size_t k = 0; k < (size_t)n * NSAMPLE; k++) dy[k] = (yp[k] - dy[k]) / (2 * h);
  cv_derivcheck dc;
  cv_status st = CVAR_ENOMEM;
  if (!s->c1)
    st = cv_problem_check_derivatives(p, NSAMPLE, x, y, dy, &dc);
  else
    check_c1(s, p, x, y, dy, &dc, &st);
  free(y);
  if (st != CVAR_OK) {
    printf("  derivatives  cannot be checked along the guess: %s\n", cv_strerror(st));
    rc = EXIT_UNSOLVED;
  } else if (!(dc.worst <= CHECK_TOL)) {
    printf("  derivatives  WRONG: %s at point %d is %.10g, finite differences give %.10g "
           "(relative difference %.2g > %.0e)\n",
           dc.which, dc.point, dc.analytic, dc.fd, dc.worst, CHECK_TOL);
    rc = EXIT_UNSOLVED;
  } else {
    printf("  derivatives  agree with finite differences at %d points along the guess "
           "(worst relative difference %.2g, in %s; tolerance %.0e)\n",
           NSAMPLE, dc.worst, dc.which, CHECK_TOL);
    rc = EXIT_SOLVED;
  }
done:
  cv_problem_free(p);
  scene_free(s);
  cli_opts_free(&o);
  return rc;
}
