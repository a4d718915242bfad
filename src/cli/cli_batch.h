/* src/cli/cli_batch.h — `calcvar batch`: output buffers and the MPI layer.
 * SPDX-License-Identifier: MIT */
#ifndef CV_CLI_BATCH_H
#define CV_CLI_BATCH_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "cli/cli.h"

/* A growing text buffer (the formatted rows of a window). */
typedef struct {
  char *data;
  size_t len, cap;
  int failed;
} cli_buf;
/* Append len bytes of s (not NUL-terminated) to o. 0, or -1 out of memory (o->failed). */
int cli_buf_put(cli_buf *o, const char *s, size_t len);
int cli_buf_printf(cli_buf *o, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Which columns the output has. */
typedef struct {
  int ncols;              /* input columns */
  int err_nodal, err_est; /* error_max_nodal / error_estimate present */
  int nout;               /* [report] entries and multipliers */
} cli_batch_cols;

/* The process's place among MPI ranks (size 1, rank 0 without MPI). */
typedef struct {
  int rank, size, initialised;
} cli_mpi;
/* cli_mpi.c: MPI_Init when the build has MPI and the process was started by mpirun. */
void cli_mpi_init(cli_mpi *m);
void cli_mpi_finish(cli_mpi *m);
/* Rank 0 writes every rank's rows of the window to f, in rank order. 0, or -1. */
int cli_mpi_gather_write(cli_mpi *m, FILE *f, const cli_buf *rows);
/* The least of v over all ranks (every rank gets it). */
long cli_mpi_min_long(cli_mpi *m, long v);
/* The number of failed rows over all ranks (every rank gets it). */
long cli_mpi_reduce_failures(cli_mpi *m, long failures);

int cli_cores_available(void);
int cli_batch_run(const cli_opts *o, const char *table_path, const char *out_path, int threads,
                  int warm, cli_mpi *mpi);

#endif /* CV_CLI_BATCH_H */
