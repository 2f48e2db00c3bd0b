#!/usr/bin/python3
"""K_I(t) of a stationary crack from the crack opening behind the tip,
delta = 8 K sqrt(r / 2 pi) / E' (E' = E / (1 - nu^2) in plane strain, E in plane stress: --modulus),
delta/sqrt(r) = C + D r fitted over [rmin, rmax].
The opening is measured between the face node lines (y0, y0 + h) less h.
usage: k_cod.py OUT.h5 ... [--rmin --rmax --y0 --a --modulus]"""
import argparse, h5py, numpy as np, math
ap = argparse.ArgumentParser()
ap.add_argument("h5", nargs="+"); ap.add_argument("--y0", type=float, default=12e-3)
ap.add_argument("--a", type=float, default=16e-3)
ap.add_argument("--rmin", type=float, default=0.1e-3); ap.add_argument("--rmax", type=float, default=0.4e-3)
ap.add_argument("--every", type=int, default=1)
ap.add_argument("--modulus", type=float, default=None, help="E' (Pa); default the plane-strain glass of crack_case.py")
A = ap.parse_args()
E, nu, rho = 72e9, 0.22, 2440.0
Ep = A.modulus or E / (1 - nu**2)
cd = math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)
for path in A.h5:
    f = h5py.File(path, "r")
    X0 = f["frames/0/node_position"][:]
    h = np.min(np.abs(np.diff(np.unique(np.round(X0[:, 0], 9)))))
    key = {(int(round(x / h)), int(round(y / h))): k for k, (x, y) in enumerate(X0)}
    j0 = int(round(A.y0 / h))
    bn = f["frames/0/bond_nodes"][:]
    bs = set(map(tuple, np.sort(bn, axis=1).tolist()))
    i = int(round(A.a / h))
    while True:
        p, q = key[(i, j0)], key[(i, j0 + 1)]
        if (min(p, q), max(p, q)) in bs: break
        i += 1
    n = int(f["frames"].attrs["count"])
    print(f"{path}: h {h*1e3:.3g} mm, tip at x-a = {(i*h - A.a)*1e3:.3f} mm")
    for k in range(1, n, A.every):
        # Openings from displacements, not positions: float32 frames keep 7 digits of each.
        fr = f[f"frames/{k}"]; U = fr["node_displacement"][:]; t = float(fr["time"][()])
        rs, cs = [], []
        for m in range(1, int(A.rmax / h) + 1):
            r = m * h
            if r < A.rmin: continue
            dl = U[key[(i - m, j0 + 1)], 1] - U[key[(i - m, j0)], 1]
            rs.append(r); cs.append(dl / math.sqrt(r))
        C, D = np.polyfit(rs, cs, 1)[::-1] if len(rs) > 2 else (np.mean(cs), 0)
        K = C * Ep * math.sqrt(2 * math.pi) / 8
        Kan = 2 * 6e6 * math.sqrt(cd * t * (1 - 2 * nu) / math.pi) / (1 - nu)
        print(f"  t {t*1e6:5.2f} us  K {K/1e6:6.3f} (l=0 analytic {Kan/1e6:6.3f})  G/Gc {K*K/Ep/3.8:5.2f}")
