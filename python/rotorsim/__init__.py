"""rotorsim: rotor-blade aeroelastic loads with physics-based hydraulic lead-lag dampers.

The computations run in the rotorsim library (Rust); this package converts arrays and results.
"""
import json as _json
import tempfile as _tempfile
from pathlib import Path as _Path

import numpy as _np

from . import _native

__version__ = _native.__version__
__all__ = ["Damper", "run", "RunResult"]


def _array(x, name):
    a = _np.asarray(x, dtype=_np.float64)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a one-dimensional array (got shape {a.shape})")
    return _np.ascontiguousarray(a)


class Damper:
    """A damper from a damper deck (any TOML file with a ``[damper]`` table).

    ``Damper(deck, model="physical", substeps=25, scheme="rk4")``: ``model`` is physical,
    linear or nonlinear; ``substeps`` hydraulic sub-steps per sample interval and ``scheme``
    (rk4 or implicit) as in ``rotorsim bench``. Errors in the deck raise FileNotFoundError,
    OSError or ValueError with the file and key in the message.
    """

    def __init__(self, deck, model="physical", substeps=25, scheme="rk4"):
        self._d = _native.Damper(str(deck), model, int(substeps), scheme)

    model = property(lambda self: self._d.model, doc="The damper model.")
    deck = property(lambda self: self._d.deck, doc="The deck file.")
    substeps = property(lambda self: self._d.substeps, doc="Hydraulic sub-steps per sample.")
    scheme = property(lambda self: self._d.scheme, doc="Hydraulic sub-step scheme.")
    channel_names = property(
        lambda self: list(self._d.channel_names),
        doc="Names (with units) of the device's internal channels.",
    )

    def __repr__(self):
        return f"Damper({self.deck!r}, model={self.model!r}, substeps={self.substeps}, scheme={self.scheme!r})"

    def force(self, time_s, stroke_m):
        """Force [N] of the damper driven by the stroke history, one value per sample.

        The device starts at rest; each sample interval is one step (the stroke moving linearly
        between the samples) of ``substeps`` hydraulic sub-steps, as ``rotorsim bench
        --measured`` replays a bench test. The first value is the initial force. ``time_s``
        must increase; both arrays must have the same length and finite values (ValueError).
        """
        return self._d.force(_array(time_s, "time_s"), _array(stroke_m, "stroke_m"))

    def states(self, time_s, stroke_m):
        """The replay of ``force`` with the device's internal channels.

        Columns: time_s, stroke_m, velocity_m_s (central differences of the stroke), force_N
        and the channels of ``channel_names`` (pressures, flows, valve states with their units).
        A pandas DataFrame when pandas is installed, else a dict of numpy arrays.
        """
        cols = self._d.states(_array(time_s, "time_s"), _array(stroke_m, "stroke_m"))
        data = dict(cols)
        try:
            import pandas as pd
        except ImportError:
            return data
        return pd.DataFrame(data)


_MODELS = ("linear", "nonlinear", "physical")


def _damper_choice(models):
    if models is None:
        return "all"
    if isinstance(models, str):
        models = [models]
    models = list(models)
    if sorted(models) == sorted(_MODELS):
        return "all"
    if len(models) == 1:
        return str(models[0])
    raise ValueError(
        f"models: a run compares one damper model or all three {list(_MODELS)} (got {models})"
    )


