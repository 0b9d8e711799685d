#!/usr/bin/env bash
# Wall time of a sweep against its cases run one by one, and revolutions saved by warm starts
# (docs/performance.md, "Sweeps"). Usage: benches/sweep_wall.sh PLAN [WORK_DIR]
# Runs: the sweep with warm starts (--jobs 2), the same cold (--no-warm-start), then every case
# as its own `rotorsim run` (cold), one after the other; prints the wall times and the
# revolutions summed over sweep.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
PLAN=$1
W=${2:-$(mktemp -d "${TMPDIR:-/tmp}/rotorsim-sweep-bench.XXXXXX")}
B=${CARGO_TARGET_DIR:-target}/release/rotorsim
rm -rf "$W/warm" "$W/cold" "$W/single"
mkdir -p "$W"
now() { date +%s.%N; }
t0=$(now); "$B" sweep "$PLAN" --out "$W/warm" --jobs 2 >"$W/warm.log" 2>&1; t1=$(now)
"$B" sweep "$PLAN" --out "$W/cold" --jobs 2 --no-warm-start >"$W/cold.log" 2>&1; t2=$(now)
python3 - "$W" "$B" > "$W/one_by_one.sh" <<'PY'
import json, shlex, sys
w, exe = sys.argv[1], sys.argv[2]
for c in json.load(open(w + "/warm/plan.json"))["cases"]:
    a = []
    for k, v in c["settings"].items():
        if "." in k:
            a += ["--set", f"{k}={v}"]
        elif v is True:
            a += ["--" + k.replace("_", "-")]
        elif v is not False:
            a += ["--" + k.replace("_", "-"), str(v)]
    a += ["--out", f"{w}/single/{c['id']}"]
    print(" ".join(shlex.quote(x) for x in [exe, "run"] + a) + " >/dev/null 2>&1")
PY
t3=$(now); bash "$W/one_by_one.sh"; t4=$(now)
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$W" "$t0" "$t1" "$t2" "$t3" "$t4" <<'PY'
import csv, sys
w = sys.argv[1]
t = [float(x) for x in sys.argv[2:]]
print(f"sweep, warm starts, --jobs 2: {t[1]-t[0]:.1f} s")
print(f"sweep, cold, --jobs 2:        {t[2]-t[1]:.1f} s")
print(f"cases one by one (cold):      {t[4]-t[3]:.1f} s")
rows = {n: list(csv.DictReader(open(f"{w}/{n}/sweep.csv"))) for n in ["warm", "cold"]}
for n, r in rows.items():
    print(f"{n}: {len(r)} rows, {sum(int(x['revolutions']) for x in r)} revolutions, "
          f"{sum(1 for x in r if x['warm_start_from'])} warm-started, "
          f"{sum(1 for x in r if x['status'] == 'ok')} periodic")
d = [abs(float(a["rms_error_N"]) - float(b["rms_error_N"])) / float(b["rms_error_N"])
     for a, b in zip(rows["warm"], rows["cold"]) if a["rms_error_N"] and b["rms_error_N"]]
d.sort()
print(f"RMS error, warm vs cold: median relative difference {d[len(d)//2]:.1e}, largest {d[-1]:.1e}")
PY
