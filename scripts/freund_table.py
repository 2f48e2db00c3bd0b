#!/usr/bin/python3
"""Freund's equation of motion with the measured K*(t, l) of stationary cracks (elastic runs
el_L.h5 of crack_case.py --st 0 --ext L, K from the opening: k_cod.py), and the comparison with
crack runs: G at the running tip, g(v) G*(t, l(t)), vs the dissipated G_c.
usage: freund_table.py --ref el_0.h5:0 el_0.5.h5:0.5e-3 ... --runs run.h5 ... [--t0 T]"""
import argparse, subprocess, math, json, h5py, numpy as np, sys, os
ap = argparse.ArgumentParser()
ap.add_argument("--ref", nargs="+", required=True); ap.add_argument("--runs", nargs="*", default=[])
ap.add_argument("--gc", type=float, default=3.8); ap.add_argument("--t0", type=float, default=None)
ap.add_argument("--end", type=float, default=4e-6)
ap.add_argument("--pscale", type=float, default=1.0, help="load of the runs / load of the references (K is linear in p)")
A = ap.parse_args()
E, nu, rho = 72e9, 0.22, 2440.0
Ep = E / (1 - nu**2)
cR = 3180.0
here = os.path.dirname(os.path.abspath(__file__))
ls, Ks, ts = [], [], None
for spec in A.ref:
    path, l = spec.split(":")
    out = subprocess.run([sys.executable, f"{here}/k_cod.py", path, "--rmin", "0.1e-3", "--rmax", "0.4e-3"],
                         capture_output=True, text=True).stdout.splitlines()[1:]
    t = np.array([float(s.split()[1]) for s in out]) * 1e-6
    K = np.array([float(s.split()[4]) for s in out]) * 1e6
    ls.append(float(l)); Ks.append(np.maximum(K, 0) * A.pscale); ts = t
ls = np.array(ls); Ks = np.array(Ks)
def Gstar(t, l):
    Kl = np.array([np.interp(t, ts, K) for K in Ks])
    return float(np.interp(l, ls, Kl)) ** 2 / Ep
# initiation time: G*(t, 0) = G_c
tt = np.linspace(ts[0], ts[-1], 2000)
ti = next(x for x in tt if Gstar(x, 0) >= A.gc)
def integrate(t0):
    t, l, dt, res = t0, 0.0, 1e-10, []
    while t < A.end:
        G = Gstar(t, l); v = max(0.0, cR * (1 - A.gc / G)); l += v * dt; t += dt; res.append((t, l, v))
    return res
print(f"G*(t,0) = G_c at t_i = {ti*1e6:.3f} us")
for t0 in [ti] + ([A.t0] if A.t0 else []):
    res = integrate(t0)
    print(f"Freund from {t0*1e6:.3f} us: " + "  ".join(f"t {r[0]*1e6:.1f} l {r[1]*1e3:.3f} v {r[2]:.0f}" for r in res[::len(res)//6]) + f"  end l {res[-1][1]*1e3:.3f} mm v {res[-1][2]:.0f}")
def summary(path):
    subprocess.run([sys.executable, f"{here}/crack_tip.py", path, "--quiet", "--json", "/tmp/ct.json"], capture_output=True, text=True)
    return json.load(open("/tmp/ct.json"))
print("run                      h(mm)  soft(us) broken(us) vs t_i  G_diss  a_E(3us) a_E(4us) tip(4us) pz(4us) | v_E 3-4us  G*(3.5)/Gc  g(v)G*/Gc | Freund a(4us) from t_i")
res_i = integrate(ti)
aF4 = res_i[-1][1]
for path in A.runs:
    d = summary(path)
    rows = d["rows"]
    t = np.array([r["t"] for r in rows]); aE = np.array([r["fracture"] for r in rows]) / A.gc
    tip = np.array([r["tip"] for r in rows]); pz = np.array([r["pz"] for r in rows])
    t1, t2 = A.end - 1e-6, A.end
    a3, a35, a4 = (np.interp(x, t, aE) for x in (t1, 0.5 * (t1 + t2), t2))
    vE = (a4 - a3) / (t2 - t1)
    Gs = Gstar(0.5 * (t1 + t2), a35)
    tst = d["t_start"] if d["t_start"] is not None else float("nan")
    print(f"{os.path.basename(path):24s} {d['h']*1e3:5.3f} {(d['t_soft'] or float('nan'))*1e6:8.2f} {tst*1e6:9.2f}  {100*(tst/ti-1):+4.0f}%  {d.get('G_dissipated', float('nan')):6.2f}"
          f"  {a3*1e3:7.3f}  {a4*1e3:7.3f}  {tip[-1]*1e3:7.3f} {pz[-1]*1e3:7.3f} | {vE:7.0f}  {Gs/A.gc:9.2f}  {Gs*(1-vE/cR)/A.gc:9.2f} | {aF4*1e3:.3f}")
