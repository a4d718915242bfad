/* src/core/cv_nlopt.c — the NLopt engine: minimise the discrete action over the free nodal
 * values with the exact gradient, constraints as NLopt equality (or paired
 * inequality) constraints and obstacles as inequality constraints (OB-1), multipliers
 * recovered afterwards by least squares (C-5).
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
/* ... with the action below its start by this multiple of (|S0| + 1) (NL-3) */
#define RUNAWAY_FALL 1e3

typedef struct {
  cv_solver *s;
  const cv_disc *d;
  cv_kkt *kkt;
  double *Y, *g;   /* nodal values (full), gradient over all unknowns */
  int nv;          /* NLopt variables: the free y unknowns */
  int *yof, *fof;  /* variable -> y dof, variable -> unknown index */
  int *rows;       /* constraint row -> unknown index of its multiplier, or nu row */
  int *lrow, *var; /* unknown index -> constraint row / NLopt variable, or -1 */
  int m;           /* number of constraint rows */
  int *rsense;     /* constraint row -> 0 (equality) or the sense of its inequality */
  int *sel;        /* the rows of one NLopt constraint set: equalities, then inequalities */
  int me, mi;      /* how many of each */
  double *J;       /* scratch: the Jacobian of all m rows (m x nv), when both sets exist */
  double scale, action;
  double smin, ymax; /* smallest action and largest |y| seen (runaway diagnosis) */
  double S0;         /* the action at the start (NAN before it is known) */
  long evals;
  cv_status stop; /* status stored before a forced stop */
  nlopt_opt opt;
  /* Preconditioned variables (theory NL-1): y = y0 + L^{-T} |D|^{-1/2} z with L D L^T the
   * factor of a model Hessian (stiffness + mass), so the minimisers see an O(1)-conditioned
   * problem instead of one whose condition grows like (elements)^2. */
  cv_ldlt *P;
  double *dinv, *Y0, *w;
} nl_ctx;

/* y(z) into c->Y, theory (NL-1). */
static void load(nl_ctx *c, const double *z) {
  int nf = c->d->nfree;
  memset(c->w, 0, (size_t)nf * sizeof *c->w);
  for (int v = 0; v < c->nv; v++) c->w[c->fof[v]] = c->dinv[c->fof[v]] * z[v];
  cv_ldlt_solve_L(c->P, 1, c->w);
  memcpy(c->Y, c->Y0, (size_t)c->d->ndof * sizeof *c->Y);
  for (int v = 0; v < c->nv; v++) c->Y[c->yof[v]] += c->w[c->fof[v]];
}

/* A gradient row over the y unknowns (unknown-indexed in r, zero elsewhere) to z:
 * dz = |D|^{-1/2} L^{-1} r. Overwrites r; writes nv values to out. */
static void to_z(nl_ctx *c, double *r, double *out) {
  cv_ldlt_solve_L(c->P, 0, r);
  for (int v = 0; v < c->nv; v++) out[v] = c->dinv[c->fof[v]] * r[c->fof[v]];
}

/* Model Hessian integrand: (|y'|^2 + |y|^2 / L^2) / 2 per component, L = b - a; with y''
 * (C^1 elements, CVAR_NEED_Y2) L^2 |y''|^2 / 2 more (H-4). */
static void model_y2(int m, int n, double L2, unsigned need, cv_partials *o) {
  cv_partials2 *o2 = cv_partials_y2(o);
  for (int k = 0; k < m; k++)
    for (int i = 0; i < n; i++) {
      double q = o2->d2y[i * m + k];
      o->F[k] += 0.5 * L2 * q * q;
      if (o2->Fq) o2->Fq[i * m + k] = L2 * q;
    }
  for (size_t k = 0; o2->Fqq && k < (size_t)n * n * m; k++) o2->Fyq[k] = o2->Fpq[k] = 0.0;
  for (int i = 0; o2->Fqq && i < n; i++)
    for (int j = 0; j < n; j++)
      for (int k = 0; k < m; k++) o2->Fqq[(i * n + j) * m + k] = i == j ? L2 : 0.0;
  (void)need;
}

