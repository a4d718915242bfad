/* tests/physics/test_mechanics.c — scene_equations_new and scene_modes_new against
 * hand-derived mechanics: the printed Euler–Lagrange equations, momenta and Hamiltonians
 * parsed back and evaluated at random points; normal modes of the double pendulum; the
 * inverted pendulum; neutral, singular and refused cases.
 * SPDX-License-Identifier: MIT
 *
 * usage: test_mechanics DATA_DIR   (DATA_DIR: copies of shared/problems)
 *
 * Tolerances: the printed expressions are collected (ex_collect) and printed with the
 * shortest round-trip decimals, so they agree with the hand-derived formulas to a few
 * ulps of the largest term: 1e-12 relative to the terms' magnitude. Eigenvalues of 2x2
 * symmetric-definite problems from LAPACK: 1e-12 relative, as the issue asks.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expr/expr.h"
#include "scene/scene.h"
#include "scene/scene_mechanics.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int failures, checks;

static void near(const char *what, double actual, double expected, double tol) {
  checks++;
  if (!(fabs(actual - expected) <= tol)) {
    failures++;
    printf("FAIL %s\n  expected: %.17g\n  actual:   %.17g\n  tolerance: %g\n", what, expected,
           actual, tol);
  }
}

static void truth(const char *what, int ok, const char *detail) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: %s\n", what, detail);
  }
}

static double urand(double lo, double hi) { return lo + (hi - lo) * (rand() / (double)RAND_MAX); }

/* Re-parsing printed text: names are resolved against eq->names (name plus primes). */
static ex_id resolve(ex_dag *d, const char *name, int primes, void *user, char *err,
                     size_t errlen) {
  const mech_equations *eq = user;
  char full[128];
  snprintf(full, sizeof full, "%s%.*s", name, primes, "''");
  for (int k = 0; k < eq->nslots; k++)
    if (strcmp(eq->names[k], full) == 0) return ex_slot(d, k);
  snprintf(err, errlen, "unknown name '%s'", full);
  return -1;
}

/* Print e (of the scene's DAG), parse the text into `into`; -1 on failure. */
static ex_id reparse(const scene *s, const mech_equations *eq, ex_id e, ex_dag *into, char *text,
                     size_t len) {
  char err[256];
  ex_print(s->dag, e, (const char *const *)eq->names, text, len);
  ex_id r = ex_parse(into, text, resolve, (void *)eq, 1, err, sizeof err);
  if (r < 0) printf("  cannot re-parse '%s': %s\n", text, err);
  return r;
}

static scene *load(const char *dir, const char *file, int nset, const sc_set *set) {
  char path[1024], err[SC_ERRLEN] = "";
  snprintf(path, sizeof path, "%s/%s", dir, file);
  scene *s = scene_load_file(path, nset, set, err, sizeof err);
  truth(file, s != NULL, err);
  return s;
}

static scene *load_text(const char *text) {
  char err[SC_ERRLEN] = "";
  scene *s = scene_load_buffer(text, strlen(text), "t.scene", 0, NULL, err, sizeof err);
  truth("in-memory scene", s != NULL, err);
  return s;
}

/* Pendulum L = m l^2 th'^2/2 + m g l cos th: E = m l^2 th'' + m g l sin th,
 * p = m l^2 th', H = m l^2 th'^2/2 - m g l cos th. */
static void pendulum(const char *dir, double m, double l, double g, int nset, const sc_set *set) {
  scene *s = load(dir, "pendulum_angle.scene", nset, set);
  mech_equations eq;
  char err[SC_ERRLEN] = "", tE[512], tp[512], tH[512], what[128];
  if (!s) return;
  if (scene_equations_new(s, &eq, err, sizeof err) != CVAR_OK) {
    truth("pendulum equations", 0, err);
    scene_free(s);
    return;
  }
  ex_dag *d = ex_dag_new();
  ex_id E = reparse(s, &eq, eq.el[0], d, tE, sizeof tE);
  ex_id P = reparse(s, &eq, eq.momentum[0], d, tp, sizeof tp);
  ex_id H = reparse(s, &eq, eq.hamiltonian, d, tH, sizeof tH);
  printf("pendulum m=%g l=%g g=%g:\n  E = %s\n  p = %s\n  H = %s\n", m, l, g, tE, tp, tH);
  truth("pendulum expressions re-parse", E >= 0 && P >= 0 && H >= 0, tE);
  truth("pendulum: not cyclic, autonomous", !eq.cyclic[0] && eq.autonomous, "flags");
  /* The simplified form: no 0*, *1, +0 left, and the y'' coefficient printed first. */
  truth("pendulum E has no zero terms",
        !strstr(tE, "0*") && !strstr(tE, "*1") && !strstr(tE, "+ 0"), tE);
  for (int k = 0; k < 200 && E >= 0 && P >= 0 && H >= 0; k++) {
    double v[4] = {urand(-10, 10), urand(-7, 7), urand(-5, 5), urand(-50, 50)};
    double e, p, h; /* slots: 0 = t, 1 = th, 2 = th', 3 = th'' */
    ex_eval(d, E, v, &e);
    ex_eval(d, P, v, &p);
    ex_eval(d, H, v, &h);
    double he = m * l * l * v[3] + m * g * l * sin(v[1]);
    double hp = m * l * l * v[2];
    double hh = m * l * l * v[2] * v[2] / 2 - m * g * l * cos(v[1]);
    double sc = m * l * l * fabs(v[3]) + m * g * l + m * l * l * v[2] * v[2];
    snprintf(what, sizeof what, "pendulum(m=%g) E at point %d", m, k);
    near(what, e, he, 1e-12 * sc);
    snprintf(what, sizeof what, "pendulum(m=%g) p at point %d", m, k);
    near(what, p, hp, 1e-12 * sc);
    snprintf(what, sizeof what, "pendulum(m=%g) H at point %d", m, k);
    near(what, h, hh, 1e-12 * sc);
  }
  ex_dag_free(d);
  mech_equations_free(&eq);
  scene_free(s);
}

