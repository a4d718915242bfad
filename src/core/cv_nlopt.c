/* src/core/cv_nlopt.c — the NLopt engine: minimise the discrete action over the free nodal
 * values with the exact gradient, constraints as NLopt equality (or paired
 * inequality) constraints, multipliers recovered afterwards by least squares (C-5).
 * The only file that includes nlopt.h.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include <nlopt.h>

#include "cv_internal.h"

/* NLopt's vector constraints take a dense m x n Jacobian. 2.5e7 doubles (200 MB) is where
 * that stops being sensible on a workstation; above it we refuse and suggest newton. */
#define MAX_DENSE_JACOBIAN 2.5e7
/* Iterates beyond this multiple of the starting size mean the action is unbounded below. */
#define RUNAWAY 1e8

typedef struct {
  cv_solver *s;
  const cv_disc *d;
  cv_kkt *kkt;
  double *Y, *g;      /* nodal values (full), gradient over all unknowns */
  int nv;             /* NLopt variables: the free y unknowns */
  int *yof, *fof;     /* variable -> y dof, variable -> unknown index */
  int *rows;          /* constraint row -> unknown index of its multiplier, or nu row */
  int *lrow, *var;    /* unknown index -> constraint row / NLopt variable, or -1 */
  int m;              /* number of constraint rows */
  double scale;
  long evals;
  cv_status stop;     /* status stored before a forced stop */
  nlopt_opt opt;
} nl_ctx;

static void load(nl_ctx *c, const double *x) {
  for (int v = 0; v < c->nv; v++) c->Y[c->yof[v]] = x[v];
}

static double objective(unsigned n, const double *x, double *grad, void *data) {
  nl_ctx *c = data;
  double S;
  (void)n;
  c->evals++;
  load(c, x);
  for (int v = 0; v < c->nv; v++) {
    if (!(fabs(x[v]) <= RUNAWAY * c->scale)) {
      c->stop = CVAR_ENOTMIN;
      nlopt_force_stop(c->opt);
      return 0.0;
    }
  }
  memset(c->g, 0, (size_t)c->d->nfree * sizeof *c->g);
  cv_status st = cv_assemble(&c->kkt->as, c->kkt->prob->F, c->kkt->prob->user, c->Y, &S,
                             grad ? c->g : NULL, c->kkt->colptr, NULL, 0.0);
  if (st == CVAR_ECALLBACK || st == CVAR_ENOMEM) {
    c->stop = st;
    nlopt_force_stop(c->opt);
    return 0.0;
  }
  if (st) return HUGE_VAL; /* outside the integrand's domain: a rejected trial point */
  if (grad)
    for (int v = 0; v < c->nv; v++) grad[v] = c->g[c->fof[v]];
  return S;
}

/* Constraint rows: G_k(x_j, Y_j) at the nodes with multipliers, then I_r - c_r; sign = +1
 * or -1 (MMA and CCSAQ take inequalities only: h <= 0 and -h <= 0). */
static void constraints(unsigned m, double *result, unsigned n, const double *x, double *grad,
                        double sign, nl_ctx *c) {
  (void)n;
  load(c, x);
  if (grad) memset(grad, 0, (size_t)m * c->nv * sizeof *grad);
  cv_status st = cv_kkt_constraint_values(c->kkt, c->Y, c->g, grad, c->nv, c->lrow, c->var);
  if (st) {
    c->stop = st;
    nlopt_force_stop(c->opt);
  }
  for (unsigned i = 0; i < m; i++) result[i] = st ? 0.0 : sign * c->g[c->rows[i]];
  if (grad && sign < 0)
    for (size_t i = 0; i < (size_t)m * c->nv; i++) grad[i] = -grad[i];
}

static void eq_constraints(unsigned m, double *r, unsigned n, const double *x, double *g,
                           void *data) {
  constraints(m, r, n, x, g, 1.0, data);
}
static void neg_constraints(unsigned m, double *r, unsigned n, const double *x, double *g,
                            void *data) {
  constraints(m, r, n, x, g, -1.0, data);
}

static nlopt_algorithm algorithm(cv_method m) {
  switch (m) {
  case CVAR_METHOD_LBFGS: return NLOPT_LD_LBFGS;
  case CVAR_METHOD_TNEWTON: return NLOPT_LD_TNEWTON_PRECOND_RESTART;
  case CVAR_METHOD_MMA: return NLOPT_LD_MMA;
  case CVAR_METHOD_CCSAQ: return NLOPT_LD_CCSAQ;
  case CVAR_METHOD_SLSQP: return NLOPT_LD_SLSQP;
  default: return NLOPT_AUGLAG;
  }
}