static int model_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  const int *nn = user;
  int n = nn[0];
  double iL2 = 1.0 / ((double)nn[1] * 1e-6); /* nn[1] holds (b-a)^2 in micro-units */
  (void)x;
  if (need & CVAR_NEED_Y2) n /= 2; /* d->n counts values and slopes */
  for (int k = 0; k < m; k++) {
    double s = 0.0;
    for (int i = 0; i < n; i++)
      s += dy[i * m + k] * dy[i * m + k] + iL2 * y[i * m + k] * y[i * m + k];
    o->F[k] = 0.5 * s;
    for (int i = 0; i < n && o->Fy; i++) {
      o->Fy[i * m + k] = iL2 * y[i * m + k];
      o->Fp[i * m + k] = dy[i * m + k];
    }
    for (int i = 0; i < n && o->Fyy; i++)
      for (int j = 0; j < n; j++) {
        o->Fyy[(i * n + j) * m + k] = i == j ? iL2 : 0.0;
        o->Fyp[(i * n + j) * m + k] = 0.0;
        o->Fpp[(i * n + j) * m + k] = i == j ? 1.0 : 0.0;
      }
  }
  if (need & CVAR_NEED_Y2) model_y2(m, n, 1e-6 * nn[1], need, o);
  return 0;
}

static double objective(unsigned n, const double *x, double *grad, void *data) {
  nl_ctx *c = data;
  double S;
  (void)n;
  c->evals++;
  load(c, x);
  int far = 0;
  for (int v = 0; v < c->nv && !far; v++) far = !(fabs(c->Y[c->yof[v]]) <= RUNAWAY * c->scale);
  memset(c->g, 0, (size_t)c->d->nfree * sizeof *c->g);
  cv_status st = cv_assemble(&c->kkt->as, c->kkt->prob->F, c->kkt->prob->user, c->Y, &S,
                             grad && !far ? c->g : NULL, c->kkt->colptr, NULL, 0.0, 0);
  if (st == CVAR_ECALLBACK || st == CVAR_ENOMEM) {
    c->stop = st;
    nlopt_force_stop(c->opt);
    return 0.0;
  }
  /* A trial point beyond RUNAWAY x the data is evidence of an action unbounded below only
   * if the action fell with it (NL-3): a truncated-Newton step along a direction where F
   * is flat in y (a medium in layers: F_y = 0 between the interfaces) goes as far without
   * any fall, and is a rejected trial point like one outside the integrand's domain. */
  if (far && st == CVAR_OK && S < c->S0 - RUNAWAY_FALL * (fabs(c->S0) + 1.0)) {
    c->stop = CVAR_ENOTMIN;
    nlopt_force_stop(c->opt);
    return 0.0;
  }
  if (st || far) return HUGE_VAL; /* outside the integrand's domain: a rejected trial point */
  if (S < c->smin) c->smin = S;
  for (int v = 0; v < c->nv; v++) c->ymax = fmax(c->ymax, fabs(c->Y[c->yof[v]]));
  if (grad) {
    for (int f = 0; f < c->d->nfree; f++) c->w[f] = 0.0;
    for (int v = 0; v < c->nv; v++) c->w[c->fof[v]] = c->g[c->fof[v]];
    to_z(c, c->w, grad);
  }
  return S;
}

/* The m rows sel[0 .. m-1] of the constraint rows (G_k(x_j, Y_j) at the nodes with
 * multipliers, then I_r - c_r), in NLopt's form: an equality as it is, an inequality
 * s G >= 0 as -s G <= 0 (OB-1). All rows are evaluated (into c->J when the set is a part
 * of them) and the set's are copied out. */
