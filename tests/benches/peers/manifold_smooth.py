#!/usr/bin/env python3
"""Peer for the speed comparison: Manifold (manifold3d) smoothing of the raw dump of mesh.py.

smooth_by_normals (tangents from the vertex normals) + refine(N) + calculate_normals, written as
a GLB (float32 POSITION with min/max, float32 NORMAL, uint32 indices). Manifold interpolates the
input vertices and is G1; it needs a closed manifold mesh and carries no UVs here.

    manifold_smooth.py IN.raw N OUT.glb
"""
import json
import struct
import sys

import numpy as np


def main():
    import manifold3d  # only the peer run needs it; write_glb is shared with shape.py

    raw_path, n, out_path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    raw = open(raw_path, "rb").read()
    if raw[:4] != b"G2TM":
        sys.exit("manifold_smooth.py: not a G2TM dump")
    nv, nt = struct.unpack_from("<II", raw, 4)
    pos = np.frombuffer(raw, np.float32, 3 * nv, 12).reshape(nv, 3)
    tris = np.frombuffer(raw, np.uint32, 3 * nt, 12 + 12 * nv).reshape(nt, 3)
    normals = pos / np.linalg.norm(pos, axis=1, keepdims=True)  # the input is a unit sphere
    props = np.ascontiguousarray(np.hstack([pos, normals]), np.float32)
    mesh = manifold3d.Mesh(vert_properties=props, tri_verts=np.array(tris, np.uint32))
    smooth = manifold3d.Manifold(mesh).smooth_by_normals(0).refine(n).calculate_normals(0)
    out = smooth.to_mesh()
    vp = np.ascontiguousarray(out.vert_properties, np.float32)
    p, nrm = np.ascontiguousarray(vp[:, :3]), np.ascontiguousarray(vp[:, 3:6])
    idx = np.ascontiguousarray(out.tri_verts, np.uint32)
    write_glb(out_path, p, nrm, idx)


def write_glb(path, pos, nrm, tris):
    """A GLB of one triangle primitive (float32 POSITION with min/max and NORMAL, uint32
    indices)."""
    p, n = np.asarray(pos, np.float32), np.asarray(nrm, np.float32)
    blobs = [p.tobytes(), n.tobytes(), np.asarray(tris, np.uint32).tobytes()]
    offsets = np.cumsum([0] + [len(b) for b in blobs]).tolist()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(p), "type": "VEC3",
             "min": p.min(axis=0).tolist(), "max": p.max(axis=0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(p), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": int(np.size(tris)), "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": offsets[k], "byteLength": len(b)}
                        for k, b in enumerate(blobs)],
        "buffers": [{"byteLength": offsets[-1]}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + offsets[-1]))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", offsets[-1], b"BIN\0"))
        for b in blobs:
            f.write(b)

if __name__ == "__main__":
    main()
