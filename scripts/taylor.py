#!/usr/bin/env python3
"""Taylor impact: final length and impact-face diameter of a rod against the experiments.

    taylor.py OUT.h5 [OUT.h5 ...]        measure finished runs (last frame)
    taylor.py --run DIR [--cells 8 16]   run the published tests (fracta, 2 threads) into DIR
                                         and print the comparison table (markdown)
    taylor.py --anvil DIR [--cells 8]    the copper rod at 190 m/s on an elastic anvil with
                                         friction 0, 0.1, 0.2, 0.3 (taylor_copper_anvil.toml)
    taylor.py --plot PNG CU190.h5 ST208.h5   final shapes of the copper (190 m/s) and steel
                                         (208 m/s) rods beside the digitised outlines

The rod's final length is the axial extent of its nodes at the last frame (the top of the rod
over the lowest node of its impact face, so a rod that has lifted off the anvil is measured as
it is); the impact-face ("footprint") diameter is twice the largest radius of the nodes that
started on the impact face (y = 0). Run the cases to after the rod has left the anvil
(cases/validation/taylor_*.toml do).

The measured values are those of Johnson & Cook (1983, 7th Int. Symp. Ballistics, p. 546) as
tabulated by Zerilli & Armstrong (1987, J. Appl. Phys. 61) and compiled with digitised outlines
in B. Banerjee's Taylor-test collection (github.com/bbanerjee/HighRateExptData, TaylorData):
the table's ratios to L0 = 25.4 mm, D0 = 7.62 mm, and the diameters read from the digitised
outlines where they differ (the footprint to about 0.4 mm).
"""
import argparse
import os
import subprocess
import sys

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (label, case, speed m/s, rod length m, measured final length mm, measured footprint mm
# (table, outline)).
TESTS = [
    ("OFHC copper", "taylor_copper.toml", 130.0, 25.4e-3, 19.56, (9.91, 9.53)),
    ("OFHC copper", "taylor_copper.toml", 146.0, 25.4e-3, 18.69, (10.67, 10.30)),
    ("OFHC copper", "taylor_copper.toml", 190.0, 25.4e-3, 16.21, (13.56, 13.68)),
    ("4340 steel", "taylor_steel_4340.toml", 208.0, 25.4e-3, 22.48, (11.10, 11.06)),
    ("4340 steel", "taylor_steel_4340.toml", 282.0, 12.7e-3, 10.71, (10.40, 10.40)),
    ("4340 steel", "taylor_steel_4340.toml", 343.0, 8.1e-3, 6.54, (12.0, 12.0)),
]
ROD_RADIUS = 3.81e-3

# Digitised outlines (radius, height) in mm, impact face first, of the copper rod at 190 m/s
# (Zerilli & Armstrong 1987's figure of the Johnson & Cook test) and the steel rod at 208 m/s
# (Johnson & Cook 1983, p. 546), from the same collection (TaylorData/DAT).
OUTLINES = {
    "copper": [(6.842, 0), (6.408, 0.584), (6.011, 1.137), (5.615, 1.657), (5.396, 2.014),
               (5.107, 3.214), (5.074, 4.061), (5.000, 5.782), (4.892, 7.536), (4.748, 8.639),
               (4.529, 9.970), (4.314, 11.464), (4.099, 12.797), (3.917, 13.868),
               (3.880, 15.005), (3.810, 16.205)],
    "steel": [(5.528, 0), (4.780, 2.097), (4.300, 4.021), (4.033, 5.998), (3.979, 8.094),
              (3.881, 10.105), (3.881, 12.150), (3.748, 14.255), (3.783, 16.300),
              (3.774, 18.311), (3.765, 20.365), (3.810, 22.496)],
}


def measure(path):
    """Final length and footprint diameter (mm) at the last frame of a run."""
    with h5py.File(path, "r") as f:
        frames = f["frames"]
        last = frames[max(frames.keys(), key=int)]
        x = last["node_position"][:]
        x0 = x - last["node_displacement"][:]
    face = np.abs(x0[:, 1]) < 1e-9
    length = x[:, 1].max() - x[face, 1].min()
    footprint = 2.0 * x[face, 0].max()
    return 1e3 * length, 1e3 * footprint


def plot(png, copper, steel):
    """The rods' final meshes (mirrored about the axis) beside the digitised outlines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    fig, axes = plt.subplots(1, 2, figsize=(8, 6))
    for ax, path, key, title in ((axes[0], copper, "copper", "OFHC copper, 190 m/s"),
                                 (axes[1], steel, "steel", "4340 steel, 208 m/s")):
        with h5py.File(path, "r") as f:
            frames = f["frames"]
            last = frames[max(frames.keys(), key=int)]
            x = 1e3 * last["node_position"][:]
            x0 = x - 1e3 * last["node_displacement"][:]
            quads = last["element_nodes"][:].reshape(-1, 4)
        base = x0[:, 1].min()
        face = np.abs(x0[:, 1] - base) < 1e-9
        y_face = x[face, 1].min()  # the rod stands on its impact face
        for sign in (1.0, -1.0):
            polys = [[(sign * x[n, 0], x[n, 1] - y_face) for n in q] for q in quads]
            ax.add_collection(PolyCollection(polys, facecolors="#c8d8e8", edgecolors="#5a7a9a",
                                             linewidths=0.3))
            r, z = zip(*OUTLINES[key])
            ax.plot([sign * v for v in r], z, "o-", color="#c03020", ms=3, lw=1,
                    label="measured (digitised)" if sign > 0 else None)
        length, footprint = measure(path)
        ax.set_title("%s\nfracta: L %.2f mm, D %.2f mm" % (title, length, footprint), fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlim(-8, 8)
        ax.set_ylim(-0.5, 26)
        ax.set_xlabel("r (mm)")
        ax.legend(loc="upper right", fontsize=8)
    axes[0].set_ylabel("z (mm)")
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def run(case, speed, length, cells, out):
    fracta = os.path.join(ROOT, "build", "fracta")
    cmd = [
        fracta, "run", os.path.join(ROOT, "cases", "validation", case), "-o", out,
        "--set", "body.rod.cell_size=%.9g" % (ROD_RADIUS / cells),
        "--set", "body.rod.shape.height=%.9g" % length,
        "--set", "body.rod.initial_velocity=[0.0, %.9g]" % -speed,
    ]
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "2"))
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outputs", nargs="*")
    ap.add_argument("--run", metavar="DIR", help="run the published tests into DIR")
    ap.add_argument("--anvil", metavar="DIR", help="run the elastic-anvil friction study")
    ap.add_argument("--plot", metavar="PNG", help="picture of two runs: copper 190, steel 208")
    ap.add_argument("--cells", type=int, nargs="+", default=[8],
                    help="cells across the rod's radius (default 8, as the cases)")
    args = ap.parse_args()
    if args.plot:
        if len(args.outputs) != 2:
            ap.error("--plot takes two outputs: copper at 190 m/s, steel at 208 m/s")
        plot(args.plot, *args.outputs)
        return
    if args.anvil:
        os.makedirs(args.anvil, exist_ok=True)
        fracta = os.path.join(ROOT, "build", "fracta")
        env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "2"))
        print("| anvil friction | cells across the radius | final length (mm) | footprint (mm) |")
        print("|---|---|---|---|")
        for cells in args.cells:
            for mu in (0.0, 0.1, 0.2, 0.3):
                out = os.path.join(args.anvil, "anvil_%g_%d.h5" % (mu, cells))
                h = ROD_RADIUS / cells
                subprocess.run([fracta, "run", os.path.join(ROOT, "cases", "validation",
                                                            "taylor_copper_anvil.toml"),
                                "-o", out, "--set", "contact.friction=%g" % mu,
                                "--set", "body.rod.cell_size=%.9g" % h,
                                "--set", "body.anvil.cell_size=%.9g" % h],
                               check=True, env=env, stdout=subprocess.DEVNULL)
                length, footprint = measure(out)
                print("| %.1f | %d | %.2f | %.2f |" % (mu, cells, length, footprint))
                sys.stdout.flush()
        return
    if not args.run:
        if not args.outputs:
            ap.error("give outputs, or --run DIR")
        for path in args.outputs:
            length, footprint = measure(path)
            print("%s: final length %.3f mm, footprint diameter %.3f mm" % (path, length, footprint))
        return
    os.makedirs(args.run, exist_ok=True)
    print("| rod | speed (m/s) | L0 (mm) | cells across the radius | final length: measured / fracta"
          " | error | footprint: measured (table, outline) / fracta | error |")
    print("|---|---|---|---|---|---|---|---|")
    for label, case, speed, length, lf, df in TESTS:
        for cells in args.cells:
            out = os.path.join(args.run, "%s_%d_%d.h5" % (case[:-5], int(speed), cells))
            run(case, speed, length, cells, out)
            got_l, got_d = measure(out)
            mean_d = 0.5 * (df[0] + df[1])
            print("| %s | %.0f | %.1f | %d | %.2f / %.2f | %+.1f %% | %.2f, %.2f / %.2f | %+.1f %% |"
                  % (label, speed, 1e3 * length, cells, lf, got_l, 100 * (got_l / lf - 1), df[0],
                     df[1], got_d, 100 * (got_d / mean_d - 1)))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
