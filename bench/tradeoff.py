#!/usr/bin/env python3
"""The speed-accuracy trade, measured. Runs `fracta run` over a grid of
settings (one thread: the accuracy numbers are then bitwise reproducible, atomics add in a fixed
order), reads the HDF5 output and writes, per study, a CSV and a Pareto plot (error against wall
time) into the results directory.

(a) plate: the paper's plate (Section 4.1; cases/plate_fe.toml, plate_case_a.toml,
    plate_case_b.toml), cell size x method (fe, de, case A, case B) x dt_safety (0.3, 0.6, 0.9),
    run to 8 us (the pulse has passed the last probe at 22.5 mm before the reflection from the
    free edge comes back). Errors against the exact plane wave of the plane-stress plate:
      wave speed   c = sqrt(E / (rho (1 - nu^2))) = 5717 m/s, from the half-plateau arrival
                   times at two probes of the same domain (fe, de: 7.5 -> 22.5 mm; case A: each
                   half, 7.5 -> 22.5 mm; case B: 3.75 -> 7.5 mm in FE and 15 -> 22.5 mm in DE);
      plateau      v = p / (rho c) = 11.21 m/s, mean particle velocity over the middle 1.5 us
                   of the 3 us pulse at each probe;
      peak stress  500 MPa, the largest compressive sxx at each probe (includes the front's
                   overshoot, which is what a user reading peak stress sees);
    each error is the largest relative error over the case's probes (and domains).
(b) penetration: cases/penetration.toml (80 us, the projectile still moving at the end), cell
    size x concrete conversion_strain x hourglass form (viscous, stiffness). Reported: depth
    (downward displacement of the projectile's centre of mass, less the 2 mm initial gap),
    residual velocity (projectile's mass-averaged downward velocity at the end), converted
    elements, largest relative energy error over the run; depth and velocity errors are
    relative to the reference run: the finest cell size with the case's own settings
    (conversion_strain 0.02, viscous hourglass control).
    Then the impact speed: the same scene to 40 us with the projectile at 50 m/s to 10 km/s, at
    the case's cells and half of them. Reported: steps, wall time, the smallest step over the
    initial one, the largest relative energy error, the converted elements and the projectile's
    elements left: where the method holds, and what the fast impacts cost.

(c) fragmentation: cases/validation/bar_fragmentation_e10.toml (a ceramic bar at a uniform
    strain rate, eps_dot / eps_dot_0 = 10, to 10 t0), cell size x seed of the strength scatter.
    Reported per cell size: the mean fragment size (bar length / fragments) over the first n
    seeds for n = 1..4, the spread of the seeds (standard deviation), the standard error of the
    mean, the ratio to the Zhou-Molinari-Ramesh fit 4.5 L0 / (1 + 4.5 e^(2/3)) = 62.8 um and the
    wall time per seed: what an ensemble and a finer lattice buy and cost.

(d) crackpath: cases/validation/kalthoff_winkler_turned.toml (the Kalthoff-Winkler plate turned
    30 degrees against a perturbed lattice, node_perturbation 0.15), cell size (1, 0.5 mm) x
    seed. Each crack's angle to the notch line (the line through its notch tip fitted to its path
    5 to 25 mm from the tip, as the test measures). Reported per cell size and number of seeds n:
    the mean angle of the 2n cracks, their spread (standard deviation), the standard error of the
    mean, the distance of the mean from the published 70 degrees and the wall time; with the
    regular lattice's two angles for comparison.

Usage: /usr/bin/python3 bench/tradeoff.py [--fracta build/fracta] [--out bench/results]
                                 [--study plate|penetration|speed|fragmentation|crackpath|crackspeed|all]
                                 [--quick]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmeta import machine_info  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
E, NU, RHO, P = 232e9, 0.3, 7800.0, 500e6
C_PLANE = math.sqrt(E / (RHO * (1 - NU * NU)))
V_PLANE = P / (RHO * C_PLANE)

# Cells must divide the 15 mm and 30 mm region edges and put nodes on the probes.
PLATE_CELLS_MM = [1.875, 1.25, 0.9375, 0.625, 0.46875]
PLATE_METHODS = {
    # name: (case file, overrides, probes, wave-speed probe pairs (x in m))
    "fe": ("plate_fe.toml", ['body.plate.method="fe"'], ["a_x7_5mm", "b_x15mm", "c_x22_5mm"],
           [("a_x7_5mm", "c_x22_5mm")]),
    "de": ("plate_fe.toml", ['body.plate.method="de"'], ["a_x7_5mm", "b_x15mm", "c_x22_5mm"],
           [("a_x7_5mm", "c_x22_5mm")]),
    "case A": ("plate_case_a.toml", [], ["a", "a2", "b", "b2"], [("a", "a2"), ("b", "b2")]),
    "case B": ("plate_case_b.toml", [], ["c1", "c", "d", "e"], [("c1", "c"), ("d", "e")]),
}
DT_SAFETY = [0.3, 0.6, 0.9]

PEN_CELLS_MM = [1.667, 1.111, 0.8333, 0.5556]
PEN_CONVERSION = [0.01, 0.02, 0.05]
PEN_HOURGLASS = ["viscous", "stiffness"]
PEN_END = 80e-6  # s, the case's own end time
PEN_GAP = 0.002  # m, projectile above the slab in the case file
SPEED_MPS = [50, 500, 2000, 5000, 10000]
SPEED_CELLS_MM = [3.333, 1.667]
SPEED_END = 40e-6  # s

FRAG_CASE = "validation/bar_fragmentation_e10.toml"
FRAG_CELLS_UM = [10.0, 5.0, 2.5]
FRAG_SEEDS = [1, 2, 3, 4]
FRAG_LENGTH = 3.75e-3  # m, the bar in the case file
FRAG_ZMR = 62.8e-6  # m, 4.5 L0 / (1 + 4.5 * 10^(2/3)) with L0 = 0.306 mm


def run_fracta(fracta, case, overrides, out):
    cmd = [fracta, "run", os.path.join(ROOT, "cases", case), "-o", out, "--set"] + overrides
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_PROC_BIND="spread", OMP_PLACES="threads")
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    return r.returncode, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""


def attr(f, name):
    v = f["run"].attrs[name]
    return v.decode() if isinstance(v, bytes) else v


def arrival(t, v):
    """Time of the first half-plateau crossing of the particle velocity (linear interpolation)."""
    half = 0.5 * V_PLANE
    i = int(np.argmax(v >= half))
    if v[i] < half or i == 0:
        return float("nan")
    return t[i - 1] + (half - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1])


def probe_x(f, name):
    import tomllib
    for p in tomllib.loads(attr(f, "case"))["probe"]:
        if p["name"] == name:
            return float(p["at"][0])
    raise KeyError(name)


def plate_metrics(path, probes, pairs):
    with h5py.File(path, "r") as f:
        wall = float(f["run"].attrs["wall_seconds"])
        steps = int(f["run"].attrs["steps"])
        err_v, err_s, arr = 0.0, 0.0, {}
        for n in probes:
            g = f["probes"][n]
            t, v, s = g["time"][:], g["vx"][:], g["sxx"][:]
            ta = arrival(t, v)
            arr[n] = (probe_x(f, n), ta)
            window = (t > ta + 0.75e-6) & (t < ta + 2.25e-6)
            plateau = float(np.mean(v[window])) if window.any() else float("nan")
            err_v = max(err_v, abs(plateau / V_PLANE - 1))
            err_s = max(err_s, abs(-float(np.min(s)) / P - 1))
        err_c = 0.0
        for a, b in pairs:
            (xa, ta), (xb, tb) = arr[a], arr[b]
            err_c = max(err_c, abs((xb - xa) / (tb - ta) / C_PLANE - 1))
        energy = float(np.max(np.abs(f["history"]["energy"]["error"][:])))
    return dict(wall_s=wall, steps=steps, err_wave_speed=err_c, err_plateau=err_v,
                err_peak_stress=err_s, energy_error=energy)


def penetration_metrics(path):
    with h5py.File(path, "r") as f:
        wall = float(f["run"].attrs["wall_seconds"])
        steps = int(f["run"].attrs["steps"])
        bp = f["body_probes"]["projectile"]
        y, vy = bp["y"][:], bp["vy"][:]
        h = f["history"]
        elements = h["count"]["elements"][:]
        conv = int(elements[0] - elements[-1])  # converted elements (active count drops)
        energy = float(np.max(np.abs(h["energy"]["error"][:])))
    return dict(wall_s=wall, steps=steps, depth_mm=1e3 * ((y[0] - y[-1]) - PEN_GAP),
                residual_velocity=-float(vy[-1]), conversions=conv, energy_error=energy)


def pareto(points):
    """Indices of the points not dominated in (time, error): no other point is both faster and
    more accurate."""
    keep = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for t2, e2 in points):
            keep.append(i)
    return keep


def plot(rows, err_keys, labels, group_key, title, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(err_keys), figsize=(5.2 * len(err_keys), 4.4))
    groups = sorted({r[group_key] for r in rows})
    markers = "osD^v<>p*"
    coarsest = max(r["cell_mm"] for r in rows)
    size = lambda r: 12 * (coarsest / r["cell_mm"]) ** 1.5  # noqa: E731 (finer cell: larger)
    for ax, key, label in zip(axes, err_keys, labels):
        ok = [r for r in rows if r["status"] == 0 and np.isfinite(r[key])]
        for g, m in zip(groups, markers):
            pts = [r for r in ok if r[group_key] == g]
            ax.scatter([r["wall_s"] for r in pts], [max(r[key], 1e-5) * 100 for r in pts],
                       s=[size(r) for r in pts], marker=m, label=str(g), alpha=0.75)
        front = pareto([(r["wall_s"], r[key]) for r in ok])
        fr = sorted((ok[i] for i in front), key=lambda r: r["wall_s"])
        ax.step([r["wall_s"] for r in fr], [max(r[key], 1e-5) * 100 for r in fr], "k-",
                where="post", lw=1, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s, 1 thread)")
        ax.set_ylabel(label + " error (%)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title + " (marker size grows as the cell size falls)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_csv(rows, fields, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for r in rows:
            w.writerow([f"{r[k]:.6g}" if isinstance(r[k], float) else r[k] for k in fields])


def study_plate(fracta, out, tmp, quick):
    cells = PLATE_CELLS_MM[:2] if quick else PLATE_CELLS_MM
    rows = []
    for h in cells:
        for method, (case, sets, probes, pairs) in PLATE_METHODS.items():
            for a in DT_SAFETY:
                path = os.path.join(tmp, "plate.h5")
                rc, msg = run_fracta(fracta, case, sets + [
                    f"body.plate.cell_size={h * 1e-3:.9g}", f"simulation.dt_safety={a}",
                    "simulation.end_time=8e-6", "simulation.output_interval=1.0",
                    'output.fields=["velocity"]'], path)
                row = dict(cell_mm=h, method=method, dt_safety=a, status=rc, message=msg)
                if rc == 0:
                    row.update(plate_metrics(path, probes, pairs))
                else:
                    row.update(wall_s=float("nan"), steps=0, err_wave_speed=float("nan"),
                               err_plateau=float("nan"), err_peak_stress=float("nan"),
                               energy_error=float("nan"))
                rows.append(row)
                print(f"plate {method:<7} h {h:.4g} mm dt_safety {a}: " +
                      (f"{row['wall_s']:.2f} s, c {100 * row['err_wave_speed']:.2f}%, "
                       f"v {100 * row['err_plateau']:.2f}%, peak {100 * row['err_peak_stress']:.2f}%"
                       if rc == 0 else f"exit {rc}: {msg}"), flush=True)
    fields = ["method", "cell_mm", "dt_safety", "status", "steps", "wall_s", "err_wave_speed",
              "err_plateau", "err_peak_stress", "energy_error", "message"]
    write_csv(rows, fields, os.path.join(out, "tradeoff_plate.csv"))
    plot(rows, ["err_wave_speed", "err_plateau", "err_peak_stress"],
         ["wave speed", "plateau velocity", "peak stress"], "method",
         "Plate wave: error vs exact plane wave against wall time", 
         os.path.join(out, "tradeoff_plate.png"))
    return rows


def study_penetration(fracta, out, tmp, quick):
    cells = PEN_CELLS_MM[:2] if quick else PEN_CELLS_MM
    rows = []
    for h in cells:
        for conv in PEN_CONVERSION:
            for hg in PEN_HOURGLASS:
                path = os.path.join(tmp, "pen.h5")
                rc, msg = run_fracta(fracta, "penetration.toml", [
                    f"body.slab.cell_size={h * 1e-3:.9g}",
                    f"body.projectile.cell_size={h * 1e-3:.9g}",
                    f"material.concrete.conversion_strain={conv}",
                    f'simulation.hourglass="{hg}"', f"simulation.end_time={PEN_END}",
                    "simulation.output_interval=1.0", 'output.fields=["velocity"]'], path)
                row = dict(cell_mm=h, conversion_strain=conv, hourglass=hg, status=rc,
                           message=msg)
                if rc == 0:
                    row.update(penetration_metrics(path))
                else:
                    row.update(wall_s=float("nan"), steps=0, depth_mm=float("nan"),
                               residual_velocity=float("nan"), conversions=0,
                               energy_error=float("nan"))
                rows.append(row)
                print(f"penetration h {h:.4g} mm conversion {conv} {hg}: " +
                      (f"{row['wall_s']:.2f} s, depth {row['depth_mm']:.3f} mm, "
                       f"v {row['residual_velocity']:.2f} m/s, {row['conversions']} converted, "
                       f"energy error {100 * row['energy_error']:.3f}%"
                       if rc == 0 else f"exit {rc}: {msg}"), flush=True)
    ref = [r for r in rows if r["cell_mm"] == min(cells) and r["conversion_strain"] == 0.02
           and r["hourglass"] == "viscous"][0]
    for r in rows:
        ok = r["status"] == 0 and ref["status"] == 0
        r["err_depth"] = abs(r["depth_mm"] / ref["depth_mm"] - 1) if ok else float("nan")
        r["err_residual_velocity"] = (abs(r["residual_velocity"] / ref["residual_velocity"] - 1)
                                      if ok else float("nan"))
        r["reference"] = r is ref
    fields = ["cell_mm", "conversion_strain", "hourglass", "status", "steps", "wall_s",
              "depth_mm", "residual_velocity", "conversions", "energy_error", "err_depth",
              "err_residual_velocity", "reference", "message"]
    write_csv(rows, fields, os.path.join(out, "tradeoff_penetration.csv"))
    for r in rows:
        r["setting"] = f"eps_c {r['conversion_strain']}, {r['hourglass']}"
    plot([r for r in rows if not r["reference"]], ["err_depth", "err_residual_velocity",
                                                  "energy_error"],
         ["depth (vs finest)", "residual velocity (vs finest)", "energy balance"], "setting",
         "Penetration (80 us): error against wall time", 
         os.path.join(out, "tradeoff_penetration.png"))
    return rows


def speed_metrics(path):
    with h5py.File(path, "r") as f:
        wall = float(f["run"].attrs["wall_seconds"])
        steps = int(f["run"].attrs["steps"])
        h = f["history"]
        dt = h["dt"][:]
        elements = h["count"]["elements"][:]
        energy = float(np.max(np.abs(h["energy"]["error"][:])))
        conversions = int(h["count"]["conversions"][-1])
        mass = h["mass"][:]
    # dt[-1] may be the step shortened to land on end_time.
    return dict(wall_s=wall, steps=steps, dt_min_over_initial=float(dt[:-1].min() / dt[0]),
                energy_error=energy, conversions=conversions, elements_left=int(elements[-1]),
                mass_change=float(np.max(np.abs(mass - mass[0])) / mass[0]))


def study_speed(fracta, out, tmp, quick):
    cells = SPEED_CELLS_MM[:1] if quick else SPEED_CELLS_MM
    rows = []
    for h in cells:
        for v in SPEED_MPS:
            path = os.path.join(tmp, "speed.h5")
            rc, msg = run_fracta(fracta, "penetration.toml", [
                f"body.slab.cell_size={h * 1e-3:.9g}", f"body.projectile.cell_size={h * 1e-3:.9g}",
                f"body.projectile.initial_velocity=[0.0, {-float(v)}]",
                f"simulation.end_time={SPEED_END}", "simulation.output_interval=1.0",
                'output.fields=["velocity"]'], path)
            row = dict(cell_mm=h, speed_mps=v, status=rc, message=msg)
            if rc == 0:
                row.update(speed_metrics(path))
            rows.append(row)
            print(f"speed {v} m/s h {h:.4g} mm: " +
                  (f"{row['steps']} steps, {row['wall_s']:.2f} s, smallest step "
                   f"{row['dt_min_over_initial']:.2f} of the initial, energy error "
                   f"{100 * row['energy_error']:.2f}%, {row['elements_left']} elements left"
                   if rc == 0 else f"exit {rc}: {msg}"), flush=True)
    write_csv(rows, ["cell_mm", "speed_mps", "status", "steps", "wall_s", "dt_min_over_initial",
                     "energy_error", "conversions", "elements_left", "mass_change", "message"],
              os.path.join(out, "tradeoff_speed.csv"))
    return rows


def study_fragmentation(fracta, out, tmp, quick):
    cells = FRAG_CELLS_UM[:2] if quick else FRAG_CELLS_UM
    seeds = FRAG_SEEDS[:2] if quick else FRAG_SEEDS
    runs = []
    for h in cells:
        for seed in seeds:
            path = os.path.join(tmp, "bar.h5")
            rc, msg = run_fracta(fracta, FRAG_CASE, [
                f"body.bar.cell_size={h * 1e-6:.9g}", f"simulation.seed={seed}",
                "simulation.output_interval=1.0", 'output.fields=["velocity"]'], path)
            run = dict(cell_um=h, seed=seed, status=rc, message=msg, fragments=0,
                       wall_s=float("nan"), energy_error=float("nan"))
            if rc == 0:
                with h5py.File(path, "r") as f:
                    frames = f["frames"]
                    last = frames[max(frames.keys(), key=int)]
                    run["fragments"] = len(last["fragment_mass"])
                    run["wall_s"] = float(attr(f, "wall_seconds"))
                    run["energy_error"] = float(np.max(np.abs(f["history/energy/error"][:])))
            runs.append(run)
            print(f"fragmentation h {h:g} um seed {seed}: " +
                  (f"{run['fragments']} fragments, {run['wall_s']:.2f} s" if rc == 0
                   else f"exit {rc}: {msg}"), flush=True)
    write_csv(runs, ["cell_um", "seed", "status", "fragments", "wall_s", "energy_error",
                     "message"], os.path.join(out, "tradeoff_fragmentation_runs.csv"))
    rows = []
    for h in cells:
        sizes = [FRAG_LENGTH / r["fragments"] for r in runs
                 if r["cell_um"] == h and r["status"] == 0 and r["fragments"] > 0]
        walls = [r["wall_s"] for r in runs if r["cell_um"] == h and r["status"] == 0]
        for n in range(1, len(sizes) + 1):
            sample = np.array(sizes[:n])
            sd = float(np.std(sample, ddof=1)) if n > 1 else float("nan")
            rows.append(dict(cell_um=h, seeds=n, mean_size_um=1e6 * float(sample.mean()),
                             sd_um=1e6 * sd, standard_error_um=1e6 * sd / math.sqrt(n),
                             size_over_zmr=float(sample.mean()) / FRAG_ZMR,
                             wall_s=float(np.sum(walls[:n]))))
    write_csv(rows, ["cell_um", "seeds", "mean_size_um", "sd_um", "standard_error_um",
                     "size_over_zmr", "wall_s"], os.path.join(out, "tradeoff_fragmentation.csv"))
    return rows


CRACK_CASE = "validation/kalthoff_winkler_turned.toml"
CRACK_CELLS_MM = [1.0, 0.5]
CRACK_SEEDS = {1.0: [1, 2, 3, 4, 5, 6, 7, 8], 0.5: [1, 2, 3, 4]}
CRACK_ALPHA = math.radians(30.0)
CRACK_ORIGIN = (60e-3, 120e-3)  # the plate's struck-edge midpoint (m)


def crack_angles(path):
    """The two cracks' angles to the notch line (degrees), from the last frame."""
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from cracks import trace  # noqa: E402
    ca, sa = math.cos(CRACK_ALPHA), math.sin(CRACK_ALPHA)
    with h5py.File(path, "r") as f:
        frames = f["frames"]
        first, last = frames["0"], frames[max(frames.keys(), key=int)]
        x0 = first["node_position"][:] - first["node_displacement"][:]
        bn, st = last["bond_nodes"][:], last["bond_state"][:]
    broken = bn[st == 2]
    points = 0.5 * (x0[broken[:, 0]] + x0[broken[:, 1]])
    angles = []
    for side in (1, -1):
        tip = np.array([CRACK_ORIGIN[0] + 1e-3 * (50 * ca - side * 25 * sa),
                        CRACK_ORIGIN[1] + 1e-3 * (50 * sa + side * 25 * ca)])
        r = trace(points, tip, 2e-3, 10e-3)
        sss = ssn = snn = 0.0
        for p in r["path"]:
            w = np.asarray(p) - tip
            if not 5e-3 <= math.hypot(w[0], w[1]) <= 25e-3:
                continue
            ds, dn = w[0] * ca + w[1] * sa, side * (-w[0] * sa + w[1] * ca)
            sss, ssn, snn = sss + ds * ds, ssn + ds * dn, snn + dn * dn
        angles.append(0.5 * math.degrees(math.atan2(2 * ssn, sss - snn)) if sss + snn > 0
                      else float("nan"))
    return angles


