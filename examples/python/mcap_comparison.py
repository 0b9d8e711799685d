"""Damper force of every model over the measurement, from a run's result.mcap.

    python mcap_comparison.py RESULT_MCAP OUT_DIR

result.mcap (docs/formats.md, "result.mcap"): topic /run/<model> per damper model, one JSON
message per structural step of the last revolution (azimuth_deg and every last_rev.csv column),
and /run/measured (azimuth_deg, damper_force_N). Writes OUT_DIR/damper_force_mcap.png and
prints the RMS difference of each model from the measurement.
"""
import json
from collections import defaultdict

import matplotlib.pyplot as plt
import numpy as np
from mcap.reader import make_reader

from _common import COLORS, args, save

path, out_dir = args("RESULT_MCAP OUT_DIR", 2)
series = defaultdict(lambda: ([], []))
synthetic = False
with open(path, "rb") as f:
    for schema, channel, message in make_reader(f).iter_messages():
        if not channel.topic.startswith("/run/"):
            continue
        assert channel.message_encoding == "json", channel.message_encoding
        synthetic |= channel.metadata.get("synthetic") == "true"
        m = json.loads(message.data)
        psi, force = series[channel.topic.removeprefix("/run/")]
        psi.append(m["azimuth_deg"])
        force.append(np.nan if m["damper_force_N"] is None else m["damper_force_N"])
assert "measured" in series and len(series) > 1, f"{path}: topics {sorted(series)}"
tag = " (SYNTHETIC record)" if synthetic else ""
fig, ax = plt.subplots(figsize=(9, 4.5))
psi_m, f_m = (np.asarray(v) for v in series["measured"])
for name, (psi, force) in sorted(series.items()):
    psi, force = np.asarray(psi), np.asarray(force)
    style = {"ls": "--", "lw": 1.0} if name == "measured" else {}
    ax.plot(psi, force / 1e3, color=COLORS.get(name), label=name + (tag if name == "measured" else ""),
            **style)
    if name != "measured":
        err = np.interp(psi_m, psi, force, period=360.0) - f_m
        print(f"{name:10s} RMS difference from the measurement {np.sqrt(np.mean(err**2)):8.1f} N")
ax.set_xlabel("azimuth [deg]")
ax.set_ylabel("damper force [kN]")
ax.set_xticks(range(0, 361, 90))
ax.set_xlim(0, 360)
ax.grid(True, alpha=0.3)
ax.set_title("result.mcap: damper force" + tag)
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
save(fig, out_dir, "damper_force_mcap.png")
