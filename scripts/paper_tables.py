#!/usr/bin/env python3
"""The paper's Tables 1 and 2 (Section 4.1) beside fracta's results for cases A and B.

Runs cases/plate_case_a.toml and cases/plate_case_b.toml (a second each) unless output files are
given, then prints, for probes a-e: the plateau particle velocity (mean over the middle of the
3 us pulse), the peak compressive stress, and the wave speed per domain, against both the
paper's 1D bar theory values (5453.8 m/s, 11.7537 m/s, 500 MPa) and the exact plane-wave values
of our formulation (plane stress, eps_yy = 0 on the centre line: c = sqrt(E/(rho(1-nu^2))),
v = p/(rho c)).

Usage: /usr/bin/python3 scripts/paper_tables.py [--fracta build/fracta] [--a A.h5 --b B.h5]
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile
import tomllib

import h5py
import numpy as np

E, NU, RHO, P = 232e9, 0.3, 7800.0, 500e6
C_BAR, V_BAR = math.sqrt(E / RHO), P / (RHO * math.sqrt(E / RHO))
C_PLANE = math.sqrt(E / (RHO * (1 - NU * NU)))
V_PLANE = P / (RHO * C_PLANE)
PAPER_V = {"a": 11.3793, "b": 11.4294, "c": 11.4153, "d": 11.5396, "e": 11.6750}
PAPER_S = {"a": 509.92, "b": 523.70, "c": 518.44, "d": 549.84, "e": 532.54}
PAPER_C = {"FEM in case A": 5387.9, "DEM in case A": 5296.6, "FEM in case B": 5506.7,
           "DEM in case B": 5494.0}


def run(fracta, case, out):
    subprocess.run([fracta, "run", case, "-o", out], check=True, stdout=subprocess.DEVNULL)


def probe(f, name):
    g = f["probes"][name]
    return g["time"][:], g["vx"][:], g["sxx"][:]


def arrival(t, v):
    """Time of the first half-amplitude crossing of the plane-wave particle velocity."""
    half = 0.5 * V_PLANE
    i = np.argmax(v >= half)
    if v[i] < half:
        return float("nan")
    return t[i - 1] + (half - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1])


def probe_x(case_text, name):
    for p in tomllib.loads(case_text)["probe"]:
        if p["name"] == name:
            return float(p["at"][0])
    raise KeyError(name)


def main():
    ap = argparse.ArgumentParser()
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    ap.add_argument("--fracta", default=os.path.join(root, "build", "fracta"))
    ap.add_argument("--a")
    ap.add_argument("--b")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()
    a = args.a or os.path.join(tmp, "a.h5")
    b = args.b or os.path.join(tmp, "b.h5")
    if not args.a:
        run(args.fracta, os.path.join(root, "cases", "plate_case_a.toml"), a)
    if not args.b:
        run(args.fracta, os.path.join(root, "cases", "plate_case_b.toml"), b)
    rows, arrivals = {}, {}
    for path, names in ((a, ["a", "a2", "b", "b2"]), (b, ["c1", "c", "d", "e"])):
        with h5py.File(path, "r") as f:
            text = f["run"].attrs["case"]
            text = text.decode() if isinstance(text, bytes) else text
            for n in names:
                t, v, s = probe(f, n)
                ta = arrival(t, v)
                window = (t > ta + 0.75e-6) & (t < ta + 2.25e-6)  # middle of the 3 us pulse
                rows[n] = (float(np.mean(v[window])), float(-np.min(s)) / 1e6,
                           float(-np.mean(s[window])) / 1e6)
                arrivals[n] = (probe_x(text, n), ta)

    print("Table 1: particle velocity (m/s) and peak stress (MPa) at probes a-e")
    print(f"  exact plane wave: v = {V_PLANE:.4f} m/s, stress {P/1e6:.0f} MPa;"
          f" paper's 1D theory: v = {V_BAR:.4f} m/s")
    print("  (v: mean over the middle of the pulse; peak: largest compressive stress, incl. the")
    print("   front's overshoot; plateau: mean stress over the same window)")
    print(f"  {'probe':<6}{'fracta v':>10}{'paper v':>10}{'err vs plane':>14}{'err vs 1D':>11}"
          f"{'peak s':>9}{'paper s':>9}{'err':>9}{'plateau s':>11}{'err':>8}")
    for n in "abcde":
        v, s, sp = rows[n]
        print(f"  {n:<6}{v:>10.4f}{PAPER_V[n]:>10.4f}{100*(v/V_PLANE-1):>13.2f}%"
              f"{100*(v/V_BAR-1):>10.2f}%{s:>9.1f}{PAPER_S[n]:>9.2f}{100*(s/500-1):>8.2f}%"
              f"{sp:>11.1f}{100*(sp/500-1):>7.2f}%")

    def speed(p, q):
        (xp, tp), (xq, tq) = arrivals[p], arrivals[q]
        return (xq - xp) / (tq - tp)

    # Speed between two probes of the same domain (arrival at half the plateau velocity).
    speeds = {
        "FEM in case A": speed("a", "a2"),
        "DEM in case A": speed("b", "b2"),
        "FEM in case B": speed("c1", "c"),
        "DEM in case B": speed("d", "e"),
    }
    print()
    print(f"Table 2: wave speed (m/s); exact plane wave {C_PLANE:.1f}, paper's 1D theory {C_BAR:.1f}")
    print(f"  {'domain':<15}{'fracta':>9}{'paper':>9}{'err vs plane':>14}{'err vs 1D':>11}")
    for k, c in speeds.items():
        print(f"  {k:<15}{c:>9.1f}{PAPER_C[k]:>9.1f}{100*(c/C_PLANE-1):>13.2f}%"
              f"{100*(c/C_BAR-1):>10.2f}%")
    return 0


if __name__ == "__main__":
    sys.exit(main())
