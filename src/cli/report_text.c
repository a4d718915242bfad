/* src/cli/report_text.c — the human summary `solve` prints by default.
 * SPDX-License-Identifier: MIT */
#include "cli/cli.h"

void cli_report_text(FILE *f, const cli_report *r) {
  const scene *s = r->sc;
  fprintf(f, "%s\n", s->title);
  fprintf(f, "  status      %s: %s\n", r->status, r->message);
  fprintf(f, "  method      %s, %d iteration%s", cv_method_name(r->method), r->iterations,
          r->iterations == 1 ? "" : "s");
  if (r->has_time) fprintf(f, ", %.3g s", r->time_s);
  fputc('\n', f);
  int dmin = r->degree;
  for (int e = 0; r->degrees && e < r->elements; e++)
    dmin = r->degrees[e] < dmin ? r->degrees[e] : dmin;
  if (r->nodes > 0 && dmin < r->degree)
    fprintf(f, "  mesh        %d elements of degrees %d to %d, %d nodes\n", r->elements, dmin,
            r->degree, r->nodes);
  else if (r->nodes > 0)
    fprintf(f, "  mesh        %d elements of degree %d, %d nodes\n", r->elements, r->degree,
            r->nodes);
  if (r->has_interval) /* a moving end: the solved interval */
    fprintf(f, "  interval    [%.15g, %.15g] (an end moved)\n", r->interval[0], r->interval[1]);
  if (r->has_action) fprintf(f, "  action      %.15g\n", r->action);
  if (r->has_gradient_norm) {
    fprintf(f, "  residual    %.3g (max-norm of the scaled Euler-Lagrange residual)\n",
            r->gradient_norm);
    /* relative to its round-off floor (theory N-3a): a few times the floor is round-off */
    if (r->has_residual_floor) {
      double q = r->gradient_norm / r->residual_floor;
      /* above it after a converged solve: the step test (N-4), whose absolute part can be
       * large next to tiny values (a singular end), stopped Newton first */
      fprintf(f, "  floor       %.3g: the residual is %.2g times this round-off floor (%s)\n",
              r->residual_floor, q,
              q <= 100           ? "at round-off"
              : r->st == CVAR_OK ? "above round-off: Newton stopped on its step test, which "
                                   "does not test the residual"
                                 : "above round-off");
    }
    /* Newton's convergence test is on the step, not on this number, which on fine meshes
     * sits at a round-off floor that grows with the number of elements (docs/faq.md). */
    if (r->method == CVAR_METHOD_NEWTON && r->st == CVAR_OK)
      fprintf(f,
              "  test        Newton step within %.3g (relative to |y|); the residual is "
              "not tested\n",
              s->tolerance);
  }
  if (r->has_morse) fprintf(f, "  stationary  %s (Morse index %d)\n", r->kind, r->morse);
  if (r->has_err_nodal)
    fprintf(f, "  error       %.3g max at the nodes (against [exact])\n", r->err_nodal);
  if (r->has_err_action)
    fprintf(f, "  error       %.3g in the action (against [exact] action = %.17g)\n", r->err_action,
            s->exact_action);
  if (r->has_err_est)
    fprintf(f, "  estimate    %.3g max nodal error (from a solve with higher degrees)\n",
            r->err_est);
  if (r->has_energy)
    fprintf(f, "  energy      H from %.15g to %.15g (drift %.3g%s)\n", r->emin, r->emax,
            r->emax - r->emin,
            r->e_skipped > 0 ? "; elements where y' is not known left out, see status" : "");
  for (int i = 0; i < s->n; i++)
    if (r->has_mom[i])
      fprintf(f, "  momentum    dF/d%s' from %.15g to %.15g (%s is cyclic)\n", s->unknowns[i],
              r->mom_min[i], r->mom_max[i], s->unknowns[i]);
  for (int k = 0; k < s->nreports; k++)
    if (r->has_rep[k]) fprintf(f, "  report      %s = %.15g\n", s->reports[k].name, r->rep[k]);
}