/* Double pendulum (equal m, l): hand-derived equations, a constant multiple allowed. */
static void double_pendulum_equations(const char *dir) {
  scene *s = load(dir, "double_pendulum.scene", 0, NULL);
  mech_equations eq;
  char err[SC_ERRLEN] = "", t[2][512], tH[512], what[128];
  const double m = 1, l = 1, g = 9.81;
  if (!s || scene_equations_new(s, &eq, err, sizeof err) != CVAR_OK) {
    truth("double pendulum equations", 0, err);
    scene_free(s);
    return;
  }
  ex_dag *d = ex_dag_new();
  ex_id E[2], H = reparse(s, &eq, eq.hamiltonian, d, tH, sizeof tH);
  for (int i = 0; i < 2; i++) E[i] = reparse(s, &eq, eq.el[i], d, t[i], sizeof t[i]);
  printf("double pendulum:\n  E_a = %s\n  E_b = %s\n  H = %s\n", t[0], t[1], tH);
  truth("double pendulum re-parse", E[0] >= 0 && E[1] >= 0 && H >= 0, "");
  /* slots: 0 t, 1 a, 2 b, 3 a', 4 b', 5 a'', 6 b'' */
  for (int k = 0; k < 200 && E[0] >= 0 && E[1] >= 0 && H >= 0; k++) {
    double v[7];
    v[0] = 0;
    for (int j = 1; j < 7; j++) v[j] = urand(-4, 4);
    double a = v[1], b = v[2], da = v[3], db = v[4], dda = v[5], ddb = v[6], c = cos(a - b),
           sn = sin(a - b), ml2 = m * l * l;
    double ha = ml2 * (2 * dda + c * ddb + db * db * sn) + 2 * m * g * l * sin(a);
    double hb = ml2 * (c * dda + ddb - da * da * sn) + m * g * l * sin(b);
    double hh =
        ml2 * (2 * da * da + db * db + 2 * da * db * c) / 2 - m * g * l * (2 * cos(a) + cos(b));
    double ea, eb, eh;
    ex_eval(d, E[0], v, &ea);
    ex_eval(d, E[1], v, &eb);
    ex_eval(d, H, v, &eh);
    double sc = 100;
    snprintf(what, sizeof what, "double pendulum E_a at point %d", k);
    near(what, ea, ha, 1e-12 * sc);
    snprintf(what, sizeof what, "double pendulum E_b at point %d", k);
    near(what, eb, hb, 1e-12 * sc);
    snprintf(what, sizeof what, "double pendulum H at point %d", k);
    near(what, eh, hh, 1e-12 * sc);
  }
  ex_dag_free(d);
  mech_equations_free(&eq);
  scene_free(s);
}

/* Cyclic and autonomous flags of the reference scenes. */
static void flags(const char *dir) {
  static const struct {
    const char *file;
    int autonomous;
    int cyclic0, cyclic1;
  } cases[] = {{"graded_index_ray.scene", 0, 1, -1},
               {"sphere_geodesic.scene", 1, 0, 1},
               {"catenary.scene", 1, 0, -1},
               {"harmonic_minimum.scene", 1, 0, -1},
               {"straight_line.scene", 1, 1, -1}};
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    scene *s = load(dir, cases[c].file, 0, NULL);
    mech_equations eq;
    char err[SC_ERRLEN] = "";
    if (!s || scene_equations_new(s, &eq, err, sizeof err) != CVAR_OK) {
      truth(cases[c].file, 0, err);
      scene_free(s);
      continue;
    }
    truth(cases[c].file, eq.autonomous == cases[c].autonomous, "autonomous flag");
    truth(cases[c].file, eq.cyclic[0] == cases[c].cyclic0, "cyclic flag of unknown 0");
    if (cases[c].cyclic1 >= 0)
      truth(cases[c].file, eq.cyclic[1] == cases[c].cyclic1, "cyclic flag of unknown 1");
    mech_equations_free(&eq);
    scene_free(s);
  }
}

