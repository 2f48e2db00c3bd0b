#!/usr/bin/python3
"""Brazilian disc report (cases/validation/brazilian_disc.toml): the peak platen force against
pi D t sigma_t / 2 (ISRM), the two platens' forces at the peak (quasi-static equilibrium), and
where and at what load the first bond softened (from the first frame with damage).
usage: brazilian_disc.py OUT.h5 [--diameter D] [--thickness T] [--strength S]"""
import argparse, h5py, numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("h5")
ap.add_argument("--diameter", type=float, default=0.04)
ap.add_argument("--thickness", type=float, default=0.01)
ap.add_argument("--strength", type=float, default=10e6)
A = ap.parse_args()
f = h5py.File(A.h5, "r")
formula = np.pi * A.diameter * A.thickness * A.strength / 2
t = f["boundaries/top/time"][:]
top, bottom = -f["boundaries/top/fy"][:], f["boundaries/bottom/fy"][:]
k = int(np.argmax(top))
th, fracture = f["history/time"][:], f["history/energy/fracture"][:]
t_soft = th[np.argmax(fracture > 0)] if np.any(fracture > 0) else None
print(f"pi D t sigma_t / 2 = {formula:.1f} N")
print(f"peak platen force {top[k]:.1f} N = {top[k] / formula:.4f} x formula at {t[k] * 1e6:.1f} us;"
      f" bottom platen {bottom[k] / top[k]:.4f} of it")
if t_soft is not None:
    print(f"first softening at {t_soft * 1e6:.1f} us, load {np.interp(t_soft, t, top) / formula:.4f} x formula")
x0 = f["frames/0/node_position"][:] - f["frames/0/node_displacement"][:]
for key in sorted(f["frames"].keys(), key=int):
    fr = f["frames"][key]
    damaged = (fr["bond_damage"][:] > 0) | (fr["bond_state"][:] == 2)
    if damaged.any():
        bn = fr["bond_nodes"][:][damaged]
        mid = 0.5 * (x0[bn[:, 0]] + x0[bn[:, 1]])
        r = np.hypot(mid[:, 0], mid[:, 1])
        print(f"first frame with damage: {float(fr['time'][()]) * 1e6:.1f} us, {damaged.sum()} bonds,"
              f" farthest {r.max() * 1e3:.2f} mm from the centre")
        break
