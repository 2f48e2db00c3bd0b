#!/usr/bin/env python3
"""Crack growth in the SCB granite specimen (cases/scb_granite.toml), beside the paper's Table 6.

From every frame of OUT.h5: the crack tip is the highest broken bond (its midpoint) within
3 mm of the specimen's axis that is joined to the notch tip (y = 5 mm) by broken bonds less
than 1.5 mm apart (1.5 cells), so damage under the loading point is not taken for the tip.
The crack speeds are measured like crack gauges: the distance between two heights over the
time the tip takes from one to the other (first frame at or above each), for the lower half
of the ligament (5.4-12.5 mm) and the upper half (12.5-19 mm, up to 1 mm below the apex,
where the load is applied); their resolution is the frame interval ("inf": both heights
passed within one frame). The fragment rotation at the last frame (160 us) is the rigid
rotation (2D Kabsch fit) of the nodes of each half (|x| > 3 mm) from their reference positions;
the mean of the two magnitudes is reported.

Usage: /usr/bin/python3 scripts/scb_crack.py OUT.h5
"""
import math
import sys

import h5py
import numpy as np

NOTCH_TIP, TOP, AXIS_BAND, GAP = 5e-3, 20e-3, 3e-3, 1.5e-3
PAPER = {"speed1": (268, 233), "speed2": (355, 361), "rotation": (9.0, 10.2)}


def rotation_deg(x0, x):
    c0, c = x0.mean(axis=0), x.mean(axis=0)
    a, b = x0 - c0, x - c
    return math.degrees(math.atan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]),
                                   np.sum(a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1])))


def main(path):
    f = h5py.File(path, "r")
    # Complete frames only: /frames@count (a killed run may leave a partial frame beyond it).
    count = int(f["frames"].attrs.get("count", len(f["frames"])))
    frames = [str(k) for k in range(count)]
    x0 = f["frames"][frames[0]]["node_position"][:]
    times, tips = [], []
    for k in frames:
        g = f["frames"][k]
        t = float(g["time"][()])
        bn, st = g["bond_nodes"][:], g["bond_state"][:]
        x = g["node_position"][:]
        tip = NOTCH_TIP
        if len(st):
            broken = bn[st == 2]
            mid0 = 0.5 * (x0[broken[:, 0]] + x0[broken[:, 1]])  # reference midpoints
            near = np.sort(mid0[np.abs(mid0[:, 0]) < AXIS_BAND][:, 1])
            # Follow the crack up from the notch: broken bonds no more than GAP apart (a bond
            # crushed under the loading point, not joined to the crack, is not its tip).
            for y in near[near > NOTCH_TIP - GAP]:
                if y > tip + GAP:
                    break
                tip = max(tip, float(y))
        times.append(t)
        tips.append(tip)
    times, tips = np.array(times), np.array(tips)
    print("Crack tip height (mm) vs time (us), from broken bonds near the axis:")
    for t, y in zip(times, tips):
        print(f"  {t*1e6:7.1f}  {y*1e3:6.2f}")

    def reached(y):
        """First frame time at which the tip is at or above y (nan if never)."""
        hit = np.nonzero(tips >= y - 1e-9)[0]
        return float(times[hit[0]]) if len(hit) else float("nan")

    # Like crack gauges: the time the tip takes between three heights (the first bond above
    # the notch tip, mid-ligament, 1 mm below the apex, where the load is applied).
    gauges = (NOTCH_TIP + 0.4e-3, 0.5 * (NOTCH_TIP + TOP), TOP - 1e-3)
    t_gauge = [reached(y) for y in gauges]
    def speed(k):
        # Both heights passed within one frame: faster than the frames resolve (inf).
        dt = t_gauge[k + 1] - t_gauge[k]
        return (gauges[k + 1] - gauges[k]) / dt if dt > 0 else float("inf") if dt == 0 else dt

    s1, s2 = speed(0), speed(1)
    dt_frame = float(np.median(np.diff(times))) if len(times) > 1 else float("nan")
    print()
    print("Crack tip reaches y = " + ", ".join(
        f"{y*1e3:.1f} mm at {t*1e6:.0f} us" for y, t in zip(gauges, t_gauge)) +
        f" (frames every {dt_frame*1e6:.1f} us)")
    last = f["frames"][frames[-1]]["node_position"][:]
    left, right = x0[:, 0] < -AXIS_BAND, x0[:, 0] > AXIS_BAND
    rot = 0.5 * (abs(rotation_deg(x0[left], last[left])) + abs(rotation_deg(x0[right], last[right])))
    print()
    print(f"{'quantity':<30}{'fracta':>10}{'experiment':>12}{'paper':>10}")
    print(f"{'crack speed 1 (m/s)':<30}{s1:>10.0f}{PAPER['speed1'][0]:>12}{PAPER['speed1'][1]:>10}")
    print(f"{'crack speed 2 (m/s)':<30}{s2:>10.0f}{PAPER['speed2'][0]:>12}{PAPER['speed2'][1]:>10}")
    print(f"{'fragment rotation at %.0f us (deg)' % (times[-1]*1e6):<30}{rot:>10.2f}"
          f"{PAPER['rotation'][0]:>12}{PAPER['rotation'][1]:>10}")
    return 0


if __name__ == "__main__":
    import signal
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # quiet when piped into head
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
