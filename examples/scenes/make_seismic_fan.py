#!/usr/bin/env python3
# examples/scenes/make_seismic_fan.py — a fan of source-receiver pairs for seismic_fan.scene
# and the check of `calcvar batch`'s travel times against the closed form.
#
#   make_seismic_fan.py table [N] > fan.csv     the fan, or N rows spread evenly over it
#   calcvar batch seismic_fan.scene fan.csv --tol 1e-10 --out times.csv
#   make_seismic_fan.py check times.csv [MAX]   every travel time against the closed form:
#                                               exit 1 when a row did not converge or is
#                                               off by more than MAX relative (1e-8)
#
# The fan: 10 sources down a well at x = y = 0, depths 0.5 to 3 km, and 1000 receivers on
# the surface z = 0, a grid of 40 x 25 over x in [3, 10] km, y in [-2.5, 2.5] km: 10^4 rays,
# source by source, the receivers in order (neighbouring rows are neighbouring rays). Every
# ray stays inside the grid of velocity3d.csv (z up to 3.9 km, |y| <= 2.5 km) and is a graph
# over x (|y'| < 1.1, |z'| < 2.6), which `table` checks on the exact arcs.
# SPDX-License-Identifier: MIT
import csv
import math
import sys

V0 = 2.0
GRAD = (0.08, -0.05, 0.6)   # as make_tables.py writes velocity3d.csv
GRID = ((-1.0, 11.0), (-4.0, 4.0), (-1.0, 5.0))
COLUMNS = ("xs", "ys", "zs", "xr", "yr", "zr")


def velocity(r):
    return V0 + sum(g * c for g, c in zip(GRAD, r))


def travel_time(r0, r1):
    """The closed form: T = acosh(1 + |g|^2 |r1 - r0|^2 / (2 v(r0) v(r1))) / |g|."""
    g2 = sum(g * g for g in GRAD)
    d2 = sum((b - a) ** 2 for a, b in zip(r0, r1))
    return math.acosh(1 + g2 * d2 / (2 * velocity(r0) * velocity(r1))) / math.sqrt(g2)


def arc(r0, r1, n=400):
    """n + 1 points of the exact ray from r0 to r1: the circle through both, centred on the
    plane v = 0, in the plane through them that contains the gradient."""
    gn = math.sqrt(sum(g * g for g in GRAD))
    a = [g / gn for g in GRAD]
    h0, h1 = velocity(r0) / gn, velocity(r1) / gn
    d = [q - p for p, q in zip(r0, r1)]
    dg = sum(p * q for p, q in zip(d, a))
    e = [p - dg * q for p, q in zip(d, a)]
    s1 = math.sqrt(sum(p * p for p in e))
    e = [p / s1 for p in e]
    sc = (s1 * s1 + h1 * h1 - h0 * h0) / (2 * s1)
    rad = math.hypot(sc, h0)
    p0, p1 = math.atan2(h0, -sc), math.atan2(h1, s1 - sc)
    pts = []
    for k in range(n + 1):
        ph = p0 + (p1 - p0) * k / n
        s, h = sc + rad * math.cos(ph), rad * math.sin(ph)
        pts.append([r0[i] + s * e[i] + (h - h0) * a[i] for i in range(3)])
    return pts


def fan():
    rows = []
    for i in range(10):
        src = (0.0, 0.0, 0.5 + 2.5 * i / 9)
        for j in range(40):
            for k in range(25):
                rows.append(src + (3 + 7 * j / 39, -2.5 + 5 * k / 24, 0.0))
    return rows


def select(n):
    rows = fan()
    if n >= len(rows):
        return rows
    return [rows[(i * len(rows)) // n] for i in range(n)]


def table(n):
    out = [", ".join(COLUMNS)]
    for row in select(n):
        pts = arc(row[:3], row[3:])
        for p, q in zip(pts, pts[1:]):
            dx = q[0] - p[0]
            assert dx > 0 and abs(q[1] - p[1]) < 1.1 * dx and abs(q[2] - p[2]) < 2.6 * dx, row
            assert all(lo < c < hi for c, (lo, hi) in zip(q, GRID)), row
        out.append(", ".join("%.17g" % c for c in row))
    return "\n".join(out) + "\n"


def check(path, limit):
    """Max relative error of the travel times in a batch output table, the rows over limit
    and the rows not converged; returns (summary text, number of bad rows)."""
    worst, over, failed, n, nodal = 0.0, 0, 0, 0, 0.0
    with open(path) as f:
        for row in csv.DictReader(f):
            n += 1
            if row["status"] != "converged" or not row["action"]:
                failed += 1
                continue
            r = [float(row[c]) for c in COLUMNS]
            t = travel_time(r[:3], r[3:])
            rel = abs(float(row["action"]) - t) / t
            worst = max(worst, rel)
            over += rel > limit
            if row.get("error_max_nodal"):
                nodal = max(nodal, float(row["error_max_nodal"]))
    text = ("%d rays: max relative travel-time error %.3g, %d over %g, %d not converged; "
            "max nodal error of the rays %.3g km" % (n, worst, over, limit, failed, nodal))
    return text, over + failed + (n == 0)


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "table":
        sys.stdout.write(table(int(sys.argv[2]) if len(sys.argv) > 2 else 10**4))
        return 0
    if len(sys.argv) >= 3 and sys.argv[1] == "check":
        text, bad = check(sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 1e-8)
        print(text)
        return 1 if bad else 0
    sys.stderr.write("usage: make_seismic_fan.py table [N] | check OUT.csv [MAX]\n")
    return 2


if __name__ == "__main__":
    sys.exit(main())
