#!/usr/bin/env bash
# LAMMPS reference for fracta's bond kernel: plain harmonic bonds on an N x N
# square lattice (edges + both diagonals, ~4 bonds/atom), 1e5 and 1e6 atoms.
#
# Configurations (each repeated REPS times, best + range reported):
#   omp_t1, omp_t2 : lmp -sf omp -pk omp T, 1 MPI rank, OMP_NUM_THREADS=T
#                    (only if the lmp binary has the OPENMP package)
#   plain_r1       : bond_style harmonic (no suffix), 1 MPI rank, 1 thread
#   plain_mpi2     : bond_style harmonic, mpirun -np 2 (2 cores via MPI) --
#                    2-core comparator when OPENMP is not available
#
# env: LMP (lmp binary), WORK (scratch dir for data/logs), REPS, LOADMAX,
#      BUSYMAX (max CPU busy % over 2 s before a run),
#      LOADWAIT (max s to wait for low load), SIZES ("N:steps N:steps")
set -u
HERE="$(cd "$(dirname "$0")" && pwd)"
RES="$HERE/../results"
LMP="${LMP:-lmp}"
WORK="${WORK:-/tmp/fracta_lammps_bonds}"
REPS="${REPS:-3}"
LOADMAX="${LOADMAX:-0.5}"
LOADWAIT="${LOADWAIT:-900}"
BUSYMAX="${BUSYMAX:-10}"
SIZES="${SIZES:-316:2000 1000:200}"
H=1e-3
COMMCUT=3e-3
mkdir -p "$WORK" "$RES"
RAW="$WORK/raw.csv"
echo "config,atoms,bonds,steps,ranks,threads,rep,load1_before,busy_pct_before,waited_s,loop_s,bond_s_max,bond_s_avg,modify_s,lmp_cpu_pct,Mbs_bond,Mbs_loop,log" > "$RAW"

HAS_OMP=0
if "$LMP" -h 2>/dev/null | sed -n '/Installed packages:/,/List of individual/p' | grep -qw OPENMP; then HAS_OMP=1; fi
echo "lmp: $("$LMP" -h 2>/dev/null | grep -m1 'Large-scale')"
echo "OPENMP package present: $HAS_OMP"

busy_pct() {  # whole-machine CPU busy % over 2 s (/proc/stat)
  local a b
  a=($(head -1 /proc/stat)); sleep 2; b=($(head -1 /proc/stat))
  local t=0 i=0
  for k in 1 2 3 4 5 6 7 8; do t=$((t + ${b[$k]} - ${a[$k]})); done
  i=$(( (${b[4]} - ${a[4]}) + (${b[5]} - ${a[5]}) ))
  echo $(( t > 0 ? 100 * (t - i) / t : 0 ))
}

wait_load() {  # wait until 1-min load <= LOADMAX and CPU busy < BUSYMAX % (max LOADWAIT s)
  local w=0
  while :; do
    BUSY=$(busy_pct); w=$((w + 2))
    if awk -v m="$LOADMAX" '{exit !($1 <= m)}' /proc/loadavg && [ "$BUSY" -lt "$BUSYMAX" ]; then break; fi
    [ $w -ge "$LOADWAIT" ] && break
    sleep 10; w=$((w + 10))
  done
  WAITED=$w
}

run_one() {  # config ranks threads data steps atoms bonds rep
  local cfg=$1 np=$2 nt=$3 data=$4 steps=$5 atoms=$6 bonds=$7 rep=$8
  local log="$WORK/${cfg}_a${atoms}_r${rep}.log"
  wait_load
  local load1; load1=$(cut -d' ' -f1 /proc/loadavg)
  local busy=$BUSY
  local args=(-in "$HERE/in.bonds" -var data "$data" -var nsteps "$steps" -var h $H
              -var commcut $COMMCUT -log "$log" -screen none)
  case $cfg in
    omp_t*) cmd=(env OMP_NUM_THREADS=$nt "$LMP" -sf omp -pk omp $nt "${args[@]}") ;;
    plain_r1) cmd=(env OMP_NUM_THREADS=1 "$LMP" "${args[@]}") ;;
    plain_mpi2) cmd=(mpirun --allow-run-as-root -np 2 -x OMP_NUM_THREADS=1 "$LMP" "${args[@]}") ;;
  esac
  echo "+ ${cmd[*]}   [load1=$load1 busy=$busy% waited=${WAITED}s]"
  "${cmd[@]}" || { echo "  FAILED (rc=$?)"; return 1; }
  python3 - "$log" "$cfg" "$atoms" "$bonds" "$steps" "$np" "$nt" "$rep" "$load1" "$busy" "$WAITED" >> "$RAW" <<'PY'
