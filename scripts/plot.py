#!/usr/bin/python3
"""Plots from a fracta output file (docs/output.md).

    plot.py OUT.h5 [-o DIR]
        energy.png       every energy term (J) vs time (us), and the relative energy error
        probes.png       vx (m/s) and sxx (MPa) of each probe vs time, if the run has probes
        body_probes.png  position (mm) and velocity (m/s) of each body probe, if any
    plot.py OUT.h5 --frame K [--field FIELD] [--bonds | --no-bonds] [-o DIR]
        field_<field>_<K>.png   frame K (only this plot): elements coloured by FIELD, discs as
                                circles of their true radius, active bonds as thin grey lines,
                                broken bonds (cracks) as red lines,
                                softening cohesive bonds as orange ones
    plot.py OUT.h5 --frames K1,K2,K3,K4 [--field FIELD] [-o DIR]
        field_<field>_<K1>-<K2>-...png   those frames as panels of one figure, one colour scale
    FIELD: plastic_strain, von_mises (default), pressure, sxx, syy, szz, sxy (elements; discs
    drawn in a neutral colour), rotation, spin (discs; elements neutral), speed (both).
    Bonds: all of them when there are fewer than 20000, else only the broken ones, unless
    --bonds (all) or --no-bonds (none) is given. A broken bond whose discs are further apart
    than 3 x the sum of their radii is not drawn (the gap between the fragments shows it).

DIR defaults to the directory of OUT.h5. Needs h5py, numpy and matplotlib (Debian's
python3-h5py, python3-numpy and python3-matplotlib).
"""
import argparse
import os
import re
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the backend)
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection, LineCollection, PolyCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from mpl_toolkits.axes_grid1 import make_axes_locatable  # noqa: E402

ENERGY_TERMS = ["kinetic", "internal", "plastic", "hourglass", "viscous", "contact", "fracture",
                "conversion", "time_discretization", "external", "error"]
US = 1e6   # s -> us
MPA = 1e-6  # Pa -> MPa
MM = 1e3   # m -> mm

# --field name -> (what it lives on, dataset in /frames/K, column of an M x 4 dataset or None,
# scale, label). "element" fields colour the elements (discs are drawn in a neutral colour),
# "disc" fields the discs (elements neutral), "node" fields both (elements by their nodes' mean).
FIELDS = {
    "plastic_strain": ("element", "element_plastic_strain", None, 1.0,
                       "equivalent plastic strain (-)"),
    "von_mises": ("element", "element_von_mises", None, MPA, "von Mises stress (MPa)"),
    "pressure": ("element", "element_pressure", None, MPA, "pressure (MPa)"),
    "sxx": ("element", "element_stress", 0, MPA, r"$\sigma_{xx}$ (MPa)"),
    "syy": ("element", "element_stress", 1, MPA, r"$\sigma_{yy}$ (MPa)"),
    "szz": ("element", "element_stress", 2, MPA, r"$\sigma_{zz}$ (MPa)"),
    "sxy": ("element", "element_stress", 3, MPA, r"$\sigma_{xy}$ (MPa)"),
    "speed": ("node", "node_velocity", None, 1.0, "speed (m/s)"),
    "rotation": ("disc", "particle_rotation", None, 1.0, "disc rotation (rad)"),
    "spin": ("disc", "particle_spin", None, 1.0, "disc spin (rad/s)"),
}
SIGNED = {"pressure", "sxx", "syy", "szz", "sxy", "rotation", "spin"}
ELEMENT_NEUTRAL = "#c8c8c8"  # elements when the field is a disc quantity
DISC_NEUTRAL = "#e3d3a8"     # discs when the field is an element quantity
BOND_ACTIVE = "#6e6e6e"
BOND_SOFTENING = "#ff9f1c"  # orange: cohesive bonds softening
BOND_BROKEN = "#d62728"
MAX_AUTO_BONDS = 20000       # above this many bonds, only broken ones are drawn by default
BROKEN_REACH = 3.0           # broken bonds longer than this x (sum of the radii) are not drawn


