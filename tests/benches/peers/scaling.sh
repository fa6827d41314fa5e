#!/bin/bash
# Whole-process time of g2tess against output triangles: levels 2 to 32 on 1k, 10k and 100k
# input triangles, on one thread and on two. Median wall time of RUNS runs (default 3) with GNU
# time; jobs over 50 M output triangles are skipped (the limit is raised above the default 20 M
# for the 25.8 M of 100k at level 16).
#
#   tests/benches/peers/scaling.sh      (after compare.sh, which builds and makes the meshes)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
WORK=${WORK:-$ROOT/target/bench-peers}
RUNS=${RUNS:-3}
G2=$ROOT/target/release/g2tess
mkdir -p "$WORK/out"
echo "| input | level | output triangles | 1 thread s | 2 threads s | 2 threads M tris/s | speed-up |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for tris in 1000 10000 100000; do
  name=ico$((tris / 1000))k
  [ -f "$WORK/$name.glb" ] || python3 "$HERE/mesh.py" --tris "$tris" "$WORK/$name.glb" "$WORK/$name.raw" > /dev/null
  for level in 2 4 8 16 32; do
    [ $(( tris * level * level )) -gt 50000000 ] && continue
    t=()
    for threads in 1 2; do
      times=$(for _ in $(seq "$RUNS"); do
        RAYON_NUM_THREADS=$threads /usr/bin/time -f %e "$G2" "$WORK/$name.glb" \
          -o "$WORK/out/scaling.glb" --level "$level" --h 0.212 --max-triangles 50000000 \
          2>&1 > /dev/null | tail -1
      done | sort -n)
      t+=("$(echo "$times" | sed -n "$(( (RUNS + 1) / 2 ))p")")
    done
    out=$(python3 -c "import json,struct,sys; b=open('$WORK/out/scaling.glb','rb').read(); n=struct.unpack_from('<I',b,12)[0]; j=json.loads(b[20:20+n]); print(sum(a['count'] for m in j['meshes'] for p in m['primitives'] for a in [j['accessors'][p['indices']]])//3)")
    python3 -c "print(f'| $name | $level | {$out:,} | ${t[0]} | ${t[1]} | {$out/${t[1]}/1e6:.1f} | {${t[0]}/${t[1]}:.2f} |')"
  done
done
