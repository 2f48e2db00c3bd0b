#!/usr/bin/env python3
"""Write a LAMMPS data file (atom_style bond, 2D) of an N x N square lattice.

Bonds match fracta's lattice: every node is bonded to its right and upper
neighbour (edge bonds, type 1, rest length h) and each cell carries both
diagonals (type 2, rest length h*sqrt(2)).  Bond count:
    2*N*(N-1) edges + 2*(N-1)^2 diagonals  ~= 4 N^2.

usage: lattice.py N out.data [h]
"""
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    n = int(sys.argv[1])
    out = sys.argv[2]
    h = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-3
    natoms = n * n
    nedge = 2 * n * (n - 1)
    ndiag = 2 * (n - 1) * (n - 1)
    nbonds = nedge + ndiag
    pad = 5 * h  # fixed (non-periodic) x/y boundaries: keep atoms inside
    idx = lambda i, j: j * n + i + 1  # 1-based atom id, i = column, j = row
    with open(out, "w") as f:
        f.write(f"# fracta bond bench: {n}x{n} square lattice, h={h}\n\n")
        f.write(f"{natoms} atoms\n{nbonds} bonds\n1 atom types\n2 bond types\n\n")
        f.write(f"{-pad:.9g} {(n - 1) * h + pad:.9g} xlo xhi\n")
        f.write(f"{-pad:.9g} {(n - 1) * h + pad:.9g} ylo yhi\n")
        f.write(f"{-0.5 * h:.9g} {0.5 * h:.9g} zlo zhi\n\n")
        f.write("Masses\n\n1 1.0\n\n")
        f.write("Atoms # bond\n\n")
        buf = []
        for j in range(n):
            y = j * h
            for i in range(n):
                buf.append(f"{idx(i, j)} 1 1 {i * h:.9g} {y:.9g} 0\n")
            if len(buf) > 100000:
                f.write("".join(buf)); buf.clear()
        f.write("".join(buf)); buf.clear()
        f.write("\nBonds\n\n")
        b = 0
        for j in range(n):
            for i in range(n):
                a = idx(i, j)
                if i + 1 < n:  # right edge
                    b += 1; buf.append(f"{b} 1 {a} {idx(i + 1, j)}\n")
                if j + 1 < n:  # upper edge
                    b += 1; buf.append(f"{b} 1 {a} {idx(i, j + 1)}\n")
                if i + 1 < n and j + 1 < n:  # both diagonals of cell (i,j)
                    b += 1; buf.append(f"{b} 2 {a} {idx(i + 1, j + 1)}\n")
                    b += 1; buf.append(f"{b} 2 {idx(i + 1, j)} {idx(i, j + 1)}\n")
            if len(buf) > 200000:
                f.write("".join(buf)); buf.clear()
        f.write("".join(buf))
        assert b == nbonds, (b, nbonds)
    print(f"N={n} atoms={natoms} bonds={nbonds} -> {out}")


if __name__ == "__main__":
    main()
