#!/usr/bin/env python3
"""Shape benchmark: how close each scheme's output lies to the exact shape its coarse mesh
samples, side by side with Manifold's smooth_by_normals + refine on the same files.

For spheres and tori (R 1, r 0.35) of 20 to 10k triangles made by gen_mesh.py (exact normals),
runs g2tess at one level per scheme and nets option, and Manifold (manifold3d 3.5.4) at the same
refine count, and prints a Markdown table per mesh: max and RMS distance of the output vertices
to the exact surface, max and RMS angle between output and exact normals, and the range of the
normal curvature along output edges, (n_a - n_b)·(a - b)/|a - b|² (1/radius on a sphere).

    python3 tests/benches/shape/shape.py [--level 8] [--bin target/release/g2tess]
        [--gen ../shared/bench/gen_mesh.py] [--only NAME...] [--no-manifold]

Needs numpy, and manifold3d==3.5.4 for the peer column (pip install manifold3d==3.5.4).
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np

# One GLB writer for the benches: the Manifold peer's.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
from manifold_smooth import write_glb  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
R_MAJOR, R_MINOR = 1.0, 0.35
# Semi-axes of the ellipsoid: the icosphere's vertices and normals mapped by diag(AXES).
AXES = np.array([1.5, 1.0, 0.6])

# (name, gen_mesh shape, triangles asked for, exact surface)
MESHES = [
    ("icosahedron_20", "icosphere", 20, "sphere"),
    ("icosphere_80", "icosphere", 80, "sphere"),
    ("icosphere_320", "icosphere", 320, "sphere"),
    ("icosphere_1k", "icosphere", 1000, "sphere"),
    ("icosphere_10k", "icosphere", 10000, "sphere"),
    ("torus_72", "torus", 72, "torus"),
    ("torus_200", "torus", 200, "torus"),
    ("torus_1k", "torus", 1000, "torus"),
    ("torus_10k", "torus", 10000, "torus"),
    ("ellipsoid_320", "icosphere", 320, "ellipsoid"),
    ("ellipsoid_1k", "icosphere", 1000, "ellipsoid"),
]

# (label, g2tess arguments)
VARIANTS = [
    ("g2 round (default)", []),
    ("g2 paper", ["--nets", "paper"]),
    ("pn round", ["--scheme", "pn"]),
    ("pn paper", ["--scheme", "pn", "--nets", "paper"]),
    ("hybrid", ["--scheme", "hybrid"]),
    ("coons", ["--scheme", "coons"]),
]


def read_glb(path):
    """Positions, normals and triangles of every triangle primitive, concatenated (float64)."""
    data = open(path, "rb").read()
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        sys.exit(f"{path}: not a GLB")
    off, doc, binary = 12, None, b""
    while off < len(data):
        length, kind = struct.unpack_from("<I4s", data, off)
        chunk = data[off + 8 : off + 8 + length]
        if kind == b"JSON":
            doc = json.loads(chunk)
        elif kind == b"BIN\0":
            binary = chunk
        off += 8 + length
    comp = {5126: ("f4", 4), 5125: ("u4", 4), 5123: ("u2", 2), 5121: ("u1", 1)}
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}

    def accessor(i):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        dtype, size = comp[a["componentType"]]
        n, w = a["count"], width[a["type"]]
        stride = view.get("byteStride", size * w)
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        rows = np.ndarray((n, w), "<" + dtype, binary, start, (stride, size))
        return rows.astype(np.float64) if dtype == "f4" else rows.astype(np.int64)

    pos, nrm, tris, base = [], [], [], 0
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            if prim.get("mode", 4) != 4:
                continue
            p = accessor(prim["attributes"]["POSITION"])
            pos.append(p)
            nrm.append(accessor(prim["attributes"]["NORMAL"]))
            t = accessor(prim["indices"]).reshape(-1, 3)
            tris.append(t + base)
            base += len(p)
    return np.vstack(pos), np.vstack(nrm), np.vstack(tris)


def exact(kind, p):
    """Signed distance to the exact surface and its unit normal at the nearest point (for the
    ellipsoid, the first-order distance F/|∇F| of its implicit form, exact to the square of the
    figures measured)."""
    if kind == "ellipsoid":
        grad = 2.0 * p / AXES**2
        f = np.sum((p / AXES) ** 2, axis=1) - 1.0
        g = np.linalg.norm(grad, axis=1)
        return f / g, grad / g[:, None]
    if kind == "sphere":
        r = np.linalg.norm(p, axis=1)
        return r - 1.0, p / r[:, None]
    rho = np.hypot(p[:, 0], p[:, 2])
    radial = np.stack([p[:, 0] / rho, np.zeros_like(rho), p[:, 2] / rho], axis=1)
    g = (rho - R_MAJOR)[:, None] * radial + np.stack(
        [np.zeros_like(rho), p[:, 1], np.zeros_like(rho)], axis=1
    )
    d = np.linalg.norm(g, axis=1)
    return d - R_MINOR, g / d[:, None]


def measure(kind, pos, nrm, tris):
    dist, n_exact = exact(kind, pos)
    n = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    ang = np.degrees(np.arccos(np.clip(np.sum(n * n_exact, axis=1), -1.0, 1.0)))
    edges = np.vstack([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    d = pos[edges[:, 0]] - pos[edges[:, 1]]
    dn = n[edges[:, 0]] - n[edges[:, 1]]
    l2 = np.sum(d * d, axis=1)
    ok = l2 > 0
    curv = np.sum(dn * d, axis=1)[ok] / l2[ok]
    return {
        "max": np.abs(dist).max(),
        "rms": np.sqrt(np.mean(dist * dist)),
        "nmax": ang.max(),
        "nrms": np.sqrt(np.mean(ang * ang)),
        "kmin": curv.min(),
        "kmax": curv.max(),
        "out": len(tris),
    }


def manifold(glb, level):
    """Manifold 3.5.4: smooth_by_normals on the welded input, refine(level), vertex normals
    from calculate_normals (what its users get)."""
    import manifold3d

    pos, nrm, tris = read_glb(glb)
    # Weld by exact position (the generated seams repeat vertices; Manifold needs them shared).
    _, first, inverse = np.unique(pos, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    props = np.hstack([pos[first], nrm[first]]).astype(np.float32)
    mesh = manifold3d.Mesh(
        vert_properties=np.ascontiguousarray(props),
        tri_verts=np.ascontiguousarray(inverse[tris].astype(np.uint32)),
    )
    m = manifold3d.Manifold(mesh).smooth_by_normals(0).refine(level).calculate_normals(0)
    out = m.to_mesh()
    vp = np.asarray(out.vert_properties, np.float64)
    return vp[:, :3], vp[:, 3:6], np.asarray(out.tri_verts, np.int64)


def fmt(m):
    return (
        f"{m['max']:.3g} | {m['rms']:.3g} | {m['nmax']:.3g}° | {m['nrms']:.3g}° | "
        f"{m['kmin']:.3g} – {m['kmax']:.3g}"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--level", type=int, default=8)
    ap.add_argument("--bin", default=os.path.join(REPO, "target", "release", "g2tess"))
    ap.add_argument("--gen", default=os.path.join(REPO, "..", "shared", "bench", "gen_mesh.py"))
    ap.add_argument("--only", nargs="*", help="mesh names to run (default: all)")
    ap.add_argument("--variants", nargs="*", help="variant labels to run (default: all)")
    ap.add_argument("--no-manifold", action="store_true")
    a = ap.parse_args()
    if not os.path.exists(a.gen):
        sys.exit(f"shape.py: no mesh generator at {a.gen} (pass --gen)")
    if not os.path.exists(a.bin):
        sys.exit(f"shape.py: no g2tess binary at {a.bin} (cargo build --release, or --bin)")
    with tempfile.TemporaryDirectory() as tmp:
        for name, shape, tris, kind in MESHES:
            if a.only and name not in a.only:
                continue
            glb = os.path.join(tmp, name + ".glb")
            subprocess.run(
                [sys.executable, a.gen, "--shape", shape, "--tris", str(tris), "-o", glb],
                check=True,
                stdout=subprocess.DEVNULL,
            )
            if kind == "ellipsoid":
                p, n, t = read_glb(glb)
                n = n / AXES
                write_glb(glb, p * AXES, n / np.linalg.norm(n, axis=1, keepdims=True), t)
            n_in = len(read_glb(glb)[2])
            print(f"\n### {name} ({n_in} triangles, {kind}), level {a.level}\n")
            print("| | max distance | RMS distance | max normal error | RMS normal error "
                  "| edge normal curvature |")
            print("|---|---|---|---|---|---|")
            for label, args in VARIANTS:
                if a.variants and label not in a.variants:
                    continue
                out = os.path.join(tmp, "out.glb")
                run = subprocess.run(
                    [a.bin, glb, "-o", out, "--level", str(a.level), *args],
                    capture_output=True,
                    text=True,
                )
                if run.returncode != 0:
                    sys.exit(f"shape.py: g2tess {' '.join(args)} failed:\n{run.stderr}")
                print(f"| {label} | {fmt(measure(kind, *read_glb(out)))} |", flush=True)
            if not a.no_manifold:
                try:
                    m = measure(kind, *manifold(glb, a.level))
                    print(f"| Manifold refine({a.level}) | {fmt(m)} |", flush=True)
                except ImportError:
                    print("| Manifold | not installed (pip install manifold3d==3.5.4) |")


if __name__ == "__main__":
    main()
