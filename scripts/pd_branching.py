#!/usr/bin/env python3
"""The published simulation of the glass branching benchmark, reproduced independently.

Ha & Bobaru (2010, Int. J. Fract. 162) ran the glass plate of
cases/validation/ha_bobaru_plate.toml with bond-based peridynamics: the prototype microelastic
brittle (PMB) model of Silling & Askari (2005) in 2D plane stress, horizon delta = 1 mm on a grid
of delta / 4. This script is that model, written from its published equations alone (numpy, no
fracta code), so that fracta's branching statistics can be set beside what the published model
itself does when its bonds are not all equal (docs/validation.md, "The published model with
heterogeneous bonds"). It is a reference for the report, not part of fracta.

Model (SI units, thickness t = 1 m):
  pair force density   f = c s (xi + eta) / |xi + eta|,   s = (|xi + eta| - |xi|) / |xi|
  micromodulus         c = 9 E / (pi t delta^3)           (2D plane stress; fixes nu = 1/3)
  critical stretch     s0 = sqrt(4 pi G0 / (9 E delta))   (a bond breaks for good at s > s0)
  neighbours           every particle within |xi| <= delta (no volume or surface correction)
  load                 the traction sigma as a body force sigma / dx on the outermost rows
  pre-crack            bonds crossing y = 20 mm at x <= 50 mm are cut at t = 0
  time stepping        velocity Verlet, dt = 25 ns (stable below ~67 ns on this grid)
  damage               phi = 1 - intact / initial bonds of a particle
With --seed each bond's s0 is scaled by a Weibull factor of unit mean and modulus --weibull
(fracta's case draws its bond strengths so, with m = 6).

Measured as fracta's test measures (tests/physics/test_glass_branching.cpp), on the damage map
(phi >= 0.35, the pre-crack's faces start at 0.42): the crack is the 8-connected damaged set
that holds the pre-crack; its tip the rightmost damaged particle; its length the path length
through the damaged cells from x = 50 mm; a lasting branch is a split of the crack into two
arms of at least 10 mm each at the end; the junction is the last column before the split.

  scripts/pd_branching.py --load 2e6 [--seed K --weibull 6] [--json out.json] [--png out.png]
  scripts/pd_branching.py --stack out.png a.png b.png ...   (pictures one above the other)

One run to 43 us takes about 2 minutes on one core (1.5 M bonds, 1720 steps).
"""
import argparse
import heapq
import json
import math
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

E, RHO, G0 = 72e9, 2440.0, 3.8  # Pa, kg/m^3, J/m^2: soda-lime glass (Ha & Bobaru 2010)
WIDTH, HEIGHT = 0.100, 0.040  # m
PRECRACK_TIP, MIDLINE = 0.050, 0.020  # m
DAMAGED = 0.35  # phi of a cracked particle
LASTING = 10e-3  # m: a branch of at least this length at the end (fracta's test)


def build(horizon, per_horizon, seed, weibull):
    """Particles on the grid ((i + 1/2) dx, (j + 1/2) dx), the bond pairs, their s0."""
    dx = horizon / per_horizon
    nx, ny = int(round(WIDTH / dx)), int(round(HEIGHT / dx))
    # Bonds by grid offsets within the horizon (each pair once: di > 0, or di = 0 and dj > 0).
    offsets = [(di, dj) for di in range(0, per_horizon + 1)
               for dj in range(-per_horizon, per_horizon + 1)
               if (di > 0 or dj > 0) and di * di + dj * dj <= per_horizon * per_horizon]
    index = np.arange(nx * ny).reshape(nx, ny)  # particle k = i ny + j
    first, second = [], []
    for di, dj in offsets:
        a = index[0:nx - di, max(0, -dj):ny - max(0, dj)]
        b = index[di:nx, max(0, dj):ny + min(0, dj)]
        first.append(a.ravel())
        second.append(b.ravel())
    i = np.concatenate(first)
    j = np.concatenate(second)
    grid = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij"), -1).reshape(-1, 2)
    x = (grid + 0.5) * dx
    xi = x[j] - x[i]
    length = np.hypot(xi[:, 0], xi[:, 1])
    # The pre-crack: bonds whose segment crosses the midline at x <= 50 mm.
    ya, yb = x[i, 1] - MIDLINE, x[j, 1] - MIDLINE
    crosses = ya * yb < 0
    x_cross = x[i, 0] + (-ya) / np.where(crosses, yb - ya, 1.0) * xi[:, 0]
    # (those crossing at the tip itself too, with a margin: the cut stays mirror-symmetric)
    intact = ~(crosses & (x_cross <= PRECRACK_TIP + 1e-3 * dx))
    s0 = np.full(len(i), math.sqrt(4 * math.pi * G0 / (9 * E * horizon)))
    if seed is not None:
        u = np.random.default_rng(seed).random(len(i))
        s0 *= (-np.log(u)) ** (1.0 / weibull) / math.gamma(1.0 + 1.0 / weibull)
    return dict(dx=dx, nx=nx, ny=ny, x=x, grid=grid, i=i, j=j, xi=xi, length=length,
                intact=intact, s0=s0)