static void constraint_set(unsigned m, double *result, const double *x, double *grad, nl_ctx *c,
                           const int *sel) {
  load(c, x);
  int all = (int)m == c->m;
  double *J = grad ? (all ? grad : c->J) : NULL;
  if (J) memset(J, 0, (size_t)c->m * c->nv * sizeof *J);
  cv_status st = cv_kkt_constraint_values(c->kkt, c->Y, c->g, J, c->nv, c->lrow, c->var);
  if (st) {
    c->stop = st;
    nlopt_force_stop(c->opt);
  }
  for (unsigned i = 0; i < m; i++) {
    int r = sel[i], sg = c->rsense[r] ? -c->rsense[r] : 1;
    result[i] = st ? 0.0 : sg * c->g[c->rows[r]];
    if (!grad) continue;
    double *row = grad + (size_t)i * c->nv;
    if (!all) memcpy(row, J + (size_t)r * c->nv, (size_t)c->nv * sizeof *row);
    /* the Jacobian row from y to z (NL-1): row <- |D|^{-1/2} L^{-1} row */
    memset(c->w, 0, (size_t)c->d->nfree * sizeof *c->w);
    for (int v = 0; v < c->nv; v++) c->w[c->fof[v]] = sg * row[v];
    to_z(c, c->w, row);
  }
}

static void eq_constraints(unsigned m, double *result, unsigned n, const double *x, double *grad,
                           void *data) {
  nl_ctx *c = data;
  (void)n;
  constraint_set(m, result, x, grad, c, c->sel);
}

