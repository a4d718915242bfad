/* src/cli/plot.c — pictures with PLplot: panels of labelled curves written to SVG or PNG.
 * SPDX-License-Identifier: MIT
 *
 * The only file that includes plplot.h. The device follows the file's ending: ".svg" is
 * PLplot's own "svg" driver (text stays <text>, so a browser renders and searches it),
 * ".png" is "pngcairo" (Debian plplot-driver-cairo).
 *
 * Drawing runs in a child process (fork), into a scratch file: PLplot, cairo, fontconfig
 * and GLib end the process on errors of their own (plexit, a SIGTRAP from GLib, SIGSEGV
 * in fontconfig under a memory limit), check no write, and may leave half a file. The
 * child's end is a status here: a child that failed or died is "the plotting library
 * failed" (exit 3), a picture cut short is refused (cli_outfile_commit_rendered), and a
 * whole one is copied into the output's temporary file and renamed into place.
 */
#include <errno.h>
#include <math.h>
#include <plplot.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli/cli.h"

/* cmap0: 0 background, 1 axes and text, 2 grid, 3.. line colours (a qualitative palette
 * that stays distinguishable in grey print). */
static const PLINT pal_r[] = {255, 0, 215, 31, 255, 44, 214, 148, 140, 227, 127, 188, 23};
static const PLINT pal_g[] = {255, 0, 215, 119, 127, 160, 39, 103, 86, 119, 127, 189, 190};
static const PLINT pal_b[] = {255, 0, 215, 180, 14, 44, 40, 189, 75, 194, 127, 34, 207};
enum { NPAL = (int)(sizeof pal_r / sizeof pal_r[0]), FIRST_LINE_COLOUR = 3 };

#define MARK "#(728)" /* a filled circle, as a PLplot Hershey escape */

static double chr_factor = 1.0; /* character scale of the page being drawn */

enum { CHILD_PLEXIT = 4 }; /* the child's status when PLplot gave up (plexit) */

/* In the drawing child: PLplot gives up. Its message, then the child ends (the parent
 * says what failed and removes the scratch file). */
static int plplot_exit(PLCHAR_VECTOR msg) {
  fprintf(stderr, "calcvar: the plotting library failed: %s\n", msg);
  _exit(CHILD_PLEXIT);
}

int cli_plot_path_ok(const char *path) {
  size_t n = strlen(path);
  return n >= 5 && (strcmp(path + n - 4, ".svg") == 0 || strcmp(path + n - 4, ".png") == 0);
}

/* cmap0 index of a line colour; negative is the text colour (black). */
static PLINT colour_index(int colour) {
  return colour < 0 ? 1 : FIRST_LINE_COLOUR + colour % (NPAL - FIRST_LINE_COLOUR);
}

/* Value as drawn: log10 on a logarithmic axis; NaN where it cannot be drawn. */
static double coord(double v, int logscale) {
  if (!isfinite(v)) return NAN;
  if (logscale) return v > 0 ? log10(v) : NAN;
  return v;
}

/* Data range of a panel along x (which = 0) or y (1), in drawn coordinates, padded. */
static void panel_range(const cli_plot_panel *p, int which, double *lo, double *hi) {
  int logscale = which ? p->logy : p->logx;
  *lo = INFINITY;
  *hi = -INFINITY;
  for (int l = 0; l < p->nlines; l++)
    for (int k = 0; k < p->lines[l].n; k++) {
      double v = coord(which ? p->lines[l].y[k] : p->lines[l].x[k], logscale);
      if (isfinite(v) &&
          isfinite(coord(which ? p->lines[l].x[k] : p->lines[l].y[k], which ? p->logx : p->logy))) {
        *lo = fmin(*lo, v);
        *hi = fmax(*hi, v);
      }
    }
  if (!(*lo <= *hi)) { /* nothing drawable */
    *lo = 0;
    *hi = 1;
  }
  double span = *hi - *lo;
  if (logscale) {
    /* whole decades keep the logarithmic tick labels readable */
    *lo = floor(*lo - 0.05);
    *hi = ceil(*hi + 0.05);
    if (*hi - *lo < 1) *hi = *lo + 1;
  } else {
    double pad = span > 0 ? 0.05 * span : (fabs(*lo) > 0 ? 0.1 * fabs(*lo) : 1);
    if (which == 0 && span > 0) pad = 0; /* the variable's interval is drawn exactly */
    *lo -= pad;
    *hi += pad;
  }
}

