/* bench/bench_seismic_fan.c — issue 28's seismic fan (docs/scale-out.md "A seismic fan"):
 * N source-receiver pairs through the tabulated 3-D constant-gradient velocity model of
 * examples/scenes/seismic_fan.scene, `calcvar batch --tol 1e-10` as a whole process (median
 * of RUNS runs) on one and two threads, with and without --warm, and every travel time (the
 * action) against the closed form T = acosh(1 + |g|^2 |r1 - r0|^2 / (2 v0 v1)) / |g|,
 * computed here independently of the scene's [exact]. Prints rays per second (and per core),
 * the CPU time per ray, the max relative travel-time error, the rows over 1e-8, the rows
 * not converged, the max nodal error of the rays against the exact arcs, the rounds and
 * elements of the rows, the date and the load average before and after.
 * The fan is make_seismic_fan.py's: 10 sources down a well at x = y = 0, depths 0.5 to 3
 * km, 1000 receivers on the surface, x in [3, 10] km, y in [-2.5, 2.5] km (40 x 25), rows
 * source by source; N < 10^4 takes N rows spread evenly over it, N > 10^4 repeats it.
 * Usage: bench_seismic_fan [RAYS (10000)] [RUNS (3)]. Not a test: run it by hand.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef CV_CALCVAR
#define CV_CALCVAR "calcvar"
#endif
#ifndef CV_EXAMPLES
#define CV_EXAMPLES "examples/scenes"
#endif

#define FAN     10000
#define MAX_REL 1e-8

static const double V0 = 2.0, GRAD[3] = {0.08, -0.05, 0.6}; /* make_tables.py's model */

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double children_cpu(void) {
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
         (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static void loadavg(char *buf, size_t len) {
  FILE *f = fopen("/proc/loadavg", "r");
  buf[0] = '\0';
  if (f) {
    if (!fgets(buf, (int)len, f)) buf[0] = '\0';
    fclose(f);
  }
  char *sp = buf;
  for (int k = 0; k < 3 && sp; k++) sp = strchr(sp + (k > 0), ' ');
  if (sp) *sp = '\0';
  buf[strcspn(buf, "\n")] = '\0';
}

/* Row k of the fan: source (0, 0, zs), receiver (xr, yr, 0). */
static void fan_row(int k, double r[6]) {
  int i = k / 1000, j = k / 25 % 40, l = k % 25;
  r[0] = 0.0, r[1] = 0.0, r[2] = 0.5 + 2.5 * i / 9;
  r[3] = 3 + 7.0 * j / 39, r[4] = -2.5 + 5.0 * l / 24, r[5] = 0.0;
}

static double velocity(const double *r) {
  return V0 + GRAD[0] * r[0] + GRAD[1] * r[1] + GRAD[2] * r[2];
}

static double travel_time(const double r[6]) {
  double g2 = GRAD[0] * GRAD[0] + GRAD[1] * GRAD[1] + GRAD[2] * GRAD[2], d2 = 0.0;
  for (int k = 0; k < 3; k++) d2 += (r[3 + k] - r[k]) * (r[3 + k] - r[k]);
  return acosh(1 + g2 * d2 / (2 * velocity(r) * velocity(r + 3))) / sqrt(g2);
}

typedef struct {
  double wall, cpu, max_rel, max_nodal, max_est, rounds, elements;
  long over, failed, rows;
} result;

/* The output's columns of one row (the message, last and quoted, kept whole). */
static int field(const char *line, int col, char *out, size_t len) {
  const char *p = line;
  for (int c = 0; c < col; c++) {
    if (*p == '"') return -1;
    p = strchr(p, ',');
    if (!p) return -1;
    p++;
  }
  size_t n = *p == '"' ? strlen(p) : strcspn(p, ",\n");
  if (n >= len) n = len - 1;
  memcpy(out, p, n);
  out[n] = '\0';
  return 0;
}

static int column(const char *header, const char *name) {
  char h[1024];
  size_t len = strlen(header) < sizeof h - 1 ? strlen(header) : sizeof h - 1;
  memcpy(h, header, len);
  h[len] = '\0';
  int c = 0;
  for (char *tok = strtok(h, ",\n"); tok; tok = strtok(NULL, ",\n"), c++)
    if (!strcmp(tok, name)) return c;
  return -1;
}

static void check(const char *path, const double *rows, long n, result *r) {
  FILE *f = fopen(path, "r");
  static char line[1 << 16];
  r->max_rel = r->max_nodal = r->max_est = r->rounds = r->elements = 0.0;
  r->over = r->failed = r->rows = 0;
  if (!f || !fgets(line, sizeof line, f)) {
    printf("  (no output in %s)\n", path);
    if (f) fclose(f);
    r->failed = n;
    return;
  }
  int cs = column(line, "status"), ca = column(line, "action"),
      cn = column(line, "error_max_nodal"), ce = column(line, "error_estimate"),
      cm = column(line, "message");
  char v[4096];
  for (long i = 0; i < n && fgets(line, sizeof line, f); i++) {
    r->rows++;
    if (field(line, cs, v, sizeof v) || strcmp(v, "converged") || field(line, ca, v, sizeof v) ||
        !v[0]) {
      r->failed++;
      continue;
    }
    double t = travel_time(rows + 6 * i), rel = fabs(atof(v) - t) / t;
    r->max_rel = fmax(r->max_rel, rel);
    r->over += rel > MAX_REL;
    if (!field(line, cn, v, sizeof v) && v[0]) r->max_nodal = fmax(r->max_nodal, atof(v));
    if (!field(line, ce, v, sizeof v) && v[0]) r->max_est = fmax(r->max_est, atof(v));
    const char *m = field(line, cm, v, sizeof v) ? NULL : strstr(v, " elements (");
    const char *a = m ? strstr(m, "after ") : NULL;
    if (m && a) {
      const char *e = m;
      while (e > v && e[-1] >= '0' && e[-1] <= '9') e--;
      r->elements += atof(e);
      r->rounds += atof(a + 6);
    }
  }
  r->failed += n - r->rows;
  if (r->rows > 0) r->rounds /= (double)r->rows, r->elements /= (double)r->rows;
  fclose(f);
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static result run(const char *dir, const char *table, const double *rows, long n, int threads,
                  int warm, int runs) {
  char cmd[4096], out[1024];
  result r;
  double t[64], cpu0 = children_cpu();
  snprintf(out, sizeof out, "%s/out_%d%s.csv", dir, threads, warm ? "w" : "");
  snprintf(cmd, sizeof cmd, "%s batch %s/seismic_fan.scene %s --tol 1e-10 --threads %d%s --out %s",
           CV_CALCVAR, CV_EXAMPLES, table, threads, warm ? " --warm" : "", out);
  if (runs > 64) runs = 64;
  for (int k = 0; k < runs; k++) {
    double t0 = now();
    int rc = system(cmd);
    t[k] = now() - t0;
    if (rc == -1 || !WIFEXITED(rc) || WEXITSTATUS(rc) > 1) printf("  (command failed: %s)\n", cmd);
  }
  qsort(t, (size_t)runs, sizeof *t, cmp);
  check(out, rows, n, &r);
  r.wall = t[runs / 2];
  r.cpu = (children_cpu() - cpu0) / runs;
  printf("| %d%s | %.0f | %.0f | %.0f | %.0f | %.2e | %ld | %ld | %.2e | %.2e | %.2f | %.2f |\n",
         threads, warm ? ", --warm" : "", n / r.wall, n / r.wall / threads, 1e6 * r.wall / n,
         1e6 * r.cpu / n, r.max_rel, r.over, r.failed, r.max_nodal, r.max_est, r.rounds,
         r.elements);
  fflush(stdout);
  return r;
}

int main(int argc, char **argv) {
  long n = argc > 1 ? atol(argv[1]) : FAN;
  int runs = argc > 2 ? atoi(argv[2]) : 3;
  if (n < 1 || runs < 1) {
    fprintf(stderr, "usage: bench_seismic_fan [RAYS (10000)] [RUNS (3)]\n");
    return 2;
  }
  char dir[256], table[300], la0[64], la1[64], date[64];
  snprintf(dir, sizeof dir, "/tmp/cv_bench_seismic_%ld", (long)getpid());
  snprintf(table, sizeof table, "%s/fan.csv", dir);
  char mk[300];
  snprintf(mk, sizeof mk, "mkdir -p %s", dir);
  double *rows = malloc((size_t)n * 6 * sizeof *rows);
  FILE *f = rows && system(mk) == 0 ? fopen(table, "w") : NULL;
  if (!f) {
    fprintf(stderr, "bench_seismic_fan: cannot write %s\n", table);
    return 1;
  }
  fprintf(f, "xs, ys, zs, xr, yr, zr\n");
  for (long i = 0; i < n; i++) {
    long k = n < FAN ? i * FAN / n : i % FAN;
    fan_row((int)k, rows + 6 * i);
    for (int c = 0; c < 6; c++) fprintf(f, c ? ", %.17g" : "%.17g", rows[6 * i + c]);
    fprintf(f, "\n");
  }
  fclose(f);
  time_t now_t = time(NULL);
  strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now_t));
  loadavg(la0, sizeof la0);
  printf("Seismic fan: %ld rays through the tabulated 3-D constant-gradient model\n"
         "(examples/scenes/seismic_fan.scene), calcvar batch --tol 1e-10, whole processes, median "
         "of %d runs; %s, load average %s\n\n",
         n, runs, date, la0);
  printf("| threads | rays/s | rays/s per thread | wall us per ray | CPU us per ray | max rel. "
         "time error | > %g | not converged | max nodal error (km) | max estimate | rounds per "
         "ray | elements per ray |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
         MAX_REL);
  result r1 = run(dir, table, rows, n, 1, 0, runs);
  result r2 = run(dir, table, rows, n, 2, 0, runs);
  run(dir, table, rows, n, 1, 1, runs);
  run(dir, table, rows, n, 2, 1, runs);
  loadavg(la1, sizeof la1);
  printf("\ntwo threads: %.2fx one; load average after: %s\n", r1.wall / r2.wall, la1);
  char rm[300];
  snprintf(rm, sizeof rm, "rm -rf %s", dir);
  if (system(rm) != 0) printf("(%s left behind)\n", dir);
  free(rows);
  return r1.over || r1.failed || r2.over || r2.failed;
}
