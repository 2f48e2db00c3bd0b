#!/usr/bin/env python3
"""Rewrites the generated tables of docs/performance.md from bench/results/: every block
between `<!-- BEGIN name -->` and `<!-- END name -->` is replaced; the prose around is kept.

Usage: /usr/bin/python3 bench/update_docs.py [--results bench/results] [--doc docs/performance.md]
                                             [--status "preliminary: ..."]
"""
import argparse
import csv
import json
import math
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PHASES = ["fe_forces", "bond_forces", "contact_search", "contact_forces", "integrate",
          "conversion", "output", "other"]


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def fmt(x, spec):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return format(x, spec)


def machine_block(results, status):
    lines = [f"Status: **{status}**", ""]
    path = os.path.join(results, "penetration.json")
    if os.path.exists(path):
        m = json.load(open(path))["machine"]
        lines.append(f"Machine: {m['cpu']}, {m['cores']} cores, Linux {m['kernel']}; "
                     f"commit `{m['commit']}`; {m['date_utc']} UTC; 1-min load at the end of "
                     f"the throughput runs {m['load_1min_at_end']}.")
    return "\n".join(lines)


def penetration_block(results):
    path = os.path.join(results, "penetration.json")
    if not os.path.exists(path):
        return "(not run)"
    runs = json.load(open(path))["runs"]
    t1 = table(["level", "cell (mm)", "threads", "nodes", "active elements", "particles", "bonds",
                "contacts", "steps", "steps/s", "M entity-steps/s", "M bond-steps/s",
                "peak RSS (MB)", "setup (s)", "speed-up"],
               [[r["level"], fmt(r["cell_size_m"] * 1e3, ".3f"), r["threads"], r["nodes"],
                 fmt(r["active_elements"], ".0f"), fmt(r["particles"], ".0f"),
                 fmt(r["bonds"], ".0f"), fmt(r["contacts"], ".0f"), r["steps"],
                 fmt(r["steps_per_s"], ".2f"), fmt(r["entity_steps_per_s"] / 1e6, ".3f"),
                 fmt(r["bond_steps_per_s"] / 1e6, ".3f"), fmt(r["peak_rss_mb"], ".0f"),
                 fmt(r["setup_s"], ".2f"), fmt(r.get("speedup_vs_1_thread"), ".2f")]
                for r in runs])
    t2 = table(["level", "threads"] + [p.replace("_", " ") + " %" for p in PHASES] +
               ["contact search calls"],
               [[r["level"], r["threads"]] + [fmt(r[p + "_pct"], ".1f") for p in PHASES] +
                [r["phase_calls"]["contact_search"]] for r in runs])
    return t1 + "\n\nPhase split (% of the timed window):\n\n" + t2


