#!/usr/bin/env bash
# The 50-asset batch of BENCHMARKS.md ("Batch precompute"): wall time of one
# process (one shard) against two shard processes at once on one machine and
# one cache, and of a re-run served from the cache.
#
#   cargo build --release && crates/modal-batch/bench/batch50.sh [WORKDIR]
#
# Assets: 50 small generated meshes (boxes, spheres, tubes, cylinders of
# different sizes; quadratic tets, ≈ 2–8k DOF, 16 modes each), so a run takes
# about a minute on 2 cores.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../../.." && pwd)
MODAL=${MODAL:-$ROOT/target/release/modal}
WORK=${1:-$(mktemp -d)}
mkdir -p "$WORK/props"
cd "$WORK"
for i in $(seq 0 12); do
  s=$(echo "0.15 + 0.01 * $i" | bc -l)
  "$MODAL" mesh box --size "$s,0.08,0.05" --h 0.02 -o "props/box_$i.msh" >/dev/null
  r=$(echo "0.04 + 0.002 * $i" | bc -l)
  "$MODAL" mesh sphere --radius "$r" --h 0.025 -o "props/sphere_$i.msh" >/dev/null
  "$MODAL" mesh tube --inner-radius 0.02 --outer-radius 0.026 --length "$s" --h 0.012 -o "props/tube_$i.msh" >/dev/null
  if [ "$i" -lt 11 ]; then
    "$MODAL" mesh cylinder --radius 0.03 --length "$s" --h 0.022 -o "props/cylinder_$i.msh" >/dev/null
  fi
done
cat > library.toml <<'TOML'
[defaults]
material = "steel"
modes = 16
max_freq = 40000

[[globs]]
pattern = "props/box_*.msh"

[[globs]]
pattern = "props/sphere_*.msh"
material = "glass"

[[globs]]
pattern = "props/tube_*.msh"
material = "aluminium"

[[globs]]
pattern = "props/cylinder_*.msh"
material = "brass"
TOML
echo "assets: $(ls props | wc -l)"
# Wall time of a command [s] (its stdout discarded).
# Wall time of a command [s] (its output to batch.log).
t() { local start end; start=$(date +%s.%N); "$@" >>batch.log 2>&1; end=$(date +%s.%N); echo "$end - $start" | bc -l; }
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"

rm -rf one jobs2 two rerun rerun2 cache-one cache-jobs2 cache-two batch.log
echo "one shard (one process): $(t "$MODAL" precompute-batch library.toml --out one --cache-dir cache-one --json) s"
echo "one process, --jobs 2: $(t "$MODAL" precompute-batch library.toml --out jobs2 --cache-dir cache-jobs2 --jobs 2 --json) s"
start=$(date +%s.%N)
"$MODAL" precompute-batch library.toml --out two --cache-dir cache-two --shard 0/2 --json >shard0.json 2>>batch.log &
p0=$!
"$MODAL" precompute-batch library.toml --out two --cache-dir cache-two --shard 1/2 --json >shard1.json 2>>batch.log &
p1=$!
wait $p0 $p1
end=$(date +%s.%N)
echo "two shards (two processes at once): $(echo "$end - $start" | bc -l) s ($(grep -h '"total"' shard0.json shard1.json | tr -d ' ,\n'))"
"$MODAL" catalogue merge two -o two/catalogue.json
echo "cache-hit re-run (one process): $(t "$MODAL" precompute-batch library.toml --out rerun --cache-dir cache-one --json) s"
"$MODAL" precompute-batch library.toml --out rerun2 --cache-dir cache-one --json 2>>batch.log | grep -E '^  "(computed|cached)"' | tr -d ' ,\n'; echo
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
