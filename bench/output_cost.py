#!/usr/bin/env python3
"""What output costs (docs/performance.md, "Output"): wall time per frame against the number
of frames a run writes, and bytes per node and frame for each frame storage setting.

Runs `fracta run` (one thread) on
  - the paper's plate (cases/plate_case_b.toml, 2145 nodes), a frame every microsecond, to
    100, 1000 and 10000 frames with the commits spaced (the default), and to 100 and 1000 with a
    commit at every frame (the FRACTA_COMMIT_EVERY_FRAME test hook: how every frame was written
    before the commits were spaced);
  - the penetration scene at level 8 (0.05 mm cells, 1.16e6 nodes, 2 threads), 5 frames in its
    first 40 steps, in single and double precision and with compression 1;
  - the plate, 100 frames, in each storage setting (bytes per node and frame).
Reads /run@output_seconds and the frame count from each output, the split of the frame time
from the run's summary line, and the size of the finished file. Writes output_cost.csv to --out.

Usage: bench/output_cost.py [--fracta build/fracta] [--out bench/results] [--quick]
(about 6 minutes; --quick skips the 10000-frame run and the level-8 scene).
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

import h5py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUMMARY = re.compile(r"frames ([0-9.]+) s \((\d+) frames, [^;]+; gathering ([0-9.-]+) s, "
                     r"files ([0-9.-]+) s, final copy ([0-9.-]+) s\)")


def run(fracta, case, out, sets, threads, env_extra=None):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="spread",
               OMP_PLACES="threads")
    env.update(env_extra or {})
    cmd = [fracta, "run", case, "-o", out, "--set"] + sets
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"output_cost: {' '.join(cmd)} failed ({p.returncode}):\n{p.stdout}{p.stderr}")
    m = SUMMARY.search(p.stdout)
    if not m:
        sys.exit(f"output_cost: no summary line in:\n{p.stdout}")
    with h5py.File(out, "r") as f:
        frames = int(f["frames"].attrs["count"])
        nodes = f["frames/0/node_position"].shape[0]
        output_s = float(f["run"].attrs["output_seconds"])
        wall_s = float(f["run"].attrs["wall_seconds"])
    size = os.path.getsize(out)
    return {
        "frames": frames, "nodes": nodes, "wall_s": wall_s, "output_s": output_s,
        "ms_per_frame": 1e3 * output_s / frames,
        "gather_ms": 1e3 * float(m.group(3)) / frames,
        "files_ms": 1e3 * float(m.group(4)) / frames,
        "copy_ms": 1e3 * float(m.group(5)) / frames,
        "bytes_per_node_frame": size / frames / nodes,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fracta", default=os.path.join(ROOT, "build", "fracta"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results"))
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    plate = os.path.join(ROOT, "cases", "plate_case_b.toml")
    penetration = os.path.join(ROOT, "cases", "penetration.toml")
    rows = []
    with tempfile.TemporaryDirectory(prefix="fracta_output_cost_") as tmp:
        out = os.path.join(tmp, "run.h5")

        def add(scene, commits, precision, compression, result):
            rows.append(dict(scene=scene, commits=commits, precision=precision,
                             compression=compression, **result))
            r = rows[-1]
            print(f"{scene:12s} {commits:11s} {precision:6s} z{compression} "
                  f"{r['frames']:6d} frames {r['ms_per_frame']:8.3f} ms/frame "
                  f"(gather {r['gather_ms']:.3f}, files {r['files_ms']:.3f}, "
                  f"copy {r['copy_ms']:.3f}) {r['bytes_per_node_frame']:7.1f} B/node/frame",
                  flush=True)
            os.remove(out)

        counts = [100, 1000] + ([] if args.quick else [10000])
        for n in counts:
            add("plate", "spaced", "single", 0,
                run(args.fracta, plate, out, [f"simulation.end_time={n}e-6"], 1))
        for n in [100, 1000]:
            add("plate", "every frame", "single", 0,
                run(args.fracta, plate, out, [f"simulation.end_time={n}e-6"], 1,
                    {"FRACTA_COMMIT_EVERY_FRAME": "1"}))
        for precision, compression in [("double", 0), ("single", 1), ("single", 9)]:
            add("plate", "spaced", precision, compression,
                run(args.fracta, plate, out,
                    ["simulation.end_time=100e-6", f'output.precision="{precision}"',
                     f"output.compression={compression}"], 1))
        if not args.quick:
            for precision, compression in [("single", 0), ("double", 0), ("single", 1)]:
                add("penetration8", "spaced", precision, compression,
                    run(args.fracta, penetration, out,
                        ["body.0.cell_size=5e-5", "body.1.cell_size=5e-5",
                         "simulation.end_time=9.1e-8", "simulation.output_interval=2.27e-8",
                         f'output.precision="{precision}"', f"output.compression={compression}"],
                        2))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "output_cost.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