def paper_block(results):
    out = []
    for t in (1, 2):
        path = os.path.join(results, f"paper_efficiency_t{t}.json")
        if not os.path.exists(path):
            continue
        d = json.load(open(path))
        out.append(f"**{d['threads']} thread(s)**, {d['steps']} steps, median of "
                   f"{d['repeats']} runs:\n")
        out.append(table(
            ["method", "elements", "particles", "time (s)", "/ DE only", "paper (s)",
             "paper / DE only", "contact search calls"],
            [[r["method"], r["elements"], r["particles"], fmt(r["seconds"], ".3f"),
              fmt(100 * r["ratio_to_de"], ".1f") + "%",
              fmt(r["paper_seconds"], ".2f") if r["paper_seconds"] else "-",
              (fmt(100 * r["paper_ratio_to_de"], ".1f") + "%") if r["paper_ratio_to_de"]
              else "-", r["phases"]["contact_search"]["calls"]] for r in d["table3"]]))
        out.append(f"\nAdaptive-capable plate (nothing converts) / pure FE plate: "
                   f"**{d['adaptive_over_fe']:.3f}** (target <= 1.05).\n")
        out.append("Phase split (s / calls):\n")
        out.append(table(["method"] + [p.replace("fracta::", "") for p in PHASES[:6]],
                         [[r["method"]] + [f"{r['phases'][p]['s']:.3f} / {r['phases'][p]['calls']}"
                                           for p in PHASES[:6]] for r in d["table3"]]))
        if "fig8" in d:
            out.append(f"\nFig. 8 analogue ({d['threads']} thread(s), {d['steps']} steps; "
                       f"the paper gives a plot only):\n")
            out.append(table(
                ["cells", "discs", "FE (s)", "DE pre-search (s)", "DE traversal (s)",
                 "traversal / pre-search", "DE pre-search / FE"],
                [[r["cells"], r["discs"], fmt(r["fe_s"], ".3f"), fmt(r["de_presearch_s"], ".3f"),
                  fmt(r["de_traversal_s"], ".3f"),
                  fmt(r["de_traversal_s"] / r["de_presearch_s"], ".2f"),
                  fmt(r["de_presearch_s"] / r["fe_s"], ".2f")] for r in d["fig8"]]))
        out.append("")
    return "\n".join(out) if out else "(not run)"


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def plate_block(results):
    path = os.path.join(results, "tradeoff_plate.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    pct = lambda r, k: fmt(100 * float(r[k]), ".2f") if r["status"] == "0" else "-"  # noqa
    return table(["method", "cell (mm)", "dt_safety", "steps", "wall (s)", "wave speed err %",
                  "plateau err %", "peak stress err %", "energy err %"],
                 [[r["method"], r["cell_mm"], r["dt_safety"], r["steps"],
                   fmt(float(r["wall_s"]), ".2f"), pct(r, "err_wave_speed"),
                   pct(r, "err_plateau"), pct(r, "err_peak_stress"), pct(r, "energy_error")]
                  for r in rows])


def penetration_tradeoff_block(results):
    path = os.path.join(results, "tradeoff_penetration.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    ok = lambda r: r["status"] == "0"  # noqa
    return table(["cell (mm)", "conversion strain", "hourglass", "steps", "wall (s)",
                  "depth (mm)", "residual v (m/s)", "converted", "energy err %",
                  "depth err %", "velocity err %"],
                 [[r["cell_mm"], r["conversion_strain"], r["hourglass"] +
                   (" (reference)" if r["reference"] == "True" else ""), r["steps"],
                   fmt(float(r["wall_s"]), ".2f"),
                   fmt(float(r["depth_mm"]), ".3f") if ok(r) else "-",
                   fmt(float(r["residual_velocity"]), ".2f") if ok(r) else "-",
                   r["conversions"] if ok(r) else "-",
                   fmt(100 * float(r["energy_error"]), ".3f") if ok(r) else "-",
                   fmt(100 * float(r["err_depth"]), ".2f") if ok(r) else "-",
                   fmt(100 * float(r["err_residual_velocity"]), ".2f") if ok(r) else
                   f"exit {r['status']}"] for r in rows])


def speed_tradeoff_block(results):
    path = os.path.join(results, "tradeoff_speed.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    ok = lambda r: r["status"] == "0"  # noqa
    return table(["cell (mm)", "impact speed (m/s)", "exit", "steps", "wall (s)",
                  "smallest step / initial", "energy err %", "converted", "elements left"],
                 [[r["cell_mm"], r["speed_mps"], r["status"], r["steps"] if ok(r) else "-",
                   fmt(float(r["wall_s"]), ".2f") if ok(r) else "-",
                   fmt(float(r["dt_min_over_initial"]), ".2f") if ok(r) else "-",
                   fmt(100 * float(r["energy_error"]), ".2f") if ok(r) else "-",
                   r["conversions"] if ok(r) else "-", r["elements_left"] if ok(r) else "-"]
                  for r in rows])


def fragmentation_tradeoff_block(results):
    path = os.path.join(results, "tradeoff_fragmentation.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    return table(["cell (µm)", "seeds", "mean size (µm)", "seed spread (µm)",
                  "standard error (µm)", "size / ZMR fit", "wall, all seeds (s)"],
                 [[r["cell_um"], r["seeds"], fmt(float(r["mean_size_um"]), ".1f"),
                   fmt(float(r["sd_um"]), ".1f"), fmt(float(r["standard_error_um"]), ".1f"),
                   fmt(float(r["size_over_zmr"]), ".3f"), fmt(float(r["wall_s"]), ".2f")]
                  for r in rows])


def crackpath_tradeoff_block(results):
    path = os.path.join(results, "tradeoff_crackpath.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    return table(["cell (mm)", "seeds", "mean angle (°)", "crack spread (°)",
                  "standard error (°)", "mean − 70°", "wall, all seeds (s)",
                  "regular lattice (°)"],
                 [[r["cell_mm"], r["seeds"], fmt(float(r["mean_deg"]), ".1f"),
                   fmt(float(r["sd_deg"]), ".1f"), fmt(float(r["standard_error_deg"]), ".1f"),
                   fmt(float(r["off_published_deg"]), "+.1f"), fmt(float(r["wall_s"]), ".1f"),
                   r["regular_deg"]] for r in rows])


def crackspeed_tradeoff_block(results):
    path = os.path.join(results, "tradeoff_crackspeed.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    return table(["cell (mm)", "process zone (cells)", "crack length a_E at 4 µs (mm)",
                  "a_E / Freund (1.50 mm)", "speed over the last µs (m/s)", "wall (s)"],
                 [[r["cell_mm"], fmt(float(r["process_zone_cells"]), ".1f"),
                   fmt(float(r["a_end_mm"]), ".3f"), fmt(float(r["a_over_freund"]), ".3f"),
                   fmt(float(r["speed_last_us"]), ".0f"), fmt(float(r["wall_s"]), ".1f")]
                  for r in rows])


