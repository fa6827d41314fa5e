#!/usr/bin/env python3
"""Triangles a pattern family needs for a chord error ε on the exact torus, without g2tess.

A model, to tell what a kind of transition pattern can gain before building it. The mesh is the
U×V torus ../shared/bench/gen_mesh.py writes (radii 1 and 0.35; `--tris 2000` gives 50×20,
each quad cut along the diagonal that raises both indices). Over a source triangle the surface
is taken as the exact torus in its angles (θ around the ring, φ around the tube), whose second
fundamental form is

    II(dθ, dφ) = (R + r cos φ) cos φ dθ² + r dφ²,

and the chord error of a flat triangle with corners at angles λ_a is, as in `estimate.rs`, the
largest over the seven sample weights of `chord.rs` of ½ |Σ_{a<b} w_a w_b II(λ_a − λ_b)|,
with II taken at the lowest, middle and highest φ of the triangle. On the 50×20 torus this
predicts the error g2tess measures at uniform levels within 2% (level 9: 8.57e-5 predicted,
8.73e-5 measured).

Three families, each at its smallest counts meeting ε:
- uniform: one level everywhere;
- isotropic: each triangle at its own uniform level (the lattice of one inner level that the
  current transition patterns put inside a triangle; transitions between levels ignored, so this
  is about the best they reach);
- rows: rows parallel to the triangle's ring-direction edge (φ constant), R of them, so the tube
  edge and the diagonal carry R segments and the ring edge b; row r has ⌈b(R − r)/R⌉ segments
  and neighbouring rows are zipped, each step taking the triangle of smaller error. One (R, b)
  per row of quads (both triangles of a quad, so shared edges agree).

Usage: torus_patterns.py [--eps 1e-3,3e-4,1e-4] [--grid 50x20]
"""
import argparse
import math

R_RING, R_TUBE = 1.0, 0.35
WEIGHTS = [(1/3, 1/3, 1/3), (.5, .5, 0), (0, .5, .5), (.5, 0, .5),
           (2/3, 1/6, 1/6), (1/6, 2/3, 1/6), (1/6, 1/6, 2/3)]


def second_form(phi, d):
    return (R_RING + R_TUBE * math.cos(phi)) * math.cos(phi) * d[0] ** 2 + R_TUBE * d[1] ** 2


def flat_error(phis, p):
    """Chord error of the flat triangle with corners p (angles), II at each of phis."""
    worst = 0.0
    for phi in phis:
        q = [second_form(phi, (p[a][0] - p[b][0], p[a][1] - p[b][1]))
             for a, b in ((0, 1), (1, 2), (0, 2))]
        worst = max(worst, max(abs(.5 * (w[0] * w[1] * q[0] + w[1] * w[2] * q[1]
                                         + w[0] * w[2] * q[2])) for w in WEIGHTS))
    return worst


def lerp(a, b, t):
    return (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t)


def uniform_error(phis, corners, n):
    # Every triangle of the level-n lattice is the source triangle scaled by 1/n (up or down).
    return flat_error(phis, corners) / n ** 2


def row_pattern(phis, corners, base, rows, b):
    """(triangles, worst error) of the row pattern on edge `base` (opposite corner `base`)."""
    apex, left, right = corners[base], corners[(base + 1) % 3], corners[(base + 2) % 3]
    points = []
    for r in range(rows + 1):
        t = r / rows
        s = b if r == 0 else 0 if r == rows else max(1, math.ceil(b * (rows - r) / rows))
        a, c = lerp(left, apex, t), lerp(right, apex, t)
        points.append([lerp(a, c, q / s) for q in range(s + 1)] if s else [a])
    count, worst = 0, 0.0
    for low, high in zip(points, points[1:]):
        i = j = 0
        while i < len(low) - 1 or j < len(high) - 1:
            up = (low[i], low[i + 1], high[j]) if i < len(low) - 1 else None
            down = (low[i], high[j + 1], high[j]) if j < len(high) - 1 else None
            eu = flat_error(phis, up) if up else math.inf
            ed = flat_error(phis, down) if down else math.inf
            if eu <= ed:
                i, e = i + 1, eu
            else:
                j, e = j + 1, ed
            count, worst = count + 1, max(worst, e)
    return count, worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--eps", default="1e-3,3e-4,1e-4")
    ap.add_argument("--grid", default="50x20")
    a = ap.parse_args()
    nu, nv = map(int, a.grid.split("x"))
    dt, dp = 2 * math.pi / nu, 2 * math.pi / nv
    # The two triangles of a quad, as gen_mesh.py winds them, and the edge (opposite that
    # corner) that runs around the ring.
    quad = [(((0, 0), (dt, 0), (dt, dp)), 2), (((0, 0), (dt, dp), (0, dp)), 0)]
    print("| ε | uniform level (tris) | isotropic per triangle (tris) | rows (tris) "
          "| rows / isotropic |")
    print("|---|---|---|---|---|")
    for eps in [float(x) for x in a.eps.split(",")]:
        rows_of = []
        for j in range(nv):
            phis = (j * dp, (j + .5) * dp, (j + 1) * dp)
            tris = [[(p[0], p[1] + j * dp) for p in c] for c, _ in quad]
            level = 1
            while max(uniform_error(phis, t, level) for t in tris) > eps:
                level += 1
            best = None
            for rows in range(max(1, level - 3), level + 4):
                for b in range(1, rows + 1):
                    found = [row_pattern(phis, t, base, rows, b) for t, (_, base) in zip(tris, quad)]
                    if all(e <= eps for _, e in found):
                        n = sum(c for c, _ in found)
                        if best is None or n < best:
                            best = n
                        break
            rows_of.append((level, best))
        uniform = max(l for l, _ in rows_of)
        iso = nu * sum(2 * l * l for l, _ in rows_of)
        rows = nu * sum(n for _, n in rows_of)
        print(f"| {eps:.0e} | {uniform} ({2 * nu * nv * uniform ** 2}) | {iso} | {rows} "
              f"| {rows / iso:.2f} |")


if __name__ == "__main__":
    main()
