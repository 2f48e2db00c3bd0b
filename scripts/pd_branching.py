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

Measured as fracta's test measures (tests/physics/test_glass_branching.cpp), with the project's
crack tracer (scripts/cracks.py) on the damaged particles (phi >= 0.35) right of the pre-crack's
tip, as fracta's on its broken bonds: the crack is the set joined to the tip by steps of at most
1.5 grid spacings, its length the path to the farthest point; a lasting branch leaves that path
and reaches 10 mm from it at the end; the tip reaches the junction when the crack is as long as
the path to it (linear in time between the 0.5 us samples, as the test's); the speed before
branching is the mean over the 10 us before that.

  scripts/pd_branching.py --load 2e6 [--seed K --weibull 6] [--json out.json] [--png out.png]
  scripts/pd_branching.py --stack out.png a.png b.png ...   (pictures one above the other)

One run to 43 us takes about 2 minutes on one core (1.5 M bonds, 1720 steps).
"""
import argparse
import json
import math
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cracks import before_branching, fastest, trace  # noqa: E402  the project's crack tracer

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


def measure(times, damage, centres, dx, end_time):
    """The crack as fracta's glass test measures it, with the project's tracer (scripts/cracks.py,
    the mirror of src/host/cracks.cpp) on the damaged particles right of the pre-crack's tip."""
    right = centres[..., 0] > PRECRACK_TIP  # the pre-crack's faces start damaged

    def crack(phi, min_branch):
        points = centres[(phi >= DAMAGED) & right]
        return trace(points, np.array([PRECRACK_TIP, MIDLINE]), 1.5 * dx, min_branch)

    end = min(range(len(times)), key=lambda k: abs(times[k] - end_time))
    samples = [(0.0, 0.0)] + [(times[k], crack(damage[k], 10 * dx)["length"])
                              for k in range(end + 1)]
    final = crack(damage[end], LASTING)
    result = dict(time_s=float(times[end]), crack_length_m=final["length"],
                  tip_m=final["tip"], branched=bool(final["branches"]))

    result["fastest_1us_m_per_s"] = fastest(samples)  # over 1 us: samples two apart, as the test
    before = before_branching(samples, final)
    if before is not None:
        result.update(junction_m=before["junction_m"], branch_time_s=before["branch_time_s"],
                      branch_length_m=before["branch_length_m"],
                      path_past_junction_m=before["path_past_junction_m"],
                      speed_before_branching_m_per_s=before["speed_before_branching_m_per_s"],
                      fastest_1us_to_junction_m_per_s=before["fastest_to_junction_m_per_s"])
    result["history"] = [[round(t * 1e6, 3), round(length * 1e3, 3)] for t, length in samples]
    return result


def picture(phi, path, title):
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
    centres = model["x"].reshape(model["nx"], model["ny"], 2)  # as the damage maps
    result = measure(times, damage, centres, model["dx"], a.end_time)
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
        picture(damage[-1], a.png,
                f"bond-based PD, {a.load / 1e6:g} MPa, {label}, {times[-1] * 1e6:.0f} us")


if __name__ == "__main__":
    main()