import re, sys
log, cfg, atoms, bonds, steps, np, nt, rep, load1, busy, waited = sys.argv[1:]
t = open(log).read()
loop = float(re.search(r"Loop time of (\S+) on", t).group(1))
def row(name):
    m = re.search(r"^%s\s*\|\s*(\S+)\s*\|\s*(\S+)\s*\|\s*(\S+)" % name, t, re.M)
    return float(m.group(1)), float(m.group(2)), float(m.group(3))
_, bavg, bmax = row("Bond")
_, mavg, _ = row("Modify")
cpu = re.search(r"([\d.]+)% CPU use", t).group(1)  # LAMMPS' own CPU-use figure
b, s = int(bonds), int(steps)
print(",".join(map(str, [cfg, atoms, bonds, steps, np, nt, rep, load1, busy, waited,
      f"{loop:.4f}", f"{bmax:.4f}", f"{bavg:.4f}", f"{mavg:.4f}", cpu,
      f"{b*s/bmax/1e6:.1f}", f"{b*s/loop/1e6:.1f}", log])))
PY
  tail -1 "$RAW"
}

CONFIGS="plain_r1 plain_mpi2"
[ $HAS_OMP = 1 ] && CONFIGS="omp_t1 omp_t2 $CONFIGS"
for sz in $SIZES; do
  n=${sz%%:*}; steps=${sz##*:}
  data="$WORK/n$n.data"
  [ -s "$data" ] || python3 "$HERE/lattice.py" "$n" "$data"
  atoms=$((n * n)); bonds=$((2 * n * (n - 1) + 2 * (n - 1) * (n - 1)))
  for rep in $(seq 1 "$REPS"); do
    for cfg in $CONFIGS; do
      case $cfg in omp_t1) np=1 nt=1;; omp_t2) np=1 nt=2;; plain_r1) np=1 nt=1;; plain_mpi2) np=2 nt=1;; esac
      run_one $cfg $np $nt "$data" "$steps" $atoms $bonds $rep
    done
  done
done

cp "$RAW" "$RES/lammps_bonds.csv"
python3 - "$RAW" "$HAS_OMP" "$("$LMP" -h 2>/dev/null | grep -m1 'Large-scale')" > "$RES/lammps_bonds.txt" <<'PY'
import csv, sys, collections, platform
rows = list(csv.DictReader(open(sys.argv[1])))
print("LAMMPS bond-kernel reference (bench/lammps_bonds/run.sh)")
print(f"lmp: {sys.argv[3].strip()}   OPENMP package: {'yes' if sys.argv[2]=='1' else 'NO (no /omp styles)'}")
print(f"host: {platform.node()}  cores: 2   lattice: N x N, edges + both diagonals, bond_style harmonic, pair_style none, fix nve")
print("load1/busy% = 1-min loadavg / whole-machine CPU busy over 2 s just before the run; cpu% = LAMMPS' own '% CPU use'")
print("Mbs_bond = bonds*steps/Bond time (max over ranks); Mbs_loop = bonds*steps/Loop time; M bond-steps/s\n")
hdr = f"{'config':<11}{'atoms':>9}{'bonds':>9}{'steps':>6}{'rk':>3}{'th':>3}{'rep':>4}{'load1':>6}{'busy%':>6}{'cpu%':>6}{'loop_s':>8}{'bond_s':>8}{'Mbs_bond':>9}{'Mbs_loop':>9}"
print(hdr); print("-" * len(hdr))
for r in rows:
    print(f"{r['config']:<11}{r['atoms']:>9}{r['bonds']:>9}{r['steps']:>6}{r['ranks']:>3}{r['threads']:>3}{r['rep']:>4}{r['load1_before']:>6}{r['busy_pct_before']:>6}{r['lmp_cpu_pct']:>6}{float(r['loop_s']):>8.3f}{float(r['bond_s_max']):>8.3f}{float(r['Mbs_bond']):>9.1f}{float(r['Mbs_loop']):>9.1f}")
print("\nSummary: best (range) over repetitions, M bond-steps/s")
g = collections.OrderedDict()
for r in rows: g.setdefault((r['config'], r['atoms'], r['bonds'], r['ranks'], r['threads']), []).append(r)
print(f"{'config':<11}{'atoms':>9}{'bonds':>9}{'rk':>3}{'th':>3}{'n':>3}   {'Mbs_bond best (range)':<24}{'Mbs_loop best (range)':<24}")
for k, v in g.items():
    b = [float(x['Mbs_bond']) for x in v]; l = [float(x['Mbs_loop']) for x in v]
    print(f"{k[0]:<11}{k[1]:>9}{k[2]:>9}{k[3]:>3}{k[4]:>3}{len(v):>3}   {max(b):>6.1f} ({min(b):.1f}-{max(b):.1f}){'':<6}{max(l):>6.1f} ({min(l):.1f}-{max(l):.1f})")
PY
cat "$RES/lammps_bonds.txt"
