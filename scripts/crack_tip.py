#!/usr/bin/python3
"""Crack-tip history of a run of scripts/crack_case.py (or any straight crack along y = const).

Crack-plane bonds: bonds whose two reference nodes lie on the two node lines y0 and y0 + h
(edges crossing the plane and diagonals), ahead of the pre-crack tip x = a.  Per frame: the
broken tip (largest x of a broken crack-plane bond, x of its node midpoint), the process-zone tip
(largest x with damage > 0), off-plane bonds with damage > 0 / broken, and from /history the
fracture energy.  Prints a table and the fracture energy per unit of crack advance
(dissipated energy per unit area, thickness 1 m) over the running phase.
usage: crack_tip.py OUT.h5 [--y0 Y] [--a A] [--json out.json]
"""
import argparse, json, h5py, numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("h5")
ap.add_argument("--y0", type=float, default=12e-3)
ap.add_argument("--a", type=float, default=16e-3)
ap.add_argument("--json")
ap.add_argument("--quiet", action="store_true")
A = ap.parse_args()
f = h5py.File(A.h5, "r")
n = int(f["frames"].attrs["count"])
f0 = f["frames/0"]
X0 = f0["node_position"][:]
bn = f0["bond_nodes"][:]
yi, yj = X0[bn[:, 0], 1], X0[bn[:, 1], 1]
ylo, yhi = np.minimum(yi, yj), np.maximum(yi, yj)
h = np.min(np.abs(np.diff(np.unique(np.round(X0[:, 0], 9)))))
tol = 0.25 * h
plane = (np.abs(ylo - A.y0) < tol) & (np.abs(yhi - (A.y0 + h)) < tol)
xm = 0.5 * (X0[bn[:, 0], 0] + X0[bn[:, 1], 0])
dx = np.abs(X0[bn[:, 0], 0] - X0[bn[:, 1], 0])
vert = plane & (dx < tol)
t_h = f["history/time"][:]
ef = f["history/energy/fracture"][:]
ek = f["history/energy/kinetic"][:]
ei = f["history/energy/internal"][:]
ex = f["history/energy/external"][:]
rows = []
for k in range(n):
    fr = f[f"frames/{k}"]
    t = float(fr["time"][()])
    st = fr["bond_state"][:]
    d = fr["bond_damage"][:]
    broken = st == 2
    tip_b = xm[vert & broken].max() if np.any(vert & broken) else A.a
    tip_pz = xm[plane & (d > 0)].max() if np.any(plane & (d > 0)) else A.a
    off_soft = int(np.sum(~plane & (d > 0) & ~broken))
    off_broken = int(np.sum(~plane & broken))
    pz_soft = int(np.sum(plane & (d > 0) & ~broken))
    # broken crack-plane verticals must be contiguous: count them
    nvb = int(np.sum(vert & broken))
    efk = float(np.interp(t, t_h, ef))
    rows.append(dict(t=t, tip=tip_b - A.a, pz=tip_pz - A.a, nvb=nvb, pz_soft=pz_soft,
                     off_soft=off_soft, off_broken=off_broken, fracture=efk,
                     kinetic=float(np.interp(t, t_h, ek)), internal=float(np.interp(t, t_h, ei)),
                     external=float(np.interp(t, t_h, ex))))
if not A.quiet:
    print(f"h = {h*1e3:.4g} mm; crack-plane bonds {plane.sum()}, verticals {vert.sum()}")
    print(" t(us)  tip(mm) pz(mm) nbroken pz_soft off_soft off_brk  fracture(J/m) kinetic  external")
    for r in rows:
        print(f"{r['t']*1e6:6.2f} {r['tip']*1e3:7.3f} {r['pz']*1e3:6.3f} {r['nvb']:7d} {r['pz_soft']:7d}"
              f" {r['off_soft']:8d} {r['off_broken']:7d} {r['fracture']:12.5g} {r['kinetic']:9.4g} {r['external']:9.4g}")
# initiation: first frame with a broken crack-plane vertical; and first softening
t_start = next((r["t"] for r in rows if r["nvb"] > 0), None)
t_soft = next((r["t"] for r in rows if r["pz"] > 0 or r["pz_soft"] > 0), None)
out = dict(h=h, t_start=t_start, t_soft=t_soft, rows=rows)
# dissipation per unit area during running: fit fracture energy vs tip over frames with tip > 2h
run = [r for r in rows if r["tip"] > 2 * h]
if len(run) >= 3:
    a_ = np.array([r["tip"] for r in run]); e_ = np.array([r["fracture"] for r in run])
    slope = np.polyfit(a_, e_, 1)[0]
    out["G_dissipated"] = slope
    print(f"start (first broken) {t_start*1e6:.3f} us, first softening {t_soft*1e6:.3f} us;"
          f" dE_fracture/da over tip>{2*h*1e3:.2f} mm: {slope:.3f} J/m^2")
    # the whole: fracture energy / (tip + something)
    r = rows[-1]
    out["E_over_a_end"] = r["fracture"] / r["tip"] if r["tip"] > 0 else None
    print(f"end: tip {r['tip']*1e3:.3f} mm, fracture {r['fracture']:.4g} J/m -> {r['fracture']/max(r['tip'],1e-12):.3f} J/m^2 (incl. process zone)")
if A.json:
    # Frames may store float32 (docs/output.md); JSON takes Python numbers.
    json.dump(out, open(A.json, "w"), indent=1,
              default=lambda x: x.item() if isinstance(x, np.generic) else x.tolist())
