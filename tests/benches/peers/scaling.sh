#!/bin/bash
# Whole-process time of g2tess against output triangles: levels 2 to 32 on 1k, 10k and 100k
# input triangles, on one thread and on two. Median wall time of RUNS runs (default 5), from the
# shell's clock; jobs over 50 M output triangles are skipped (the limit is raised above the default 20 M
# for the 25.8 M of 100k at level 16).
#
#   tests/benches/peers/scaling.sh      (after compare.sh, which builds and makes the meshes)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
WORK=${WORK:-$ROOT/target/bench-peers}
RUNS=${RUNS:-5}
G2=$ROOT/target/release/g2tess
mkdir -p "$WORK/out"
echo "| input | level | output triangles | 1 thread s | 2 threads s | 2 threads M tris/s | speed-up |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for tris in 1000 10000 100000; do
  name=ico$((tris / 1000))k
  [ -f "$WORK/$name.glb" ] || python3 "$HERE/mesh.py" --tris "$tris" "$WORK/$name.glb" "$WORK/$name.raw" > /dev/null
  for level in 2 4 8 16 32; do
    [ $(( tris * level * level )) -gt 50000000 ] && continue
    # One thread and two in turn, the order swapped every run, so neither gets the pages the
    # other just freed more often: the median of each is then comparable.
    one=() two=()
    for run in $(seq "$RUNS"); do
      order="1 2"; [ $(( run % 2 )) -eq 0 ] && order="2 1"
      for threads in $order; do
        start=$EPOCHREALTIME
        "$G2" "$WORK/$name.glb" -o "$WORK/out/scaling.glb" --level "$level" --h 0.212 \
          --max-triangles 50000000 -j "$threads" 2> /dev/null
        took=$(python3 -c "print(f'{$EPOCHREALTIME - $start:.3f}')")
        if [ "$threads" = 1 ]; then one+=("$took"); else two+=("$took"); fi
      done
    done
    median() { printf '%s\n' "$@" | sort -n | sed -n "$(( ($# + 1) / 2 ))p"; }
    t=("$(median "${one[@]}")" "$(median "${two[@]}")")
    out=$(python3 -c "import json,struct,sys; b=open('$WORK/out/scaling.glb','rb').read(); n=struct.unpack_from('<I',b,12)[0]; j=json.loads(b[20:20+n]); print(sum(a['count'] for m in j['meshes'] for p in m['primitives'] for a in [j['accessors'][p['indices']]])//3)")
    python3 -c "print(f'| $name | $level | {$out:,} | ${t[0]} | ${t[1]} | {$out/${t[1]}/1e6:.1f} | {${t[0]}/${t[1]}:.2f} |')"
  done
done
