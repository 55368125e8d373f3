#!/usr/bin/env bash
# Whole-process timings of tessera's command line against plain baseline
# programs (examples/plain_writers.rs: spherical Fibonacci, a jittered
# grid, i.i.d. inverse-CDF sampling of a map, written the obvious way),
# run by run alternated so that both see the same machine load. Every
# program writes the same kind of bytes (UTK binary, f64) to /dev/null.
# Prints a markdown table: median wall time and peak RSS of each side over
# RUNS runs, and the ratio of the medians (tessera / baseline).
#   bash scripts/whole-process.sh [RUNS] [--large] [--only TEXT]
# --large adds 10^8 sphere points and 4096x2048 and 8192x4096 maps;
# --only TEXT keeps the requests whose label contains TEXT.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
shift || true
large=
only=
while [ $# -gt 0 ]; do
  case "$1" in
    --large) large=1 ;;
    --only) only=$2; shift ;;
    *) echo "whole-process.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
cargo build -q --release --bin tessera --example plain_writers --example synth_maps
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
maps="$work/maps"
./target/release/examples/synth_maps "$maps" ${large:+--large} >/dev/null
tessera=./target/release/tessera
plain=./target/release/examples/plain_writers
sky="$maps/clear-sky_1024x512_f32.exr"

# label | tessera threads | tessera arguments | baseline arguments (one thread)
cases=(
  "sphere, uniform, 10^7|1|sphere -n 10000000|fibonacci 10000000"
  "sphere, uniform, 10^7|2|sphere -n 10000000|fibonacci 10000000"
  "map 1024x512, load + 10^6|1|sphere --map $sky -n 1000000|envmap $sky 1000000"
  "map 1024x512, load + 10^6|2|sphere --map $sky -n 1000000|envmap $sky 1000000"
  "G-hexomino, uniform, 10^7|1|plane --system ghexomino -n 10000000|jittered 10000000"
  "P-pentomino, uniform, 10^7|1|plane --system ppentomino -n 10000000|jittered 10000000"
  "G-hexomino, ramp, unsorted, 10^7|1|plane --system ghexomino --density ramp --unsorted -n 10000000|jittered 10000000"
)
if [ -n "$large" ]; then
  for size in 4096x2048 8192x4096; do
    map="$maps/clear-sky_${size}_f32.exr"
    cases+=("map $size, load + 10^6|1|sphere --map $map -n 1000000|envmap $map 1000000")
  done
  cases+=("sphere, uniform, 10^8|1|sphere -n 100000000|fibonacci 100000000")
fi

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
# wall seconds (from bash's microsecond clock: /usr/bin/time's %e has
# 10 ms steps, a fifth of a plain 10^7 polyomino writer) and peak RSS (KB)
# of one run
measure() {
  local start=$EPOCHREALTIME
  /usr/bin/time -f "%M" -o "$work/time" "$@" >/dev/null
  awk -v a="$start" -v b="$EPOCHREALTIME" -v m="$(cat "$work/time")" 'BEGIN { printf "%.4f %s\n", b - a, m }'
}

echo "| request | tessera threads | tessera (s) | baseline (s) | ratio | tessera peak RSS (MB) | baseline peak RSS (MB) |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for case in "${cases[@]}"; do
  IFS='|' read -r label threads targs bargs <<<"$case"
  [[ "$label" == *"$only"* ]] || continue
  : >"$work/t"
  : >"$work/b"
  for _ in $(seq "$runs"); do
    # shellcheck disable=SC2086
    RAYON_NUM_THREADS=1 measure $plain $bargs /dev/null >>"$work/b"
    # shellcheck disable=SC2086
    RAYON_NUM_THREADS=$threads measure $tessera $targs --format bin -o /dev/null >>"$work/t"
  done
  tw=$(cut -d' ' -f1 "$work/t" | median)
  bw=$(cut -d' ' -f1 "$work/b" | median)
  tm=$(cut -d' ' -f2 "$work/t" | median)
  bm=$(cut -d' ' -f2 "$work/b" | median)
  awk -v l="$label" -v th="$threads" -v tw="$tw" -v bw="$bw" -v tm="$tm" -v bm="$bm" \
    'BEGIN { printf "| %s | %d | %.3f | %.3f | %.2f | %.0f | %.0f |\n", l, th, tw, bw, tw / bw, tm / 1024, bm / 1024 }'
done
echo
echo "$runs runs each, alternated; $(nproc) hardware threads; load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
