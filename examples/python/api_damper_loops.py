"""The damper alone through the rotorsim package: force-stroke loops of the three damper models
of a damper deck on a stroke history of your own, and the physical model's chamber pressures.

    python api_damper_loops.py OUT_DIR [DAMPER_DECK]

DAMPER_DECK: any TOML file with a [damper] table (default rotors/uh60a.toml). The stroke is 6 mm
at 4.3 Hz (the 1/rev of the UH-60A) plus 1.5 mm at 17.2 Hz, 2 s at 2 kHz: the kind of history a
user's own model or optimiser hands over. Writes OUT_DIR/damper_loops.png and
OUT_DIR/damper_pressures.png and prints the energy each model dissipates over the last second.
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np
import rotorsim

from _common import COLORS, save

if len(sys.argv) not in (2, 3):
    print(f"usage: {os.path.basename(sys.argv[0])} OUT_DIR [DAMPER_DECK]", file=sys.stderr)
    sys.exit(2)
out_dir = sys.argv[1]
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
deck = sys.argv[2] if len(sys.argv) == 3 else os.path.join(root, "rotors", "uh60a.toml")

t = np.arange(4000) / 2000.0
x = 6e-3 * np.sin(2 * np.pi * 4.3 * t) + 1.5e-3 * np.sin(2 * np.pi * 17.2 * t)
last = t >= 1.0  # the second second: the device settled from rest
fig, ax = plt.subplots(figsize=(6, 5))
for model in ("linear", "nonlinear", "physical"):
    f = rotorsim.Damper(deck, damper=model).force(t, x)
    # the force is the damper's on the stroking point: it takes out -integral of F dx
    e = -(np.trapezoid(f[last], x[last]) if hasattr(np, "trapezoid") else np.trapz(f[last], x[last]))
    print(f"{model:>9}: {e:8.1f} J dissipated over the last second")
    ax.plot(x[last] * 1e3, f[last] / 1e3, color=COLORS[model], label=model)
ax.set_xlabel("stroke [mm]")
ax.set_ylabel("damper force [kN]")
ax.set_title("Force-stroke loops (model output, no measurement)")
ax.grid(True, alpha=0.3)
ax.legend()
save(fig, out_dir, "damper_loops.png")

s = rotorsim.Damper(deck, damper="physical").states(t, x)
pressures = [c for c in s.keys() if c.endswith("_Pa")]
assert pressures, f"no pressure channel in {list(s.keys())}"
fig, ax = plt.subplots(figsize=(8, 4))
for c in pressures:
    ax.plot(t[last], np.asarray(s[c])[last] / 1e6, label=c)
ax.set_xlabel("time [s]")
ax.set_ylabel("pressure [MPa]")
ax.set_title("Physical damper: pressures")
ax.grid(True, alpha=0.3)
ax.legend(fontsize=8)
save(fig, out_dir, "damper_pressures.png")
