"""rotorsim.run against `rotorsim run` (the library's run pipeline both call): the default run
of a model gives the CLI's last_rev.csv bit for bit; errors and progress. Runs in the
repository's root, where the defaults (rotors/uh60a.toml, flightdata/c8534like) are."""
import filecmp
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)


@pytest.fixture(autouse=True)
def in_repository(monkeypatch):
    monkeypatch.chdir(ROOT)


def test_default_run_is_the_clis_bit_for_bit(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "run", "--damper", "physical", "--out", str(cli)],
                   check=True, capture_output=True)
    events = []
    r = rotorsim.run(damper=["physical"], out=tmp_path / "py", progress=events.append)
    assert r.models == ["physical"]
    assert filecmp.cmp(cli / "physical" / "last_rev.csv", r.folder / "physical" / "last_rev.csv",
                       shallow=False)
    # the values handed back are the file's, exactly
    text = (cli / "physical" / "last_rev.csv").read_text().splitlines()
    ref = np.array([[float(v) for v in row.split(",")] for row in text[1:]])
    lr = r.last_rev("physical")
    values = lr.to_numpy() if hasattr(lr, "to_numpy") else np.column_stack(list(lr.values()))
    assert list(lr.keys() if isinstance(lr, dict) else lr.columns) == text[0].split(",")
    assert np.array_equal(values, ref)
    # the summary, the periodic solution and its Floquet multipliers are the CLI's
    cli_summary = __import__("json").loads((cli / "summary.json").read_text())
    assert r.periodic()["residual"] == cli_summary["models"]["physical"]["periodic"]["residual"]
    assert r.periodic()["converged"] is True
    assert r.floquet() == cli_summary["models"]["physical"]["periodic"]["floquet_multipliers"]
    assert r.loads() == cli_summary["models"]["physical"]["loads"]
    # progress: the start, one event per revolution, the end
    assert events[0] == {"event": "start", "units": ["physical"], "revs": 100}
    revs = [e for e in events if e["event"] == "revolution"]
    assert [e["revolution"] for e in revs] == list(range(1, len(revs) + 1))
    assert events[-1]["event"] == "finished" and events[-1]["ok"]


def test_a_run_without_a_folder_leaves_none_behind():
    r = rotorsim.run(damper="linear", progress=False)
    folder = r.folder
    assert (folder / "linear" / "last_rev.csv").exists()
    del r
    import gc

    gc.collect()
    assert not folder.exists()


def test_errors_name_the_file_and_the_key(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.run(rotor=tmp_path / "nope.toml", progress=False)
    with pytest.raises(ValueError, match="damper.physical.A_orf_m2"):
        rotorsim.run(damper="physical", set={"damper.physical.A_orf_m2": -1.0},
                     out=tmp_path / "bad", progress=False)
    with pytest.raises(ValueError, match="one damper model or all three"):
        rotorsim.run(damper=["linear", "physical"], progress=False)
    with pytest.raises(ValueError, match="--damper"):
        rotorsim.run(damper="viscous", progress=False)
    with pytest.raises(ValueError, match="--airloads"):
        rotorsim.run(damper="linear", airloads="guessed", progress=False)
    with pytest.raises(ValueError, match="did not run"):
        rotorsim.run(damper="linear", model="rigid", progress=False).last_rev("physical")


def test_the_rigid_reduction_is_the_clis_and_reads_back(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "run", "--model", "rigid", "--revs", "30", "--out", str(cli)],
                   check=True, capture_output=True)
    r = rotorsim.run(model="rigid", revs=30, out=tmp_path / "py", progress=False)
    assert r.models == ["linear", "nonlinear", "physical"]
    for m in r.models:
        assert filecmp.cmp(cli / m / "last_rev.csv", r.folder / m / "last_rev.csv", shallow=False)
    # a folder written earlier reads back as the call's result
    again = rotorsim.RunResult.open(cli)
    assert again.models == r.models and again.summary["models"].keys() == r.summary["models"].keys()
    with pytest.raises(ValueError, match="--model"):
        rotorsim.run(model="flexible", progress=False)
    with pytest.raises(FileNotFoundError, match="summary.json"):
        rotorsim.RunResult.open(tmp_path)


def test_every_option_of_the_command_is_a_keyword(tmp_path):
    # rotorsim.RUN_OPTIONS is the library's one definition of the run's options
    every = dict(rotorsim.RUN_OPTIONS)
    assert {"scheme", "newton", "damper_deck", "initial_state", "require_periodic",
            "write_all_revs"} <= set(every)
    every.update(model="rigid", revs=30, damper="physical", damper_deck="rotors/uh60a.toml",
                 set={"damper.physical.A_orf_m2": 2.0e-6}, write_all_revs=True)
    cli = tmp_path / "cli"
    subprocess.run([CLI, "run", "--model", "rigid", "--revs", "30", "--damper", "physical",
                    "--damper-deck", "rotors/uh60a.toml", "--set", "damper.physical.A_orf_m2=2.0e-6",
                    "--write-all-revs", "--out", str(cli)], check=True, capture_output=True)
    r = rotorsim.run(out=tmp_path / "py", progress=False, **every)
    for f in ("last_rev.csv", "all_revs.csv"):
        assert filecmp.cmp(cli / "physical" / f, r.folder / "physical" / f, shallow=False)
    # a state to start from, by its own name
    again = rotorsim.run(out=tmp_path / "again", progress=False, model="rigid", revs=30,
                         damper="physical", initial_state=cli)
    assert again.models == ["physical"]
    with pytest.raises(TypeError, match="stepz"):
        rotorsim.run(stepz=3, progress=False)
    with pytest.warns(DeprecationWarning, match="damper="):
        rotorsim.run(models="physical", model="rigid", revs=30, progress=False)
