"""rotorsim.Damper against `rotorsim bench --measured` (the same library replay, so bit for bit)
and its errors. The CLI is the release binary of the repository (ROTORSIM_CLI overrides)."""
import math
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


def stroke(n=1200, rate_hz=2000.0, amp_m=0.004, w_rad_s=27.0):
    t = np.arange(n) / rate_hz
    return t, amp_m * np.sin(w_rad_s * t) + 0.001 * np.sin(3.0 * w_rad_s * t)


def cli_replay(tmp_path, t, x, model):
    test = tmp_path / "t1.csv"
    with open(test, "w") as f:
        f.write("time_s,stroke_m\n")
        for a, b in zip(t.tolist(), x.tolist()):
            f.write(f"{a!r},{b!r}\n")
    out = tmp_path / f"out_{model}"
    subprocess.run(
        # the Damper steps as a run does (RK4, 25 sub-steps), the bench's default is its
        # converged implicit scheme: ask the bench for the run's
        [CLI, "bench", "--damper-deck", str(DECK), "--damper", model, "--scheme", "rk4",
         "--measured", str(test), "--out", str(out)],
        check=True, capture_output=True,
    )
    rows = (out / f"replay_t1_{model}.csv").read_text().splitlines()
    names = rows[0].split(",")
    values = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    return {n: values[:, i] for i, n in enumerate(names)}


@pytest.mark.parametrize("model", ["physical", "linear", "nonlinear"])
def test_force_is_the_bench_replay_bit_for_bit(tmp_path, model):
    t, x = stroke()
    ref = cli_replay(tmp_path, t, x, model)
    f = rotorsim.Damper(DECK, damper=model).force(t, x)
    assert f.dtype == np.float64 and f.shape == t.shape
    assert np.array_equal(f, ref["force_model_N"])


def test_states_are_the_bench_replay_columns(tmp_path):
    t, x = stroke(n=600)
    ref = cli_replay(tmp_path, t, x, "physical")
    d = rotorsim.Damper(DECK)
    s = d.states(t, x)
    names = list(s.keys()) if isinstance(s, dict) else list(s.columns)
    # the CLI's replay file names the model force force_model_N
    assert [n if n != "force_N" else "force_model_N" for n in names] == list(ref)
    for n in names:
        col = np.asarray(s[n], dtype=np.float64)
        assert np.array_equal(col, ref["force_model_N" if n == "force_N" else n]), n
    assert set(d.channel_names) <= set(names)
    # the internal channels move: both chamber pressures vary over the history
    assert np.ptp(np.asarray(s["p0_Pa"])) > 1e5 and np.ptp(np.asarray(s["p1_Pa"])) > 1e5


def test_a_missing_deck_names_the_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        rotorsim.Damper(missing)


def test_a_deck_without_a_damper_table_names_file_and_table(tmp_path):
    deck = tmp_path / "empty.toml"
    deck.write_text("[rotor]\nblades = 4\n")
    with pytest.raises(ValueError, match="empty.toml") as e:
        rotorsim.Damper(deck)
    assert "damper" in str(e.value)


def test_an_unknown_model_and_scheme_are_refused():
    with pytest.raises(ValueError, match="model magic"):
        rotorsim.Damper(DECK, damper="magic")
    with pytest.raises(ValueError, match="scheme euler"):
        rotorsim.Damper(DECK, scheme="euler")
    with pytest.raises(ValueError, match="substeps"):
        rotorsim.Damper(DECK, substeps=0)


def test_bad_histories_are_refused_with_what_was_expected():
    d = rotorsim.Damper(DECK)
    t, x = stroke(n=100)
    with pytest.raises(ValueError, match="one-dimensional"):
        d.force(np.vstack([t, t]), x)
    with pytest.raises(ValueError):
        d.force(t, x[:-1])
    back = t.copy()
    back[50] = back[49]
    with pytest.raises(ValueError):
        d.force(back, x)
    nan = x.copy()
    nan[10] = math.nan
    with pytest.raises(ValueError):
        d.force(t, nan)
