"""Print the verdict of a `rotorsim run` folder from its summary.json, one row per damper model.

    python summary_verdict.py RUN_DIR

Reads (docs/formats.md, "summary.json"): closest.statement, synthetic, and per model status,
label, metrics.rms_error_N, metrics.correlation, periodic.converged, periodic.residual.
"""
import pandas as pd

from _common import args, summary

(run_dir,) = args("RUN_DIR", 1)
s = summary(run_dir)
rows = []
for name, m in s["models"].items():
    metrics = m.get("metrics") or {}
    periodic = m.get("periodic") or {}
    rows.append({
        "model": name,
        "label": m.get("label"),
        "status": m.get("status"),
        "rms_error_N": metrics.get("rms_error_N"),
        "correlation": metrics.get("correlation"),
        "periodic": periodic.get("converged"),
        "residual": periodic.get("residual"),
    })
table = pd.DataFrame(rows).sort_values("rms_error_N")
if s.get("synthetic"):
    print("SYNTHETIC flight record (not flight-test data)")
print(s["closest"]["statement"])
print(table.to_string(index=False))
assert (table["status"] == "ok").all(), "a model failed"
