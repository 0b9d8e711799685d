"""Helpers shared by the examples: headless matplotlib, the run's models, one colour per model."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # write PNG files, never open a window
import matplotlib.pyplot as plt  # noqa: E402

MODELS = ("linear", "nonlinear", "physical")
# One colour per damper model (and black for the measurement) in every plot of these examples.
COLORS = {"linear": "tab:blue", "nonlinear": "tab:orange", "physical": "tab:green",
          "measured": "black"}


def args(usage, n):
    """The n positional arguments, or the usage text and exit status 2."""
    if len(sys.argv) != n + 1:
        print(f"usage: {os.path.basename(sys.argv[0])} {usage}", file=sys.stderr)
        sys.exit(2)
    return sys.argv[1:]


def summary(run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)


def models_run(run_dir):
    """The damper models whose last_rev.csv the run folder holds, in a fixed order."""
    return [m for m in MODELS if os.path.isfile(os.path.join(run_dir, m, "last_rev.csv"))]


def save(fig, out_dir, name):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")
    return path
