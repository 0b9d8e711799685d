"""Damper force and stroke over the last revolution, every model over the measurement, from the
last_rev.csv files of a `rotorsim run` folder.

    python last_rev_comparison.py RUN_DIR OUT_DIR

Writes OUT_DIR/damper_force_last_rev.png and OUT_DIR/damper_stroke_last_rev.png. The measured
damper force is the column measured_damper_force_N of last_rev.csv when the run writes it, else
the flight record's damper CSV (summary.json flight_record + ".damper.csv") averaged over its
revolutions azimuth by azimuth, as rotorsim compares it (docs/run.md).
"""
import os

import matplotlib.pyplot as plt
import pandas as pd

from _common import COLORS, args, models_run, save, summary

run_dir, out_dir = args("RUN_DIR OUT_DIR", 2)
s = summary(run_dir)
models = models_run(run_dir)
assert models, f"{run_dir}: no <model>/last_rev.csv"
data = {m: pd.read_csv(os.path.join(run_dir, m, "last_rev.csv")) for m in models}


def measured():
    """(azimuth_deg, force_N, stroke_m or None) of the measurement, or None."""
    for df in data.values():
        if "measured_damper_force_N" in df.columns:
            stroke = df.get("measured_damper_stroke_m")
            return df["azimuth_deg"], df["measured_damper_force_N"], stroke
    stem = s.get("flight_record", "")
    path = stem + ".damper.csv"
    if not os.path.isfile(path):
        return None  # an MCAP record: see mcap_comparison.py for the measured trace
    rec = pd.read_csv(path)
    avg = rec.groupby("azimuth_deg").mean(numeric_only=True).reset_index()
    return avg["azimuth_deg"], avg["damper_force_N"], avg.get("damper_stroke_m")


tag = " (SYNTHETIC record)" if s.get("synthetic") else ""
meas = measured()
for channel, scale, unit, mcol, name in [
    ("damper_force_N", 1e-3, "kN", 1, "damper_force_last_rev.png"),
    ("damper_stroke_m", 1e3, "mm", 2, "damper_stroke_last_rev.png"),
]:
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for m, df in data.items():
        ax.plot(df["azimuth_deg"], df[channel] * scale, color=COLORS[m], label=m)
    if meas is not None and meas[mcol] is not None:
        ax.plot(meas[0], meas[mcol] * scale, color=COLORS["measured"], lw=1.0, ls="--",
                label="measured" + tag)
    ax.set_xlabel("azimuth [deg]")
    ax.set_ylabel(f"{channel.rsplit('_', 1)[0].replace('_', ' ')} [{unit}]")
    ax.set_xticks(range(0, 361, 90))
    ax.set_xlim(0, 360)
    ax.grid(True, alpha=0.3)
    ax.set_title(f"last revolution, models over the measurement{tag}")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    save(fig, out_dir, name)