/* Draw one curve as its runs of drawable points (a NaN or a non-positive value on a
 * logarithmic axis breaks the line instead of ending the picture). */
static void draw_line(const cli_plot_panel *p, const cli_plot_line *ln) {
  PLFLT *x = malloc((size_t)(ln->n > 0 ? ln->n : 1) * sizeof *x);
  PLFLT *y = malloc((size_t)(ln->n > 0 ? ln->n : 1) * sizeof *y);
  if (!x || !y) {
    free(x);
    free(y);
    return;
  }
  plcol0(colour_index(ln->colour));
  pllsty(ln->style > 0 ? ln->style : 1);
  plwidth(ln->colour < 0 ? 1.5 : 2.0);
  int m = 0;
  for (int k = 0; k <= ln->n; k++) {
    double u = k < ln->n ? coord(ln->x[k], p->logx) : NAN;
    double v = k < ln->n ? coord(ln->y[k], p->logy) : NAN;
    if (isfinite(u) && isfinite(v)) {
      x[m] = u;
      y[m] = v;
      m++;
      continue;
    }
    if (m > 1) plline(m, x, y);
    if (m > 0 && (ln->symbol || m == 1)) /* a lone point would be invisible as a line */
      plstring(m, x, y, MARK);
    m = 0;
  }
  pllsty(1);
  plwidth(1.0);
  free(x);
  free(y);
}

/* The inside corner of the axes where the legend covers the fewest drawn points: bits of
 * PL_POSITION_* (TOP or BOTTOM with LEFT or RIGHT). The legend box is taken as 40% of the
 * width and 7% of the height per line. */
static PLINT legend_corner(const cli_plot_panel *p, double x0, double x1, double y0, double y1) {
  static const PLINT corners[4] = {
      PL_POSITION_TOP | PL_POSITION_RIGHT, PL_POSITION_TOP | PL_POSITION_LEFT,
      PL_POSITION_BOTTOM | PL_POSITION_RIGHT, PL_POSITION_BOTTOM | PL_POSITION_LEFT};
  double bh = fmin(0.9, 0.05 + 0.07 * p->nlines), bw = 0.4;
  long count[4] = {0, 0, 0, 0};
  for (int l = 0; l < p->nlines; l++)
    for (int k = 0; k < p->lines[l].n; k++) {
      double u = (coord(p->lines[l].x[k], p->logx) - x0) / (x1 - x0);
      double v = (coord(p->lines[l].y[k], p->logy) - y0) / (y1 - y0);
      if (!isfinite(u) || !isfinite(v)) continue;
      if (p->xdown) u = 1 - u;
      if (p->ydown) v = 1 - v;
      int right = u > 1 - bw, left = u<bw, top = v> 1 - bh, bottom = v < bh;
      count[0] += top && right;
      count[1] += top && left;
      count[2] += bottom && right;
      count[3] += bottom && left;
    }
  int best = 0;
  for (int c = 1; c < 4; c++)
    if (count[c] < count[best]) best = c;
  return corners[best];
}

/* The decimals a linear axis over [lo, hi] needs when its values share leading digits
 * (an offset far larger than the range), else -1: PLplot's own choice is right then. */
static int axis_decimals(double lo, double hi) {
  double range = fabs(hi - lo), mid = fmax(fabs(lo), fabs(hi));
  if (!(range > 0) || mid < 100 * range) return -1;
  int d = (int)ceil(-log10(range / 5));
  return d < 0 ? -1 : d > 12 ? 12 : d;
}

