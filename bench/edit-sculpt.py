#!/usr/bin/env python3
"""Moves the vertices of an OBJ sculpt that lie within a ball by a smooth bump, as an artist's
local edit, and writes the result (same topology, same vertex order).

  bench/edit-sculpt.py IN.obj OUT.obj --fraction 0.01 --amplitude 0.0002 [--centre-vertex K]

The ball is centred on vertex K (default: the vertex a third of the way through the file) and
its radius is chosen so that `fraction` of the vertices move; each moves along +z by
amplitude * (1 + cos(pi r / R)) / 2. Prints the radius and the number of vertices moved."""
import argparse
import math

parser = argparse.ArgumentParser()
parser.add_argument("input")
parser.add_argument("output")
parser.add_argument("--fraction", type=float, default=0.01)
parser.add_argument("--amplitude", type=float, default=0.0002)
parser.add_argument("--centre-vertex", type=int, default=-1)
args = parser.parse_args()

points = []
with open(args.input) as f:
    for line in f:
        if line.startswith("v "):
            x, y, z = line.split()[1:4]
            points.append((float(x), float(y), float(z)))
k = args.centre_vertex if args.centre_vertex >= 0 else len(points) // 3
c = points[k]
d2 = sorted((p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2 for p in points)
radius = math.sqrt(d2[min(len(d2) - 1, int(args.fraction * len(d2)))])
moved = 0
index = 0
with open(args.input) as f, open(args.output, "w") as out:
    for line in f:
        if line.startswith("v "):
            x, y, z = points[index]
            index += 1
            r = math.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
            if r < radius:
                z += args.amplitude * 0.5 * (1 + math.cos(math.pi * r / radius))
                line = "v %.9g %.9g %.9g\n" % (x, y, z)
                moved += 1
        out.write(line)
print(f"radius {radius:.6g}, moved {moved} of {len(points)} vertices")
