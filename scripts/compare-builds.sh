#!/usr/bin/env bash
# Alternates whole-process timings of the tessera CLI built at an earlier
# commit (default: the last commit before the thinning rule) and at the
# working tree, on the same requests, and prints each request's median
# times and their ratio (new / old). One thread each, output to /dev/null.
#   bash scripts/compare-builds.sh [OLD_COMMIT] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
old=${1:-00dc6bf}
runs=${2:-9}
pattern=${3:-}
work=$(mktemp -d)
trap 'git worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git worktree add -q --detach "$work/old" "$old"
CARGO_TARGET_DIR=target/compare-old cargo build -q --release --bin tessera --manifest-path "$work/old/Cargo.toml"
cargo build -q --release --bin tessera --example synth_maps
./target/release/examples/synth_maps "$work/maps" >/dev/null
new_bin=target/release/tessera
old_bin=target/compare-old/release/tessera
requests=(
  "sphere -n 10000000"
  "sphere -n 50000"
  "sphere -n 200000"
  "sphere -n 240000"
  "sphere -n 600000"
  "sphere -n 1000"
  "sphere --map $work/maps/clear-sky_1024x512_f32.exr -n 1000000"
  "sphere --map $work/maps/city-night_1024x512_f32.exr -n 1000000"
  "sphere --map $work/maps/textured-1_1024x512_f32.exr -n 1000000"
  "sphere --density cap:0,90,30,16 -n 1000000"
  "plane --system ghexomino --density ramp -n 2000000"
  "plane --system ppentomino --density image:$work/maps/plane_mixed_512x512.exr -n 1000000"
  "plane --system penrose --density ramp -n 300000"
)
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
now() { date +%s%N; }
for request in "${requests[@]}"; do
  [[ "$request" == *"$pattern"* ]] || continue
  : >"$work/old.t"
  : >"$work/new.t"
  for _ in $(seq "$runs"); do
    for which in old new; do
      bin=$old_bin
      [ "$which" = new ] && bin=$new_bin
      t0=$(now)
      # shellcheck disable=SC2086
      RAYON_NUM_THREADS=1 "$bin" $request --format bin -o /dev/null
      t1=$(now)
      echo $(((t1 - t0) / 1000)) >>"$work/$which.t"
    done
  done
  o=$(median <"$work/old.t")
  n=$(median <"$work/new.t")
  printf '%-70s old %8.1f ms  new %8.1f ms  new/old %.3f\n' "${request//$work\//}" \
    "$(echo "$o / 1000" | bc -l)" "$(echo "$n / 1000" | bc -l)" "$(echo "$n / $o" | bc -l)"
done
