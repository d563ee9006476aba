#!/usr/bin/env python3
"""Runs `modal precompute --json --no-cache` with two `modal` binaries on every committed
mesh (plus a cantilever, a linear-tet and an ultrasonic-band case) and prints, per case, the
largest relative frequency difference, both max residuals, both inertia checks and both
phase-time totals. For checking that a solver change keeps the answers.

    python3 tools/compare_precompute.py OLD_MODAL NEW_MODAL   (run from the repository root)
"""
import json
import subprocess
import sys

CASES = [
    ("meshes/bar_p1.msh", []),
    ("meshes/bar_p2.msh", []),
    ("meshes/sphere_p1.msh", ["--max-freq", "60000"]),
    ("meshes/bowl.obj", []),
    ("meshes/bell.obj", []),
    ("meshes/mug.obj", []),
    ("meshes/bar.obj", ["--order", "1"]),
    ("meshes/bar_p1.msh", ["--fix-box", "-1,-1,-1,0.001,1,1"]),
    ("meshes/bar_p1.msh", ["--min-freq", "100000", "--max-freq", "140000", "--modes", "40"]),
]


def run(exe, mesh, extra):
    cmd = [exe, "precompute", mesh, "-o", "/tmp/compare_precompute.bank", "--no-cache", "--json",
           "--material", "steel"] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()[-300:]
    d = json.loads(p.stdout)
    freqs = [m["frequency_hz"] for m in d["modes"]]
    worst = max((m["residual"] for m in d["modes"]), default=0.0)
    return (freqs, worst, d["inertia_check"], sum(d["timings_s"].values())), None


def main():
    old, new = sys.argv[1], sys.argv[2]
    for mesh, extra in CASES:
        (a, err_a), (b, err_b) = run(old, mesh, extra), run(new, mesh, extra)
        label = f"{mesh} {' '.join(extra)}".strip()
        if a is None or b is None:
            print(f"{label}: failed: {err_a or ''} {err_b or ''}")
            continue
        diff = max((abs(x - y) / y for x, y in zip(a[0], b[0])), default=0.0)
        print(f"{label}: modes {len(a[0])}/{len(b[0])} max rel diff {diff:.1e} "
              f"res {a[1]:.1e}/{b[1]:.1e} inertia {a[2]}/{b[2]} time {a[3]:.2f}/{b[3]:.2f} s")


if __name__ == "__main__":
    main()
