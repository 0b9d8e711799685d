"""rotorsim.modes against `rotorsim modes` (the library's ModesJob both run): the same files, the
same checks and messages."""
import filecmp
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
# a model deck with [modes] speeds_rad_s: modes, shapes and a fan (about a second)
CANTILEVER = ROOT / "docs" / "examples" / "rotating_cantilever.toml"
UH60A = ROOT / "rotors" / "uh60a.toml"
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)


def files(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def same_files(cli, py):
    assert files(cli) == files(py)
    for f in files(cli):
        if f != "manifest.json":
            assert filecmp.cmp(cli / f, py / f, shallow=False), f


def test_model_deck_writes_the_clis_files(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "modes", str(CANTILEVER), "--out", str(cli)], check=True,
                   capture_output=True)
    r = rotorsim.modes(CANTILEVER, out=tmp_path / "py")
    assert r.folder == tmp_path / "py"
    same_files(cli, r.folder)
    assert {"modes.csv", "mode_shapes.csv", "fan.csv", "fan.svg"} <= set(files(cli))
    text = (cli / "modes.csv").read_text().splitlines()
    ref = [float(row.split(",")[1]) for row in text[1:]]
    assert np.array_equal(np.asarray(r.modes["freq_Hz"]), ref)
    assert r.shapes is not None and r.fan is not None and r.comparison is None
    assert r.fan_plot == r.folder / "fan.svg"
    # a temporary folder when none is given, kept while the result lives
    r2 = rotorsim.modes(deck=CANTILEVER)
    assert filecmp.cmp(cli / "modes.csv", r2.folder / "modes.csv", shallow=False)


def test_rotor_fan_writes_the_clis_files(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "modes", "--rotor", str(UH60A), "--speed-fractions", "0.5,1", "--count", "6",
                    "--out", str(cli)], check=True, capture_output=True)
    # speeds as numbers: the same list
    r = rotorsim.modes(rotor=UH60A, speed_fractions=[0.5, 1.0], count=6, out=tmp_path / "py")
    same_files(cli, r.folder)
    assert r.shapes is None
    assert list(np.asarray(r.fan["speed_fraction"])) == [0.5, 1.0]
    assert len(r.modes["mode"]) == 2 * 6
    # the shipped reference is compared at both speeds (its note line left out)
    assert r.comparison is not None and len(r.comparison["error_pct"]) == 2 * 5


def test_errors_name_the_file_and_the_option(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.modes(tmp_path / "nope.toml", out=tmp_path / "a")
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.modes(rotor=tmp_path / "nope.toml", out=tmp_path / "b")
    with pytest.raises(ValueError, match="--speed-fractions"):
        rotorsim.modes(rotor=UH60A, speed_fractions="fast", out=tmp_path / "c")
    with pytest.raises(ValueError, match="--speeds"):
        rotorsim.modes(rotor=UH60A, speeds="0:1:0", out=tmp_path / "d")
    with pytest.raises(ValueError, match="--count 0"):
        rotorsim.modes(rotor=UH60A, count=0, out=tmp_path / "e")
    with pytest.raises(ValueError, match="give a model deck or --rotor"):
        rotorsim.modes(out=tmp_path / "f")
    with pytest.raises(ValueError, match="not both"):
        rotorsim.modes(CANTILEVER, rotor=UH60A, out=tmp_path / "g")
    # rad/s that look like fractions of the nominal 27 rad/s
    with pytest.raises(ValueError, match="27"):
        rotorsim.modes(rotor=UH60A, speeds="0.5,1", out=tmp_path / "h")
    assert not any((tmp_path / x).exists() for x in "abcdefgh")


def test_options_are_the_command_lines(tmp_path):
    # every option of `rotorsim modes` is a keyword, with the command line's default
    assert rotorsim.MODES_OPTIONS["count"] == 14
    assert rotorsim.MODES_OPTIONS["speed_fractions"] == "0:1.2:0.1"
    with pytest.raises(ValueError, match="give one"):
        rotorsim.modes(rotor=UH60A, speeds="20,27", speed_fractions="0.5,1", out=tmp_path / "a")
    with pytest.raises(TypeError, match="counts"):
        rotorsim.modes(rotor=UH60A, counts=3, out=tmp_path / "b")
    assert not (tmp_path / "a").exists()
