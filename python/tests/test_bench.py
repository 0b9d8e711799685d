"""rotorsim.bench against `rotorsim bench` (the library's BenchJob both run): the same files, the
same checks and messages. The CLI is the release binary of the repository (ROTORSIM_CLI
overrides)."""
import filecmp
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
DECK = ROOT / "flightdata" / "damper_nominal.toml"
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)


def files(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def same_folders(a, b):
    """Every file of two result folders identical, the manifest (run id, times, command line)
    aside."""
    assert files(a) == files(b)
    for f in files(a):
        if f != "manifest.json":
            assert filecmp.cmp(a / f, b / f, shallow=False), f


def column(frame, name):
    return np.asarray(frame[name])


def test_sweep_writes_the_clis_files(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "bench", "--damper-deck", str(DECK), "--damper", "all",
                    "--peak-velocity", "1,4", "--cycles", "4", "--out", str(cli)],
                   check=True, capture_output=True)
    r = rotorsim.bench(DECK, damper="all", peak_velocity=[1, 4], cycles=4, out=tmp_path / "py")
    assert r.folder == tmp_path / "py" and not r.replay
    same_folders(cli, r.folder)
    text = (cli / "bench_summary.csv").read_text().splitlines()
    assert list(r.summary["model"]) == [row.split(",")[0] for row in text[1:]]
    ref = [float(row.split(",")[6]) for row in text[1:]]
    assert np.array_equal(column(r.summary, "peak_force_pos_N"), ref)
    h = r.history(4 * 0.0254, model="linear")
    assert len(column(h, "force_N")) > 0


def test_replay_writes_the_clis_files(tmp_path):
    t = np.arange(1200) / 2000.0
    x = 0.004 * np.sin(27.0 * t)
    test = tmp_path / "t1.csv"
    test.write_text("time_s,stroke_m,force_N\n" + "".join(
        f"{a!r},{b!r},{1e5 * b!r}\n" for a, b in zip(t.tolist(), x.tolist())))
    cli = tmp_path / "cli"
    subprocess.run([CLI, "bench", "--damper-deck", str(DECK), "--damper", "physical",
                    "--measured", str(test), "--out", str(cli)], check=True, capture_output=True)
    r = rotorsim.bench(DECK, damper="physical", measured=test, out=tmp_path / "py")
    assert r.replay
    same_folders(cli, r.folder)
    assert "rms_error_N" in list(r.summary.keys() if isinstance(r.summary, dict) else r.summary.columns)


def test_a_bench_without_a_folder_leaves_none_behind():
    r = rotorsim.bench(DECK, damper="linear", peak_velocity=2, cycles=2)
    folder = r.folder
    assert (folder / "bench_summary.csv").exists()
    del r
    import gc

    gc.collect()
    assert not folder.exists()


def test_errors_name_the_file_and_the_option(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.bench(tmp_path / "nope.toml", out=tmp_path / "a")
    with pytest.raises(ValueError, match="--velocity-unit 'km/h'"):
        rotorsim.bench(DECK, velocity_unit="km/h", out=tmp_path / "b")
    with pytest.raises(ValueError, match="--skip-cycles applies to a replay"):
        rotorsim.bench(DECK, skip_cycles=2, out=tmp_path / "c")
    with pytest.raises(ValueError, match="--damper viscous"):
        rotorsim.bench(DECK, damper="viscous", out=tmp_path / "d")
    with pytest.raises(FileNotFoundError, match="missing.csv"):
        rotorsim.bench(DECK, measured=tmp_path / "missing.csv", out=tmp_path / "e")
    assert not (tmp_path / "b").exists() and not (tmp_path / "c").exists()


def test_options_are_the_command_lines(tmp_path):
    # every option of `rotorsim bench` is a keyword, with the command line's default
    assert rotorsim.BENCH_OPTIONS["omega"] == 27.02
    # left out (None): implicit, steps per cycle refined until converged
    assert rotorsim.BENCH_OPTIONS["scheme"] is None
    with pytest.raises(TypeError, match="velocity_units"):
        rotorsim.bench(DECK, velocity_units="m/s", out=tmp_path / "a")
    # `deck=`, the earlier name of `damper_deck=`, still works
    with pytest.warns(DeprecationWarning, match="damper_deck"):
        r = rotorsim.bench(deck=DECK, damper="linear", peak_velocity=2, cycles=2)
    assert list(r.summary["model"]) == ["linear"]
