#!/usr/bin/env python3
# Write a linear torus (R = 1, r = 0.35) with NU segments around the axis and NV around
# the tube (alternate rings shifted by half a step) as OFF:
#     scripts/aniso-torus.py NU NV OUT.off [--no-shift]
# (--no-shift: rings not shifted, each quad split into two right triangles)
# Few NU for many NV gives anisotropic triangles: 50 x 54 (aspect ratio 2.0 median) took
# the front's fourth configuration and a minute with edge sizes, 2.4 s with the area sizes
# `--size-from auto` picks for it (docs/cli.md); 20-25 x 54 still leave the front stuck.
import math, sys
nu, nv, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
shift = "--no-shift" not in sys.argv[4:]
R, r = 1.0, 0.35
pts = []
for j in range(nv):
    s = 0.5 if shift and j % 2 else 0.0
    for i in range(nu):
        u = 2 * math.pi * (i + s) / nu; v = 2 * math.pi * j / nv
        pts.append(((R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v)))
c = lambda i, j: (j % nv) * nu + (i % nu)
tris = []
for j in range(nv):
    for i in range(nu):
        if j % 2 == 0 or not shift:
            tris += [(c(i, j), c(i + 1, j), c(i, j + 1)), (c(i + 1, j), c(i + 1, j + 1), c(i, j + 1))]
        else:
            tris += [(c(i, j), c(i + 1, j), c(i + 1, j + 1)), (c(i, j), c(i + 1, j + 1), c(i, j + 1))]
with open(out, 'w') as f:
    f.write('OFF\n%d %d 0\n' % (len(pts), len(tris)))
    for p in pts: f.write('%.17g %.17g %.17g\n' % p)
    for t in tris: f.write('3 %d %d %d\n' % t)
