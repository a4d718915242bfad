// bench/bench_wgs84_scenes.cpp — issue 28's targets in one run (docs/scale-out.md): WGS84
// geodesics between N random pairs (|lat| < 70, |lon2 - lon1| < 150 degrees) through
// `calcvar batch --threads 1` with the two shipped scenes — the textbook one in latitude and
// longitude (examples/scenes/wgs84_geodesic.scene, its [mesh] tol = 1e-10; and the same on
// a fixed mesh of 4 elements of degree 8) and the expert's, adapted to each pair
// (wgs84_geodesic_adapted.scene; its shipped mesh, and --tol 1e-10) — every length against
// GeographicLib's Geodesic::Inverse in the same run, each batch and `GeodSolve -i -p 9`
// timed as whole processes (median of 5 runs), and the time per geodesic as a ratio to
// GeodSolve's and Inverse's. For the fixed mesh it also says whether the rows off by more
// than 1 mm carry an error_estimate that says so.
// Usage: bench_wgs84_scenes [PAIRS (2000)] [RUNS (5)]. SPDX-License-Identifier: MIT
#include <GeographicLib/Geodesic.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#ifndef CV_CALCVAR
#define CV_CALCVAR "calcvar"
#endif
#ifndef CV_EXAMPLES
#define CV_EXAMPLES "examples/scenes"
#endif

