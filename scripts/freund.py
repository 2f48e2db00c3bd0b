#!/usr/bin/python3
"""Equation of motion of a mode-I crack (Freund 1990): G_c = g(v) G*(t, l), g(v) ~ 1 - v/c_R,
for the semi-infinite crack with a suddenly applied face pressure p on the original faces x < 0
(scripts/crack_case.py). G*(t, 0) = K(t)^2 / E', K(t) = 2 p sqrt(c_d t (1-2nu)/pi)/(1-nu).
For a tip at l > 0 (new faces unloaded) the static analogue of the loaded length,
L = (1-2nu) c_d t / (2 (1-nu)^2) (same K), gives K*(t, l) = K(t) (sqrt(L + l) - sqrt(l)) / sqrt(L)
(an approximation: the loads near the tip act quasi-statically).
usage: freund.py [--p P] [--gc GC] [--t0 T_START] [--noface]   prints l(t)"""
import argparse, math
ap = argparse.ArgumentParser()
ap.add_argument("--p", type=float, default=6e6); ap.add_argument("--gc", type=float, default=3.8)
ap.add_argument("--t0", type=float, default=None); ap.add_argument("--end", type=float, default=4e-6)
ap.add_argument("--noface", action="store_true", help="ignore the unloaded new faces")
A = ap.parse_args()
E, nu, rho = 72e9, 0.22, 2440.0
Ep = E / (1 - nu**2); mu = E / (2 * (1 + nu))
cd = math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho); cs = math.sqrt(mu / rho)
# Rayleigh speed: root of (2 - x)^2 - 4 sqrt(1 - x) sqrt(1 - x k^2) = 0, x = (c/cs)^2, k = cs/cd
k2 = (cs / cd) ** 2
lo, hi = 0.5, 0.99
for _ in range(100):
    x = 0.5 * (lo + hi)
    r = (2 - x) ** 2 - 4 * math.sqrt(1 - x) * math.sqrt(1 - x * k2)
    if r > 0: hi = x
    else: lo = x
cR = cs * math.sqrt(0.5 * (lo + hi))
def Gstar(t, l):
    K = 2 * A.p * math.sqrt(cd * t * (1 - 2 * nu) / math.pi) / (1 - nu)
    if not A.noface:
        L = (1 - 2 * nu) * cd * t / (2 * (1 - nu) ** 2)
        K *= (math.sqrt(L + l) - math.sqrt(l)) / math.sqrt(L)
    return K * K / Ep
Kc = math.sqrt(A.gc * Ep)
ti = math.pi * Kc**2 * (1 - nu) ** 2 / (4 * A.p**2 * cd * (1 - 2 * nu))
t = A.t0 if A.t0 else ti
print(f"c_d {cd:.0f} c_s {cs:.0f} c_R {cR:.0f} m/s; t_i(LEFM) {ti*1e6:.3f} us; start {t*1e6:.3f} us")
l, dt = 0.0, 1e-10
out = []
while t < A.end:
    G = Gstar(t, l)
    v = max(0.0, cR * (1 - A.gc / G))
    l += v * dt; t += dt
    out.append((t, l, v, G))
for tt, ll, vv, GG in out[:: max(1, len(out) // 20)] + [out[-1]]:
    print(f"t {tt*1e6:6.3f} us  l {ll*1e3:6.3f} mm  v {vv:7.1f} m/s  G*/Gc {GG/A.gc:5.2f}")
