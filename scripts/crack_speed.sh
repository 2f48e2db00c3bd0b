#!/usr/bin/env bash
# Mode-I crack speed and fracture energy of the bonded disc lattice (docs/validation.md,
# "Mode-I crack speed"). Writes the cases (scripts/crack_case.py), runs them, and compares the
# energy-equivalent crack length and speed with Freund's equation of motion G_c = g(v) G*(t, l),
# G*(t, l) measured from stationary elastic cracks of length a + l (scripts/k_cod.py).
# usage: scripts/crack_speed.sh OUTDIR [FRACTA]        (about 15 min on 2 cores)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:?output directory}; fracta=${2:-$here/../build/fracta}
mkdir -p "$out"; cd "$out"
py=/usr/bin/python3
run() { OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} nice -n 10 "$fracta" run "$1.toml" -o "$1.h5" > "$1.log" 2>&1; }
ref=""
for l in 0 0.5 1.0 1.5 2.0 3.0 4.0 5.0; do
  $py "$here/crack_case.py" 1e-4 "el_$l.toml" --st 0 --ext "${l}e-3" --frame 0.2e-6 > /dev/null
  run "el_$l"; ref="$ref el_$l.h5:${l}e-3"
done
for h in 2e-4 1e-4 5e-5; do
  $py "$here/crack_case.py" $h "p6_$h.toml" --frame 0.2e-6 > /dev/null; run "p6_$h"
  $py "$here/crack_case.py" $h "s100_$h.toml" --st 100e6 --frame 0.2e-6 > /dev/null; run "s100_$h"
done
for h in 1e-4 5e-5; do
  $py "$here/crack_case.py" $h "p15_$h.toml" --p 15e6 --end 3e-6 --frame 0.2e-6 > /dev/null; run "p15_$h"
done
$py "$here/freund_table.py" --ref $ref --runs p6_*.h5 s100_*.h5
$py "$here/freund_table.py" --ref $ref --pscale 2.5 --end 3e-6 --runs p15_*.h5
