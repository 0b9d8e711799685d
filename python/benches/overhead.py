"""The Python package's overhead over the command line: `rotorsim.run(damper=["physical"])` and
`rotorsim run --damper physical`, both into a result folder, alternated in one process so that
the machine's load falls on both alike; prints each pair's ratio (Python / CLI) and the median.
Also `Damper.force` on a 10,000-sample stroke history (physical, 25 RK4 sub-steps).

    python python/benches/overhead.py [PAIRS]        (from the repository root; default 6)

The whole-process comparison (starting Python and importing the package included) is
`farm-bench --vs 'target/release/rotorsim run --damper physical --out /tmp/b' -- python -c
"import rotorsim; rotorsim.run(damper=['physical'], out='/tmp/a', progress=False)"`.
"""
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time
import timeit

import numpy as np

import rotorsim

root = pathlib.Path(__file__).resolve().parents[2]
os.chdir(root)
cli = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", root / "target")) / "release" / "rotorsim")
pairs = int(sys.argv[1]) if len(sys.argv) > 1 else 6
ratios = []
with tempfile.TemporaryDirectory() as tmp:
    for i in range(pairs):
        t0 = time.perf_counter()
        rotorsim.run(damper=["physical"], out=f"{tmp}/py{i}", progress=False)
        py = time.perf_counter() - t0
        t0 = time.perf_counter()
        subprocess.run([cli, "run", "--damper", "physical", "--out", f"{tmp}/cli{i}"],
                       check=True, capture_output=True)
        c = time.perf_counter() - t0
        ratios.append(py / c)
        print(f"pair {i + 1}: Python {py:.3f} s, CLI {c:.3f} s, ratio {py / c:.3f}")
print(f"run: ratio Python/CLI median {statistics.median(ratios):.3f} "
      f"(min {min(ratios):.3f}, max {max(ratios):.3f}, {pairs} pairs)")

t = np.arange(10_000) / 2000.0
x = 6e-3 * np.sin(2 * np.pi * 4.3 * t) + 1.5e-3 * np.sin(2 * np.pi * 17.2 * t)
d = rotorsim.Damper("rotors/uh60a.toml", model="physical")
times = timeit.repeat(lambda: d.force(t, x), number=1, repeat=15)
print(f"Damper.force, 10,000 samples: min {min(times) * 1e3:.1f} ms, "
      f"median {statistics.median(times) * 1e3:.1f} ms (15 repeats)")
