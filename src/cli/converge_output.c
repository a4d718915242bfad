/* src/cli/converge_output.c — the rows of `converge`: a table for a person, a JSON array.
 * SPDX-License-Identifier: MIT
 *
 * JSON: one report object per mesh with solve's keys (report_json.c) and these additions:
 * "error": {"max_vertex"} (the max over the element boundaries, beside the contract's
 * "max_nodal" over all nodes), or without [exact] "error_estimate" (solve's key) and
 * "error_estimate_vertex"; "order" and "order_vertex", the observed orders against the
 * previous mesh of the same degree. Keys that do not apply are left out.
 */
#include <jansson.h>
#include <math.h>

#include "cli/cli.h"

static void set_real(json_t *o, const char *key, double v) {
  if (isfinite(v)) json_object_set_new(o, key, json_real(v));
}

int cli_converge_json(FILE *f, const cli_conv_row *rows, int nrows) {
  json_t *a = json_array();
  if (!a) return -1;
  for (int k = 0; k < nrows; k++) {
    const cli_conv_row *row = &rows[k];
    json_t *o = cli_report_json_object(&row->r);
    if (!o) {
      json_decref(a);
      return -1;
    }
    if (!row->estimated && row->has_err_v) {
      json_t *e = json_object_get(o, "error");
      if (!e) {
        e = json_object();
        json_object_set_new(o, "error", e);
      }
      set_real(e, "max_vertex", row->err_v);
    }
    if (row->estimated && row->has_err_v) set_real(o, "error_estimate_vertex", row->err_v);
    if (row->has_order) set_real(o, "order", row->order);
    if (row->has_order_v) set_real(o, "order_vertex", row->order_v);
    json_array_append_new(a, o);
  }
  int rc = json_dumpf(a, f, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  if (rc == 0 && fputc('\n', f) == EOF) rc = -1;
  json_decref(a);
  return rc;
}

static void num(FILE *f, int has, double v, const char *fmt, int width) {
  if (has && isfinite(v))
    fprintf(f, fmt, width, v);
  else
    fprintf(f, "%*s", width, "-");
}

int cli_converge_text(FILE *f, const cli_conv_row *rows, int nrows) {
  if (nrows <= 0) return 0;
  const scene *s = rows[0].r.sc;
  int est = 0;
  for (int k = 0; k < nrows; k++) est |= rows[k].estimated;
  fprintf(f, "%s\n", s->title);
  if (est)
    fprintf(f, "  errors are ESTIMATES (no [exact]): from a reference solve on a finer mesh\n");
  else
    fprintf(f, "  errors against [exact]\n");
  fprintf(f,
          "  error: max over all nodes; error_vertices: max over the element boundaries "
          "(order %s expected there)\n",
          s->c1 ? "2p - 2 of the C1 elements, p + 1 over all nodes," : "2p");
  fprintf(f, "  order: log(e_prev/e) / log(N/N_prev) against the previous mesh\n");
  fprintf(f, "%9s %6s %9s %12s %6s %15s %14s %10s %10s\n", "elements", "degree", "nodes",
          est ? "error(est)" : "error", "order", est ? "error_vert(est)" : "error_vertices",
          "order_vertices", "iterations", "time_s");
  for (int k = 0; k < nrows; k++) {
    const cli_conv_row *row = &rows[k];
    const cli_report *r = &row->r;
    if (k > 0 && r->degree != rows[k - 1].r.degree) fputc('\n', f);
    fprintf(f, "%9d %6d %9d ", r->elements, r->degree, r->nodes);
    num(f, row->has_err, row->err, "%*.3e", 12);
    fputc(' ', f);
    num(f, row->has_order, row->order, "%*.2f", 6);
    fputc(' ', f);
    num(f, row->has_err_v, row->err_v, "%*.3e", 15);
    fputc(' ', f);
    num(f, row->has_order_v, row->order_v, "%*.2f", 14);
    fprintf(f, " %10d ", r->iterations);
    num(f, r->has_time, r->time_s, "%*.3e", 10);
    if (r->st != CVAR_OK) fprintf(f, "  %s", r->status);
    fputc('\n', f);
    if (row->no_est_at >= 0 && row->no_est_at < (int)sizeof r->message)
      fprintf(f, "%9s %s\n", "", r->message + row->no_est_at); /* why the row has "-" */
  }
  return ferror(f) ? -1 : 0;
}