static void draw_panel(const cli_plot_panel *p) {
  double x0, x1, y0, y1;
  panel_range(p, 0, &x0, &x1);
  panel_range(p, 1, &y0, &y1);
  if (p->equal) {
    /* equal scales: the same padding on both axes, the viewport shaped to the data */
    double pad = 0.04 * fmax(x1 - x0, y1 - y0);
    if (!p->logx && !p->logy) {
      x0 -= pad;
      x1 += pad;
    }
    plvpas(p->vp[0], p->vp[1], p->vp[2], p->vp[3], (y1 - y0) / (x1 - x0));
  } else {
    plvpor(p->vp[0], p->vp[1], p->vp[2], p->vp[3]);
  }
  PLINT corner = legend_corner(p, x0, x1, y0, y1);
  plwind(p->xdown ? x1 : x0, p->xdown ? x0 : x1, p->ydown ? y1 : y0, p->ydown ? y0 : y1);
  char xo[16] = "bcnst", yo[16] = "bcnstv";
  if (p->logx) strcat(xo, "l");
  if (p->logy) strcat(yo, "l");
  plcol0(2);
  plbox("g", 0, 0, "g", 0, 0);
  plcol0(1);
  /* Labels with enough decimals to tell the ticks apart: PLplot's automatic precision
   * prints 1.000 at every tick of a range of 1e-4 around 1 (a ray that hardly bends). */
  plprec(axis_decimals(x0, x1) >= 0, axis_decimals(x0, x1));
  plbox(xo, 0, 0, "", 0, 0);
  plprec(axis_decimals(y0, y1) >= 0, axis_decimals(y0, y1));
  plbox("", 0, 0, yo, 0, 0);
  plprec(0, 0);
  pllab(p->xlabel, p->ylabel, p->title);
  for (int l = 0; l < p->nlines; l++) draw_line(p, &p->lines[l]);

  /* legend: one entry per curve, inside the axes in the emptiest corner */
  int n = p->nlines;
  if (n <= 0 || p->no_legend) return;
  PLINT *opt = calloc((size_t)n, sizeof *opt), *tc = calloc((size_t)n, sizeof *tc);
  PLINT *lc = calloc((size_t)n, sizeof *lc), *ls = calloc((size_t)n, sizeof *ls);
  PLINT *sc = calloc((size_t)n, sizeof *sc), *sn = calloc((size_t)n, sizeof *sn);
  PLFLT *lw = calloc((size_t)n, sizeof *lw), *ss = calloc((size_t)n, sizeof *ss);
  const char **text = calloc((size_t)n, sizeof *text), **sym = calloc((size_t)n, sizeof *sym);
  if (opt && tc && lc && ls && sc && sn && lw && ss && text && sym) {
    for (int l = 0; l < n; l++) {
      const cli_plot_line *ln = &p->lines[l];
      opt[l] = PL_LEGEND_LINE | (ln->symbol ? PL_LEGEND_SYMBOL : 0);
      tc[l] = 1;
      lc[l] = sc[l] = colour_index(ln->colour);
      ls[l] = ln->style > 0 ? ln->style : 1;
      lw[l] = ln->colour < 0 ? 1.5 : 2.0;
      ss[l] = 1.0;
      sn[l] = 3;
      text[l] = ln->label ? ln->label : "";
      sym[l] = MARK;
    }
    PLFLT w, h;
    PLINT pos = p->legend_right ? PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT
                                : corner | PL_POSITION_INSIDE | PL_POSITION_VIEWPORT;
    pllegend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, pos,
             p->legend_right ? 0.015 : 0.02, p->legend_right ? 0.0 : 0.02, 0.05, 0, 1, 1, 0, 0, n,
             opt, 0.7 * chr_factor, 0.8 * chr_factor, 1.6, 0.0, tc, text, NULL, NULL, NULL, NULL,
             lc, ls, lw, sc, ss, sn, sym);
  }
  free(opt);
  free(tc);
  free(lc);
  free(ls);
  free(sc);
  free(sn);
  free(lw);
  free(ss);
  free(text);
  free(sym);
}

