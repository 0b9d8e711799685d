"""RMS error of the damper force against each varied value of a `rotorsim sweep` folder.

    python sweep_plot.py SWEEP_DIR OUT_DIR

Reads SWEEP_DIR/sweep.csv (docs/formats.md, docs/sweep.md): the varied keys are the columns
between case_id and damper_model. Writes OUT_DIR/sweep_<key>.png per varied key, one line per
damper model (the mean over the other varied values), and prints the best case per model.
"""
import matplotlib.pyplot as plt
import pandas as pd

from _common import COLORS, args, save

sweep_dir, out_dir = args("SWEEP_DIR OUT_DIR", 2)
df = pd.read_csv(f"{sweep_dir}/sweep.csv")
cols = list(df.columns)
varied = cols[cols.index("case_id") + 1: cols.index("damper_model")]
assert varied, "sweep.csv has no varied key"
ok = df[df["status"].isin(["ok", "not_periodic"])]
assert len(ok) == len(df), f"{len(df) - len(ok)} row(s) failed or not run"
for key in varied:
    fig, ax = plt.subplots(figsize=(7, 4))
    for model, g in ok.groupby("damper_model"):
        mean = g.groupby(key)["rms_error_N"].mean()
        ax.plot(mean.index, mean.values, "o-", color=COLORS.get(model), label=model)
    ax.set_xlabel(key)
    ax.set_ylabel("damper force RMS error [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    save(fig, out_dir, "sweep_" + key.replace(".", "_") + ".png")
best = ok.loc[ok.groupby("damper_model")["rms_error_N"].idxmin(),
              ["damper_model", "case_id", *varied, "rms_error_N"]]
print(best.to_string(index=False))