def output_cost_block(results):
    path = os.path.join(results, "output_cost.csv")
    if not os.path.exists(path):
        return "(not run)"
    rows = read_csv(path)
    return table(["scene", "nodes", "commits", "precision", "compression", "frames",
                  "ms per frame", "gathering", "frame files", "final copy",
                  "B per node and frame"],
                 [[r["scene"], r["nodes"], r["commits"], r["precision"], r["compression"],
                   r["frames"], fmt(float(r["ms_per_frame"]), ".3g"),
                   fmt(float(r["gather_ms"]), ".3g"), fmt(float(r["files_ms"]), ".3g"),
                   fmt(float(r["copy_ms"]), ".3g"),
                   fmt(float(r["bytes_per_node_frame"]), ".1f")] for r in rows])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--results", default=os.path.join(ROOT, "bench", "results"))
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "performance.md"))
    ap.add_argument("--status", default="regenerated by bench/run_all.sh")
    args = ap.parse_args()
    blocks = {
        "machine": machine_block(args.results, args.status),
        "penetration": penetration_block(args.results),
        "paper": paper_block(args.results),
        "tradeoff_plate": plate_block(args.results),
        "tradeoff_penetration": penetration_tradeoff_block(args.results),
        "tradeoff_speed": speed_tradeoff_block(args.results),
        "tradeoff_fragmentation": fragmentation_tradeoff_block(args.results),
        "tradeoff_crackpath": crackpath_tradeoff_block(args.results),
        "tradeoff_crackspeed": crackspeed_tradeoff_block(args.results),
        "output_cost": output_cost_block(args.results),
    }
    text = open(args.doc).read()
    for name, body in blocks.items():
        pattern = re.compile(rf"(<!-- BEGIN {name} -->\n).*?(<!-- END {name} -->)", re.S)
        if not pattern.search(text):
            sys.exit(f"update_docs: {args.doc} has no BEGIN/END {name} markers")
        text = pattern.sub(lambda m: m.group(1) + body.strip() + "\n" + m.group(2), text)
    open(args.doc, "w").write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
