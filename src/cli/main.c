/* src/cli/main.c — the calcvar command: dispatch to the subcommands.
 * SPDX-License-Identifier: MIT */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <plplot.h>

#include "cli/cli.h"

static void usage(FILE *f) {
  fputs("usage:\n"
        "  calcvar                         run the built-in demo gallery\n"
        "  calcvar solve SCENE [options]   solve one scene (calcvar solve --help)\n"
        "  calcvar check SCENE             parse, degrees of freedom, derivative check\n"
        "  calcvar converge SCENE [opts]   error and run time over a sequence of meshes\n"
        "  calcvar equations SCENE         momenta, Euler-Lagrange equations, Hamiltonian\n"
        "  calcvar modes SCENE             equilibrium and small-oscillation frequencies\n"
        "  calcvar batch SCENE TABLE.csv   one solve per table row (calcvar batch --help)\n"
        "  calcvar -h | --help             this text\n"
        "  calcvar -V | --version          versions of calcvar and the libraries linked\n"
        "Scene files: docs/scenes.md (\"-\" reads one from standard input).\n"
        "Exit status: 0 solved, 1 not solved, 2 bad input, 3 an output could not be "
        "written.\n",
        f);
}

/* Standard output is checked like any output file: a full disk, /dev/full or a closed
 * pipe must not pass for success (exit 3, docs/cli.md). */
static int stdout_closed; /* standard output was closed when calcvar started (>&-) */

static int finish(int rc) {
  errno = 0;
  int bad = fflush(stdout) != 0 || ferror(stdout);
  int e = errno;
  if (fclose(stdout) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  if (!bad) return rc;
  if (cli_stdout_reported())
    ; /* said already, where it happened */
  else if (stdout_closed)
    fprintf(stderr, "calcvar: cannot write standard output: it is closed\n");
  else
    fprintf(stderr, "calcvar: cannot write standard output: %s\n", e ? strerror(e) : "write error");
  return rc == EXIT_BADINPUT ? rc : EXIT_IOERROR;
}

static int run(int argc, char **argv);

int main(int argc, char **argv) {
  stdout_closed = cli_signals_setup();
  return finish(run(argc, argv));
}

static int run(int argc, char **argv) {
  if (argc < 2) return cli_gallery();
  const char *cmd = argv[1];
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
    usage(stdout);
    return EXIT_SOLVED;
  }
  if (strcmp(cmd, "--version") == 0 || strcmp(cmd, "-V") == 0) {
    int a, b, c;
    char deps[256] = "", pl[80] = "";
    cv_version(&a, &b, &c);
    cv_dependency_versions(deps, sizeof deps);
    plgver(pl); /* the pictures (--plot, --svg) */
    printf("calcvar %d.%d.%d\nlinked with %s, PLplot %s\n", a, b, c, deps, pl);
    return EXIT_SOLVED;
  }
  if (strcmp(cmd, "solve") == 0) return cli_solve(argc - 2, argv + 2);
  if (strcmp(cmd, "check") == 0) return cli_check(argc - 2, argv + 2);
  if (strcmp(cmd, "equations") == 0) return cli_equations(argc - 2, argv + 2);
  if (strcmp(cmd, "modes") == 0) return cli_modes(argc - 2, argv + 2);
  if (strcmp(cmd, "batch") == 0) return cli_batch(argc - 2, argv + 2);
  if (strcmp(cmd, "converge") == 0) return cli_converge(argc - 2, argv + 2);
  fprintf(stderr, "calcvar: unknown command '%s' (calcvar --help lists them)\n", cmd);
  return EXIT_BADINPUT;
}
