#!/usr/bin/env python3
"""Benchmark input: a geodesic icosphere (20·f² triangles) as a GLB with positions, unit
normals, UVs and an embedded checker texture (so optimizers keep the UVs), plus a welded raw dump
for the drivers that take plain arrays (OpenSubdiv, Manifold).

Raw dump, little endian: b"G2TM", u32 vertices, u32 triangles, f32 positions[3·v], u32 indices[3·t].
Standard library only. Not a general mesh tool: one shape, one layout.

    mesh.py --tris 10000 OUT.glb OUT.raw     # nearest frequency: 9 680 triangles
"""
import argparse
import json
import math
import struct
import zlib

ICO_F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def icosphere(freq):
    p = (1 + 5 ** 0.5) / 2
    base = [unit(v) for v in [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p),
                              (0, -1, -p), (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]]
    verts, index_of, tris = [], {}, []

    def vertex(a, b, c, i, j):
        # Welded by exact lattice identity: corner and edge points shared between faces.
        k = freq - i - j
        key = tuple(sorted((v, w) for v, w in ((a, k), (b, i), (c, j)) if w))
        if key not in index_of:
            pa, pb, pc = base[a], base[b], base[c]
            index_of[key] = len(verts)
            verts.append(unit(tuple((k * pa[d] + i * pb[d] + j * pc[d]) for d in range(3))))
        return index_of[key]

    for a, b, c in ICO_F:
        for j in range(freq):
            for i in range(freq - j):
                v0, v1, v2 = vertex(a, b, c, i, j), vertex(a, b, c, i + 1, j), vertex(a, b, c, i, j + 1)
                tris.append((v0, v1, v2))
                if i + j + 1 < freq:
                    tris.append((v1, vertex(a, b, c, i + 1, j + 1), v2))
    return verts, tris


def png_checker(size=8):
    rows = b"".join(b"\0" + bytes(255 if (x + y) % 2 else 40 for x in range(size) for _ in range(3))
                    for y in range(size))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def write_glb(path, verts, tris):
    uv = [(0.5 + math.atan2(v[2], v[0]) / (2 * math.pi), math.acos(max(-1, min(1, v[1]))) / math.pi)
          for v in verts]
    blobs = [b"".join(struct.pack("<3f", *v) for v in verts),
             b"".join(struct.pack("<3f", *v) for v in verts),  # unit sphere: normal = position
             b"".join(struct.pack("<2f", *t) for t in uv),
             b"".join(struct.pack("<3I", *t) for t in tris),
             png_checker()]
    views, offset = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b)})
        offset += (len(b) + 3) // 4 * 4
    for v, target in zip(views, [34962, 34962, 34962, 34963]):
        v["target"] = target
    lo = [min(v[d] for v in verts) for d in range(3)]
    hi = [max(v[d] for v in verts) for d in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "g2tess benchmark mesh.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "icosphere"}],
        "meshes": [{"name": "icosphere", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
            "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"bufferView": 4, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": len(verts), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": len(verts), "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": 3 * len(tris), "type": "SCALAR"}],
        "bufferViews": views, "buffers": [{"byteLength": offset}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = b"".join(b + b"\0" * (-len(b) % 4) for b in blobs)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(binary)))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tris", type=int, required=True)
    ap.add_argument("glb")
    ap.add_argument("raw")
    a = ap.parse_args()
    freq = max(1, round(math.sqrt(a.tris / 20)))
    verts, tris = icosphere(freq)
    write_glb(a.glb, verts, tris)
    with open(a.raw, "wb") as f:
        f.write(struct.pack("<4sII", b"G2TM", len(verts), len(tris)))
        f.write(b"".join(struct.pack("<3f", *v) for v in verts))
        f.write(b"".join(struct.pack("<3I", *t) for t in tris))
    print(f"{a.glb}: {len(tris)} triangles, {len(verts)} vertices")


if __name__ == "__main__":
    main()
