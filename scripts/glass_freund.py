#!/usr/bin/python3
"""The glass plate's crack (cases/validation/ha_bobaru_plate.toml) against Freund's equation of
motion before the reflected waves return (docs/validation.md, "Before the reflected waves
return"). The edge tractions p meet on the crack's plane at t0 = 20 mm / c as a suddenly applied
2p on the faces, K*(t) = 2 (2p) sqrt(c (t - t0)(1 - 2 nu')/pi)/(1 - nu') (plane stress: nu' =
nu/(1 + nu), c = sqrt(E/(rho (1 - nu^2)))), and G_c = (1 - v/c_R) K*^2/E gives
l(t) = c_R ((tau - tau_i) - tau_i ln(tau/tau_i)), tau = t - t0, until about 10.4 us.
  glass_freund.py RUN.h5 ...            fracta runs: traced length and a_E = fracture energy / G_c
  glass_freund.py --reference R.json    scripts/pd_branching.py results: their traced length
  glass_freund.py --stationary E.h5     an elastic run (tensile_strength 1e11, fracture_energy
                                        1e6): K* from the opening behind the tip against the formula
Options: --load P (2e6), --tip X (50e-3 m, for --stationary)."""
import argparse, json, math, os, subprocess, sys, tempfile
import h5py, numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("runs", nargs="*")
ap.add_argument("--reference", nargs="*", default=[])
ap.add_argument("--stationary", nargs="*", default=[])
ap.add_argument("--load", type=float, default=2e6)
ap.add_argument("--tip", type=float, default=50e-3)
A = ap.parse_args()
E, nu, rho, gc, thickness = 72e9, 1.0 / 3.0, 2440.0, 3.8, 1e-3
nu_p = nu / (1 + nu)
c = math.sqrt(E / (rho * (1 - nu * nu)))
cs = math.sqrt(E / (2 * (1 + nu)) / rho)
c_r = (0.862 + 1.14 * nu_p) / (1 + nu_p) * cs  # Viktorov's approximation, as tests/test_util.hpp
t0, sigma = 20e-3 / c, 2 * A.load
tau_i = math.pi * E * gc * (1 - nu_p) ** 2 / (4 * sigma**2 * c * (1 - 2 * nu_p))


def k_star(t):
    return 0.0 if t <= t0 else 2 * sigma * math.sqrt(c * (t - t0) * (1 - 2 * nu_p) / math.pi) / (1 - nu_p)


def freund(t):
    tau = t - t0
    return 0.0 if tau <= tau_i else c_r * ((tau - tau_i) - tau_i * math.log(tau / tau_i))


times = [6e-6, 7e-6, 8e-6, 9e-6, 10e-6, 11e-6, 12e-6]
print(f"c {c:.0f} m/s, c_R {c_r:.0f} m/s, waves meet at {t0*1e6:.2f} us, G* = G_c at {(t0+tau_i)*1e6:.2f} us")
print("t (us)      " + " ".join(f"{t*1e6:6.1f}" for t in times))
print("Freund (mm) " + " ".join(f"{freund(t)*1e3:6.2f}" for t in times) + "   (exact to about 10.4 us)")
here = os.path.dirname(os.path.abspath(__file__))
for path in A.runs:
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([sys.executable, f"{here}/cracks.py", path, "--seed", "0.05", "0.0201", "--json", out.name],
                       check=True, capture_output=True)
        traced = {round(r["t"] * 1e6, 1): r["length"] for r in json.load(open(out.name))}
    f = h5py.File(path, "r")
    th, fracture = f["history/time"][:], f["history/energy/fracture"][:]
    print(f"{os.path.basename(path)}:")
    print("  traced     " + " ".join(f"{traced.get(round(t*1e6, 1), float('nan'))*1e3:6.2f}" for t in times))
    print("  a_E        " + " ".join(f"{np.interp(t, th, fracture)/(gc*thickness)*1e3:6.2f}" for t in times))
for path in A.reference:
    hist = {round(t, 1): l for t, l in json.load(open(path))["history"]}  # us, mm
    print(f"{os.path.basename(path)}:")
    print("  traced     " + " ".join(f"{hist.get(round(t*1e6, 1), float('nan')):6.2f}" for t in times))
for path in A.stationary:
    # K* from the opening of the rows beside the cut (y = 20 mm and 20 mm + h) behind the tip
    # (scripts/k_cod.py, plane stress: E' = E).
    out = subprocess.run([sys.executable, f"{here}/k_cod.py", path, "--y0", "20e-3", "--a", str(A.tip),
                          "--rmin", "0.4e-3", "--rmax", "2e-3", "--modulus", str(E)],
                         check=True, capture_output=True, text=True).stdout.splitlines()[1:]
    print(f"{os.path.basename(path)}: K* (MPa m^0.5) from the opening, and the formula")
    for line in out:
        t, K = float(line.split()[1]) * 1e-6, float(line.split()[4])
        if t >= 4e-6: print(f"  {t*1e6:6.2f} us  {K:6.3f}  {k_star(t)/1e6:6.3f}")