def simulate(m, load, horizon, end_time, dt, snapshot_every):
    """Velocity Verlet to end_time; the damage map every snapshot_every (s)."""
    dx, nx, ny = m["dx"], m["nx"], m["ny"]
    n = nx * ny
    i, j, xi, length, intact, s0 = m["i"], m["j"], m["xi"], m["length"], m["intact"], m["s0"]
    c_over_rho = 9 * E / (math.pi * horizon ** 3) * dx * dx / RHO  # c V / rho, t = 1
    initial = np.bincount(i, minlength=n) + np.bincount(j, minlength=n)  # before the cut
    both = np.concatenate([i, j])
    body = np.zeros((n, 2))
    body[m["grid"][:, 1] == ny - 1, 1] = load / dx / RHO
    body[m["grid"][:, 1] == 0, 1] = -load / dx / RHO

    def acceleration(u):
        y = xi + (u[j] - u[i])
        stretched = np.hypot(y[:, 0], y[:, 1])
        s = (stretched - length) / length
        intact[s > s0] = False
        f = np.where(intact, c_over_rho * s / stretched, 0.0)
        fx, fy = f * y[:, 0], f * y[:, 1]
        ax = np.bincount(both, weights=np.concatenate([fx, -fx]), minlength=n)
        ay = np.bincount(both, weights=np.concatenate([fy, -fy]), minlength=n)
        return np.column_stack([ax, ay]) + body

    u = np.zeros((n, 2))
    v = np.zeros((n, 2))
    a = acceleration(u)
    steps = int(round(end_time / dt))
    every = int(round(snapshot_every / dt))
    times, damage = [], []
    for step in range(1, steps + 1):
        v += 0.5 * dt * a
        u += dt * v
        a = acceleration(u)
        v += 0.5 * dt * a
        if step % every == 0 or step == steps:
            alive = np.bincount(i, weights=intact, minlength=n) + np.bincount(
                j, weights=intact, minlength=n)
            times.append(step * dt)
            damage.append((1.0 - alive / initial).reshape(nx, ny).astype(np.float32))
    return np.array(times), damage


NEIGHBOURS = [(di, dj, math.hypot(di, dj)) for di in (-1, 0, 1) for dj in (-1, 0, 1)
              if di or dj]


def crack_cells(phi, dx):
    """The 8-connected damaged cells that hold the pre-crack (a set of (i, j))."""
    damaged = phi >= DAMAGED
    nx, ny = phi.shape
    i0, j0 = int(0.045 / dx), ny // 2
    start = [(i0, jj) for jj in range(j0 - 2, j0 + 2) if damaged[i0, jj]]
    seen = set(start)
    stack = list(start)
    while stack:
        ci, cj = stack.pop()
        for di, dj, _ in NEIGHBOURS:
            q = (ci + di, cj + dj)
            if 0 <= q[0] < nx and 0 <= q[1] < ny and q not in seen and damaged[q]:
                seen.add(q)
                stack.append(q)
    return seen


def path_lengths(cells, sources, dx):
    """Path length through `cells` from the nearest source cell (Dijkstra, 8 neighbours)."""
    dist = {s: 0.0 for s in sources}
    heap = [(0.0, s) for s in sources]
    while heap:
        d, p = heapq.heappop(heap)
        if d > dist[p]:
            continue
        for di, dj, w in NEIGHBOURS:
            q = (p[0] + di, p[1] + dj)
            if q in cells and d + w * dx < dist.get(q, math.inf):
                dist[q] = d + w * dx
                heapq.heappush(heap, (dist[q], q))
    return dist


def components(cells):
    """The 8-connected components of a set of cells."""
    left, parts = set(cells), []
    while left:
        seed = left.pop()
        part, stack = {seed}, [seed]
        while stack:
            p = stack.pop()
            for di, dj, _ in NEIGHBOURS:
                q = (p[0] + di, p[1] + dj)
                if q in left:
                    left.remove(q)
                    part.add(q)
                    stack.append(q)
        parts.append(part)
    return parts


def tip_and_length(phi, dx):
    cells = crack_cells(phi, dx)
    start = int(PRECRACK_TIP / dx) - 1  # the column of the pre-crack's tip
    right = {p for p in cells if p[0] >= start}
    if not right:
        return PRECRACK_TIP, 0.0
    dist = path_lengths(right, [p for p in right if p[0] == start], dx)
    tip = (max(p[0] for p in right) + 0.5) * dx
    return tip, max(dist.values()) if dist else 0.0