def _tqdm_progress():
    """A progress callback drawing one tqdm bar per unit, or None without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    bars = {}

    def progress(ev):
        if ev["event"] == "start":
            for i, name in enumerate(ev["units"]):
                bars[i] = tqdm(total=ev["revs"], desc=name, unit="rev", leave=False)
        elif ev["event"] == "revolution" and ev["unit"] in bars:
            b = bars[ev["unit"]]
            b.update(ev["revolution"] - b.n)
            if ev["periodicity"] is not None:
                b.set_postfix(periodicity=f"{ev['periodicity']:.2e}")
        elif ev["event"] == "finished" and ev["unit"] in bars:
            bars.pop(ev["unit"]).close()

    return progress


def run(
    rotor=None,
    flight=None,
    models=None,
    set=None,
    all_blades=False,
    airloads="measured",
    out=None,
    revs=None,
    steps_per_rev=None,
    substeps=None,
    progress=True,
):
    """Forced response of the rotor to a flight record, as ``rotorsim run`` does.

    Every option left out takes the command line's default, so ``rotorsim.run(models=["physical"])``
    in the repository is ``rotorsim run --damper physical``: ``rotor`` (rotor deck, default
    rotors/uh60a.toml), ``flight`` (MCAP file or CSV stem, default flightdata/c8534like),
    ``models`` (one of linear, nonlinear, physical, or all three; default all), ``set`` (deck
    values overridden by dotted key, ``{"damper.physical.A_orf_m2": 2e-6}``), ``all_blades``,
    ``airloads`` (measured, computed or hybrid), ``revs``, ``steps_per_rev``, ``substeps``.
    ``out``: the result folder to write (a temporary one, removed with the result, when not
    given). ``progress``: True for tqdm bars when tqdm is installed, False for none, or a callable
    taking one dict per event (``start``, ``revolution``, ``finished``).

    Bad input raises FileNotFoundError or ValueError naming the file and key, as the command
    line does. Returns a :class:`RunResult`.
    """
    keep = None
    if out is None:
        keep = _tempfile.TemporaryDirectory(prefix="rotorsim-run-")
        out = _Path(keep.name) / "run"
    sets = [] if set is None else [f"{k}={_set_value(v)}" for k, v in dict(set).items()]
    if progress is True:
        progress = _tqdm_progress()
    elif progress is False:
        progress = None
    folder, summary, last_rev = _native.run(
        str(out),
        rotor=None if rotor is None else str(rotor),
        flight=None if flight is None else str(flight),
        damper=_damper_choice(models),
        set=sets,
        all_blades=bool(all_blades),
        airloads=str(airloads),
        revs=revs,
        steps_per_rev=steps_per_rev,
        substeps=substeps,
        progress=progress,
    )
    return RunResult(folder, summary, dict(last_rev), keep)


def _set_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_set_value(x) for x in v) + "]"
    return str(v)


def _read_csv(path):
    """A CSV file of the result folder: a DataFrame with pandas (values parsed exactly), else a
    dict of numpy arrays."""
    try:
        import pandas as pd
    except ImportError:
        head = _Path(path).read_text().splitlines()[0].split(",")
        data = _np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
        return {h: data[:, i] for i, h in enumerate(head)}
    if int(pd.__version__.split(".")[0]) >= 3:
        return pd.read_csv(path)  # exact by default
    return pd.read_csv(path, float_precision="round_trip")


class RunResult:
    """What :func:`run` returns: the result folder's summary and files.

    ``folder`` (a temporary folder, removed with this object, unless ``out`` was given),
    ``summary`` (summary.json as a dict), ``models`` (the models that ran),
    ``last_rev(model, blade=None)`` (last_rev.csv of a model or one blade of a whole-rotor
    run), ``periodic(model)``, ``loads(model)``, ``floquet(model)``.
    """

    def __init__(self, folder, summary, last_rev, keep=None):
        self.folder = _Path(folder)
        self._keep = keep
        self._last_rev = {m: _Path(p) for m, p in last_rev.items()}
        with open(summary) as f:
            self.summary = _json.load(f)

    @property
    def models(self):
        return list(self._last_rev)

    def _model(self, model):
        if model is None and len(self._last_rev) == 1:
            return next(iter(self._last_rev))
        if model not in self._last_rev:
            raise ValueError(f"model {model!r} did not run (models: {self.models})")
        return model

    def last_rev(self, model=None, blade=None):
        """The last revolution of a model (last_rev.csv), or of blade ``blade`` (1-based) of a
        whole-rotor run: a DataFrame with pandas, else a dict of numpy arrays."""
        model = self._model(model)
        path = self._last_rev[model]
        if blade is not None:
            path = path.parent / f"blade{int(blade)}" / "last_rev.csv"
            if not path.exists():
                raise ValueError(f"no blade {blade} in the run of {model} ({path} missing)")
        return _read_csv(path)

    def periodic(self, model=None):
        """How the periodic solution was reached (summary.json's ``periodic``)."""
        return self.summary["models"][self._model(model)]["periodic"]

    def loads(self, model=None):
        """The blade loads of the last revolution (summary.json's ``loads``)."""
        return self.summary["models"][self._model(model)]["loads"]

    def floquet(self, model=None):
        """Floquet multipliers of the periodic solution, with their residuals."""
        return self.periodic(model).get("floquet_multipliers")

    def __repr__(self):
        return f"RunResult({str(self.folder)!r}, models={self.models})"
