#!/bin/bash
# Error against cost of `modal radiation` on the demo's steel bar (BENCHMARKS.md "Acoustic radiation").
# Usage: sweep.sh DIR  — DIR holds bar.bank and bowl.bank made with the demo's recipes:
#   modal mesh box --size 0.3,0.02,0.012 --h 0.006 --order 2 -o bar.msh && modal precompute bar.msh --material steel -o bar.bank --no-cache
#   modal mesh bowl --radius 0.06 --thickness 0.004 --h 0.006 --order 2 -o bowl.msh && modal precompute bowl.msh --material glass -o bowl.bank --no-cache
# Then: cargo run -p modal-radiation --example pareto -- docs/radiation-pareto.png DIR/bar_full.json DIR/bar_full.err \
#         DIR/bar_k2.json DIR/bar_k2.err "κ = 2" DIR/bar_k1.json DIR/bar_k1.err "κ = 1" …
set -euo pipefail
cd "${1:-.}"
# 12 points on the sphere of twice the bar's bounding radius (0.30 m) about its centre of mass.
P=$(awk 'BEGIN { for (i = 0; i < 12; i++) { t = 0.15 + 0.25 * i; f = 1.1 * i;
  printf "--point %.6f,%.6f,%.6f ", 0.15 + 0.3 * sin(t) * cos(f), 0.01 + 0.3 * sin(t) * sin(f), 0.006 + 0.3 * cos(t) } }')
M="--mode 0 --mode 1 --mode 2 --mode 3 --mode 4 --mode 8"
for k in 2 1 0.5 0.35 0.3; do
  /usr/bin/time -f "%e s %M KB" modal radiation bar.bank $M $P --cluster-kh $k --json > bar_k$k.json 2> bar_k$k.err
done
/usr/bin/time -f "%e s %M KB" modal radiation bar.bank $M $P --full-resolution --json > bar_full.json 2> bar_full.err
/usr/bin/time -f "%e s %M KB" modal radiation bowl.bank --max-freq 3000 --point 0.2,0.2,0.2 --json > bowl3k.json 2> bowl3k.err
