// bench/bench_geodesic.cpp — issue 18's targets, all measured in one run (docs/scale-out.md):
// geodesics on the WGS84 ellipsoid between N random point pairs (distances <= 10^7 m)
// through `calcvar batch` (one thread, two threads, mpirun -np 1 and 2) and through the C
// API (cv_batch, warm starts off and on), every length compared with GeographicLib's
// Geodesic::Inverse in the same run (1 mm allowed, no pair wrong), timed against
// GeographicLib itself and its command `GeodSolve -i`; then a fan of rays through
// Maxwell's fish-eye lens (rows per second, every ray against its exact circle).
// Usage: bench_geodesic [PAIRS (10000)] [RAYS (100000)]. Timings on a shared machine are
// noisy: the ratios compare runs made seconds apart in the same process.
// SPDX-License-Identifier: MIT
#include <GeographicLib/Geodesic.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include "calcvar.h"

#ifndef CV_CALCVAR
#define CV_CALCVAR "calcvar"
#endif
#ifndef CV_DATA
#define CV_DATA "bench/data"
#endif
#ifndef CV_EXAMPLES
#define CV_EXAMPLES "examples/scenes"
#endif

static double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// CPU seconds (user + system) of the children waited for so far.
static double child_cpu() {
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
         (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

// Wall seconds of a shell command (its CPU seconds into *cpu); -1 when it fails.
static double timed(const std::string &cmd, double *cpu = nullptr) {
  double t0 = now(), c0 = child_cpu();
  int rc = std::system(cmd.c_str());
  double t = now() - t0;
  if (cpu) *cpu = child_cpu() - c0;
  if (rc != 0) {
    std::printf("  (command failed, status %d: %s)\n", rc, cmd.c_str());
    return -1;
  }
  return t;
}

// Column `name` of a CSV file written by calcvar batch (the message, last, may hold commas
// inside quotes; the columns asked for here come before it).
static std::vector<std::string> column(const std::string &path, const char *name) {
  std::vector<std::string> out;
  FILE *f = std::fopen(path.c_str(), "r");
  if (!f) return out;
  char line[8192];
  int idx = -1;
  if (std::fgets(line, sizeof line, f)) {
    int k = 0;
    for (char *p = std::strtok(line, ",\n"); p; p = std::strtok(nullptr, ",\n"), k++)
      if (std::strcmp(p, name) == 0) idx = k;
  }
  while (idx >= 0 && std::fgets(line, sizeof line, f)) {
    int k = 0;
    const char *p = line;
    while (k < idx && (p = std::strchr(p, ','))) p++, k++;
    if (!p) {
      out.push_back("");
      continue;
    }
    const char *e = std::strchr(p, ',');
    out.push_back(std::string(p, e ? (size_t)(e - p) : std::strlen(p)));
  }
  std::fclose(f);
  return out;
}

struct Check {
  double maxerr = 0;
  long wrong = 0, failed = 0;
};

static Check compare(const std::vector<double> &got, const std::vector<double> &ref) {
  Check c;
  for (size_t i = 0; i < ref.size(); i++) {
    if (i >= got.size() || !std::isfinite(got[i])) {
      c.failed++;
      continue;
    }
    double e = std::fabs(got[i] - ref[i]);
    c.maxerr = std::fmax(c.maxerr, e);
    c.wrong += e > 1e-3;
  }
  return c;
}

static std::vector<double> lengths(const std::string &path, const char *col) {
  std::vector<double> v;
  for (auto &s : column(path, col)) v.push_back(s.empty() ? NAN : std::atof(s.c_str()));
  return v;
}

int main(int argc, char **argv) {
  long N = argc > 1 ? std::atol(argv[1]) : 10000, RAYS = argc > 2 ? std::atol(argv[2]) : 100000;
  std::string tmp = "/tmp/cv_bench_geodesic_" + std::to_string((long)getpid());
  if (std::system(("mkdir -p " + tmp).c_str()) != 0) return 1;
  const GeographicLib::Geodesic &g = GeographicLib::Geodesic::WGS84();
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<double> u(-1, 1), lon(-180, 180);
  std::vector<double> P, ref; // P: lat1, lon1, lat2, lon2 per pair
  while ((long)ref.size() < N) {
    double a1 = std::asin(u(rng)) * 180 / M_PI, o1 = lon(rng);
    double a2 = std::asin(u(rng)) * 180 / M_PI, o2 = lon(rng);
    double s12;
    g.Inverse(a1, o1, a2, o2, s12);
    if (s12 > 1e7) continue; // the range; nearly antipodal pairs have several geodesics
    P.insert(P.end(), {a1, o1, a2, o2});
    ref.push_back(s12);
  }
  std::printf("WGS84 geodesics: %ld random pairs, distances <= 1e7 m (uniform on the sphere, "
              "longer pairs rejected)\n",
              N);

  // GeographicLib's own Inverse, repeated to a measurable time.
  double t0 = now(), sink = 0;
  int reps = 0;
  do {
    for (long i = 0; i < N; i++) {
      double s12;
      g.Inverse(P[4 * i], P[4 * i + 1], P[4 * i + 2], P[4 * i + 3], s12);
      sink += s12;
    }
    reps++;
  } while (now() - t0 < 0.3);
  double us_lib = 1e6 * (now() - t0) / ((double)reps * N);
  std::printf("  GeographicLib Geodesic::Inverse   %8.2f us/geodesic  (checksum %.3g)\n", us_lib,
              sink);

  // The tables: CSV for calcvar batch, whitespace for GeodSolve.
  std::string csv = tmp + "/pairs.csv", txt = tmp + "/pairs.txt";
  FILE *fc = std::fopen(csv.c_str(), "w"), *ft = std::fopen(txt.c_str(), "w");
  if (!fc || !ft) return 1;
  std::fprintf(fc, "lat1,lon1,lat2,lon2\n");
  for (long i = 0; i < N; i++) {
    std::fprintf(fc, "%.17g,%.17g,%.17g,%.17g\n", P[4 * i], P[4 * i + 1], P[4 * i + 2],
                 P[4 * i + 3]);
    std::fprintf(ft, "%.17g %.17g %.17g %.17g\n", P[4 * i], P[4 * i + 1], P[4 * i + 2],
                 P[4 * i + 3]);
  }
  std::fclose(fc);
  std::fclose(ft);
  double t_gs = timed("GeodSolve -i -p 9 < " + txt + " > " + tmp + "/gs.txt");
  double us_gs = t_gs > 0 ? 1e6 * t_gs / N : NAN;
  std::printf("  GeodSolve -i (text in, text out)  %8.2f us/line\n", us_gs);

  std::string scene = std::string(CV_EXAMPLES) + "/wgs84_geodesic_adapted.scene";
  // The way before the batch: one process per pair (200 pairs suffice to time it).
  {
    long M = N < 200 ? N : 200;
    std::string sh = tmp + "/each.sh";
    FILE *fs = std::fopen(sh.c_str(), "w");
    if (!fs) return 1;
    for (long i = 0; i < M; i++)
      std::fprintf(fs,
                   "%s solve %s --quiet --set lat1=%.17g --set lon1=%.17g --set lat2=%.17g "
                   "--set lon2=%.17g || exit 1\n",
                   CV_CALCVAR, scene.c_str(), P[4 * i], P[4 * i + 1], P[4 * i + 2], P[4 * i + 3]);
    std::fclose(fs);
    double te = timed("sh " + sh);
    std::printf("  calcvar solve --set, one process per pair %8.2f us/row  (%ld pairs)\n",
                1e6 * te / M, M);
  }
  std::string base = std::string(CV_CALCVAR) + " batch " + scene + " " + csv;
  double t1 = timed(base + " --threads 1 --out " + tmp + "/r1.csv");
  Check c1 = compare(lengths(tmp + "/r1.csv", "s"), ref);
  std::printf("  calcvar batch, 1 thread           %8.2f us/row   %5.1fx GeodSolve -i   "
              "max |error| %.2e m, %ld > 1 mm, %ld not converged\n",
              1e6 * t1 / N, t1 / t_gs, c1.maxerr, c1.wrong, c1.failed);
  double t2 = timed(base + " --threads 2 --out " + tmp + "/r2.csv");
  Check c2 = compare(lengths(tmp + "/r2.csv", "s"), ref);
  std::printf("  calcvar batch, 2 threads          %8.2f us/row   speed-up %.2f  "
              "max |error| %.2e m, %ld > 1 mm, %ld not converged\n",
              1e6 * t2 / N, t1 / t2, c2.maxerr, c2.wrong, c2.failed);

  // Scaling on a longer table (the pairs repeated to about 10^5 rows, so that a run is
  // seconds, not milliseconds): wall and CPU time per row, and for MPI the launcher's
  // start-up (mpirun on a one-row table, same run) apart from the rows' time.
  long R = N < 100000 ? (100000 + N - 1) / N : 1, NB = R * N;
  std::string big = tmp + "/big.csv", one = tmp + "/one.csv";
  {
    FILE *fb = std::fopen(big.c_str(), "w"), *f1 = std::fopen(one.c_str(), "w");
    if (!fb || !f1) return 1;
    std::fprintf(fb, "lat1,lon1,lat2,lon2\n");
    std::fprintf(f1, "lat1,lon1,lat2,lon2\n%.17g,%.17g,%.17g,%.17g\n", P[0], P[1], P[2], P[3]);
    for (long r = 0; r < R; r++)
      for (long i = 0; i < N; i++)
        std::fprintf(fb, "%.17g,%.17g,%.17g,%.17g\n", P[4 * i], P[4 * i + 1], P[4 * i + 2],
                     P[4 * i + 3]);
    std::fclose(fb);
    std::fclose(f1);
  }
  std::string bigb = std::string(CV_CALCVAR) + " batch " + scene + " " + big;
  double cpu1, cpu2;
  double b1 = timed(bigb + " --threads 1 --out " + tmp + "/b1.csv", &cpu1);
  double b2 = timed(bigb + " --threads 2 --out " + tmp + "/b2.csv", &cpu2);
  std::printf("  %ld rows: batch 1 thread %.2f us/row (CPU %.2f), 2 threads %.2f us/row (CPU "
              "%.2f): speed-up %.2f, CPU per row 2 threads / 1 thread %.2f\n",
              NB, 1e6 * b1 / NB, 1e6 * cpu1 / NB, 1e6 * b2 / NB, 1e6 * cpu2 / NB, b1 / b2,
              cpu2 / cpu1);
#ifdef CV_MPIRUN
  std::string mpi = std::string(CV_MPIRUN) + " --oversubscribe" +
                    (geteuid() == 0 ? " --allow-run-as-root" : "") + " -np ";
  std::string oneb = std::string(CV_CALCVAR) + " batch " + scene + " " + one;
  double s1 = timed(mpi + "1 " + oneb + " --threads 1 --out " + tmp + "/s1.csv");
  double s2 = timed(mpi + "2 " + oneb + " --threads 1 --out " + tmp + "/s2.csv");
  double m1 = timed(mpi + "1 " + bigb + " --threads 1 --out " + tmp + "/m1.csv");
  double m2 = timed(mpi + "2 " + bigb + " --threads 1 --out " + tmp + "/m2.csv");
  std::vector<double> refb;
  for (long r = 0; r < R; r++) refb.insert(refb.end(), ref.begin(), ref.end());
  Check cm = compare(lengths(tmp + "/m2.csv", "s"), refb);
  std::printf("  %ld rows: mpirun -np 1 / -np 2 (1 thread each) %.2f / %.2f s, speed-up %.2f; "
              "start-up (one row) %.2f / %.2f s; without it %.2f / %.2f us/row, speed-up %.2f  "
              "max |error| %.2e m, %ld > 1 mm, %ld not converged\n",
              NB, m1, m2, m1 / m2, s1, s2, 1e6 * (m1 - s1) / NB, 1e6 * (m2 - s2) / NB,
              (m1 - s1) / (m2 - s2), cm.maxerr, cm.wrong, cm.failed);
#else
  std::printf("  mpirun: not measured (calcvar built without MPI)\n");
#endif

  // The C API: one compiled problem, no text.
  char err[512];
  cv_batch *b = cv_batch_new(scene.c_str(), err, sizeof err);
  const char *cols[] = {"lat1", "lon1", "lat2", "lon2"};
  if (!b || cv_batch_set_columns(b, 4, cols, err, sizeof err) != CVAR_OK) {
    std::printf("cv_batch: %s\n", err);
    return 1;
  }
  std::vector<cv_batch_result> res((size_t)N);
  std::vector<double> out((size_t)N);
  for (long i = 0; i < N; i++) res[(size_t)i].outputs = &out[(size_t)i];
  for (int warm = 0; warm < 2; warm++) {
    cv_batch_set_warm_start(b, warm);
    double ta = now();
    cv_batch_solve(b, (int)N, P.data(), res.data());
    ta = now() - ta;
    long nw = 0;
    for (auto &r : res) nw += r.warm;
    std::vector<double> s((size_t)N);
    for (long i = 0; i < N; i++)
      s[(size_t)i] = res[(size_t)i].status == CVAR_OK ? out[(size_t)i] : NAN;
    Check ca = compare(s, ref);
    std::printf("  C API cv_batch, 1 thread, warm %s %6.2f us/row   %5.1fx Geodesic::Inverse  "
                "max |error| %.2e m, %ld > 1 mm, %ld not converged, %ld warm-started\n",
                warm ? "on " : "off", 1e6 * ta / N, 1e6 * ta / N / us_lib, ca.maxerr, ca.wrong,
                ca.failed, nw);
  }
  cv_batch_free(b);

  // A fan of rays through Maxwell's fish-eye lens: from (-0.5, 0.2) to (0.5, y), y in
  // [0.25, 1]; every ray is checked against its exact circle (error_max_nodal).
  std::string fan = tmp + "/fan.csv";
  FILE *ff = std::fopen(fan.c_str(), "w");
  if (!ff) return 1;
  std::fprintf(ff, "yr\n");
  for (long i = 0; i < RAYS; i++)
    std::fprintf(ff, "%.15g\n", 0.25 + 0.5 * (double)i / (double)(RAYS > 1 ? RAYS - 1 : 1));
  std::fclose(ff);
  std::string fb = std::string(CV_CALCVAR) + " batch " + CV_DATA + "/fisheye_fan.scene " + fan;
  double tf1 = timed(fb + " --threads 1 --out " + tmp + "/f1.csv");
  double tf2 = timed(fb + " --threads 2 --out " + tmp + "/f2.csv");
  double emax = 0;
  long fails = 0;
  for (auto &e : column(tmp + "/f2.csv", "error_max_nodal")) {
    if (e.empty())
      fails++;
    else
      emax = std::fmax(emax, std::atof(e.c_str()));
  }
  double tf3 = timed(fb + " --threads 2 --warm --out " + tmp + "/f3.csv");
  std::printf("Fish-eye ray fan: %ld rays: 1 thread %.0f rows/s, 2 threads %.0f rows/s "
              "(speed-up %.2f), 2 threads --warm %.0f rows/s; max nodal error %.2e, %ld not "
              "converged\n",
              RAYS, RAYS / tf1, RAYS / tf2, tf1 / tf2, RAYS / tf3, emax, fails);
  if (std::system(("rm -rf " + tmp).c_str()) != 0) return 1;
  return 0;
}
