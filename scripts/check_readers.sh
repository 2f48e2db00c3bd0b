#!/usr/bin/env bash
# The plot and crack scripts read every frame storage (run by ctest as Scripts.ReadEveryFrameStorage):
# the paper's plate (FE and bonded discs) to 3 us in double precision, single precision and single
# precision with compression 1; then scripts/plot.py (histories and a frame),
# scripts/cracks.py (fragments, before branching) and scripts/crack_tip.py (its JSON) on each,
# and a check that each .xdmf declares the stored types and that the single-precision frames are
# the double ones rounded to float32: exactly on the host code path, where the runs repeat to the
# bit; within 1e-6 of the largest value for a build that takes the device path (atomic sums: the
# runs agree to round-off, and a float32 rounding may land one unit apart).
# Usage: scripts/check_readers.sh FRACTA_EXE [host|device]
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
fracta=${1:?usage: check_readers.sh FRACTA_EXE [host|device]}
code_path=${2:-host}
work=$(mktemp -d "${TMPDIR:-/tmp}/fracta_readers_XXXXXX")
trap 'rm -rf "$work"' EXIT
py=/usr/bin/python3
for setting in double:0 single:0 single:1; do
  precision=${setting%:*} compression=${setting#*:}
  out=$work/${precision}_$compression.h5
  "$fracta" run "$repo/cases/plate_case_b.toml" -o "$out" --set simulation.end_time=3e-6 \
    "output.precision=\"$precision\"" "output.compression=$compression" >"$work/run.log" 2>&1 ||
    { cat "$work/run.log"; exit 1; }
  MPLBACKEND=Agg "$py" "$repo/scripts/plot.py" "$out" -o "$work/plots_$setting" >/dev/null
  MPLBACKEND=Agg "$py" "$repo/scripts/plot.py" "$out" --frame 3 --field speed \
    -o "$work/plots_$setting" >/dev/null
  "$py" "$repo/scripts/cracks.py" "$out" --seed 0 0 --fragments --before-branching >/dev/null
  "$py" "$repo/scripts/crack_tip.py" "$out" --quiet --json "$work/tip_$setting.json" >/dev/null
done
"$py" - "$work" "$code_path" <<'EOF'
import re, sys
import h5py, numpy as np
work, code_path = sys.argv[1], sys.argv[2]
frames = {}
for name in ("double_0", "single_0", "single_1"):
    path = f"{work}/{name}.h5"
    with h5py.File(path, "r") as f:
        frames[name] = {k: f[f"frames/3/{k}"][:] for k in ("node_position", "element_stress",
                                                             "bond_normal_force")}
        kinds = {k: (f[f"frames/3/{k}"].dtype.kind, f[f"frames/3/{k}"].dtype.itemsize)
                 for k in f["frames/3"] if f[f"frames/3/{k}"].shape != ()}
    xdmf = open(f"{work}/{name}.xdmf").read()
    items = re.findall(
        r'NumberType="(\w+)" Precision="(\d)" Format="HDF">[^:]+:/frames/3/(\w+)<', xdmf)
    assert len(items) >= 10, f"{name}: only {len(items)} references to frame 3 in the .xdmf"
    for number_type, precision, dataset in items:
        kind, size = kinds[dataset]
        assert (number_type == "Float") == (kind == "f") and int(precision) == size, \
            f"{name}: {dataset} declared {number_type} {precision}, stored {kind}{size}"
for name in ("single_0", "single_1"):
    for k, d in frames["double_0"].items():
        s = frames[name][k]
        assert s.dtype == np.float32, f"{name}: {k} is {s.dtype}"
        if code_path == "host":
            assert np.array_equal(s, d.astype(np.float32)), \
                f"{name}: {k} is not the double rounded"
        else:
            gap = np.max(np.abs(s.astype(np.float64) - d.astype(np.float32)))
            assert gap <= 1e-6 * np.max(np.abs(d)), \
                f"{name}: {k} is {gap} from the double rounded"
print("readers: plot.py and cracks.py read double, single and deflated frames; "
      "the .xdmf types match")
EOF