def text_attr(obj, name):
    """A string attribute as str, whether stored variable- or fixed-length."""
    value = obj.attrs.get(name)
    if value is None:
        return None
    if isinstance(value, np.ndarray):
        value = value.item() if value.size == 1 else value[0]
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def case_title(f):
    """`title` of [simulation] in the case text stored in /run, or None."""
    case = text_attr(f["run"], "case") if "run" in f else None
    if case is None and "run/case" in f:  # the case text as a dataset, if a writer chose that
        case = f["run/case"][()]
        case = case.decode() if isinstance(case, bytes) else str(case)
    if not case:
        return None
    try:
        import tomllib  # Python >= 3.11
        title = tomllib.loads(case).get("simulation", {}).get("title")
        if isinstance(title, str):
            return title
    except Exception:  # not TOML after all, or an older Python: fall back to a regex
        pass
    m = re.search(r'^\s*title\s*=\s*"((?:[^"\\]|\\.)*)"', case, re.MULTILINE)
    return m.group(1) if m else None


def with_title(text, title):
    return f"{title}: {text}" if title else text


def plot_energy(f, out_dir, title):
    h = f["history"]
    t = h["time"][:] * US
    if t.size == 0:
        print("no history rows: energy.png not written")
        return None
    e = {name: h["energy"][name][:] for name in ENERGY_TERMS if name in h["energy"]}
    fig, (ax, ax_err) = plt.subplots(2, 1, figsize=(9, 7.5), sharex=True,
                                     gridspec_kw={"height_ratios": [3, 1.4]})
    for name, values in e.items():
        if name == "error":
            continue  # relative, shown in the lower panel
        style = "--" if name == "external" else "-"
        ax.plot(t, values, style, lw=1.4, label=name)
    ax.set_ylabel("energy (J)")
    ax.set_title(with_title("energy balance", title))
    ax.grid(True, alpha=0.3)
    ax.legend(ncol=2, fontsize="small", loc="best")

    # /history/energy/error is already relative (docs/physics.md 1.4):
    # |balance| / max(E_ext + E_0, E_kin).
    rel = np.abs(e["error"])
    ax_err.plot(t, rel, color="tab:red", lw=1.2)
    if np.nanmax(rel, initial=0) > 0:
        ax_err.set_yscale("log")
    ax_err.set_ylabel("relative error (-)")
    ax_err.set_xlabel("time (µs)")
    ax_err.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return save(fig, out_dir, "energy.png")


def plot_probes(f, out_dir, title):
    names = sorted(f["probes"]) if "probes" in f else []
    if not names:
        return None
    fig, axes = plt.subplots(len(names), 2, figsize=(10, 2.8 * len(names) + 0.8), sharex=True,
                             squeeze=False)
    for row, name in enumerate(names):
        p = f["probes"][name]
        t = p["time"][:] * US
        axes[row, 0].plot(t, p["vx"][:], color="tab:blue", lw=1.3)
        axes[row, 0].set_ylabel(r"$v_x$ (m/s)")
        axes[row, 1].plot(t, p["sxx"][:] * MPA, color="tab:orange", lw=1.3)
        axes[row, 1].set_ylabel(r"$\sigma_{xx}$ (MPa)")
        for ax in axes[row]:
            ax.set_title(f"probe {name}", fontsize="medium")
            ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time (µs)")
    fig.suptitle(with_title("probes", title))
    fig.tight_layout()
    return save(fig, out_dir, "probes.png")


