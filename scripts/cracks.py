#!/usr/bin/python3
"""Crack tip, length, speed history and branches from an output file, frame by frame; the same
tracing as src/host/cracks.cpp (docs/output.md, "Measuring cracks").

The crack is the set of broken bonds (reference midpoints) joined to the seed (a notch tip) by
steps of at most LINK; its tip is the point of the set farthest from the seed along the set, so
damage beside the crack or near the seed is never the tip. A branch leaves the path to the tip
(or an earlier branch) and reaches at least MIN_BRANCH from it, along the set. The speed is the change
of the length along the crack between frames. With --fragments, the fragment mass distribution
of the last frame (cumulative mass fraction against fragment mass), from /frames/K/fragment_mass.

usage: cracks.py OUT.h5 --seed X Y [--link L] [--min-branch B] [--json OUT.json] [--fragments]
       (lengths in m; LINK defaults to 1.5 cells, MIN_BRANCH to 10 cells: a damage band's spurs
       are a few cells long)
"""
import argparse
import heapq
import json
import math

import h5py
import numpy as np


def trace(points, seed, link, min_branch, max_branches=8):
    """Mirror of trace_crack (src/host/cracks.cpp): Dijkstra through the points."""
    n = len(points)
    out = {"found": False, "tip": None, "length": 0.0, "path": [], "branches": [], "points": 0}
    if n == 0:
        return out
    bins = {}
    cells = np.floor(points / link).astype(np.int64)
    for i, (bx, by) in enumerate(cells):
        bins.setdefault((int(bx), int(by)), []).append(i)

    def near(p):
        bx, by = int(math.floor(p[0] / link)), int(math.floor(p[1] / link))
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for j in bins.get((bx + dx, by + dy), ()):
                    d = math.hypot(points[j][0] - p[0], points[j][1] - p[1])
                    if d <= link:
                        yield j, d

    def shortest_paths(sources):
        """Dijkstra from several (point, starting distance) sources: distance, previous, origin."""
        dist, prev, origin = np.full(n, np.inf), np.full(n, -1), np.full(n, -1)
        heap = []
        for i, d in sources:
            if d < dist[i]:
                dist[i], origin[i] = d, i
                heap.append((d, int(i)))
        heapq.heapify(heap)
        while heap:
            d, i = heapq.heappop(heap)
            if d > dist[i]:
                continue
            for j, step in near(points[i]):
                if d + step < dist[j]:
                    dist[j], prev[j], origin[j] = d + step, i, origin[i]
                    heapq.heappush(heap, (dist[j], j))
        return dist, prev, origin

    dist, prev, _ = shortest_paths(list(near(seed)))
    reached = np.isfinite(dist)
    out["points"] = int(reached.sum())
    if not reached.any():
        return out
    tip = int(np.argmax(np.where(reached, dist, -1)))
    out.update(found=True, tip=points[tip].tolist(), length=float(dist[tip]))
    on = np.zeros(n, bool)
    i, path = tip, []
    while i >= 0:
        path.append(points[i].tolist())
        on[i] = True
        i = prev[i]
    out["path"] = [list(seed)] + path[::-1]
    # Branches: the point farthest from the crack through the set (shortest paths from every
    # point on the crack at once); measured from the crack, so a chain beside the path is none.
    while len(out["branches"]) < max_branches:
        far, back, origin = shortest_paths([(i, 0.0) for i in np.nonzero(on)[0]])
        finite = np.isfinite(far)
        best = int(np.argmax(np.where(finite, far, -1)))
        if not finite[best] or far[best] < min_branch:
            break
        out["branches"].append({"junction": points[origin[best]].tolist(),
                                "tip": points[best].tolist(), "length": float(far[best])})
        i = best
        while i >= 0 and not on[i]:
            on[i] = True
            i = back[i]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("h5")
    ap.add_argument("--seed", type=float, nargs=2, required=True, metavar=("X", "Y"))
    ap.add_argument("--link", type=float)
    ap.add_argument("--min-branch", type=float)
    ap.add_argument("--json")
    ap.add_argument("--fragments", action="store_true")
    a = ap.parse_args()
    f = h5py.File(a.h5, "r")
    count = int(f["frames"].attrs.get("count", len(f["frames"])))
    first = f["frames/0"]
    x0 = first["node_position"][:] - first["node_displacement"][:]
    radius = first["particle_radius"][:]
    # The largest disc: a perturbed lattice (node_perturbation) shrinks its interior discs only.
    cell = 2 * float(np.max(radius)) if len(radius) else None
    link = a.link or (1.5 * cell if cell else None)
    if link is None:
        raise SystemExit("cracks.py: no discs in the first frame; give --link")
    min_branch = a.min_branch or 10 * (cell or link)
    rows = []
    print(f"seed ({a.seed[0] * 1e3:.3f}, {a.seed[1] * 1e3:.3f}) mm, link {link * 1e3:.3f} mm, "
          f"branches from {min_branch * 1e3:.3f} mm")
    print("  t(us)  tip x(mm)  tip y(mm)  length(mm)  speed(m/s)  branches (junction -> length mm)")
    for k in range(count):
        g = f[f"frames/{k}"]
        t = float(g["time"][()])
        bn, st = g["bond_nodes"][:], g["bond_state"][:]
        broken = bn[st == 2]
        points = 0.5 * (x0[broken[:, 0]] + x0[broken[:, 1]]) if len(broken) else np.zeros((0, 2))
        r = trace(points, np.array(a.seed), link, min_branch)
        speed = (r["length"] - rows[-1]["length"]) / (t - rows[-1]["t"]) if rows and t > rows[-1]["t"] else 0.0
        rows.append(dict(t=t, speed=speed, **r))
        if r["found"]:
            br = "  ".join(f"({b['junction'][0] * 1e3:.1f}, {b['junction'][1] * 1e3:.1f}) -> {b['length'] * 1e3:.1f}"
                           for b in r["branches"])
            print(f"{t * 1e6:7.2f} {r['tip'][0] * 1e3:10.3f} {r['tip'][1] * 1e3:10.3f} {r['length'] * 1e3:11.3f}"
                  f" {speed:11.1f}  {br}")
        else:
            print(f"{t * 1e6:7.2f}          -          -       0.000         0.0")
    if a.fragments:
        masses = np.sort(f[f"frames/{count - 1}/fragment_mass"][:])[::-1]
        total = masses.sum()
        print(f"\nfragments at the last frame: {len(masses)}, largest {masses[0] / total:.4f} of the mass")
        print("  mass(kg)    cumulative mass fraction of fragments at most this heavy")
        for m in np.unique(np.quantile(masses, np.linspace(0, 1, 11))):
            print(f"  {m:10.4g}  {masses[masses <= m].sum() / total:.4f}")
    if a.json:
        with open(a.json, "w") as out:
            json.dump(rows, out, indent=1)


if __name__ == "__main__":
    main()