static double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Median wall seconds of `runs` runs of a shell command; -1 when one fails.
static double median_time(const std::string &cmd, int runs) {
  std::vector<double> t;
  for (int r = 0; r < runs; r++) {
    double t0 = now();
    if (std::system(cmd.c_str()) != 0) {
      std::printf("  (command failed: %s)\n", cmd.c_str());
      return -1;
    }
    t.push_back(now() - t0);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// The columns of a calcvar batch output table (the message, last and quoted, is skipped).
static std::vector<std::vector<std::string>> table(const std::string &path,
                                                   const std::vector<std::string> &names) {
  std::vector<std::vector<std::string>> out(names.size());
  std::ifstream f(path);
  std::string line;
  std::vector<int> idx(names.size(), -1);
  if (!std::getline(f, line)) return out;
  {
    std::stringstream ss(line);
    std::string h;
    for (int k = 0; std::getline(ss, h, ','); k++)
      for (size_t c = 0; c < names.size(); c++)
        if (h == names[c]) idx[c] = k;
  }
  while (std::getline(f, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line.substr(0, line.find('"')));
    std::string v;
    while (std::getline(ss, v, ',')) fields.push_back(v);
    for (size_t c = 0; c < names.size(); c++)
      out[c].push_back(idx[c] >= 0 && idx[c] < (int)fields.size() ? fields[idx[c]] : "");
  }
  return out;
}

struct Result {
  double us, maxerr = 0, min_est_wrong = INFINITY;
  long wrong = 0, failed = 0, est_missing = 0;
};

// Run one batch, time it, and compare its lengths (column s) with the reference.
static Result run(const std::string &what, const std::string &scene, const std::string &flags,
                  const std::string &csv, const std::string &out, const std::vector<double> &ref,
                  int runs, double us_gs, double us_lib) {
  Result r;
  std::string cmd = std::string(CV_CALCVAR) + " batch " + scene + " " + csv + " --threads 1 " +
                    flags + " --out " + out;
  double t = median_time(cmd, runs);
  r.us = t > 0 ? 1e6 * t / (double)ref.size() : NAN;
  auto cols = table(out, {"status", "s", "error_estimate"});
  for (size_t i = 0; i < ref.size(); i++) {
    if (i >= cols[0].size() || cols[0][i] != "converged" || cols[1][i].empty()) {
      r.failed++;
      continue;
    }
    double e = std::fabs(std::atof(cols[1][i].c_str()) - ref[i]);
    r.maxerr = std::fmax(r.maxerr, e);
    r.est_missing += cols[2][i].empty();
    if (e > 1e-3) {
      r.wrong++;
      double est = cols[2][i].empty() ? NAN : std::atof(cols[2][i].c_str());
      r.min_est_wrong = std::fmin(r.min_est_wrong, est);
    }
  }
  std::printf("| %s | %.1f us | %.1fx | %.0fx | %.2e m | %ld | %ld | %ld |\n", what.c_str(), r.us,
              r.us / us_gs, r.us / us_lib, r.maxerr, r.wrong, r.failed, r.est_missing);
  return r;
}

int main(int argc, char **argv) {
  long N = argc > 1 ? std::atol(argv[1]) : 2000;
  int runs = argc > 2 ? std::atoi(argv[2]) : 5;
  std::string tmp = "/tmp/cv_bench_wgs84_" + std::to_string((long)getpid());
  if (N < 1 || runs < 1 || std::system(("mkdir -p " + tmp).c_str()) != 0) return 1;
  const GeographicLib::Geodesic &g = GeographicLib::Geodesic::WGS84();
  std::mt19937_64 rng(28);
  std::uniform_real_distribution<double> lat(-70, 70), lon(-180, 180), dlon(-150, 150);
  std::vector<double> P, ref;
  for (long i = 0; i < N; i++) {
    double a1 = lat(rng), o1 = lon(rng), a2 = lat(rng), o2 = o1 + dlon(rng), s12;
    g.Inverse(a1, o1, a2, o2, s12);
    P.insert(P.end(), {a1, o1, a2, o2});
    ref.push_back(s12);
  }
  std::string csv = tmp + "/pairs.csv", txt = tmp + "/pairs.txt";
  {
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
  }
  // Inverse, repeated to a measurable time
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
  double t_gs = median_time("GeodSolve -i -p 9 < " + txt + " > " + tmp + "/gs.txt", runs);
  double us_gs = 1e6 * t_gs / N;
  std::printf("WGS84 geodesics: %ld random pairs, |lat| < 70, |lon2 - lon1| < 150 degrees "
              "(seed 28); whole processes, median of %d runs, one thread\n\n",
              N, runs);
  std::printf("| what | time per geodesic | vs GeodSolve | vs Inverse | max length error | "
              "> 1 mm | not converged | no error_estimate |\n|---|---|---|---|---|---|---|---|\n");
  std::printf("| GeographicLib Geodesic::Inverse (C++, checksum %.6g) | %.2f us | | | reference "
              "| | | |\n",
              sink / reps, us_lib);
  std::printf("| GeodSolve -i -p 9 (text in, text out) | %.1f us | 1x | %.0fx | | | | |\n", us_gs,
              us_gs / us_lib);

  std::string ll = std::string(CV_EXAMPLES) + "/wgs84_geodesic.scene";
  std::string ad = std::string(CV_EXAMPLES) + "/wgs84_geodesic_adapted.scene";
  // the textbook scene on a fixed mesh: its [mesh] section replaced by 4 elements of degree 8
  std::string fixed = tmp + "/wgs84_geodesic_4p8.scene";
  {
    std::ifstream in(ll);
    std::ofstream o(fixed);
    std::string line;
    bool mesh = false;
    while (std::getline(in, line)) {
      if (!line.empty() && line[0] == '[') mesh = line == "[mesh]";
      if (!mesh) o << line << "\n";
    }
    o << "[mesh]\nelements = 4\ndegree = 8\n";
  }
  run("lat/lon scene (its [mesh] tol = 1e-10)", ll, "", csv, tmp + "/ll.csv", ref, runs, us_gs,
      us_lib);
  Result rf = run("lat/lon scene, 4 elements of degree 8", fixed, "", csv, tmp + "/fixed.csv", ref,
                  runs, us_gs, us_lib);
  run("pair-adapted scene, shipped mesh (1 element of degree 5)", ad, "", csv, tmp + "/ad.csv", ref,
      runs, us_gs, us_lib);
  run("pair-adapted scene, --tol 1e-10", ad, "--tol 1e-10", csv, tmp + "/adtol.csv", ref, runs,
      us_gs, us_lib);
  if (rf.wrong > 0)
    std::printf("\nlat/lon on 4 x p8: the %ld rows off by more than 1 mm have error_estimate >= "
                "%.2g (radians; a metre is 1.6e-7 rad of the equator)\n",
                rf.wrong, rf.min_est_wrong);
  if (std::system(("rm -rf " + tmp).c_str()) != 0) std::printf("(%s left behind)\n", tmp.c_str());
  return 0;
}