/* Double pendulum modes: w2 = (g/l)(2 -+ sqrt 2); K v = w2 M v, v^T M v = 1. */
static void double_pendulum_modes(const char *dir, double l, double g, int nset,
                                  const sc_set *set) {
  scene *s = load(dir, "double_pendulum.scene", nset, set);
  mech_modes md;
  char err[SC_ERRLEN] = "", what[128];
  if (!s) return;
  cv_status rc = scene_modes_new(s, &md, err, sizeof err);
  truth("double pendulum modes", rc == CVAR_OK, err);
  if (rc == CVAR_OK) {
    double w2[2] = {g / l * (2 - sqrt(2.0)), g / l * (2 + sqrt(2.0))};
    for (int k = 0; k < 2; k++) {
      snprintf(what, sizeof what, "double pendulum l=%g g=%g omega2[%d]", l, g, k);
      near(what, md.omega2[k], w2[k], 1e-12 * w2[k]);
      truth(what, md.kind[k] == MECH_MODE_STABLE, "kind stable");
      const double *v = md.shape + 2 * k;
      double Mv[2], Kv[2], vMv = 0;
      for (int i = 0; i < 2; i++) {
        Mv[i] = md.mass[2 * i] * v[0] + md.mass[2 * i + 1] * v[1];
        Kv[i] = md.stiffness[2 * i] * v[0] + md.stiffness[2 * i + 1] * v[1];
        vMv += v[i] * Mv[i];
      }
      snprintf(what, sizeof what, "double pendulum mode %d unit M-norm", k);
      near(what, vMv, 1.0, 1e-13);
      for (int i = 0; i < 2; i++) {
        snprintf(what, sizeof what, "double pendulum mode %d K v = w2 M v row %d", k, i);
        near(what, Kv[i], md.omega2[k] * Mv[i], 1e-12 * md.omega2[1]);
      }
    }
    /* Shapes (hand-derived): lower mode a : b = 1 : sqrt 2, upper 1 : -sqrt 2. */
    near("double pendulum lower mode ratio", md.shape[1] / md.shape[0], sqrt(2.0), 1e-12);
    near("double pendulum upper mode ratio", md.shape[3] / md.shape[2], -sqrt(2.0), 1e-12);
    near("double pendulum equilibrium a", md.equilibrium[0], 0, 0);
    near("double pendulum equilibrium b", md.equilibrium[1], 0, 0);
  }
  mech_modes_free(&md);
  scene_free(s);
}

static const char *top_text = "[scene]\ntitle = top\nvariable = t\ninterval = 0, 1\nunknowns = th\n"
                              "integrand = m*l^2*th'^2/2 + m*g*l*cos(th)\n"
                              "[parameters]\nm = 2\nl = 0.5\ng = 9.81\nth0 = 3\n"
                              "[boundary]\nth = 0, 0\n[guess]\nth = th0\n";

/* The pendulum about th = pi (Newton from th = 3): unstable, growth rate sqrt(g/l). */
static void inverted_pendulum(void) {
  scene *s = load_text(top_text);
  mech_modes md;
  char err[SC_ERRLEN] = "";
  if (!s) return;
  cv_status rc = scene_modes_new(s, &md, err, sizeof err);
  truth("inverted pendulum modes", rc == CVAR_OK, err);
  if (rc == CVAR_OK) {
    near("inverted pendulum equilibrium", md.equilibrium[0], M_PI, 1e-14);
    truth("inverted pendulum Newton iterations", md.iterations >= 2 && md.iterations < 10,
          "expected a few");
    truth("inverted pendulum kind", md.kind[0] == MECH_MODE_UNSTABLE, "unstable");
    near("inverted pendulum growth rate", sqrt(-md.omega2[0]), sqrt(9.81 / 0.5),
         1e-12 * sqrt(9.81 / 0.5));
    near("inverted pendulum unit M-norm", md.shape[0] * md.shape[0] * md.mass[0], 1, 1e-14);
  }
  mech_modes_free(&md);
  scene_free(s);
}

