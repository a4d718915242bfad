/* src/cli/plot_converge.c — `converge --svg FILE`: max nodal error against run time,
 * log-log, one line per degree (a work-precision diagram).
 * SPDX-License-Identifier: MIT
 *
 * Rows of one degree are consecutive (cli_converge); each such run is one line with a
 * mark per mesh. A mesh that did not converge has no error and breaks its line.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

int cli_plot_converge(cli_outfile *o, const cli_conv_row *rows, int nrows) {
  if (nrows <= 0) return -1;
  double *t = malloc((size_t)nrows * sizeof *t), *e = malloc((size_t)nrows * sizeof *e);
  cli_plot_line *lines = calloc((size_t)nrows, sizeof *lines);
  char(*labels)[48] = calloc((size_t)nrows, sizeof *labels);
  int nl = 0, est = 0, rc = -1;
  if (!t || !e || !lines || !labels) goto done;
  for (int k = 0; k < nrows; k++) {
    const cli_conv_row *row = &rows[k];
    t[k] = row->r.has_time ? row->r.time_s : NAN;
    e[k] = row->has_err ? row->err : NAN;
    est |= row->estimated;
    if (k == 0 || row->r.degree != rows[k - 1].r.degree) {
      cli_plot_line *ln = &lines[nl];
      ln->x = t + k;
      ln->y = e + k;
      ln->colour = nl;
      ln->symbol = 1;
      snprintf(labels[nl], sizeof labels[nl], "degree p = %d", row->r.degree);
      ln->label = labels[nl++];
    }
    lines[nl - 1].n++;
  }
  char title[256];
  snprintf(title, sizeof title, "%s: error against run time", rows[0].r.sc->title);
  cli_plot_panel pan;
  memset(&pan, 0, sizeof pan);
  pan.title = title;
  pan.xlabel = "run time of the solve [s]";
  pan.ylabel = est ? "estimated max nodal error" : "max nodal error (against the exact solution)";
  pan.logx = pan.logy = 1;
  pan.nlines = nl;
  pan.lines = lines;
  rc = cli_plot_write(o, 1, &pan);
done:
  free(t);
  free(e);
  free(lines);
  free(labels);
  return rc;
}
