#!/usr/bin/env bash
# MBDyn against rotorsim on the NASA TM-4760 blade lag free decay at 660 rpm: 2000 steps of 5 ms,
# rho_inf 0.6 in both codes (docs/performance.md, "MBDyn on the same blade"). Not part of CI.
#
# Usage: benches/mbdyn_tm4760/run.sh [WORK_DIR]     (default: a fresh temporary folder)
# Environment:
#   MBDYN       the mbdyn executable (default: `mbdyn` on PATH)
#   TM4760_BLK  tm4760.blk, the NASTRAN bulk data of MBDyn's test tests/rbk/tm4760
#   ROTORSIM    the rotorsim executable (default: target/release/rotorsim; build it first with
#               `cargo build --release`)
#   PAIRS       timed pairs after one warm-up pair (default 5)
# Skips (exit 0, one line saying why) when MBDyn, the bulk data, python3 or the rotorsim build is
# missing.
#
# What it does:
#  1. gen_deck.py writes the MBDyn deck from tm4760.blk (the model MBDyn's test script
#     tm4760_blk.m builds: beam2 elements, lumped bodies, lbm-in-s units) with the bench's
#     analysis: 660 rpm (rigid body kinematics), `ms, .6, .6`, modified Newton, tolerance 1e-3,
#     no eigenanalysis, output of the lag hinge only; the lag couple of 4.5 N m raised over 0.5 s,
#     held, released (linear ramp over 10 ms) at 1 s. rotorsim starts from the static equilibrium
#     under the same moment and releases it over 10 ms at t = 0.
#  2. One check run of each: the damped-sine fit of the lag angle from 1 s after the release
#     (MBDyn: bench_tools.py on the .jnt file; rotorsim: its decay_summary.csv), against the
#     linearised lag mode rotorsim computes.
#  3. Timing: whole processes, CPU (user + sys) and wall, MBDyn and rotorsim alternately, one
#     warm-up pair then PAIRS pairs; each pair also runs the short runs (MBDyn: one step; rotorsim:
#     its shortest run, 1.1 s = 220 steps) so that stepping = (whole - short) / steps between.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
skip() {
    echo "benches/mbdyn_tm4760: skipped: $*"
    exit 0
}
MBDYN=$(command -v "${MBDYN:-mbdyn}" || true)
[ -n "$MBDYN" ] && [ -x "$MBDYN" ] || skip "no MBDyn (set MBDYN to the mbdyn executable or put mbdyn on PATH)"
[ -n "${TM4760_BLK:-}" ] && [ -f "$TM4760_BLK" ] || skip "no tm4760.blk (set TM4760_BLK to MBDyn's tests/rbk/tm4760/tm4760.blk)"
command -v python3 >/dev/null || skip "no python3"
ROTORSIM=${ROTORSIM:-${CARGO_TARGET_DIR:-$root/target}/release/rotorsim}
[ -x "$ROTORSIM" ] || skip "no rotorsim build at $ROTORSIM (cargo build --release)"
abs() { echo "$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; }
MBDYN=$(abs "$MBDYN")
ROTORSIM=$(abs "$ROTORSIM")
TM4760_BLK=$(abs "$TM4760_BLK")
PAIRS=${PAIRS:-5}
W=${1:-$(mktemp -d "${TMPDIR:-/tmp}/rotorsim-mbdyn-bench.XXXXXX")}
mkdir -p "$W"
W=$(cd "$W" && pwd)
tools="python3 $here/bench_tools.py"
H=0.005
STEPS=2000
RELEASE=1.0
R_SHORT=220 # rotorsim decay's shortest run: analysed from 1 s, so at least 1 s + 20 steps

version=$("$MBDYN" -v 2>&1 || true)
echo "MBDyn: $MBDYN (version $(echo "$version" | grep -m1 -o '[0-9][0-9]*\.[0-9][0-9.]*' || echo unknown))"
echo "rotorsim: $ROTORSIM"
python3 "$here/gen_deck.py" "$TM4760_BLK" "$W/deck" --final-time 10 --release-at $RELEASE
python3 "$here/gen_deck.py" "$TM4760_BLK" "$W/deck1" --final-time $H --release-at $RELEASE

mbdyn_run() { # DECK_DIR OUT_PREFIX
    (cd "$1" && exec "$MBDYN" -f tm4760_bench.mbd -o "$2")
}
rotorsim_run() { # DURATION_S OUT_DIR [extra args]
    local d=$1 o=$2
    shift 2
    (cd "$root" && exec "$ROTORSIM" decay --rotor rotors/tm4760.toml --rpm 660 --duration-s "$d" \
        --rho-inf 0.6 --out "$o" "$@")
}

# 2. check runs
mkdir -p "$W/check"
mbdyn_run "$W/deck" "$W/check/mbdyn" >"$W/check/mbdyn.stdout" 2>&1 ||
    {
        tail -5 "$W/check/mbdyn.stdout"
        echo "MBDyn failed (output: $W/check/mbdyn.stdout)"
        exit 1
    }
rotorsim_run 10 "$W/check/rotorsim" >"$W/check/rotorsim.log" 2>&1 ||
    {
        tail -5 "$W/check/rotorsim.log"
        echo "rotorsim failed"
        exit 1
    }
read -r m_hz m_zeta m_rows < <($tools fit "$W/check/mbdyn.jnt" 204 $H "$(python3 -c "print($RELEASE + 1)")")
[ "$m_rows" = $((STEPS + 1)) ] || echo "warning: $m_rows rows of the lag hinge in mbdyn.jnt, expected $((STEPS + 1))"
awk -v n=$STEPS '/^total iterations:/ { i = $3 } /^total Jacobian matrices:/ { j = $4 }
    END { printf "MBDyn check run: %.3f iterations and %.4f Jacobian matrices per step\n", i / n, j / n }' "$W/check/mbdyn.stdout"
echo "rotorsim check run: $(grep -m1 -o '[0-9.]* iterations and [0-9.]* factorizations per step' "$W/check/rotorsim.log")"
python3 - "$W/check/rotorsim/decay_summary.csv" "$m_hz" "$m_zeta" <<'PY'
import csv, sys
rows = {r["method"]: (float(r["frequency_Hz"]), float(r["damping_ratio"])) for r in csv.DictReader(open(sys.argv[1]))}
ref = rows["linearised_modal"]
print("lag decay, damped-sine fit from 1 s after the release (rho_inf 0.6, h = 5 ms):")
print(f"  {'linearised mode (rotorsim)':<28} {ref[0]:.5f} Hz  damping ratio {ref[1]:.6f}")
for name, (f, z) in (("MBDyn", (float(sys.argv[2]), float(sys.argv[3]))), ("rotorsim", rows["damped_sine_fit"])):
    print(f"  {name:<28} {f:.5f} Hz  damping ratio {z:.6f}  ({100 * (f / ref[0] - 1):+.3f}% / {100 * (z / ref[1] - 1):+.2f}%)")
PY

# 3. timing
t="$W/times"
rm -rf "$t"
mkdir -p "$t"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
R_ARGS=(decay --rotor rotors/tm4760.toml --rpm 660 --rho-inf 0.6 --no-modal)
R_SHORT_S=$(python3 -c "print($R_SHORT * $H)")
for i in $(seq 0 "$PAIRS"); do
    [ "$i" = 0 ] && d="$t/warmup" || d="$t"
    mkdir -p "$d"
    $tools time "$d/mbdyn.times" "$W/deck" -- "$MBDYN" -f tm4760_bench.mbd -o "$W/times_out_m"
    $tools time "$d/rotorsim.times" "$root" -- "$ROTORSIM" "${R_ARGS[@]}" --duration-s 10 --out "$W/times_out_r"
    $tools time "$d/mbdyn_short.times" "$W/deck1" -- "$MBDYN" -f tm4760_bench.mbd -o "$W/times_out_m1"
    $tools time "$d/rotorsim_short.times" "$root" -- "$ROTORSIM" "${R_ARGS[@]}" --duration-s "$R_SHORT_S" \
        --out "$W/times_out_r1"
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
$tools report "$t" $STEPS 1 $R_SHORT
echo "work folder: $W"