static void ineq_constraints(unsigned m, double *result, unsigned n, const double *x, double *grad,
                             void *data) {
  nl_ctx *c = data;
  (void)n;
  constraint_set(m, result, x, grad, c, c->sel + c->me);
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

/* Scaled residual of the Lagrangian (N-3) at Y with least-squares multipliers (C-5), which
 * are left in the solver's multiplier array; the action goes to c->action. */
static double stationarity(nl_ctx *c, cv_kkt *kkt, const double *Y) {
  const cv_disc *d = c->d;
  double S, rn = 0.0;
  cv_status st = CVAR_OK;
  if (d->nc > 0 || d->ni > 0) st = cv_kkt_init_multipliers(kkt, Y, c->s->mult);
  if (!st) st = cv_kkt_eval(kkt, Y, c->s->mult, &S, c->g, NULL, NULL);
  if (st) return NAN;
  c->action = S;
  for (int f = 0; f < d->nfree; f++) rn = fmax(rn, fabs(c->g[f]) / d->mass[f]);
  return rn;
}

/* Factor the model Hessian (stiffness + mass of each component, identity on multiplier
 * rows) in the solver's sparsity pattern; D is positive, so |D|^{-1/2} is plain D^{-1/2}. */
static cv_status precondition(nl_ctx *c, const cv_disc *d, const int *colptr) {
  int nn[2];
  double S, L2 = (d->b - d->a) * (d->b - d->a);
  nn[0] = d->n;
  nn[1] = (int)fmin(2e9, fmax(1.0, L2 * 1e6));
  double *Ax = cv_ldlt_values(c->P);
  cv_status st = cv_assemble(&c->kkt->as, model_F, nn, c->Y0, &S, NULL, colptr, Ax, 1.0, 0);
  if (st) return st;
  for (int f = 0; f < d->nfree; f++) c->dinv[f] = 1.0;
  for (int f = 0; f < d->nfree; f++)
    if (c->var[f] < 0) Ax[colptr[f + 1] - 1] = 1.0; /* multiplier rows: identity */
  int neg;
  double dmin, dmax;
  char msg[160];
  st = cv_ldlt_factor(c->P, &neg, &dmin, &dmax, msg, sizeof msg);
  if (st || neg > 0) {
    cv_set_msg(c->s->msg, sizeof c->s->msg, "model Hessian for preconditioning is singular");
    return st ? st : CVAR_ESINGULAR;
  }
  cv_ldlt_diag(c->P, c->dinv);
  for (int f = 0; f < d->nfree; f++) c->dinv[f] = 1.0 / sqrt(c->dinv[f]);
  return CVAR_OK;
}

/* NLopt's variables are the free y unknowns (var: variable of each free unknown, or -1;
 * yof, fof: its y dof and free index), its constraints the multiplier rows (lrow: row of
 * each free unknown, or -1; rows: the free index of each row). */
static void index_unknowns(nl_ctx *c, const cv_disc *d) {
  for (int f = 0; f < d->nfree; f++) c->lrow[f] = c->var[f] = -1;
  for (long j = 0; j < d->nodes; j++) {
    for (int i = 0; i < d->n; i++) {
      int f = cv_disc_fidx(d, j * d->n + i);
      if (f < 0) continue;
      c->var[f] = c->nv;
      c->yof[c->nv] = (int)(j * d->n + i);
      c->fof[c->nv++] = f;
    }
    for (int k = 0; k < d->nc; k++) {
      int f = cv_disc_lidx(d, j, k);
      if (f >= 0)
        c->lrow[f] = c->m, c->rsense[c->m] = c->kkt->prob->pc[k].sense, c->rows[c->m++] = f;
    }
  }
  for (int r = 0; r < d->ni; r++)
    c->lrow[d->nu0 + r] = c->m, c->rsense[c->m] = 0, c->rows[c->m++] = d->nu0 + r;
  c->me = c->mi = 0; /* sel: the equality rows, then the inequality rows */
  for (int r = 0; r < c->m; r++)
    if (!c->rsense[r]) c->sel[c->me++] = r;
  for (int r = 0; r < c->m; r++)
    if (c->rsense[r]) c->sel[c->me + c->mi++] = r;
}

/* The NLopt object for s->method with the objective, tolerances and constraints (NL-2).
 * MMA and CCSAQ take only inequality constraints; an equality as two opposite inequalities
 * leaves them no interior to move in (they stall far from the answer). NLopt's remedy is
 * AUGLAG_EQ: the equalities go to an augmented Lagrangian whose subproblems MMA or CCSAQ
 * solve. *local: the subsidiary optimiser, if any (the caller destroys it). */
static cv_status make_optimizer(nl_ctx *c, cv_solver *s, nlopt_opt *local, const double *tol) {
  int eq_wrap = c->me > 0 && (s->method == CVAR_METHOD_MMA || s->method == CVAR_METHOD_CCSAQ);
  c->opt = nlopt_create(eq_wrap ? NLOPT_AUGLAG_EQ : algorithm(s->method), (unsigned)c->nv);
  if (!c->opt) return CVAR_ENOMEM;
  if (s->method == CVAR_METHOD_AUGLAG || eq_wrap) {
    *local = nlopt_create(eq_wrap ? algorithm(s->method) : NLOPT_LD_LBFGS, (unsigned)c->nv);
    if (!*local) return CVAR_ENOMEM;
    nlopt_set_xtol_rel(*local, s->rtol);
    nlopt_set_ftol_rel(*local, 0.0);
    nlopt_set_local_optimizer(c->opt, *local);
  }
  nlopt_set_min_objective(c->opt, objective, c);
  nlopt_set_xtol_rel(c->opt, s->rtol);
  nlopt_set_ftol_rel(c->opt, s->rtol * 1e-2);
  /* Evaluations, not Newton iterations: a quasi-Newton method needs many more. */
  nlopt_set_maxeval(c->opt, 200 * s->maxit);
  if (c->m > 0) {
    nlopt_result r = NLOPT_SUCCESS;
    if (c->me > 0)
      r = nlopt_add_equality_mconstraint(c->opt, (unsigned)c->me, eq_constraints, c, tol);
    if (r >= 0 && c->mi > 0) /* MMA, CCSAQ, SLSQP and AUGLAG take inequalities natively */
      r = nlopt_add_inequality_mconstraint(c->opt, (unsigned)c->mi, ineq_constraints, c, tol);
    if (r < 0) {
      cv_set_msg(s->msg, sizeof s->msg, "NLopt refused the constraints (%s)",
                 nlopt_result_to_string(r));
      return CVAR_EDEPENDENCY;
    }
  }
  return CVAR_OK;
}

/* The status and message for NLopt's result r (S0: the action at the start; *roundoff:
 * the line search ended at round-off, accepted only on a larger fall of the residual).
 * Runaway: iterates a thousand times the size of the data with the action far below its
 * start mean the action is unbounded below, whatever code NLopt returned (L-BFGS may
 * report a generic failure after overflowing steps). */
static cv_status result_status(const nl_ctx *c, cv_solver *s, nlopt_result r, double S0,
                               int *roundoff) {
  cv_status st;
  int runaway = c->ymax > 1e3 * c->scale && c->smin < S0 - RUNAWAY_FALL * (fabs(S0) + 1.0);
  if ((r == NLOPT_FORCED_STOP && c->stop == CVAR_ENOTMIN) || (r < 0 && runaway)) {
    st = CVAR_ENOTMIN;
    cv_set_msg(s->msg, sizeof s->msg,
               "the action decreases without bound under %s: it has no minimum here, so its "
               "stationary path (if any) is a saddle that a minimiser cannot find; use method "
               "newton, which reports the Morse index",
               cv_method_name(s->method));
  } else if (r == NLOPT_FORCED_STOP) {
    st = c->stop ? c->stop : CVAR_EDEPENDENCY;
    cv_set_msg(s->msg, sizeof s->msg, "%s stopped: %s", cv_method_name(s->method), cv_strerror(st));
  } else if (r == NLOPT_ROUNDOFF_LIMITED || r == NLOPT_FAILURE) {
    /* L-BFGS reports a failed line search as a generic failure; near the minimum that is
     * round-off. Accepted by the caller only if the residual fell by 1e4 (NL-2). */
    st = CVAR_OK;
    *roundoff = 1;
    cv_set_msg(s->msg, sizeof s->msg,
               "%s converged in %ld evaluations (its line search ended at round-off)",
               cv_method_name(s->method), c->evals);
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
               cv_method_name(s->method), nlopt_result_to_string(r), c->evals);
  }
  return st;
}

