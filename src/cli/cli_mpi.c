/* src/cli/cli_mpi.c — the MPI layer of `calcvar batch` (docs/scale-out.md): rows are
 * shared among the ranks in blocks, rank 0 gathers the formatted rows and writes them.
 * Without MPI in the build (meson -Dmpi=disabled or no MPI installed) every function is
 * the single-process case. SPDX-License-Identifier: MIT */
#include <stdlib.h>
#include <string.h>

#include "cli/cli_batch.h"

#ifdef CALCVAR_MPI
#include <mpi.h>

/* Started by mpirun/mpiexec (or a batch system's launcher)? A plain run stays a plain
 * process: no singleton MPI start-up. */
static int under_launcher(void) {
  static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK",
                                     NULL};
  for (int k = 0; vars[k]; k++)
    if (getenv(vars[k])) return 1;
  return 0;
}

void cli_mpi_init(cli_mpi *m) {
  m->rank = 0, m->size = 1, m->initialised = 0;
  if (!under_launcher()) return;
  if (MPI_Init(NULL, NULL) != MPI_SUCCESS) return;
  m->initialised = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &m->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m->size);
}

void cli_mpi_finish(cli_mpi *m) {
  if (m->initialised) MPI_Finalize();
  m->initialised = 0;
}

int cli_mpi_gather_write(cli_mpi *m, FILE *f, const cli_buf *rows) {
  if (m->size == 1) return rows->len && fwrite(rows->data, 1, rows->len, f) != rows->len ? -1 : 0;
  int len = (int)rows->len, rc = 0;
  int *lens = m->rank == 0 ? malloc((size_t)m->size * sizeof *lens) : NULL;
  int *displ = m->rank == 0 ? malloc((size_t)m->size * sizeof *displ) : NULL;
  MPI_Gather(&len, 1, MPI_INT, lens, 1, MPI_INT, 0, MPI_COMM_WORLD);
  char *all = NULL;
  if (m->rank == 0) {
    size_t total = 0;
    for (int r = 0; r < m->size; r++) {
      displ[r] = (int)total;
      total += (size_t)lens[r];
    }
    all = malloc(total + 1);
    if (!all) MPI_Abort(MPI_COMM_WORLD, 1); /* cannot continue: the others wait in Gatherv */
  }
  MPI_Gatherv(rows->data ? rows->data : "", len, MPI_CHAR, all, lens, displ, MPI_CHAR, 0,
              MPI_COMM_WORLD);
  if (m->rank == 0) {
    size_t total = (size_t)displ[m->size - 1] + (size_t)lens[m->size - 1];
    if (total && fwrite(all, 1, total, f) != total) rc = -1;
  }
  free(all);
  free(lens);
  free(displ);
  MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return rc;
}

long cli_mpi_min_long(cli_mpi *m, long v) {
  long least = v;
  if (m->size > 1) MPI_Allreduce(&v, &least, 1, MPI_LONG, MPI_MIN, MPI_COMM_WORLD);
  return least;
}

long cli_mpi_reduce_failures(cli_mpi *m, long failures) {
  long total = failures;
  if (m->size > 1) MPI_Allreduce(&failures, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

#else /* no MPI in this build */

void cli_mpi_init(cli_mpi *m) { m->rank = 0, m->size = 1, m->initialised = 0; }
void cli_mpi_finish(cli_mpi *m) { (void)m; }
int cli_mpi_gather_write(cli_mpi *m, FILE *f, const cli_buf *rows) {
  (void)m;
  return rows->len && fwrite(rows->data, 1, rows->len, f) != rows->len ? -1 : 0;
}
long cli_mpi_min_long(cli_mpi *m, long v) {
  (void)m;
  return v;
}
long cli_mpi_reduce_failures(cli_mpi *m, long failures) {
  (void)m;
  return failures;
}

#endif