/* Cases with a known outcome: neutral modes, no equilibrium, singular M, refusals. */
static void special_cases(void) {
  static const struct {
    const char *what, *text;
    cv_status rc;
    const char *msg;
  } cases[] = {
      {"two masses on a spring (translation neutral)",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=a,b\n"
       "integrand=(a'^2 + b'^2)/2 - 3*(a - b)^2/2\n[boundary]\na=0,0\nb=1,1\n",
       CVAR_OK, NULL},
      {"constant force (no equilibrium)",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=y\nintegrand=y'^2/2 + 2*y\n"
       "[boundary]\ny=0,0\n",
       CVAR_EMAXITER, "no equilibrium"},
      {"b without kinetic energy (M singular)",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=a,b\n"
       "integrand=a'^2/2 - a^2/2 - b^2/2\n[boundary]\na=0,0\nb=0,0\n",
       CVAR_ESINGULAR, "not positive definite"},
      {"negative kinetic energy (M not positive definite)",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=y\nintegrand=-y'^2/2 - y^2/2\n"
       "[boundary]\ny=0,0\n",
       CVAR_ESINGULAR, "not positive definite"},
      {"explicit variable",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=y\nintegrand=y'^2/2 - x*y^2\n"
       "[boundary]\ny=0,0\n",
       CVAR_EINVAL, "t.scene:5: the integrand depends explicitly on x"},
      {"constraint (Cartesian pendulum, g = l = 1)",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=x1,y1\nintegrand=(x1'^2+y1'^2)/2 - y1\n"
       "[boundary]\nx1=0,0\ny1=-1,-1\n[constraints]\nrod = x1^2 + y1^2 - 1\n",
       CVAR_OK, NULL},
      {"integral constraint",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=y\nintegrand=y'^2/2 - y^2/2\n"
       "[boundary]\ny=0,0\n[integrals]\narea = y, 1\n",
       CVAR_EINVAL, "t.scene:9: modes does not handle integral constraints"},
      {"moving constraint",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=a,b\nintegrand=(a'^2+b'^2)/2\n"
       "[boundary]\na=0,free\nb=0,free\n[constraints]\nslide = a - x*b\n",
       CVAR_EINVAL, "t.scene:10: the constraint 'slide' depends on x"},
      {"not finite at the guess",
       "[scene]\ntitle=t\ninterval=0,1\nunknowns=y\nintegrand=y'^2/2 + log(y)\n"
       "[boundary]\ny=0,1\n",
       CVAR_ENONFINITE, "not finite"},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    scene *s = load_text(cases[c].text);
    mech_modes md;
    char err[SC_ERRLEN] = "";
    if (!s) continue;
    cv_status rc = scene_modes_new(s, &md, err, sizeof err);
    truth(cases[c].what, rc == cases[c].rc, err[0] ? err : "(no message)");
    if (cases[c].msg) truth(cases[c].what, strstr(err, cases[c].msg) != NULL, err);
    if (rc == CVAR_OK && strstr(cases[c].what, "Cartesian pendulum")) {
      /* hanging at (0, -1): lambda = -g/(2l) = -1/2, one mode on the circle, omega2 = g/l,
       * shape along x with unit mass norm */
      truth("pendulum: one constrained mode", md.nmodes == 1 && md.nc == 1, "nmodes");
      near("pendulum: x", md.equilibrium[0], 0, 1e-14);
      near("pendulum: y", md.equilibrium[1], -1, 1e-14);
      near("pendulum: lambda", md.multipliers[0], -0.5, 1e-14);
      near("pendulum: omega2", md.omega2[0], 1, 1e-13);
      near("pendulum: shape x", md.shape[0], 1, 1e-13);
      near("pendulum: shape y", md.shape[1], 0, 1e-13);
    }
    if (rc == CVAR_OK && c == 0) {
      truth("spring: lower mode neutral", md.kind[0] == MECH_MODE_NEUTRAL, "neutral");
      near("spring: lower omega2", md.omega2[0], 0, 1e-12);
      near("spring: upper omega2", md.omega2[1], 6, 1e-12);
      near("spring: neutral shape a = b", md.shape[0] - md.shape[1], 0, 1e-12);
      near("spring: equilibrium keeps the guess's centre", md.equilibrium[0] + md.equilibrium[1], 1,
           1e-12);
      near("spring: equilibrium a = b", md.equilibrium[0] - md.equilibrium[1], 0, 1e-12);
    }
    mech_modes_free(&md);
    scene_free(s);
  }
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: test_mechanics DATA_DIR\n");
    return 2;
  }
  const char *dir = argv[1];
  srand(12345);
  pendulum(dir, 1, 1, 9.81, 0, NULL);
  sc_set set[3] = {{"m", "2"}, {"l", "3"}, {"g", "1.5"}};
  pendulum(dir, 2, 3, 1.5, 3, set);
  double_pendulum_equations(dir);
  flags(dir);
  double_pendulum_modes(dir, 1, 9.81, 0, NULL);
  sc_set set2[2] = {{"l", "0.7"}, {"g", "3.25"}};
  double_pendulum_modes(dir, 0.7, 3.25, 2, set2);
  inverted_pendulum();
  special_cases();
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? 1 : 0;
}