def plot_body_probes(f, out_dir, title):
    names = sorted(f["body_probes"]) if "body_probes" in f else []
    if not names:
        return None
    fig, (ax_pos, ax_vel) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for name in names:
        p = f["body_probes"][name]
        t = p["time"][:] * US
        for ax, a, b, unit in ((ax_pos, "x", "y", MM), (ax_vel, "vx", "vy", 1.0)):
            line, = ax.plot(t, p[a][:] * unit, lw=1.4, label=f"{name} {a}")
            ax.plot(t, p[b][:] * unit, "--", lw=1.4, color=line.get_color(), label=f"{name} {b}")
    ax_pos.set_ylabel("mass-averaged position (mm)")
    ax_vel.set_ylabel("mass-averaged velocity (m/s)")
    for ax in (ax_pos, ax_vel):
        ax.set_xlabel("time (µs)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle(with_title("body probes", title))
    fig.tight_layout()
    return save(fig, out_dir, "body_probes.png")


def frame_count(f):
    """Complete frames: /frames@count (a killed run may leave a partial /frames/K beyond it)."""
    if "frames" not in f:
        return 0
    g = f["frames"]
    return int(g.attrs["count"]) if "count" in g.attrs else len(g)


def load_frame(f, k, field):
    """Geometry and `field` values of frame K: elements, discs and bonds (mm, field units)."""
    group = f"frames/{k}"
    frames = frame_count(f)
    if not 0 <= k < frames or group not in f:
        sys.exit(f"plot.py: {f.filename} has no frame {k} ({frames} frames)")
    g = f[group]
    kind, dataset, column, scale, _ = FIELDS[field]
    pos = g["node_position"][:] * MM
    conn = g["element_nodes"][:]
    particles = g["particle_node"][:] if "particle_node" in g else np.zeros(0, dtype=int)
    bonds = g["bond_nodes"][:] if "bond_nodes" in g else np.zeros((0, 2), dtype=int)
    state = g["bond_state"][:] if "bond_state" in g else np.zeros(0, dtype=int)
    damage = g["bond_damage"][:] if "bond_damage" in g else np.zeros(state.shape[0])
    if conn.shape[0] == 0 and particles.size == 0:
        sys.exit(f"plot.py: frame {k} has no elements and no discs")
    radius = np.zeros(pos.shape[0])  # per node, 0 for non-disc nodes
    if particles.size:
        radius[particles] = g["particle_radius"][:] * MM
    fr = {"k": k, "time": float(g["time"][()]), "pos": pos, "conn": conn,
          "bond_reach": radius[bonds].sum(axis=1) if bonds.shape[0] else np.zeros(0),
          "disc_xy": pos[particles], "disc_r": (g["particle_radius"][:] * MM
                                                if particles.size else np.zeros(0)),
          "bonds": pos[bonds] if bonds.shape[0] else np.zeros((0, 2, 2)), "state": state,
          "damage": damage, "element_values": None, "disc_values": None}
    if kind == "element" and conn.shape[0]:
        if dataset not in g:
            have = sorted(n for n, v in FIELDS.items() if v[0] != "element" or v[1] in g)
            sys.exit(f"plot.py: frame {k} has no {dataset}; fields in this frame: "
                     f"{', '.join(have)} (see [output] fields in the case)")
        values = g[dataset][:]
        fr["element_values"] = (values if column is None else values[:, column]) * scale
    elif kind == "disc" and particles.size:
        fr["disc_values"] = g[dataset][:] * scale
    elif kind == "node":  # speed
        speed = np.hypot(*g[dataset][:].T) * scale if pos.shape[0] else np.zeros(0)
        if conn.shape[0]:
            fr["element_values"] = speed[conn].mean(axis=1)
        if particles.size:
            fr["disc_values"] = speed[particles]
    return fr


def draw_frame(ax, fr, cmap, norm, bonds):
    """Elements, discs (true radii) and bonds of one frame on `ax`; returns the mappables."""
    mappables = []
    conn = fr["conn"]
    if conn.shape[0]:
        polys = PolyCollection(fr["pos"][conn], linewidths=0.3, zorder=1,
                               edgecolors=(0, 0, 0, 0.25) if conn.shape[0] <= 5000 else "face")
        if fr["element_values"] is not None:
            polys.set_array(fr["element_values"])
            polys.set_cmap(cmap)
            polys.set_norm(norm)
            mappables.append(polys)
        else:
            polys.set_facecolor(ELEMENT_NEUTRAL)
            polys.set_edgecolor((0, 0, 0, 0.15))
        ax.add_collection(polys)
    if fr["disc_r"].size:
        d = 2 * fr["disc_r"]
        many = d.size > 20000
        discs = EllipseCollection(d, d, np.zeros_like(d), units="xy", offsets=fr["disc_xy"],
                                  offset_transform=ax.transData, zorder=2,
                                  linewidths=0 if many else 0.2,
                                  edgecolors="face" if many else (0, 0, 0, 0.35))
        if fr["disc_values"] is not None:
            discs.set_array(fr["disc_values"])
            discs.set_cmap(cmap)
            discs.set_norm(norm)
            mappables.append(discs)
        else:
            discs.set_facecolor(DISC_NEUTRAL)
        ax.add_collection(discs)
    segments, state = fr["bonds"], fr["state"]
    if bonds == "auto":
        bonds = "all" if segments.shape[0] < MAX_AUTO_BONDS else "broken"
    broken = state == 2
    softening = (state == 1) & (fr["damage"] > 0.0)
    if bonds == "all" and np.any((state == 1) & ~softening):
        ax.add_collection(LineCollection(segments[(state == 1) & ~softening], colors=BOND_ACTIVE,
                                         linewidths=0.3, zorder=3))
    # Cohesive bonds past their strength (damage 0 < D < 1): the process zone ahead of a crack.
    if bonds in ("all", "broken") and np.any(softening):
        ax.add_collection(LineCollection(segments[softening], colors=BOND_SOFTENING,
                                         linewidths=0.6, zorder=4))
    # A broken bond whose discs have moved apart by more than a few diameters is not drawn:
    # the gap between the fragments shows that crack, a long red line would only hide it.
    length = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    broken &= length <= BROKEN_REACH * fr["bond_reach"]
    if bonds in ("all", "broken") and np.any(broken):
        ax.add_collection(LineCollection(segments[broken], colors=BOND_BROKEN, linewidths=0.7,
                                         zorder=4))
    return mappables


def mirrored(fr):
    """The frame reflected about the axis x = 0 (the other half of an axisymmetric scene)."""
    m = dict(fr)
    flip = np.array([-1.0, 1.0])
    m["pos"] = fr["pos"] * flip
    m["disc_xy"] = fr["disc_xy"] * flip
    m["bonds"] = fr["bonds"] * flip
    return m


def bounds(fr):
    """(xmin, xmax, ymin, ymax) of everything drawn, discs with their radii."""
    boxes = []
    if fr["conn"].shape[0]:
        xy = fr["pos"][np.unique(fr["conn"])]
        boxes.append((xy.min(0), xy.max(0)))
    if fr["disc_r"].size:
        r = fr["disc_r"][:, None]
        boxes.append(((fr["disc_xy"] - r).min(0), (fr["disc_xy"] + r).max(0)))
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    return lo[0], hi[0], lo[1], hi[1]


def plot_field(f, out_dir, title, ks, field, bonds="auto", mirror=False, ylim=None):
    """Frame(s) `ks` coloured by `field`, one panel per frame with one shared colour scale;
    `mirror`: each drawn with its reflection about the axis x = 0; `ylim`: (lo, hi) in mm."""
    frames = [load_frame(f, k, field) for k in ks]
    values = [v for fr in frames for v in (fr["element_values"], fr["disc_values"])
              if v is not None and v.size]
    signed = field in SIGNED
    cmap = "coolwarm" if signed else "viridis"
    if values:
        all_values = np.concatenate(values)
        vmin, vmax = float(np.nanmin(all_values)), float(np.nanmax(all_values))
        if signed:
            vmax = max(abs(vmin), abs(vmax)) or 1.0
            vmin = -vmax
        elif vmin == vmax:
            vmax = vmin + 1.0
        norm = Normalize(vmin, vmax)
    else:
        norm = None
        print(f"plot.py: no element or disc carries {field} in frame(s) "
              f"{', '.join(map(str, ks))}: drawn in neutral colours")

    n = len(frames)
    cols = 2 if n == 4 else min(n, 3)
    rows = -(-n // cols)
    box = [bounds(fr) for fr in frames]
    x0, x1 = min(b[0] for b in box), max(b[1] for b in box)
    y0, y1 = min(b[2] for b in box), max(b[3] for b in box)
    if mirror:
        x0, x1 = -max(abs(x0), abs(x1)), max(abs(x0), abs(x1))
    if ylim:
        y0, y1 = ylim
    pad = 0.02 * max(x1 - x0, y1 - y0)
    x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
    aspect = (y1 - y0) / max(x1 - x0, 1e-12)
    box_w, box_h = (9.0, 7.5) if n == 1 else (5.5, 4.8)  # inches for the drawing of one panel
    panel_w, panel_h = (box_w, box_w * aspect) if aspect < box_h / box_w else (box_h / aspect,
                                                                               box_h)
    fig, axes = plt.subplots(rows, cols, squeeze=False, sharex=True, sharey=True,
                             figsize=(cols * (panel_w + 0.8) + 1.2, rows * (panel_h + 0.7) + 0.4))
    mappable = None
    for ax, fr in zip(axes.flat, frames):
        drawn = draw_frame(ax, fr, cmap, norm, bonds)
        if mirror:
            draw_frame(ax, mirrored(fr), cmap, norm, bonds)
            ax.axvline(0.0, color=(0, 0, 0, 0.3), linewidth=0.5, linestyle="--", zorder=5)
        mappable = mappable or (drawn[0] if drawn else None)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        t = f"t = {fr['time'] * US:.3g} µs"
        ax.set_title(f"{field}, frame {fr['k']}, {t}" if n == 1 else f"frame {fr['k']}, {t}",
                     fontsize="medium")
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("x (mm)")
    for ax in axes[:, 0]:
        ax.set_ylabel("y (mm)")
    label = FIELDS[field][4]
    if n == 1:
        ax = axes[0, 0]
        ax.set_title(with_title(ax.get_title(), title))
        fig.tight_layout()
        if mappable is not None:  # a colour bar as tall as the plot
            cax = make_axes_locatable(ax).append_axes("right", size="3%", pad=0.1)
            fig.colorbar(mappable, cax=cax, label=label)
            fig.tight_layout()
        return save(fig, out_dir, f"field_{field}_{ks[0]}.png", tight=True)
    fig.suptitle(with_title(field, title))
    fig.tight_layout(rect=(0, 0, 0.92 if mappable is not None else 1, 1))
    if mappable is not None:
        top = axes[0, 0].get_position().y1
        bottom = axes[-1, 0].get_position().y0
        cax = fig.add_axes((0.935, bottom, 0.015, top - bottom))
        fig.colorbar(mappable, cax=cax, label=label)
    return save(fig, out_dir, f"field_{field}_{'-'.join(map(str, ks))}.png", tight=True)


def save(fig, out_dir, name, tight=False):
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=130, bbox_inches="tight" if tight else None)
    plt.close(fig)
    print(f"wrote {path}")
    return path


def frame_list(text):
    try:
        ks = [int(k) for k in text.split(",") if k.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected frame numbers like 2,5,8,11, got {text!r}")
    if not ks:
        raise argparse.ArgumentTypeError("no frame given")
    return ks


def float_pair(text):
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers like -300,200, got {text!r}")
    if not lo < hi:
        raise argparse.ArgumentTypeError(f"expected LO < HI, got {text!r}")
    return lo, hi


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("file", help="fracta output file (.h5)")
    parser.add_argument("-o", "--out-dir", help="where to write the PNGs (default: beside FILE)")
    parser.add_argument("--frame", type=int, help="render frame K (only that plot)")
    parser.add_argument("--frames", type=frame_list, metavar="K1,K2,...",
                        help="render these frames as panels of one figure (only that plot)")
    parser.add_argument("--field", choices=sorted(FIELDS), default="von_mises",
                        help="field for --frame/--frames (default: von_mises)")
    parser.add_argument("--bonds", action=argparse.BooleanOptionalAction, default=None,
                        help="draw every bond (active grey, broken red); --no-bonds: none. "
                             f"Default: every bond below {MAX_AUTO_BONDS} bonds, else only "
                             "the broken ones")
    parser.add_argument("--mirror", action="store_true",
                        help="draw each frame with its reflection about the axis x = 0 (a "
                             "meridian section of an axisymmetric scene)")
    parser.add_argument("--ylim", type=float_pair, metavar="LO,HI",
                        help="the y range drawn, in mm (default: everything)")
    args = parser.parse_args(argv)
    out_dir = args.out_dir or os.path.dirname(os.path.abspath(args.file))
    os.makedirs(out_dir, exist_ok=True)
    with h5py.File(args.file, "r") as f:
        title = case_title(f)
        if args.frame is not None or args.frames:
            ks = ([args.frame] if args.frame is not None else []) + (args.frames or [])
            bonds = {None: "auto", True: "all", False: "none"}[args.bonds]
            ylim = args.ylim  # mm, as the frames are drawn
            plot_field(f, out_dir, title, ks, args.field, bonds, args.mirror, ylim)
            return
        plot_energy(f, out_dir, title)
        plot_probes(f, out_dir, title)
        plot_body_probes(f, out_dir, title)


if __name__ == "__main__":
    main()
