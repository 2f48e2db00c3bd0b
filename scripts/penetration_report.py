#!/usr/bin/env python3
"""Report of a penetration run (cases/penetration.toml, the paper's Section 4.4).

Prints, from OUT.h5:
  - the projectile's velocity and nose depth below the slab's top face every 10 us (body probe
    `projectile`: its centroid; the nose is the centroid less the nose's initial offset, so a
    flattened nose reads a little deep), and the depth history at full resolution to --csv;
  - perforation: the time the nose passes the slab's rear face and the residual velocity (the
    velocity then, and at the end of the run); otherwise the final depth;
  - conversions: elements converted to discs (cumulative), active elements, discs, bonds
    active and broken;
  - fragments at the last frame: count, the largest masses, and how many are single discs,
    2-4, 5-16 and more discs (fragments of the slab; the projectile is one of them);
  - the projectile's largest equivalent plastic strain over all frames against its material's
    conversion_strain (the projectile stays `fe`; this shows it would not have converted);
  - the energy balance at the end, relative to the initial kinetic energy.

Units: SI in the file; mm, us, m/s and J per metre of thickness (plane strain, thickness 1 m)
here.

Usage: /usr/bin/python3 scripts/penetration_report.py OUT.h5 [--csv FILE]
"""
import argparse
import sys
import tomllib

import h5py
import numpy as np


def frame_count(f):
    """Complete frames: /frames@count (a killed run may leave a partial frame beyond it)."""
    g = f["frames"]
    return int(g.attrs["count"]) if "count" in g.attrs else len(g)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", help="OUT.h5 of a penetration run")
    parser.add_argument("--csv", help="write time (us), nose depth (mm), velocity (m/s) here")
    parser.add_argument("--projectile", default="projectile", help="body name (and body probe)")
    parser.add_argument("--slab", default="slab", help="body name of the target")
    args = parser.parse_args(argv)

    f = h5py.File(args.output, "r")
    case = tomllib.loads(f["run"].attrs["case"])
    # Plane scenes are per metre of depth (or of their thickness); axisymmetric ones are the
    # full revolution.
    axisymmetric = case.get("simulation", {}).get("formulation") == "axisymmetric"
    per = "" if axisymmetric else "/m"
    bodies = [b["name"] for b in case["body"]]
    materials = {m["name"]: m for m in case["material"]}
    ip, islab = bodies.index(args.projectile), bodies.index(args.slab)
    slab = case["body"][islab]["shape"]
    top, rear = slab["y"] + slab["height"], slab["y"]
    proj_material = materials[case["body"][ip]["material"]]
    default_conversion = 0.02 if proj_material["model"] == "mohr_coulomb" else 0.5
    conversion_strain = proj_material.get("conversion_strain", default_conversion)

    # Nose offset below the centroid, from frame 0 (the projectile's nodes are the corners of
    # its elements, element_body == ip).
    g0 = f["frames/0"]
    nodes0 = np.unique(g0["element_nodes"][:][g0["element_body"][:] == ip])
    nose_offset = None
    probe = f["body_probes"][args.projectile]
    t, yc, vy = probe["time"][:], probe["y"][:], probe["vy"][:]
    nose_offset = yc[0] - g0["node_position"][:][nodes0, 1].min()
    depth = top - (yc - nose_offset)
    print(f"{args.output}: {case['simulation'].get('title', '')}")
    print(f"\nProjectile (every 10 us; depth of the nose below the slab's top face):")
    print(f"{'t (us)':>8}{'depth (mm)':>12}{'v (m/s)':>10}")
    for tt in np.arange(0.0, t[-1] + 1e-9, 10e-6):
        i = int(np.argmin(np.abs(t - tt)))
        print(f"{t[i]*1e6:8.1f}{depth[i]*1e3:12.2f}{-vy[i]:10.1f}")
    if args.csv:
        np.savetxt(args.csv, np.column_stack([t * 1e6, depth * 1e3, -vy]), delimiter=",",
                   header="time_us,nose_depth_mm,velocity_m_per_s", comments="", fmt="%.6g")

    thickness = top - rear
    through = np.nonzero(depth >= thickness)[0]
    print()
    if len(through):
        i = through[0]
        print(f"Perforation: the nose passes the rear face at {t[i]*1e6:.1f} us at {-vy[i]:.1f} m/s; "
              f"residual velocity at the end ({t[-1]*1e6:.0f} us): {-vy[-1]:.1f} m/s "
              f"(impact {-vy[0]:.0f} m/s).")
    else:
        print(f"No perforation by {t[-1]*1e6:.0f} us: nose depth {depth[-1]*1e3:.2f} mm of "
              f"{thickness*1e3:.0f} mm, velocity {-vy[-1]:.1f} m/s.")

    h = f["history"]
    count = h["count"]
    # Active elements lost since the first record (history rows are not every step, so the
    # per-step conversion counts would miss some).
    converted = int(count["elements"][0] - count["elements"][-1])
    print(f"\nConversions: {converted} elements converted to discs; at the end "
          f"{int(count['elements'][-1])} active elements, {int(count['particles'][-1])} discs, "
          f"{int(count['bonds'][-1])} active and {int(count['broken_bonds'][-1])} broken bonds.")

    k = frame_count(f) - 1
    g = f["frames"][str(k)]
    mass, size = g["fragment_mass"][:], g["fragment_size"][:]
    bins = [(1, 1), (2, 4), (5, 16), (17, None)]
    hist = ", ".join(
        f"{np.sum((size >= lo) & ((size <= hi) if hi else True))} of "
        f"{lo}{'-' + str(hi) if hi and hi != lo else ('+' if not hi else '')} nodes"
        for lo, hi in bins)
    print(f"\nFragments at {float(g['time'][()])*1e6:.0f} us: {len(mass)} ({hist}); "
          f"largest masses {', '.join(f'{m:.3g}' for m in mass[:4])} kg{per}.")

    worst = 0.0
    for kk in range(frame_count(f)):
        fr = f["frames"][str(kk)]
        if "element_plastic_strain" not in fr:
            break
        sel = fr["element_body"][:] == ip
        if np.any(sel):
            worst = max(worst, float(fr["element_plastic_strain"][:][sel].max()))
    print(f"\nProjectile: largest equivalent plastic strain {worst:.4f} over the frames, "
          f"conversion_strain {conversion_strain}: "
          f"{'below' if worst < conversion_strain else 'REACHED'}.")

    e = h["energy"]
    e0 = float(e["kinetic"][0])
    print(f"\nEnergy at the end, fraction of the initial kinetic energy {e0:.4g} J{per}:")
    for name in ("kinetic", "internal", "plastic", "fracture", "contact", "conversion",
                 "hourglass", "viscous", "external"):
        if name in e:
            print(f"  {name:<12}{float(e[name][-1]) / e0:9.4f}")
    print(f"  {'error':<12}{float(e['error'][-1]):9.2e} (relative)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
