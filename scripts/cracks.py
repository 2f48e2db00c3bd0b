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
                 [--before-branching]
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


def fastest(samples, last=None):
    """The largest speed over two sample intervals (1 us for the glass test's 0.5 us samples) of
    (time s, length m) samples, up to samples[last] (default: all); 0 with fewer than three."""
    end = len(samples) if last is None else last + 1
    return max([(samples[i][1] - samples[i - 2][1]) / (samples[i][0] - samples[i - 2][0])
                for i in range(2, end)], default=0.0)


def before_branching(samples, final, window=10e-6):
    """The crack before its first branch, as fracta's glass test measures it
    (tests/physics/test_glass_branching.cpp): samples are (time s, length m) from (0, 0), final the
    last frame's trace with its lasting branches. The tip reaches the junction when the crack is
    as long as its path to the junction, at a time linear between the two samples around it (the
    sample after is up to a frame late); the speed before branching is the mean over the `window`
    before that, the window's start too linear between samples; the fastest speed is over two
    sample intervals, up to the sample after the junction. None without a branch."""
    if not final["branches"]:
        return None
    path = np.array(final["path"])
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])

    def along_to(p):  # length of the path to its point nearest p
        return along[np.argmin(np.hypot(*(path - np.array(p)).T))]

    first = min(final["branches"], key=lambda b: along_to(b["junction"]))
    junction_length = along_to(first["junction"])
    k = next(k for k, (_, length) in enumerate(samples) if length >= junction_length)
    (ta, la), (tb, lb) = samples[k - 1], samples[k]
    t_junction = ta + (tb - ta) * (junction_length - la) / (lb - la)
    times, lengths = [t for t, _ in samples], [length for _, length in samples]
    return dict(junction_m=first["junction"], junction_length_m=float(junction_length),
                branch_time_s=float(t_junction), branch_length_m=final["branches"][0]["length"],
                path_past_junction_m=final["length"] - junction_length,
                speed_before_branching_m_per_s=float(
                    (junction_length - np.interp(t_junction - window, times, lengths)) / window),
                fastest_to_junction_m_per_s=float(fastest(samples, k)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("h5")
    ap.add_argument("--seed", type=float, nargs=2, required=True, metavar=("X", "Y"))
    ap.add_argument("--link", type=float)
    ap.add_argument("--min-branch", type=float)
    ap.add_argument("--json")
    ap.add_argument("--fragments", action="store_true")
    ap.add_argument("--before-branching", action="store_true",
                    help="the first junction, when the tip gets there and the mean speed over the "
                         "10 us before (the glass test's measure; frames 0.5 us apart, as its samples)")
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
    if a.before_branching:
        samples = [(r["t"], r["length"]) for r in rows]
        if samples[0][0] > 0:
            samples.insert(0, (0.0, 0.0))
        b = before_branching(samples, rows[-1])
        if b is None:
            print("\nno branch of MIN_BRANCH at the last frame")
        else:
            print(f"\nfirst junction at ({b['junction_m'][0] * 1e3:.1f}, {b['junction_m'][1] * 1e3:.1f}) mm, "
                  f"{b['junction_length_m'] * 1e3:.2f} mm along the crack, the tip there at "
                  f"{b['branch_time_s'] * 1e6:.2f} us; mean speed over the 10 us before "
                  f"{b['speed_before_branching_m_per_s']:.0f} m/s; fastest over two frames up to it "
                  f"{b['fastest_to_junction_m_per_s']:.0f} m/s")
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
