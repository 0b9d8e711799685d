"""An orifice-area study through the rotorsim package (no result folders, no command line): the
physical damper's last-revolution force for three orifice areas over the measured force.

    python api_orifice_study.py OUT_DIR [rigid|uh60a]

Runs rotorsim.run(damper="physical", set={"damper.physical.A_orf_m2": A}) for each area A on the
shipped flight record (the rigid-blade reduction by default, a second in all; uh60a for the
multibody rotor, a few seconds per area), prints each run's RMS error against the measurement and
writes OUT_DIR/orifice_study.png. Run from the repository root or give the paths: the defaults
are rotors/uh60a.toml and flightdata/c8534like, as on the command line.
"""
import os
import sys

import matplotlib.pyplot as plt
import rotorsim

from _common import COLORS, save

if len(sys.argv) not in (2, 3):
    print(f"usage: {os.path.basename(sys.argv[0])} OUT_DIR [rigid|uh60a]", file=sys.stderr)
    sys.exit(2)
out_dir = sys.argv[1]
rotor_model = sys.argv[2] if len(sys.argv) == 3 else "rigid"
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
deck = os.path.join(root, "rotors", "uh60a.toml")
record = os.path.join(root, "flightdata", "c8534like")

fig, ax = plt.subplots(figsize=(8, 4.5))
synthetic = False
for i, area in enumerate([1.6e-6, 1.8e-6, 2.0e-6]):
    r = rotorsim.run(rotor=deck, flight=record, damper="physical", model=rotor_model,
                     set={"damper.physical.A_orf_m2": area}, progress=False)
    rev = r.last_rev("physical")
    m = r.summary["models"]["physical"]
    synthetic |= bool(r.summary.get("synthetic"))
    print(f"A_orf = {area * 1e6:.1f} mm^2: RMS error {m['metrics']['rms_error_N']:8.1f} N, "
          f"periodic {m['periodic']['converged']}")
    ax.plot(rev["azimuth_deg"], rev["damper_force_N"], color=COLORS["physical"],
            alpha=0.4 + 0.3 * i, label=f"physical, A_orf = {area * 1e6:.1f} mm$^2$")
    if i == 0 and "measured_damper_force_N" in rev:
        ax.plot(rev["azimuth_deg"], rev["measured_damper_force_N"], color=COLORS["measured"],
                lw=2, label="measured" + (" (SYNTHETIC)" if synthetic else ""))
ax.set_xlabel("azimuth [deg]")
ax.set_ylabel("damper force [N]")
ax.set_title(f"Orifice area study, {rotor_model} rotor" + (" - SYNTHETIC flight record" if synthetic else ""))
ax.grid(True, alpha=0.3)
ax.legend(fontsize=8)
save(fig, out_dir, "orifice_study.png")
