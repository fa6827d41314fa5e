#!/bin/bash
# Large inputs at low levels: whole-process wall time, user and sys time and peak resident memory
# of g2tess at levels 1, 2 and 4 on icospheres of 10k, 100k, 1M and 4M triangles, side by side
# with OpenSubdiv Loop refinement at the same output counts (Loop level 1 = g2tess level 2,
# Loop level 2 = g2tess level 4; limit positions and normals, GLB out) and gltfpack `-noq` on the
# same input (the cost of only reading, optimizing and writing it), all in the same run.
#
# Every command runs RUNS times (default 5); the commands of one input take turns, each round in
# a rotated order, so a slow spell of a busy machine falls on all of them alike. Prints the
# median, the spread (worst / median), median user and sys time, the largest peak RSS, the cost
# per input triangle and, for g2tess, the ratio to OpenSubdiv at the same output; writes the
# figures as JSON and a plot of the cost per input triangle against the input size. Each round
# also runs g2tess on the bundled 20-triangle icosahedron, the fixed cost of a run, so that the
# cost per input triangle is also given without it.
#
#   tests/benches/large/large.sh [--no-install]
#
# Environment: RUNS (default 5); SIZES (default "10000 100000 1000000 4000000"); LEVELS (default
# "1 2 4"); WORK (default target/bench-large) for meshes, outputs and results; PLOT (default
# $WORK/large.png). Installs what it needs (as root, Debian): GNU time, g++ and libosd-dev from
# apt, gltfpack from npm with the lock file of tests/benches/peers, matplotlib from PyPI.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
PEERS=$ROOT/tests/benches/peers
WORK=${WORK:-$ROOT/target/bench-large}
RUNS=${RUNS:-5}
SIZES=${SIZES:-"10000 100000 1000000 4000000"}
LEVELS=${LEVELS:-"1 2 4"}
PLOT=${PLOT:-$WORK/large.png}
mkdir -p "$WORK/out" "$WORK/npm"

if [ "${1:-}" != "--no-install" ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends time g++ libosd-dev > /dev/null
  cp "$PEERS/package.json" "$PEERS/package-lock.json" "$WORK/npm/"
  (cd "$WORK/npm" && npm ci --no-audit --no-fund --silent)
  python3 -m pip install -q matplotlib 2> /dev/null
fi
(cd "$ROOT" && cargo build --release --quiet)
g++ -O2 -std=c++17 -Wall -o "$WORK/osd_loop" "$PEERS/osd_loop.cpp" -losdCPU
G2=$ROOT/target/release/g2tess
PACK=$WORK/npm/node_modules/.bin/gltfpack
LOAD_BEFORE=$(cut -d ' ' -f 1 /proc/loadavg)

# One line per run: size, command label, output triangles factor, wall, user, sys, peak KiB,
# output bytes.
RAW=$WORK/runs.tsv
: > "$RAW"
timed() { # size, label, factor, output file, command...
  local size=$1 label=$2 factor=$3 out=$4
  shift 4
  rm -f "$out"
  # Wall time from bash's microsecond clock: GNU time's %e has a resolution of 10 ms, as long as
  # a whole 10k run.
  local start=$EPOCHREALTIME
  /usr/bin/time -f '%U %S %M' -o "$WORK/time.txt" "$@" > /dev/null 2> "$WORK/stderr.txt" || {
    echo "failed: $*" >&2
    cat "$WORK/stderr.txt" >&2
    exit 1
  }
  local end=$EPOCHREALTIME
  local wall
  wall=$(python3 -c "print(f'{$end - $start:.6f}')")
  read -r user sys kib < <(tail -n 1 "$WORK/time.txt")
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$size" "$label" "$factor" "$wall" "$user" "$sys" \
    "$kib" "$(stat -c %s "$out")" >> "$RAW"
}

for tris in $SIZES; do
  name=ico_$tris
  [ -f "$WORK/$name.glb" ] || python3 "$PEERS/mesh.py" --tris "$tris" "$WORK/$name.glb" "$WORK/$name.raw" > /dev/null
  actual=$(python3 -c "import struct; print(struct.unpack_from('<2I', open('$WORK/$name.raw','rb').read(), 4)[1])")
  cat "$WORK/$name.glb" "$WORK/$name.raw" > /dev/null # into the page cache before the first run
  commands=()
  for level in $LEVELS; do commands+=("g2 $level"); done
  for level in $LEVELS; do
    case $level in 2) commands+=("osd 1") ;; 4) commands+=("osd 2") ;; esac
  done
  commands+=("pack" "start")
  echo "== $name ($actual triangles): ${#commands[@]} commands × $RUNS runs" >&2
  for run in $(seq "$RUNS"); do
    n=${#commands[@]}
    for i in $(seq 0 $(( n - 1 ))); do
      set -- ${commands[$(( (i + run) % n ))]}
      case $1 in
        g2) timed "$actual" "g2tess level $2" $(( $2 * $2 )) "$WORK/out/g2.glb" \
              "$G2" "$WORK/$name.glb" -o "$WORK/out/g2.glb" --level "$2" --max-triangles 200000000 ;;
        osd) timed "$actual" "OpenSubdiv Loop level $2" $(( 1 << (2 * $2) )) "$WORK/out/osd.glb" \
              "$WORK/osd_loop" "$WORK/$name.raw" "$2" "$WORK/out/osd.glb" ;;
        # The fixed cost of a run: the bundled 20-triangle icosahedron at level 1 (process
        # start, reading, writing), taken in the same rounds so that the cost per input
        # triangle can be given without it.
        start) timed "$actual" "g2tess start-up" 1 "$WORK/out/start.glb" \
              "$G2" "$ROOT/fixtures/icosahedron.glb" -o "$WORK/out/start.glb" --level 1 ;;
        pack) timed "$actual" "gltfpack -noq" 1 "$WORK/out/pack.glb" \
              "$PACK" -noq -i "$WORK/$name.glb" -o "$WORK/out/pack.glb" ;;
      esac
    done
  done
done

python3 "$HERE/summary.py" "$RAW" "$WORK/large.json" "$PLOT" "$RUNS" "$LOAD_BEFORE"
