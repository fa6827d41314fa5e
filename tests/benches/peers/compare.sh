#!/bin/bash
# Whole-process speed of g2tess against the tools users run today to get dense smooth meshes into
# a glTF build, on the same input in the same run: OpenSubdiv Loop refinement (limit positions and
# normals, GLB out), the same followed by gltfpack, Manifold's smooth_by_normals + refine, and
# Blender's Subdivision Surface modifier with glTF export (10k input only: it needs half a
# minute per run there), and the floor of writing the same number of bytes to disk. Prints one
# table of medians, ratios to g2tess and peak resident memory.
#
#   tests/benches/peers/compare.sh [--no-install]
#
# Environment: RUNS (default 5) runs per command after one warm-up; WORK (default
# target/bench-peers) for builds, meshes and outputs; SIZES (default "10000 100000") input
# triangles; NO_BLENDER=1 leaves Blender out (a 650 MB install). Installs what it needs (as root,
# Debian): hyperfine, GNU time, g++, libosd-dev, blender and python3-numpy (its glTF add-on needs
# it) from apt, gltfpack and @gltf-transform/cli from npm with the lock file beside this script,
# manifold3d and numpy from PyPI.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
WORK=${WORK:-$ROOT/target/bench-peers}
RUNS=${RUNS:-5}
SIZES=${SIZES:-"10000 100000"}
mkdir -p "$WORK/out" "$WORK/results" "$WORK/npm"

if [ "${1:-}" != "--no-install" ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends hyperfine time g++ libosd-dev > /dev/null
  if [ -z "${NO_BLENDER:-}" ]; then
    apt-get install -y -qq --no-install-recommends blender python3-numpy > /dev/null
  fi
  cp "$HERE/package.json" "$HERE/package-lock.json" "$WORK/npm/"
  (cd "$WORK/npm" && npm ci --no-audit --no-fund --silent)
  python3 -m pip install -q manifold3d==3.5.4 numpy 2> /dev/null
fi
(cd "$ROOT" && cargo build --release --quiet)
LOAD_BEFORE=$(cut -d ' ' -f 1 /proc/loadavg)
g++ -O2 -std=c++17 -Wall -o "$WORK/osd_loop" "$HERE/osd_loop.cpp" -losdCPU
G2=$ROOT/target/release/g2tess
PACK=$WORK/npm/node_modules/.bin/gltfpack

: > "$WORK/results/rows.tsv"
bench() { # group, label, command[, runs]
  local group=$1 label=$2 cmd=$3 runs=${4:-$RUNS} key
  key=$(echo "$group-$label" | tr -c 'A-Za-z0-9\n' '_')
  echo "== $group: $label" >&2
  hyperfine --style none --runs "$runs" --warmup 1 --export-json "$WORK/results/$key.json" \
    --output=null "$cmd" > /dev/null
  /usr/bin/time -v sh -c "$cmd" > /dev/null 2> "$WORK/results/$key.time"
  printf '%s\t%s\t%s\n' "$group" "$label" "$key" >> "$WORK/results/rows.tsv"
}

for tris in $SIZES; do
  name=ico$((tris / 1000))k
  python3 "$HERE/mesh.py" --tris "$tris" "$WORK/$name.glb" "$WORK/$name.raw" >&2
  # Same output triangle count for every tool: level 16 = Loop level 4 at 10k, level 8 = Loop
  # level 3 at 100k.
  if [ "$tris" -ge 50000 ]; then level=8; loop=3; else level=16; loop=4; fi
  out=$WORK/out
  bench "$name" "g2tess --level $level (2 threads)" \
    "$G2 $WORK/$name.glb -o $out/g2.glb --level $level --h 0.212"
  bench "$name" "g2tess --level $level (1 thread)" \
    "RAYON_NUM_THREADS=1 $G2 $WORK/$name.glb -o $out/g2.glb --level $level --h 0.212"
  bench "$name" "OpenSubdiv Loop level $loop" "$WORK/osd_loop $WORK/$name.raw $loop $out/osd.glb"
  bench "$name" "OpenSubdiv Loop level $loop + gltfpack" \
    "$WORK/osd_loop $WORK/$name.raw $loop $out/osd.glb && $PACK -i $out/osd.glb -o $out/osd_pack.glb"
  bench "$name" "Manifold smooth_by_normals + refine($level)" \
    "python3 $HERE/manifold_smooth.py $WORK/$name.raw $level $out/manifold.glb"
  if [ -z "${NO_BLENDER:-}" ] && [ "$tris" -lt 50000 ] && command -v blender > /dev/null; then
    # Catmull-Clark level 4 makes 384 triangles per input triangle (3.72 M here), the nearest
    # Blender comes to the others' 2.48 M; 3 runs, each about half a minute.
    bench "$name" "Blender Catmull-Clark level 4 + glTF export" \
      "blender -b --factory-startup -noaudio --python-exit-code 1 -P $HERE/blender_subdiv.py -- $WORK/$name.glb $out/blender.glb 4" 3
  fi
  mib=$(( ($(stat -c %s "$out/g2.glb") + 1048575) / 1048576 ))
  bench "$name" "write floor: dd ${mib} MiB + fdatasync" \
    "dd if=/dev/zero of=$out/floor.bin bs=1M count=$mib conv=fdatasync status=none"
done

python3 - "$WORK/results" "$RUNS" "$LOAD_BEFORE" <<'PY'
import json, os, platform, re, sys
results, runs, load = sys.argv[1], sys.argv[2], sys.argv[3]
rows = [l.rstrip("\n").split("\t") for l in open(os.path.join(results, "rows.tsv"))]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
print(f"machine: {os.cpu_count()} cores, {cpu}, {platform.system()} {platform.release()}; "
      f"median of {runs} runs (fewer where the table says) after 1 warm-up; "
      f"load average before the run {load}")
print()
print("| input | command | runs | median s | min–max s | × g2tess (2 threads) | peak RSS MiB |")
print("| --- | --- | --- | --- | --- | --- | --- |")
ours = {}
for group, label, key in rows:
    r = json.load(open(os.path.join(results, key + ".json")))["results"][0]
    t = open(os.path.join(results, key + ".time")).read()
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", t)
    rss = int(m.group(1)) / 1024 if m else float("nan")
    if label.startswith("g2tess") and "2 threads" in label:
        ours[group] = r["median"]
    ratio = r["median"] / ours[group] if group in ours else float("nan")
    print(f"| {group} | {label} | {len(r['times'])} | {r['median']:.3f} | {r['min']:.3f}–{r['max']:.3f} | "
          f"{ratio:.2f} | {rss:.0f} |")
PY