def study_crackpath(fracta, out, tmp, quick):
    cells = CRACK_CELLS_MM[:1] if quick else CRACK_CELLS_MM
    runs = []
    for h in cells:
        for perturbation, seeds in ((0.0, [1]), (0.15, CRACK_SEEDS[h][:2] if quick else CRACK_SEEDS[h])):
            for seed in seeds:
                path = os.path.join(tmp, "kw.h5")
                rc, msg = run_fracta(fracta, CRACK_CASE, [
                    f"body.plate.cell_size={h * 1e-3:.9g}", f"simulation.seed={seed}",
                    f"body.plate.node_perturbation={perturbation}",
                    "simulation.output_interval=1.0", 'output.fields=["velocity"]'], path)
                run = dict(cell_mm=h, perturbation=perturbation, seed=seed, status=rc, message=msg,
                           upper_deg=float("nan"), lower_deg=float("nan"), wall_s=float("nan"))
                if rc == 0:
                    run["upper_deg"], run["lower_deg"] = crack_angles(path)
                    with h5py.File(path, "r") as f:
                        run["wall_s"] = float(attr(f, "wall_seconds"))
                runs.append(run)
                print(f"crackpath h {h:g} mm delta {perturbation:g} seed {seed}: " +
                      (f"{run['upper_deg']:.1f} / {run['lower_deg']:.1f} deg, {run['wall_s']:.1f} s"
                       if rc == 0 else f"exit {rc}: {msg}"), flush=True)
    write_csv(runs, ["cell_mm", "perturbation", "seed", "status", "upper_deg", "lower_deg",
                     "wall_s", "message"], os.path.join(out, "tradeoff_crackpath_runs.csv"))
    rows = []
    for h in cells:
        regular = [r for r in runs if r["cell_mm"] == h and r["perturbation"] == 0 and r["status"] == 0]
        ok = [r for r in runs if r["cell_mm"] == h and r["perturbation"] > 0 and r["status"] == 0]
        for n in range(1, len(ok) + 1):
            sample = np.array([a for r in ok[:n] for a in (r["upper_deg"], r["lower_deg"])])
            sd = float(np.std(sample, ddof=1))
            rows.append(dict(cell_mm=h, seeds=n, mean_deg=float(sample.mean()), sd_deg=sd,
                             standard_error_deg=sd / math.sqrt(len(sample)),
                             off_published_deg=float(sample.mean()) - 70.0,
                             wall_s=float(sum(r["wall_s"] for r in ok[:n])),
                             regular_deg=(f"{regular[0]['upper_deg']:.1f} / {regular[0]['lower_deg']:.1f}"
                                          if regular else "-")))
    write_csv(rows, ["cell_mm", "seeds", "mean_deg", "sd_deg", "standard_error_deg",
                     "off_published_deg", "wall_s", "regular_deg"],
              os.path.join(out, "tradeoff_crackpath.csv"))
    return rows