def lasting_split(phi, dx):
    """The first column where the crack parts into two arms of >= LASTING each, or None."""
    cells = crack_cells(phi, dx)
    last = max(p[0] for p in cells)
    for column in range(int(PRECRACK_TIP / dx), last + 1):
        arms = []
        for part in components([p for p in cells if p[0] >= column]):
            entry = [p for p in part if p[0] == column]
            if not entry:
                continue
            dist = path_lengths(part, entry, dx)
            far = max(dist, key=dist.get)
            arms.append(dict(length=dist[far] + dx, tip=((far[0] + 0.5) * dx, (far[1] + 0.5) * dx),
                             entry_y=(sum(p[1] for p in entry) / len(entry) + 0.5) * dx))
        long_arms = [arm for arm in arms if arm["length"] >= LASTING]
        if len(long_arms) >= 2:
            before = [p[1] for p in cells if p[0] == column - 1]
            return dict(junction=((column - 0.5) * dx, (sum(before) / len(before) + 0.5) * dx),
                        arms=sorted(long_arms, key=lambda arm: -arm["entry_y"]))
    return None


def measure(times, damage, dx, end_time):
    history = [(t,) + tip_and_length(phi, dx) for t, phi in zip(times, damage)]
    end = min(range(len(times)), key=lambda k: abs(times[k] - end_time))
    split = lasting_split(damage[end], dx)
    result = dict(time_s=float(times[end]), crack_length_m=history[end][2],
                  tip_x_m=history[end][1], branched=split is not None)
    # 1-us speeds of the path length (snapshots two apart at 0.5 us).
    speeds = [(history[k][2] - history[k - 2][2]) / (history[k][0] - history[k - 2][0])
              for k in range(2, end + 1)]
    result["fastest_1us_m_per_s"] = max(speeds) if speeds else 0.0
    if split:
        xj = split["junction"][0]
        reached = next(k for k in range(len(history)) if history[k][1] >= xj)
        t_branch = history[reached][0]
        earlier = min(range(len(history)), key=lambda k: abs(history[k][0] - (t_branch - 10e-6)))
        result.update(
            junction_m=split["junction"], arm_lengths_m=[a["length"] for a in split["arms"]],
            branch_time_s=t_branch,
            speed_before_branching_m_per_s=(history[reached][2] - history[earlier][2]) /
            (t_branch - history[earlier][0]),
            fastest_1us_to_junction_m_per_s=max(speeds[:max(1, reached - 1)]))
    result["history"] = [[round(t * 1e6, 3), round(x * 1e3, 3), round(l * 1e3, 3)]
                         for t, x, l in history]
    return result


def picture(phi, dx, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 3.4))
    ax.imshow(phi.T, origin="lower", extent=[0, WIDTH * 1e3, 0, HEIGHT * 1e3], cmap="jet",
              vmin=0, vmax=0.6)
    ax.set_title(title)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def stack(out, pictures):
    """One picture of several --png pictures of the same size, top to bottom."""
    import matplotlib.image as image
    image.imsave(out, np.vstack([image.imread(path) for path in pictures]))


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--stack":  # --stack OUT.png A.png B.png ...
        stack(sys.argv[2], sys.argv[3:])
        return
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--load", type=float, default=2e6, help="edge traction (Pa)")
    p.add_argument("--seed", type=int, help="Weibull bond strengths of this seed (none: all equal)")
    p.add_argument("--weibull", type=float, default=6.0, help="Weibull modulus of the s0 factors")
    p.add_argument("--horizon", type=float, default=1e-3, help="delta (m)")
    p.add_argument("--per-horizon", type=int, default=4, help="grid spacings per horizon")
    p.add_argument("--end-time", type=float, default=43e-6, help="s")
    p.add_argument("--dt", type=float, default=25e-9, help="s")
    p.add_argument("--json", help="write the measurements here")
    p.add_argument("--png", help="damage map at the end")
    a = p.parse_args()
    started = time.time()
    model = build(a.horizon, a.per_horizon, a.seed, a.weibull)
    times, damage = simulate(model, a.load, a.horizon, a.end_time, a.dt, 0.5e-6)
    result = measure(times, damage, model["dx"], a.end_time)
    result.update(load_pa=a.load, seed=a.seed, weibull=a.weibull if a.seed is not None else None,
                  bonds=int(len(model["i"])), wall_s=round(time.time() - started, 1))
    summary = {k: v for k, v in result.items() if k != "history"}
    json.dump(summary, sys.stdout, indent=1)
    print()
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)
    if a.png:
        label = "equal bonds" if a.seed is None else f"Weibull m = {a.weibull:g}, seed {a.seed}"
        picture(damage[-1], model["dx"], a.png,
                f"bond-based PD, {a.load / 1e6:g} MPa, {label}, {times[-1] * 1e6:.0f} us")


if __name__ == "__main__":
    main()