cv_status cv_nlopt_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y) {
  nl_ctx c;
  cv_kkt kkt;
  cv_status st = CVAR_OK;
  const int *colptr = NULL;
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
  /* The preconditioner's matrix owns the pattern the assembly scatters into. */
  st = cv_ldlt_new(d, NULL, &c.P, s->msg, sizeof s->msg);
  if (st) goto cleanup;
  colptr = cv_ldlt_colptr(c.P);
  c.g = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.g);
  c.yof = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.yof);
  c.fof = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.fof);
  c.rows = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.rows);
  c.lrow = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.lrow);
  c.var = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.var);
  c.rsense = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.rsense);
  c.sel = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.sel);
  if (!c.g || !c.yof || !c.fof || !c.rows || !c.lrow || !c.var || !c.rsense || !c.sel) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  st = cv_kkt_init(&kkt, p, d, colptr);
  if (st) goto cleanup;
  if (d->nc > 0) {
    st = cv_kkt_check_ends(&kkt, Y, s->msg, sizeof s->msg);
    if (st) goto cleanup;
  }
  c.kkt = &kkt;
  /* OB-2: multipliers recovered where NLopt's answer is within 1e-6 of an obstacle (at a
   * free node the stationarity residual, and so the least-squares multiplier, is ~0) */
  kkt.on_tol = 1e-6;
  index_unknowns(&c, d);
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
  c.Y0 = cv_malloc((size_t)d->ndof * sizeof *c.Y0);
  c.w = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.w);
  c.dinv = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *c.dinv);
  if (!c.Y0 || !c.w || !c.dinv) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  memcpy(c.Y0, Y, (size_t)d->ndof * sizeof *Y);
  c.kkt = &kkt;
  c.Y = Y;
  c.stop = CVAR_OK;
  for (long i = 0; i < d->ndof; i++) c.scale = fmax(c.scale, fabs(Y[i]));
  if (c.scale == 0) c.scale = 1;
  x = cv_malloc((size_t)(c.nv ? c.nv : 1) * sizeof *x);
  tol = cv_malloc((size_t)(c.m ? c.m : 1) * sizeof *tol);
  if (c.me > 0 && c.mi > 0) c.J = cv_malloc((size_t)c.m * c.nv * sizeof *c.J);
  if (!x || !tol || (c.me > 0 && c.mi > 0 && !c.J)) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  st = precondition(&c, d, colptr);
  if (st) goto cleanup;
  for (int v = 0; v < c.nv; v++) x[v] = 0.0; /* z = 0 is the initial guess y0 */
  /* Constraint tolerance: 10 rtol in units of G (or of the integral). */
  /* SLSQP stops as soon as the violation is within tol and S has stopped changing, and the
   * point it reaches is then only as stationary as sqrt(tol) allows (hanging chain: scaled
   * residual 1.4e-3 at tol 1e-9, 2e-5 at 1e-13, 7.5e-6 at 0). Its iterates satisfy the
   * linearised constraints exactly, so it needs no slack: tol 0, and its stop is the f and
   * x tolerances (NL-2). */
  for (int i = 0; i < c.m; i++) tol[i] = s->method == CVAR_METHOD_SLSQP ? 0.0 : 10 * s->rtol;
  st = make_optimizer(&c, s, &local, tol);
  if (st) goto cleanup;
  double fmin = 0.0, S0 = 0.0;
  c.S0 = NAN; /* the start is never taken for a runaway (NAN compares false) */
  S0 = objective((unsigned)c.nv, x, NULL, &c);
  c.S0 = S0;
  if (!isfinite(S0)) {
    st = CVAR_ENONFINITE;
    cv_set_msg(s->msg, sizeof s->msg, "the integrand is not finite at the initial guess");
    goto cleanup;
  }
  double g0 = stationarity(&c, &kkt, Y);
  c.smin = S0;
  c.ymax = 0.0;
  nlopt_result r = nlopt_optimize(c.opt, x, &fmin);
  load(&c, x);
  s->iterations = (int)c.evals;
  /* Runaway: iterates a thousand times the size of the data with the action far below its
   * start mean the action is unbounded below, whatever code NLopt returned (L-BFGS may
   * report a generic failure after overflowing steps). */
  int roundoff = 0;
  st = result_status(&c, s, r, S0, &roundoff);
  /* Report: action, multipliers by least squares (C-5), scaled residual of the Lagrangian.
   * A minimiser stops on small changes of S or z, which can happen short of stationarity;
   * converged is said only when the residual fell by at least 100 (NL-2). */
  s->gnorm = stationarity(&c, &kkt, Y);
  s->action = c.action;
  if (!isfinite(s->gnorm) && st == CVAR_OK) {
    st = CVAR_ENONFINITE;
    cv_set_msg(s->msg, sizeof s->msg, "the integrand is not finite at the point reached");
  } else if (st == CVAR_OK && !(s->gnorm <= (roundoff ? 1e-4 : 1e-2) * g0) && s->gnorm > 1e-12) {
    st = CVAR_ESTALL;
    cv_set_msg(s->msg, sizeof s->msg,
               "%s stopped short of a stationary point (scaled residual %.3g, %.3g at the "
               "start); try newton, or another method",
               cv_method_name(s->method), s->gnorm, g0);
  }
cleanup:
  if (st == CVAR_ENOMEM && !s->msg[0]) cv_set_msg(s->msg, sizeof s->msg, "out of memory");
  nlopt_destroy(local);
  nlopt_destroy(c.opt);
  cv_kkt_free(&kkt);
  cv_free(c.g);
  cv_free(c.yof);
  cv_free(c.fof);
  cv_free(c.rows);
  cv_free(c.lrow);
  cv_free(c.var);
  cv_free(c.rsense);
  cv_free(c.sel);
  cv_free(c.J);
  cv_free(c.Y0);
  cv_free(c.w);
  cv_free(c.dinv);
  cv_ldlt_free(c.P);
  cv_free(x);
  cv_free(tol);
  return st;
}
