"""Fits the Faust model's impulse responses (s<p>.raw) with damped sinusoids at the
frequencies and decay rates the model file states, and compares each mode's amplitude
with 2 g / nModes: pm.modeFilter is g (1 - z^-2) / (1 + a1 z^-1 + a2 z^-2) with poles
r e^(+-iw), whose impulse response is 2 g r^n cos(w n) up to O(1 - r) (exactly so from the
third sample when r = 1). Prints the fit residual and the amplitude ratios."""
import math, re, sys
import numpy as np

lib = open(sys.argv[1]).read()
n_ex = int(sys.argv[2])
take = lambda key: [float(v) for v in re.search(re.escape(key) + r"\(([^)]*)\)", lib).group(1).split(",")]
f = np.array(take("modesFreqs(n) = ba.take(n+1,"))
t60 = np.array(take("modesT60s(n) = t60Scale*ba.take(n+1,"))
g = np.array([float(v) for v in re.search(r"waveform\{([^}]*)\}", lib).group(1).split(",")]).reshape(n_ex, len(f))
fs = 48000.0
d = math.log(1000) / t60
t = np.arange(48000) / fs
basis = []
for fi, di in zip(f, d):
    e = np.exp(-di * t)
    basis += [e * np.cos(2 * np.pi * fi * t), e * np.sin(2 * np.pi * fi * t)]
A = np.array(basis).T[2:]  # the 1 - z^-2 numerator: exact damped sinusoids from the third sample
for p in range(n_ex):
    y = np.fromfile(f"s{p}.raw", dtype=np.float32).astype(float)[2:]
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    amp = np.hypot(c[0::2], c[1::2])
    resid = np.linalg.norm(y - A @ c) / np.linalg.norm(y)
    big = g[p] > 0.01
    ratio = amp[big] / (2 * g[p][big] / len(f))
    print(f"exPos {p}: fit residual {resid:.2e}; {big.sum()} modes with gain > 0.01, "
          f"amplitude / (2 g / nModes) in [{ratio.min():.4f}, {ratio.max():.4f}]")
