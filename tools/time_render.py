"""Times `modal render --json` N times on cached banks: min/median process wall and stage medians.

Usage: python tools/time_render.py path/to/modal N   (cache dir /tmp/dc3, output /tmp/demo_cached.wav)
Benchmark helper only (BENCHMARKS.md, demo); the tests never run it.
"""
import json, subprocess, sys, time, statistics, os
b, n = sys.argv[1], int(sys.argv[2])
walls, stages = [], []
for i in range(n):
    t0 = time.perf_counter()
    out = subprocess.run([b, 'render', '--json', '--cache-dir', '/tmp/dc3', '-o', '/tmp/demo_cached.wav'], capture_output=True, check=True).stdout
    walls.append(time.perf_counter() - t0)
    stages.append(json.loads(out))
walls.sort()
print(f"n={n} wall min {walls[0]*1e3:.1f} ms, median {statistics.median(walls)*1e3:.1f} ms, max {walls[-1]*1e3:.1f} ms; x real time (4 s / median) {4/statistics.median(walls):.0f}, best {4/walls[0]:.0f}")
for k in ['banks_s','colliders_s','physics_s','excitation_s','synthesis_s','mix_s']:
    v = sorted(s[k] for s in stages)
    print(f"  {k}: median {statistics.median(v)*1e3:.1f} ms")
print("load", os.getloadavg())
