#!/usr/bin/env bash
# scripts/deps.sh — install the Debian packages calcvar needs to build, test and plot
# (python3-numpy, -pytest, -matplotlib: the Python module, its tests and its pictures;
# python3-mesonpy, python3-build, patchelf: `pip install .` and the wheel, tests python_pip
# and python_wheel; python3-scipy, python3-sympy: the Python tutorial's comparisons and
# its sympy input, tests python_docs).
set -euo pipefail
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
  build-essential meson ninja-build pkg-config \
  libsuitesparse-dev libnlopt-dev libinih-dev libjansson-dev liblapack-dev \
  libplplot-dev plplot-driver-cairo \
  python3-numpy python3-pytest python3-matplotlib \
  python3-mesonpy python3-build patchelf python3-venv python3-scipy python3-sympy \
  doxygen groff-base \
  libopenmpi-dev openmpi-bin \
  g++ libgeographiclib-dev geographiclib-tools strace \
  coinor-libipopt-dev >/dev/null
# doxygen, groff: the API reference and the man page (tests 'docs'); OpenMPI: calcvar batch
# under mpirun (test batch_mpi); strace: --continue opens its scene once (test cli_batch);
# g++ and GeographicLib: bench/bench_geodesic only. coinor-libipopt-dev (IPOPT, EPL-2.0):
# bench/bench_ipopt and its test ipopt_disk only; the library does not link it.
# python3-scipy also serves the solve_bvp comparison of bench/work_precision.py and
# bench/bench_python.py (run them with /usr/bin/python3, docs/performance.md).
# bench/tol_convergence.py needs only matplotlib.
