#!/usr/bin/env python3
"""Merges the per-process results of bench/penetration (one JSON per level and thread count)
into the throughput table: prints it and writes penetration.csv and penetration.json.

Usage: /usr/bin/python3 bench/penetration_table.py RUN_DIR RESULTS_DIR
"""
import csv
import glob
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmeta import machine_info  # noqa: E402

PHASES = ["fe_forces", "bond_forces", "contact_search", "contact_forces", "integrate",
          "conversion", "output", "other"]
COLUMNS = ["level", "cell_size_m", "threads", "nodes", "active_elements", "particles", "bonds",
           "contacts", "steps", "conversions_in_window", "setup_s", "run_s", "steps_per_s",
           "entity_steps_per_s", "bond_steps_per_s", "peak_rss_mb"]


def main():
    run_dir, out_dir = sys.argv[1], sys.argv[2]
    rows = [json.load(open(p)) for p in glob.glob(os.path.join(run_dir, "*.json"))]
    rows.sort(key=lambda r: (r["level"], r["threads"]))
    base = {(r["level"]): r for r in rows if r["threads"] == 1}
    for r in rows:
        total = sum(r["phase_s"][p] for p in PHASES)
        for p in PHASES:
            r[p + "_pct"] = 100.0 * r["phase_s"][p] / total if total > 0 else 0.0
        b = base.get(r["level"])
        r["speedup_vs_1_thread"] = r["steps_per_s"] / b["steps_per_s"] if b else None

    print("Penetration throughput (cases/penetration.toml, cell size 0.4 mm / level; "
          "counts are the mean of the timed window's first and last state)")
    print(f"{'lvl':>3} {'thr':>3} {'nodes':>9} {'elements':>9} {'particles':>9} {'bonds':>9} "
          f"{'contacts':>8} {'steps':>5} {'steps/s':>8} {'Mentity-st/s':>12} {'Mbond-st/s':>10} "
          f"{'RSS MB':>7} {'setup s':>7} {'speed-up':>8}")
    for r in rows:
        sp = r["speedup_vs_1_thread"]
        print(f"{r['level']:>3} {r['threads']:>3} {r['nodes']:>9} {r['active_elements']:>9.0f} "
              f"{r['particles']:>9.0f} {r['bonds']:>9.0f} {r['contacts']:>8.0f} {r['steps']:>5} "
              f"{r['steps_per_s']:>8.2f} {r['entity_steps_per_s'] / 1e6:>12.3f} "
              f"{r['bond_steps_per_s'] / 1e6:>10.3f} {r['peak_rss_mb']:>7.0f} "
              f"{r['setup_s']:>7.2f} {sp if sp else float('nan'):>8.2f}")
    print()
    print("Phase split (% of the timed window: step regions + output; 'other' = rest of the step)")
    print(f"{'lvl':>3} {'thr':>3} " + " ".join(f"{p:>14}" for p in PHASES))
    for r in rows:
        print(f"{r['level']:>3} {r['threads']:>3} " +
              " ".join(f"{r[p + '_pct']:>13.1f}%" for p in PHASES))

    os.makedirs(out_dir, exist_ok=True)
    fields = COLUMNS + ["speedup_vs_1_thread"] + [p + "_s" for p in PHASES] + \
        [p + "_pct" for p in PHASES] + ["contact_search_calls"]
    with open(os.path.join(out_dir, "penetration.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for r in rows:
            flat = dict(r)
            for p in PHASES:
                flat[p + "_s"] = r["phase_s"][p]
            flat["contact_search_calls"] = r["phase_calls"]["contact_search"]
            w.writerow([flat.get(k) for k in fields])
    with open(os.path.join(out_dir, "penetration.json"), "w") as f:
        json.dump({"machine": machine_info(), "runs": rows}, f, indent=1)


if __name__ == "__main__":
    main()
