#!/usr/bin/env python3
# examples/scenes/make_tables.py — writes the CSV grids of the table scenes
# (seismic_ray_table.scene, height_map_path.scene, seismic_fan.scene). Run from this
# directory.
# SPDX-License-Identifier: MIT
import math


def write(name, header, rows):
    with open(name, "w") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(", ".join("%.17g" % v for v in r) + "\n")


# A seismic velocity model v(x, z) = 1 + 0.3 x + 0.4 z (km/s, km) sampled every 0.1 km
# in x and 0.05 km in depth z.
write("velocity.csv", "x, z, v",
      [(0.1 * i, -0.1 + 0.05 * j, 1 + 0.3 * 0.1 * i + 0.4 * (-0.1 + 0.05 * j))
       for i in range(21) for j in range(9)])

# A height map z = h(x, y): a ridge shaped like the cylinder h = sqrt(4 - y^2), sampled
# every 0.25 in x and 0.05 in y.
write("ridge.csv", "x, y, h",
      [(0.25 * i, -1.2 + 0.05 * j, math.sqrt(4 - (-1.2 + 0.05 * j) ** 2))
       for i in range(5) for j in range(49)])

# A 3-D velocity model with a constant gradient (seismic_fan.scene): v = 2 + 0.08 x - 0.05 y
# + 0.6 z (km/s; x, y horizontal and z depth in km), on a grid 1 km apart over x in [-1, 11],
# y in [-4, 4], z in [-1, 5] (13 x 9 x 7 points; v >= 1.12 there). The tricubic spline
# reproduces it exactly, so the grid can be this coarse.
write("velocity3d.csv", "x, y, z, v",
      [(x, y, z, 2 + 0.08 * x - 0.05 * y + 0.6 * z)
       for x in range(-1, 12) for y in range(-4, 5) for z in range(-1, 6)])