int cli_plot_write(cli_outfile *o, int npanels, cli_plot_panel *panels) {
  /* stacked: panel k takes the k-th band from the top, with room for its labels */
  for (int k = 0; k < npanels; k++) {
    double top = 1.0 - (double)k / npanels, bot = 1.0 - (double)(k + 1) / npanels;
    double m = 60.0 / (100 + 460 * npanels); /* a title or label line, in page units */
    panels[k].vp[0] = 0.09;
    panels[k].vp[1] = 0.97;
    panels[k].vp[2] = bot + 1.4 * m;
    panels[k].vp[3] = top - 0.9 * m;
  }
  return cli_plot_write_page(o, 960, 100 + 460 * npanels, npanels, panels);
}

/* The drawing itself (in the child). */
static void draw_page(const char *name, int svg, int width, int height, int npanels,
                      const cli_plot_panel *panels) {
  plsexit(plplot_exit);
  plsdev(svg ? "svg" : "pngcairo");
  plsfnam(name);
  plspage(0, 0, width, height, 0, 0);
  plscmap0(pal_r, pal_g, pal_b, NPAL);
  plssub(1, 1);
  plinit();
  /* PLplot scales characters with the page height: on taller pages they are scaled back
   * towards the size they have on a page of one panel (560 pixels); pllegend's text is
   * scaled from the default height, so it gets the factor too */
  chr_factor = height > 560 ? pow(560.0 / height, 0.7) : 1.0;
  plschr(0, 0.95 * chr_factor);
  pladv(0); /* one page; every panel draws into its own viewport on it */
  for (int k = 0; k < npanels; k++) draw_panel(&panels[k]);
  plend();
}

/* Why the drawing child failed, from its wait status, into why; 0 when it succeeded. */
static int child_failed(int status, char *why, size_t len) {
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
  if (WIFSIGNALED(status))
    snprintf(why, len, "the plotting library failed (killed by signal %d, %s)", WTERMSIG(status),
             strsignal(WTERMSIG(status)));
  else
    snprintf(why, len, "the plotting library failed (status %d%s)",
             WIFEXITED(status) ? WEXITSTATUS(status) : -1,
             WIFEXITED(status) && WEXITSTATUS(status) == 1
                 ? ": out of memory, or a driver it could not load?"
                 : "");
  return -1;
}

int cli_plot_write_page(cli_outfile *o, int width, int height, int npanels,
                        const cli_plot_panel *panels) {
  const char *name;
  if (npanels < 1 || cli_outfile_render_name(o, &name) < 0) return -1;
  size_t n = strlen(o->path);
  int svg = n >= 4 && strcmp(o->path + n - 4, ".svg") == 0;
  fflush(stdout); /* the child must not write the parent's buffered text again */
  fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    draw_page(name, svg, width, height, npanels, panels);
    _exit(0); /* no exit handlers: they are the parent's */
  }
  int status = 0;
  char why[160];
  if (pid < 0) {
    snprintf(why, sizeof why, "cannot start the drawing: %s", strerror(errno));
    status = -1;
  } else {
    while (waitpid(pid, &status, 0) < 0)
      if (errno != EINTR) {
        status = -1;
        break;
      }
    if (status != -1 && child_failed(status, why, sizeof why) == 0) status = 0;
  }
  if (status != 0) {
    if (status == -1 && pid >= 0) snprintf(why, sizeof why, "lost the drawing process");
    fprintf(stderr, "calcvar: cannot write %s: %s\n", o->path, why);
    cli_outfile_abandon(o);
    return -1;
  }
  return cli_outfile_commit_rendered(o, svg);
}
