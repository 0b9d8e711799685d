"""rotorsim.stability against `rotorsim stability` (the library's StabilityJob both run): the same
files, the same checks and messages."""
import filecmp
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
HAMMOND = ROOT / "rotors" / "hammond1974.toml"
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)


def files(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def test_map_writes_the_clis_files(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "stability", "--rotor", str(HAMMOND), "--speeds", "1:40:0.5",
                    "--out", str(cli)], check=True, capture_output=True)
    r = rotorsim.stability(HAMMOND, "1:40:0.5", out=tmp_path / "py")
    assert r.folder == tmp_path / "py"
    assert files(cli) == files(r.folder)
    for f in files(cli):
        if f != "manifest.json":
            assert filecmp.cmp(cli / f, r.folder / f, shallow=False), f
    assert r.stable is True and r.summary == json.loads((cli / "summary.json").read_text())
    assert r.amplitude is None
    text = (cli / "stability.csv").read_text().splitlines()
    ref = [float(row.split(",")[0]) for row in text[1:]]
    assert np.array_equal(np.asarray(r.modes[text[0].split(",")[0]]), ref)
    # speeds as numbers: the same map
    r2 = rotorsim.stability(HAMMOND, np.arange(1.0, 40.5, 0.5))
    assert filecmp.cmp(cli / "stability.csv", r2.folder / "stability.csv", shallow=False)


def test_errors_name_the_file_and_the_option(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.stability(tmp_path / "nope.toml", "1:2:1", out=tmp_path / "a")
    with pytest.raises(ValueError, match="--speeds"):
        rotorsim.stability(HAMMOND, "fast", out=tmp_path / "b")
    with pytest.raises(ValueError, match="--hover: the whole rotor's time domain"):
        rotorsim.stability(HAMMOND, "20", hover=True, time=[20], out=tmp_path / "c")
    with pytest.raises(ValueError, match="--amplitude-at-rad-s needs --amplitudes-m"):
        rotorsim.stability(HAMMOND, "20", amplitude_at_rad_s=27.0, out=tmp_path / "d")
    with pytest.raises(ValueError, match="rotor.omega_rad_s"):
        rotorsim.stability(HAMMOND, "20", set={"rotor.omega_rad_s": -1.0}, out=tmp_path / "e")
    assert not any((tmp_path / x).exists() for x in "abcde")


def test_options_are_the_command_lines(tmp_path):
    # every option of `rotorsim stability` is a keyword, with the command line's default
    assert rotorsim.STABILITY_OPTIONS["steps_per_rev"] == 512
    assert rotorsim.STABILITY_OPTIONS["hover"] is False
    with pytest.raises(TypeError, match="kick"):
        rotorsim.stability(HAMMOND, "20", kick=1e-3, out=tmp_path / "a")
    assert not (tmp_path / "a").exists()