cv_status cv_nlopt_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y) {
  nl_ctx c;
  cv_kkt kkt;
  cv_status st = CVAR_OK;
  long *colptr = NULL;
  double *x = NULL, *tol = NULL;
  nlopt_opt local = NULL;
  int constrained = d->nc > 0 || d->ni > 0, cmethod = s->method >= CVAR_METHOD_MMA;
  memset(&c, 0, sizeof c);
  memset(&kkt, 0, sizeof kkt);
  s->morse = -1;
  if (constrained && !cmethod) {
    cv_set_msg(s->msg, sizeof s->msg,
               "%s cannot impose constraints; use mma, ccsaq, slsqp, auglag or newton",
               cv_method_name(s->method));
    return CVAR_EINVAL;
  }
  /* The column layout is only needed by cv_kkt_eval's signature (no Hessian here). */
  colptr = cv_calloc((size_t)d->nfree + 1, sizeof *colptr);
  c.g = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.g);
  c.yof = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.yof);
  c.fof = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.fof);
  c.rows = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.rows);
  c.lrow = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.lrow);
  c.var = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.var);
  if (!colptr || !c.g || !c.yof || !c.fof || !c.rows || !c.lrow || !c.var) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  st = cv_kkt_init(&kkt, p, d, colptr);
  if (st) goto cleanup;
  if (d->nc > 0) {
    st = cv_kkt_check_ends(&kkt, Y, s->msg, sizeof s->msg);
    if (st) goto cleanup;
  }
  for (int f = 0; f < d->nfree; f++) c.lrow[f] = c.var[f] = -1;
  for (long j = 0; j < d->nodes; j++) {
    for (int i = 0; i < d->n; i++) {
      int f = cv_disc_fidx(d, j * d->n + i);
      if (f < 0) continue;
      c.var[f] = c.nv;
      c.yof[c.nv] = (int)(j * d->n + i);
      c.fof[c.nv++] = f;
    }
    for (int k = 0; k < d->nc; k++) {
      int f = cv_disc_lidx(d, j, k);
      if (f >= 0) c.lrow[f] = c.m, c.rows[c.m++] = f;
    }
  }
  for (int r = 0; r < d->ni; r++) c.lrow[d->nu0 + r] = c.m, c.rows[c.m++] = d->nu0 + r;
  if ((double)c.m * c.nv > MAX_DENSE_JACOBIAN) {
    st = CVAR_EINVAL;
    cv_set_msg(s->msg, sizeof s->msg,
               "NLopt's constraints need a dense %d x %d Jacobian (%.0f MB), above the %.0f MB "
               "limit; use method newton, whose sparse KKT solve has no such limit",
               c.m, c.nv, 8e-6 * c.m * c.nv, 8e-6 * MAX_DENSE_JACOBIAN);
    goto cleanup;
  }
  c.s = s;
  c.d = d;
  c.kkt = &kkt;
  c.Y = Y;
  c.stop = CVAR_OK;
  for (long i = 0; i < d->ndof; i++) c.scale = fmax(c.scale, fabs(Y[i]));
  if (c.scale == 0) c.scale = 1;
  x = cv_malloc((size_t)(c.nv ? c.nv : 1) * sizeof *x);
  tol = cv_malloc((size_t)(c.m ? c.m : 1) * sizeof *tol);
  if (!x || !tol) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  for (int v = 0; v < c.nv; v++) x[v] = Y[c.yof[v]];
  /* Constraint tolerance: 10 rtol in units of G (or of the integral). */
  for (int i = 0; i < c.m; i++) tol[i] = 10 * s->rtol;
  c.opt = nlopt_create(algorithm(s->method), (unsigned)c.nv);
  if (!c.opt) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  if (s->method == CVAR_METHOD_AUGLAG) {
    local = nlopt_create(NLOPT_LD_LBFGS, (unsigned)c.nv);
    if (!local) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    nlopt_set_xtol_rel(local, s->rtol);
    nlopt_set_ftol_rel(local, s->rtol * 1e-2);
    nlopt_set_local_optimizer(c.opt, local);
  }
  nlopt_set_min_objective(c.opt, objective, &c);
  nlopt_set_xtol_rel(c.opt, s->rtol);
  nlopt_set_ftol_rel(c.opt, s->rtol * 1e-2);
  /* Evaluations, not Newton iterations: a quasi-Newton method needs many more. */
  nlopt_set_maxeval(c.opt, 200 * s->maxit);
  if (c.m > 0) {
    nlopt_result r;
    if (s->method == CVAR_METHOD_MMA || s->method == CVAR_METHOD_CCSAQ) {
      r = nlopt_add_inequality_mconstraint(c.opt, (unsigned)c.m, eq_constraints, &c, tol);
      if (r > 0)
        r = nlopt_add_inequality_mconstraint(c.opt, (unsigned)c.m, neg_constraints, &c, tol);
    } else {
      r = nlopt_add_equality_mconstraint(c.opt, (unsigned)c.m, eq_constraints, &c, tol);
    }
    if (r < 0) {
      st = CVAR_EDEPENDENCY;
      cv_set_msg(s->msg, sizeof s->msg, "NLopt refused the constraints (%s)",
                 nlopt_result_to_string(r));
      goto cleanup;
    }
  }
  double fmin = 0.0, S0 = 0.0;
  S0 = objective((unsigned)c.nv, x, NULL, &c);
  if (!isfinite(S0)) {
    st = CVAR_ENONFINITE;
    cv_set_msg(s->msg, sizeof s->msg, "the integrand is not finite at the initial guess");
    goto cleanup;
  }
  nlopt_result r = nlopt_optimize(c.opt, x, &fmin);
  load(&c, x);
  s->iterations = (int)c.evals;
  if (r == NLOPT_FORCED_STOP && c.stop == CVAR_ENOTMIN) {
    st = CVAR_ENOTMIN;
    cv_set_msg(s->msg, sizeof s->msg,
               "the action decreases without bound under %s: it has no minimum here, so its "
               "stationary path (if any) is a saddle that a minimiser cannot find; use method "
               "newton, which reports the Morse index",
               cv_method_name(s->method));
  } else if (r == NLOPT_FORCED_STOP) {
    st = c.stop ? c.stop : CVAR_EDEPENDENCY;
    cv_set_msg(s->msg, sizeof s->msg, "%s stopped: %s", cv_method_name(s->method),
               cv_strerror(st));
  } else if (r == NLOPT_ROUNDOFF_LIMITED) {
    st = CVAR_ESTALL;
    cv_set_msg(s->msg, sizeof s->msg, "%s stopped: limited by round-off",
               cv_method_name(s->method));
  } else if (r == NLOPT_OUT_OF_MEMORY) {
    st = CVAR_ENOMEM;
    cv_set_msg(s->msg, sizeof s->msg, "NLopt ran out of memory");
  } else if (r < 0) {
    st = CVAR_EDEPENDENCY;
    cv_set_msg(s->msg, sizeof s->msg, "NLopt failed: %s", nlopt_result_to_string(r));
  } else if (r == NLOPT_MAXEVAL_REACHED || r == NLOPT_MAXTIME_REACHED) {
    st = CVAR_EMAXITER;
    cv_set_msg(s->msg, sizeof s->msg,
               "%s did not converge within %d evaluations; raise max_iterations or use newton",
               cv_method_name(s->method), 200 * s->maxit);
  } else {
    st = CVAR_OK;
    cv_set_msg(s->msg, sizeof s->msg, "%s converged (%s) in %ld evaluations",
               cv_method_name(s->method), nlopt_result_to_string(r), c.evals);
  }
  /* Report: action, multipliers by least squares (C-5), scaled residual of the Lagrangian. */
  {
    double S;
    cv_status st2 = CVAR_OK;
    if (constrained) st2 = cv_kkt_init_multipliers(&kkt, Y, s->mult);
    if (!st2) st2 = cv_kkt_eval(&kkt, Y, s->mult, &S, c.g, NULL, NULL);
    if (!st2) {
      s->action = S;
      double rn = 0.0;
      for (int f = 0; f < d->nfree; f++) rn = fmax(rn, fabs(c.g[f]) / d->mass[f]);
      s->gnorm = rn;
    } else if (st == CVAR_OK) {
      st = st2;
      cv_set_msg(s->msg, sizeof s->msg, "the integrand is not finite at the point reached");
    }
  }
cleanup:
  if (st == CVAR_ENOMEM && !s->msg[0]) cv_set_msg(s->msg, sizeof s->msg, "out of memory");
  nlopt_destroy(local);
  nlopt_destroy(c.opt);
  cv_kkt_free(&kkt);
  cv_free(colptr);
  cv_free(c.g);
  cv_free(c.yof);
  cv_free(c.fof);
  cv_free(c.rows);
  cv_free(c.lrow);
  cv_free(c.var);
  cv_free(x);
  cv_free(tol);
  return st;
}
