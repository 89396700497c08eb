#!/usr/bin/env python3
"""Writes the quad mesh whose faces are a closed cage's edges: each edge (a, b) becomes the quad
(a, centre of the face on its right, b, centre of the face on its left), the cage's vertices
and its faces' centres being the vertices. It has twice a closed quad cage's faces, so its
refinements fall between the cage's (bench/film-scale's 8x asset: the body's base made 33,024
quads, refined 6 times). A boundary or non-manifold edge is an error.
  bench/edge-quads.py CAGE.obj OUT.obj"""
import sys

if len(sys.argv) != 3:
    sys.exit(__doc__)
positions, faces = [], []
with open(sys.argv[1]) as f:
    for line in f:
        words = line.split()
        if words and words[0] == "v":
            positions.append([float(x) for x in words[1:4]])
        elif words and words[0] == "f":
            faces.append([int(w.split("/")[0]) - 1 for w in words[1:]])
# The directed edge (a, b) -> the face it turns in.
left = {}
for i, face in enumerate(faces):
    for k, a in enumerate(face):
        b = face[(k + 1) % len(face)]
        if (a, b) in left:
            sys.exit(f"{sys.argv[1]}: edge {a + 1}-{b + 1} is used twice in the same direction")
        left[(a, b)] = i
centre = len(positions)
quads = []
for (a, b), i in left.items():
    j = left.get((b, a))
    if j is None:
        sys.exit(f"{sys.argv[1]}: edge {a + 1}-{b + 1} is on a boundary: the cage must be closed")
    if a < b:
        quads.append((a, centre + j, b, centre + i))
with open(sys.argv[2], "w") as out:
    out.write(f"# {sys.argv[1]} with each edge made a quad (bench/edge-quads.py)\n")
    for p in positions:
        out.write("v {:.9g} {:.9g} {:.9g}\n".format(*p))
    for face in faces:
        c = [sum(positions[v][i] for v in face) / len(face) for i in range(3)]
        out.write("v {:.9g} {:.9g} {:.9g}\n".format(*c))
    for q in quads:
        out.write("f {} {} {} {}\n".format(*(v + 1 for v in q)))
