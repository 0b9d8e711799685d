"""rotorsim.sweep against `rotorsim sweep` (the library's SweepJob both run): the same table and
case folders, the same checks and messages."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLAN = ROOT / "sweeps" / "ci_rigid.toml"
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)
SLURM = ("SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_CPUS_PER_TASK")


def table(path):
    """sweep.csv's rows without the wall-time column."""
    rows = [line.split(",") for line in path.read_text().splitlines()]
    w = rows[0].index("wall_time_s")
    return [r[:w] + r[w + 1:] for r in rows]


def test_sweep_writes_the_clis_table(tmp_path, monkeypatch):
    for v in SLURM:
        monkeypatch.delenv(v, raising=False)
    env = {k: v for k, v in os.environ.items() if k not in SLURM}
    subprocess.run([CLI, "sweep", str(PLAN), "--out", str(tmp_path / "cli"), "--jobs", "2"],
                   check=True, capture_output=True, cwd=ROOT, env=env)
    events = []
    monkeypatch.chdir(ROOT)  # the plan's paths resolve from the working directory, as on the CLI
    r = rotorsim.sweep(PLAN, tmp_path / "py", jobs=1, progress=events.append)
    assert r.failed == []
    assert table(tmp_path / "cli" / "sweep.csv") == table(r.folder / "sweep.csv")
    assert events[0] == {"event": "start", "to_run": 4, "total": 4}
    assert sorted(e["case"] for e in events[1:]) == ["c001", "c002", "c003", "c004"]
    assert all(e["ok"] and e["message"] is None for e in events[1:])
    # a case is a run result folder: its last revolution is the command line's, bit for bit
    case = r.case("c001")
    assert case.models == ["linear", "nonlinear", "physical"]
    cli_rev = (tmp_path / "cli" / "cases" / "c001" / "physical" / "last_rev.csv").read_text()
    assert (case.folder / "physical" / "last_rev.csv").read_text() == cli_rev
    assert np.asarray(case.last_rev("physical")["azimuth_deg"]).size > 0
    # resume: every case complete, nothing runs again
    events.clear()
    again = rotorsim.sweep(PLAN, tmp_path / "py", progress=events.append)
    assert events == [{"event": "start", "to_run": 0, "total": 4}]
    assert table(again.folder / "sweep.csv") == table(r.folder / "sweep.csv")


def test_a_shard_writes_no_table(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    r = rotorsim.sweep(PLAN, tmp_path / "s", shard="0/2", progress=False)
    assert r.table is None and r.failed == []
    assert len(list((r.folder / "cases").iterdir())) == 2


def test_errors_name_the_plan_and_the_key(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.sweep(tmp_path / "nope.toml", tmp_path / "a")
    bad = tmp_path / "bad.toml"
    bad.write_text("[vary]\nbogus = [1, 2]\n")
    with pytest.raises(ValueError, match="bogus"):
        rotorsim.sweep(bad, tmp_path / "b")
    with pytest.raises(ValueError, match="shard"):
        rotorsim.sweep(PLAN, tmp_path / "c", shard="3/2")
    with pytest.raises(ValueError, match="jobs"):
        rotorsim.sweep(PLAN, tmp_path / "d", jobs=0)
    assert not any((tmp_path / x).exists() for x in "abcd")
