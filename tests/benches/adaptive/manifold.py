#!/usr/bin/env python3
"""Triangles for a chord error, side by side with Manifold's refine_to_tolerance.

For each mesh (a sphere of radius 1 or a torus of radii 1 and 0.35, as
../shared/bench/gen_mesh.py writes them) and each ε: g2tess --tolerance ε, the smallest g2tess
--level whose measured chord error is at most ε, and Manifold 3 (manifold3d from PyPI:
smooth_by_normals on the input's normals, then refine_to_tolerance(ε)). Each tool's chord error
is measured against its own smooth surface where it can be (g2tess's report: sampled points of
every output triangle); since Manifold's surface is not exposed, every output is also measured
against the exact shape the mesh samples: the largest distance of seven points per output
triangle (centroid, edge midpoints, halfway to each corner) from the sphere or torus, and the
Manifold tolerance whose output is as close to the shape as g2tess's is found by bisection
(Manifold's tolerance bounds the deviation of its edge curves only, not of triangle interiors).

Usage: manifold.py [--bin target/release/g2tess] [--eps 1e-3,3e-4,1e-4] sphere.glb torus.glb
"""
import argparse, json, os, struct, subprocess, sys, tempfile

import numpy as np

WEIGHTS = np.array([[1/3, 1/3, 1/3], [.5, .5, 0], [0, .5, .5], [.5, 0, .5],
                    [2/3, 1/6, 1/6], [1/6, 2/3, 1/6], [1/6, 1/6, 2/3]])


def read_glb(path):
    """POSITION, NORMAL and indices of the first primitive."""
    data = open(path, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    off = 20 + jlen
    blen = struct.unpack_from("<I", data, off)[0]
    binary = data[off + 8:off + 8 + blen]
    prim = doc["meshes"][0]["primitives"][0]

    def acc(i):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        dtype = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a["componentType"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        return np.frombuffer(binary, dtype, a["count"] * width, start).reshape(a["count"], width)

    return (acc(prim["attributes"]["POSITION"]).astype(np.float64),
            acc(prim["attributes"]["NORMAL"]).astype(np.float64),
            acc(prim["indices"]).reshape(-1, 3).astype(np.int64))


def shape_distance(kind, p):
    if kind == "sphere":
        return np.abs(np.linalg.norm(p, axis=1) - 1.0)
    # The torus's axis is the coordinate it is thinnest along.
    axis = int(np.argmin(np.ptp(p, axis=0)))
    a, b = [c for c in range(3) if c != axis]
    ring = np.hypot(p[:, a], p[:, b]) - 1.0
    return np.abs(np.hypot(ring, p[:, axis]) - 0.35)


def shape_error(kind, pos, tris):
    corners = pos[tris]  # (t, 3, 3)
    samples = np.einsum("wc,tcx->twx", WEIGHTS, corners).reshape(-1, 3)
    return shape_distance(kind, samples).max()


def g2tess(binary, asset, extra):
    with tempfile.TemporaryDirectory() as tmp:
        out, rep = os.path.join(tmp, "o.glb"), os.path.join(tmp, "r.json")
        subprocess.run([binary, asset, "-o", out, "--force", "--report", rep, *extra],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        report = json.load(open(rep))
        pos, _, tris = read_glb(out)
    f = report["files"][0]
    meshes = f.get("meshes") or f.get("report", {}).get("meshes") or []
    chord = max(m["adaptive"]["chord_error"] for m in meshes if m.get("adaptive"))
    return len(tris), chord, pos, tris


def manifold(pos, nrm, tris, eps):
    import manifold3d

    # Manifold needs a closed mesh: weld the seams' split vertices by position.
    _, first, inverse = np.unique(pos.round(6), axis=0, return_index=True, return_inverse=True)
    p, n = pos[first], nrm[first]
    t = inverse.reshape(-1)[tris]
    props = np.ascontiguousarray(np.hstack([p, n]), np.float32)
    mesh = manifold3d.Mesh(vert_properties=props, tri_verts=np.ascontiguousarray(t, np.uint32))
    out = manifold3d.Manifold(mesh).smooth_by_normals(0).refine_to_tolerance(eps).to_mesh()
    vp = np.asarray(out.vert_properties, np.float64)[:, :3]
    return vp, np.asarray(out.tri_verts, np.int64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/g2tess")
    ap.add_argument("--eps", default="1e-3,3e-4,1e-4")
    ap.add_argument("meshes", nargs="+")
    a = ap.parse_args()
    print("| mesh | ε | g2tess adaptive tris | its chord error | its shape error "
          "| uniform level (tris) reaching ε | Manifold tris | Manifold shape error "
          "| Manifold tris at g2tess's shape error | adaptive / Manifold |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for path in a.meshes:
        pos, nrm, tris = read_glb(path)
        kind = "sphere" if np.allclose(np.linalg.norm(pos, axis=1), 1.0, atol=1e-5) else "torus"
        for eps in [float(x) for x in a.eps.split(",")]:
            at, ae, apos, atris = g2tess(a.bin, path, ["--tolerance", repr(eps)])
            level, ut = 0, 0
            while level < 64:
                level += 1
                ut, ue, _, _ = g2tess(a.bin, path, ["--level", str(level)])
                if ue <= eps:
                    break
            mpos, mtris = manifold(pos, nrm, tris, eps)
            # Manifold's tolerance bounds its edge curves' deviation only: also the coarsest
            # Manifold output whose error against the exact shape is at most g2tess's there.
            target = shape_error(kind, apos, atris)
            lo, hi = eps / 64, eps
            for _ in range(12):
                mid = (lo * hi) ** 0.5
                p2, t2 = manifold(pos, nrm, tris, mid)
                lo, hi = (lo, mid) if shape_error(kind, p2, t2) > target else (mid, hi)
            same = len(manifold(pos, nrm, tris, lo)[1])
            print(f"| {os.path.basename(path)} ({kind}) | {eps:.0e} | {at} | {ae:.2e} "
                  f"| {target:.2e} | {level} ({ut}) | {len(mtris)} "
                  f"| {shape_error(kind, mpos, mtris):.2e} | {same} | {at / len(mtris):.2f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
