"""rotorsim.diagnose against `rotorsim diagnose` (the library's diagnosis pipeline both run): the
same diagnosis, the same checks and messages. The flight record is SYNTHETIC."""
import filecmp
import json
import os
import pathlib
import subprocess

import pytest

import rotorsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
DECK = ROOT / "flightdata" / "damper_nominal.toml"
RECORD = ROOT / "flightdata" / "c8534like"
CLI = os.environ.get("ROTORSIM_CLI") or str(
    pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "rotorsim"
)


def test_flight_record_diagnosis_is_the_clis(tmp_path):
    cli = tmp_path / "cli"
    subprocess.run([CLI, "diagnose", "--rotor", str(DECK), "--flight", str(RECORD),
                    "--out", str(cli)], check=True, capture_output=True)
    lines = []
    r = rotorsim.diagnose(rotor=DECK, flight=RECORD, out=tmp_path / "py",
                          write_deck=tmp_path / "extended.toml", progress=lines.append)
    assert r.folder == tmp_path / "py"
    assert filecmp.cmp(cli / "diagnosis.json", r.folder / "diagnosis.json", shallow=False)
    assert r.diagnosis == json.loads((cli / "diagnosis.json").read_text())
    assert r.cause == r.diagnosis["cause"] != "none"
    assert set(r.parameters) == set(r.diagnosis["parameters"])
    assert r.gain > 0.0
    assert {c["cause"] for c in r.candidates} >= {r.cause}
    assert all(isinstance(x, str) for x in lines)  # progress lines (rotor runs only)
    # the extended deck is a damper deck the bench takes
    assert r.deck == tmp_path / "extended.toml"
    b = rotorsim.bench(r.deck, peak_velocity=[2.0], cycles=2)
    assert len(b.summary["model"]) == 1


def test_errors_name_the_file_and_the_option(tmp_path):
    with pytest.raises(ValueError, match="nothing to diagnose"):
        rotorsim.diagnose(out=tmp_path / "a")
    with pytest.raises(ValueError, match="give either --flight or --measured"):
        rotorsim.diagnose(rotor=DECK, flight=RECORD, measured=[tmp_path / "t.csv"],
                          out=tmp_path / "b")
    with pytest.raises(ValueError, match="--fit-cycles must be >= 2"):
        rotorsim.diagnose(rotor=DECK, flight=RECORD, fit_cycles=1, out=tmp_path / "c")
    with pytest.raises(ValueError, match="--model: unknown rotor model 'coaxial'"):
        rotorsim.diagnose(rotor=DECK, flight=RECORD, model="coaxial", out=tmp_path / "d")
    with pytest.raises(FileNotFoundError, match="nope.csv"):
        rotorsim.diagnose(damper_deck=DECK, measured=[tmp_path / "nope.csv"], out=tmp_path / "e")
    assert not any((tmp_path / x).exists() for x in "abcd")


def test_options_are_the_commands_and_deck_is_deprecated(tmp_path):
    assert rotorsim.DIAGNOSE_OPTIONS["fit_cycles"] == 3
    assert rotorsim.DIAGNOSE_OPTIONS["model"] == "uh60a"
    with pytest.warns(DeprecationWarning, match="deck= is deprecated: use damper_deck="):
        with pytest.raises(FileNotFoundError, match="nope.csv"):
            rotorsim.diagnose(deck=DECK, measured=[tmp_path / "nope.csv"], out=tmp_path / "e")
    with pytest.raises(TypeError, match="no_such_option"):
        rotorsim.diagnose(no_such_option=1, out=tmp_path / "f")