# Mode-I crack speed (docs/validation.md, "Mode-I crack speed"): the glass-like plane-strain
# plate of scripts/crack_case.py, pre-crack faces under a suddenly applied 6 MPa, run to 4 us at
# three cell sizes. A run's crack length is its fracture energy over G_c (a_E); the answer is
# Freund's equation of motion G_c = g(v) G*(t, l) with G* of stationary cracks, which gives
# a = 1.50 mm at 4 us (validation.md's table; scripts/crack_speed.sh derives it from eight
# elastic reference runs, 10 minutes that this study does not repeat).
CRACKSPEED_CELLS_M = [2e-4, 1e-4, 5e-5]
CRACKSPEED_FREUND_MM = 1.50
CRACKSPEED_GC = 3.8  # J/m^2


def study_crackspeed(fracta, out, tmp, quick):
    import tomllib
    cells = CRACKSPEED_CELLS_M[:2] if quick else CRACKSPEED_CELLS_M
    rows = []
    for h in cells:
        case = os.path.join(tmp, f"crack_{h:g}.toml")
        subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "crack_case.py"), f"{h:g}",
                        case, "--frame", "1.0"], check=True, stdout=subprocess.DEVNULL)
        with open(case, "rb") as f:
            thickness = tomllib.load(f)["simulation"].get("thickness", 1.0)
        path = os.path.join(tmp, "crack.h5")
        rc, msg = run_fracta(fracta, case, ["simulation.output_interval=1.0"], path)
        row = dict(cell_mm=h * 1e3, process_zone_cells=float("nan"), a_end_mm=float("nan"),
                   a_over_freund=float("nan"), speed_last_us=float("nan"), wall_s=float("nan"),
                   status=rc, message=msg)
        if rc == 0:
            with h5py.File(path, "r") as f:
                t = f["history/time"][:]
                a = f["history/energy/fracture"][:] / (CRACKSPEED_GC * thickness)
                row["wall_s"] = float(attr(f, "wall_seconds"))
            end = t[-1]
            a_end, a_before = np.interp(end, t, a), np.interp(end - 1e-6, t, a)
            E, nu, sigma_t = 72e9, 0.22, 30e6
            row["process_zone_cells"] = E / (1 - nu ** 2) * CRACKSPEED_GC / sigma_t ** 2 / h
            row["a_end_mm"] = float(a_end * 1e3)
            row["a_over_freund"] = float(a_end * 1e3 / CRACKSPEED_FREUND_MM)
            row["speed_last_us"] = float((a_end - a_before) / 1e-6)
        rows.append(row)
        print(f"crackspeed h {h * 1e3:g} mm: " +
              (f"a_E {row['a_end_mm']:.3f} mm ({row['a_over_freund']:.3f} of Freund), "
               f"{row['speed_last_us']:.0f} m/s, {row['wall_s']:.1f} s" if rc == 0 else
               f"exit {rc}: {msg}"), flush=True)
    write_csv(rows, ["cell_mm", "process_zone_cells", "a_end_mm", "a_over_freund",
                     "speed_last_us", "wall_s", "status", "message"],
              os.path.join(out, "tradeoff_crackspeed.csv"))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fracta", default=os.path.join(ROOT, "build", "fracta"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results"))
    ap.add_argument("--study", choices=["plate", "penetration", "speed", "fragmentation",
                                        "crackpath", "crackspeed", "all"],
                    default="all")
    ap.add_argument("--quick", action="store_true", help="two cell sizes only (pipeline check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        if args.study in ("plate", "all"):
            study_plate(args.fracta, args.out, tmp, args.quick)
        if args.study in ("penetration", "all"):
            study_penetration(args.fracta, args.out, tmp, args.quick)
            study_speed(args.fracta, args.out, tmp, args.quick)
        if args.study == "speed":
            study_speed(args.fracta, args.out, tmp, args.quick)
        if args.study in ("fragmentation", "all"):
            study_fragmentation(args.fracta, args.out, tmp, args.quick)
        if args.study in ("crackpath", "all"):
            study_crackpath(args.fracta, args.out, tmp, args.quick)
        if args.study in ("crackspeed", "all"):
            study_crackspeed(args.fracta, args.out, tmp, args.quick)
    with open(os.path.join(args.out, "tradeoff_machine.txt"), "w") as f:
        for k, v in machine_info().items():
            f.write(f"{k}: {v}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
