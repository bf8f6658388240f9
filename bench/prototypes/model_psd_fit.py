#!/usr/bin/python3
"""Prototype (not in the core yet): the conicity of a bogie from its axle-box acceleration by a fit of the spectrum
its model predicts at the sensor, instead of the identification's pole pairs (docs/VEHICLES.md, issue #28).

The linearised bogie (bogie.h's equations, written again as test/cli/test_cli.py's bogie_matrix) driven by the track
at both wheelsets (the trailing one 2b / v later) through their lambda y terms; the track's alignment spectrum the
German low-disturbance one (excitation.c's); the predicted acceleration spectrum a |H(w; lambda)|^2 S(w / v) / v + n,
its amplitude a and noise floor n profiled out, compared with the recording's Welch spectrum by the Whittle
likelihood over 6-22 Hz, at a grid of conicities.

usage: model_psd_fit.py ACCEL.csv SPEED_KMH [SAMPLE_RATE_HZ]   (a steady-speed recording of hunting simulate
       --config config/bogie_default.yaml --sensor axlebox)
Measured (2026-12-03, conicity 0.1358, irregularity 0.3): 200 s at 440 km/h: the likelihood's minimum at 0.1358
(-2 log L: 0.13 +8.9, 0.14 +25.3, 0.12 +135, 0.15 +208), where the pole-pair identification reads -1.9..-3.0 1/s for
the true -5.95 and so the conicity 0.170; 110 s at 500 km/h: its minimum at 0.13 of the grid (0.1358 +21), the
pole pairs' windows 0.124-0.137. Not yet: a track spectrum of another shape than the simulator's (its exponent to be
fitted), overlapping Welch segments counted as independent (the error is understated by about 1.5x), a finer grid.
"""
import importlib.util
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("t", os.path.join(HERE, "..", "..", "test", "cli", "test_cli.py"))
sys.argv = [sys.argv[0], "", ""] + sys.argv[1:]
t = importlib.util.module_from_spec(spec)
spec.loader.exec_module(t)
args = sys.argv[3:]
x = np.loadtxt(args[0], delimiter=",", skiprows=1)[:, 1]
v = float(args[1]) / 3.6
fs = float(args[2]) if len(args) > 2 else 500.0


def welch(sig, n=4096):
    w = np.hanning(n)
    segs = [np.abs(np.fft.rfft((sig[i:i + n] - sig[i:i + n].mean()) * w)) ** 2 for i in range(0, len(sig) - n, n // 2)]
    return np.fft.rfftfreq(n, 1 / fs), np.mean(segs, axis=0) / (fs * (w ** 2).sum()), len(segs)


f, P, K = welch(x[int(10 * fs):])
band = (f > 6) & (f < 22)
f, P = f[band], P[band]
AA, OC, OR = 2.119e-7, 0.8246, 0.0206


def shape(lam):
    A = t.bogie_matrix(v, lam)
    b = 2 * 7.99e6 * 0.7465 * lam / (910.0 * 0.43)
    B1, B2 = np.zeros(13), np.zeros(13)
    B1[3], B2[7] = b, b
    tau = 2 * 1.25 / v
    out = []
    for ff in f:
        w = 2 * math.pi * ff
        om = w / v
        s = AA * OC ** 2 / ((om ** 2 + OR ** 2) * (om ** 2 + OC ** 2)) / v
        X = np.linalg.solve(1j * w * np.eye(13) - A, B1 + B2 * np.exp(-1j * w * tau))
        out.append(abs(1j * w * X[1]) ** 2 * s)
    return np.array(out)


def neg2loglik(lam):
    g, best = shape(lam), float("inf")
    for n in np.geomspace(P.min() * 0.01, P.max() * 0.5, 30):
        a = max((P - n).mean() / g.mean(), 1e-30)
        for _ in range(30):  # Newton on the amplitude
            m = a * g + n
            grad, hess = np.sum(g / m - P * g / m ** 2), np.sum(-g ** 2 / m ** 2 + 2 * P * g ** 2 / m ** 3)
            a = max(a - grad / hess, 1e-30) if hess > 0 else 0.5 * a
        m = a * g + n
        best = min(best, np.sum(P / m + np.log(m)))
    return 2 * K * best


grid = [0.10, 0.12, 0.13, 0.1358, 0.14, 0.15, 0.17, 0.20]
vals = [neg2loglik(lam) for lam in grid]
lo = min(vals)
for lam, val in zip(grid, vals):
    print(f"conicity {lam:.4f}: -2 log L {val - lo:+.1f}")
