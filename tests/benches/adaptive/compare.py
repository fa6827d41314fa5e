#!/usr/bin/env python3
"""Triangles needed for a chord error: adaptive (--tolerance) against uniform levels.

For each asset and uniform level L, the uniform run's measured chord error e_L (the report's
`adaptive.chord_error`: sampled points of every output triangle against the surface) is taken
as the tolerance of an adaptive run; the table gives both triangle counts, the adaptive run's
own measured error, its worst triangle shape and both wall times (median of --runs).

Usage: compare.py [--bin target/release/g2tess] [--levels 4,8,16] [--runs 3] ASSET...
Generated spheres and tori: pass the .glb files written by ../shared/bench/gen_mesh.py or
any other mesh.
"""
import argparse, json, os, statistics, subprocess, sys, tempfile, time

def run(binary, asset, extra, runs):
    with tempfile.TemporaryDirectory() as tmp:
        out, rep = os.path.join(tmp, "o.glb"), os.path.join(tmp, "r.json")
        times = []
        for _ in range(runs):
            t = time.perf_counter()
            subprocess.run([binary, asset, "-o", out, "--force", "--report", rep, *extra],
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            times.append(time.perf_counter() - t)
        report = json.load(open(rep))
    f = report["files"][0]
    meshes = f.get("meshes") or f.get("report", {}).get("meshes") or []
    figs = [m["adaptive"] for m in meshes if m.get("adaptive")]
    err = max((m["chord_error"] for m in figs), default=0.0)
    angle = min((m["min_angle_degrees"] for m in figs), default=0.0)
    return f.get("triangles_out", report["summary"]["triangles_out"]), err, angle, statistics.median(times)

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/g2tess")
    ap.add_argument("--levels", default="4,8,16")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("assets", nargs="+")
    a = ap.parse_args()
    print("| asset | level | ε (uniform, measured) | uniform tris | adaptive tris | ratio | adaptive ε measured | min angle | uniform s | adaptive s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for asset in a.assets:
        for level in [int(x) for x in a.levels.split(",")]:
            ut, ue, _, us = run(a.bin, asset, ["--level", str(level)], a.runs)
            at, ae, ang, as_ = run(a.bin, asset, ["--tolerance", repr(ue)], a.runs)
            print(f"| {os.path.basename(asset)} | {level} | {ue:.3e} | {ut} | {at} | {at/ut:.2f} | {ae:.3e} | {ang:.1f}° | {us:.2f} | {as_:.2f} |")
            sys.stdout.flush()

if __name__ == "__main__":
    main()
