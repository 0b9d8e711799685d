"""Ctrl-C stops a run: a long run in a child Python gets SIGINT once it is integrating; it ends
within seconds with KeyboardInterrupt saying where it stopped, and its result folder is marked
incomplete (no summary, no last revolution)."""
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# A run that would take minutes: marching to a tolerance it cannot reach.
CHILD = """
import sys
import rotorsim

def progress(ev):
    if ev["event"] == "revolution" and ev["revolution"] == 2:
        print("integrating", flush=True)

rotorsim.run(damper="physical", periodic="march", periodic_tol=1e-14, revs=2000,
             out=sys.argv[1], progress=progress)
print("finished", flush=True)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
def test_ctrl_c_stops_a_run_and_leaves_its_folder_incomplete(tmp_path):
    out = tmp_path / "run"
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(out)], cwd=ROOT,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = child.stdout.readline()
        assert line.strip() == "integrating", child.stderr.read()
        time.sleep(1.0)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        stdout, stderr = child.communicate(timeout=30)
        ended = time.monotonic() - sent
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode != 0
    assert "finished" not in stdout
    assert "KeyboardInterrupt: stopped by the user at t = " in stderr, stderr
    assert "physical model, revolution " in stderr
    # a structural step is milliseconds; the signal is looked for every 50 ms
    assert ended < 5.0, f"{ended:.1f} s from SIGINT to exit"
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] is False
    assert manifest["incomplete_reason"].startswith("stopped by the user at t = ")
    assert (out / "INCOMPLETE").exists()
    assert not (out / "summary.json").exists()
    assert not (out / "physical" / "last_rev.csv").exists()
    # the folder's lock is released
    assert not list(tmp_path.glob(".run.lock"))
