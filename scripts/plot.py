#!/usr/bin/python3
"""Plots from a fracta output file (DESIGN.md 3.3).

    plot.py OUT.h5 [-o DIR]
        energy.png       every energy term (J) vs time (us), and the relative energy error
        probes.png       vx (m/s) and sxx (MPa) of each probe vs time, if the run has probes
        body_probes.png  position (mm) and velocity (m/s) of each body probe, if any
    plot.py OUT.h5 --frame K [--field plastic_strain|von_mises|pressure|sxx|syy|szz|sxy] [-o DIR]
        field_<field>_<K>.png   the field on the elements of frame K (only this plot)

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
from matplotlib.collections import PolyCollection  # noqa: E402
from mpl_toolkits.axes_grid1 import make_axes_locatable  # noqa: E402

ENERGY_TERMS = ["kinetic", "internal", "plastic", "hourglass", "viscous", "contact", "fracture",
                "conversion", "time_discretization", "external", "error"]
US = 1e6   # s -> us
MPA = 1e-6  # Pa -> MPa
MM = 1e3   # m -> mm

# --field name -> (dataset in /frames/K, column of an M x 4 dataset or None, scale, label)
FIELDS = {
    "plastic_strain": ("element_plastic_strain", None, 1.0, "equivalent plastic strain (-)"),
    "von_mises": ("element_von_mises", None, MPA, "von Mises stress (MPa)"),
    "pressure": ("element_pressure", None, MPA, "pressure (MPa)"),
    "sxx": ("element_stress", 0, MPA, r"$\sigma_{xx}$ (MPa)"),
    "syy": ("element_stress", 1, MPA, r"$\sigma_{yy}$ (MPa)"),
    "szz": ("element_stress", 2, MPA, r"$\sigma_{zz}$ (MPa)"),
    "sxy": ("element_stress", 3, MPA, r"$\sigma_{xy}$ (MPa)"),
}
SIGNED = {"pressure", "sxx", "syy", "szz", "sxy"}


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

    # /history/energy/error is already relative (DESIGN.md 1.4):
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


def plot_field(f, out_dir, title, k, field):
    group = f"frames/{k}"
    if group not in f:
        frames = len(f["frames"]) if "frames" in f else 0
        sys.exit(f"plot.py: {f.filename} has no frame {k} ({frames} frames)")
    g = f[group]
    dataset, column, scale, label = FIELDS[field]
    if dataset not in g:
        have = sorted(n for n, (d, _, _, _) in FIELDS.items() if d in g)
        sys.exit(f"plot.py: frame {k} has no {dataset}; fields in this frame: "
                 f"{', '.join(have) or 'none'} (see [output] fields in the case)")
    conn = g["element_nodes"][:]
    if conn.shape[0] == 0:
        sys.exit(f"plot.py: frame {k} has no elements")
    pos = g["node_position"][:] * MM
    values = g[dataset][:]
    values = (values if column is None else values[:, column]) * scale
    time = float(g["time"][()])

    fig, ax = plt.subplots(figsize=(9, 6))
    signed = field in SIGNED
    cmap = "coolwarm" if signed else "viridis"
    polys = PolyCollection(pos[conn], array=values, cmap=cmap,
                           edgecolors=(0, 0, 0, 0.25) if conn.shape[0] <= 5000 else "face",
                           linewidths=0.3)
    if signed:
        vmax = float(np.max(np.abs(values))) or 1.0
        polys.set_clim(-vmax, vmax)
    ax.add_collection(polys)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(with_title(f"{field}, frame {k}, t = {time * US:.3g} µs", title))
    cax = make_axes_locatable(ax).append_axes("right", size="3%", pad=0.1)  # as tall as the plot
    fig.colorbar(polys, cax=cax, label=label)
    fig.tight_layout()
    return save(fig, out_dir, f"field_{field}_{k}.png")


def save(fig, out_dir, name):
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    print(f"wrote {path}")
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("file", help="fracta output file (.h5)")
    parser.add_argument("-o", "--out-dir", help="where to write the PNGs (default: beside FILE)")
    parser.add_argument("--frame", type=int, help="render frame K (only that plot)")
    parser.add_argument("--field", choices=sorted(FIELDS), default="von_mises",
                        help="element field for --frame (default: von_mises)")
    args = parser.parse_args(argv)
    out_dir = args.out_dir or os.path.dirname(os.path.abspath(args.file))
    os.makedirs(out_dir, exist_ok=True)
    with h5py.File(args.file, "r") as f:
        title = case_title(f)
        if args.frame is not None:
            plot_field(f, out_dir, title, args.frame, args.field)
            return
        plot_energy(f, out_dir, title)
        plot_probes(f, out_dir, title)
        plot_body_probes(f, out_dir, title)


if __name__ == "__main__":
    main()
