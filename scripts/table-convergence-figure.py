#!/usr/bin/env python3
# scripts/table-convergence-figure.py — draw docs/gallery/table_convergence.svg (docs/theory.md
# TB-6) from the figures tests/expr/test_table prints: max nodal error of rays through
# tabulated 1-D, 2-D and 3-D media against the grid spacing, log-log, with an h^4 guide.
# usage: scripts/table-convergence-figure.py [BUILD_DIR]   (default build)
# SPDX-License-Identifier: MIT
import math
import os
import re
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build")
out = subprocess.run([os.path.join(build, "tests", "expr", "test_table")],
                     capture_output=True, text=True).stdout
series = []
for line in out.splitlines():
    m = re.match(r"(\S+ n\([^)]*\)): .*table error ([\d.e+-]+) ([\d.e+-]+) ([\d.e+-]+) "
                 r"([\d.e+-]+) .*fitted order ([\d.]+)", line)
    if m:
        series.append((m.group(1), [float(m.group(i)) for i in range(2, 6)], m.group(6)))
if len(series) != 3:
    sys.exit("could not read the three series from test_table's output")

W, H, L, R, T, B = 640, 440, 80, 190, 30, 60
hs = [1 / 8, 1 / 16, 1 / 32, 1 / 64]  # grid spacing / coordinate range
lx0, lx1 = math.log10(1 / 90), math.log10(1 / 6)
ly0, ly1 = -10, -3


def X(h):
    return L + (math.log10(h) - lx0) / (lx1 - lx0) * (W - L - R)


def Y(e):
    return T + (ly1 - math.log10(e)) / (ly1 - ly0) * (H - T - B)


svg = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
       'font-family="sans-serif" font-size="12">' % (W, H),
       '<rect width="100%" height="100%" fill="white"/>',
       '<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="black"/>'
       % (L, T, W - L - R, H - T - B)]
for k in range(ly0, ly1 + 1):
    y = Y(10.0 ** k)
    svg.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>' % (L, W - R, y, y))
    svg.append('<text x="%d" y="%.1f" text-anchor="end">1e%d</text>' % (L - 6, y + 4, k))
for h, lab in zip(hs, ["1/8", "1/16", "1/32", "1/64"]):
    x = X(h)
    svg.append('<line x1="%.1f" x2="%.1f" y1="%d" y2="%d" stroke="#ddd"/>' % (x, x, T, H - B))
    svg.append('<text x="%.1f" y="%d" text-anchor="middle">%s</text>' % (x, H - B + 18, lab))
svg.append('<text x="%d" y="%d" text-anchor="middle">grid spacing / coordinate range</text>'
           % ((L + W - R) / 2, H - 12))
svg.append('<text x="18" y="%d" transform="rotate(-90 18 %d)" text-anchor="middle">'
           'max nodal error of the ray</text>' % ((T + H - B) / 2, (T + H - B) / 2))
colours = ["#1f77b4", "#d62728", "#2ca02c"]
for (name, errs, order), col in zip(series, colours):
    pts = " ".join("%.1f,%.1f" % (X(h), Y(e)) for h, e in zip(hs, errs))
    svg.append('<polyline points="%s" fill="none" stroke="%s" stroke-width="2"/>' % (pts, col))
    for h, e in zip(hs, errs):
        svg.append('<circle cx="%.1f" cy="%.1f" r="3" fill="%s"/>' % (X(h), Y(e), col))
ref = series[1][1][0]  # h^4 guide through the 2-D medium's first point
pts = " ".join("%.1f,%.1f" % (X(h), Y(ref * (h / hs[0]) ** 4)) for h in (hs[0], hs[-1]))
svg.append('<polyline points="%s" fill="none" stroke="gray" stroke-dasharray="6,4"/>' % pts)
ly = T + 10
for (name, errs, order), col in zip(series, colours):
    svg.append('<line x1="%d" x2="%d" y1="%d" y2="%d" stroke="%s" stroke-width="2"/>'
               % (W - R + 12, W - R + 36, ly, ly, col))
    svg.append('<text x="%d" y="%d">%s, order %s</text>' % (W - R + 40, ly + 4, name[:4], order))
    ly += 20
svg.append('<line x1="%d" x2="%d" y1="%d" y2="%d" stroke="gray" stroke-dasharray="6,4"/>'
           % (W - R + 12, W - R + 36, ly, ly))
svg.append('<text x="%d" y="%d">h^4</text>' % (W - R + 40, ly + 4))
svg.append("</svg>")
path = os.path.join(root, "docs", "gallery", "table_convergence.svg")
with open(path, "w") as f:
    f.write("\n".join(svg) + "\n")
print(path)
