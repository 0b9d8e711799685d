"""rotorsim: rotor-blade aeroelastic loads with physics-based hydraulic lead-lag dampers.

The computations run in the rotorsim library (Rust); this package converts arrays and results.
"""
import json as _json
import os as _os
import tempfile as _tempfile
from pathlib import Path as _Path

import numpy as _np

from . import _native

__version__ = _native.__version__
__all__ = ["Damper", "run", "RunResult", "bench", "BenchResult", "stability", "StabilityResult", "modes",
           "ModesResult", "diagnose", "DiagnoseResult", "sweep", "SweepResult"]


def _array(x, name):
    a = _np.asarray(x, dtype=_np.float64)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a one-dimensional array (got shape {a.shape})")
    return _np.ascontiguousarray(a)


class Damper:
    """A damper from a damper deck (any TOML file with a ``[damper]`` table).

    ``Damper(deck, damper="physical", substeps=25, scheme="rk4")``: ``damper`` is the damper
    model, physical, linear or nonlinear (``model=``, its deprecated name); ``substeps`` hydraulic sub-steps per sample interval and ``scheme``
    (rk4 or implicit) as in ``rotorsim bench``. Errors in the deck raise FileNotFoundError,
    OSError or ValueError with the file and key in the message.
    """

    def __init__(self, deck, damper=None, substeps=25, scheme="rk4", model=None):
        if model is not None:
            _deprecated("model", "damper")
            damper = damper or model
        self._d = _native.Damper(str(deck), damper or "physical", int(substeps), scheme)

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
        f"damper: a run compares one damper model or all three {list(_MODELS)} (got {models})"
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


# The options of ``rotorsim run`` with their defaults, from the library's one definition.
RUN_OPTIONS = _json.loads(_native.run_options())


def _deprecated(old, new):
    import warnings

    warnings.warn(
        f"{old}= is deprecated: use {new}= (the name of the command line's --{new.replace('_', '-')})",
        DeprecationWarning,
        stacklevel=3,
    )


# The options of the other jobs with their defaults, from the library's one definition each.
BENCH_OPTIONS = _json.loads(_native.job_options("bench"))
STABILITY_OPTIONS = _json.loads(_native.job_options("stability"))
MODES_OPTIONS = _json.loads(_native.job_options("modes"))


def _check_known(job, known, options):
    """A TypeError naming the keywords of ``options`` that are not options of ``job``."""
    unknown = sorted(k for k in options if k not in known)
    if unknown:
        raise TypeError(
            f"{job}() got unexpected keyword argument(s) {', '.join(unknown)} "
            f"(the options of rotorsim {job} are {', '.join(known)})"
        )


def _settings(job, known, options):
    """Keyword arguments of ``job`` as the JSON its settings type reads (None left out)."""
    _check_known(job, known, options)
    settings = {}
    for k, v in options.items():
        if v is None:
            continue
        if isinstance(v, _os.PathLike):
            v = _os.fspath(v)
        elif isinstance(v, _np.generic):
            v = v.item()
        settings[k] = v
    return _json.dumps(settings)


def run(out=None, progress=True, models=None, rotor_model=None, **options):
    """Forced response of the rotor to a flight record, as ``rotorsim run`` does.

    ``options`` are the options of ``rotorsim run`` by their names (``--steps-per-rev`` is
    ``steps_per_rev``); every one left out (or None) takes the command line's default, so
    ``rotorsim.run(damper="physical")`` in the repository is ``rotorsim run --damper
    physical``: ``rotor`` (rotor deck, default rotors/uh60a.toml), ``flight`` (MCAP file or CSV
    stem, default flightdata/c8534like), ``damper`` (linear, nonlinear, physical, or all three:
    also a list of them; default all), ``damper_deck``, ``set`` (deck values overridden by
    dotted key, ``{"damper.physical.A_orf_m2": 2e-6}``), ``all_blades``, ``airloads``
    (measured, computed, hybrid or hybrid-periodic), ``revs``, ``steps_per_rev``,
    ``substeps``, ``scheme``, ``newton``, ``periodic`` (shooting or march), ``periodic_tol``,
    ``initial_state``, ``require_periodic``, ``write_all_revs`` and ``model`` (the rotor model,
    ``--model``: uh60a, the multibody rotor, or rigid, its rigid-blade reduction, a run in well
    under a second). ``models`` and ``rotor_model`` are the deprecated names of ``damper`` and
    ``model``. An unknown name raises TypeError.
    ``out``: the result folder to write (a temporary one, removed with the result, when not
    given). ``progress``: True for tqdm bars when tqdm is installed, False for none, or a callable
    taking one dict per event (``start``, ``revolution``, ``finished``).

    Bad input raises FileNotFoundError or ValueError naming the file and key, as the command
    line does. Ctrl-C stops the run before its next structural step and raises
    KeyboardInterrupt saying where it stopped; the result folder is then marked incomplete.
    Returns a :class:`RunResult`.
    """
    if models is not None:
        _deprecated("models", "damper")
        options.setdefault("damper", models)
    if rotor_model is not None:
        _deprecated("rotor_model", "model")
        options.setdefault("model", rotor_model)
    _check_known("run", RUN_OPTIONS, options)
    settings = {k: v for k, v in options.items() if v is not None}
    if "damper" in settings:
        settings["damper"] = _damper_choice(settings["damper"])
    if "set" in settings:
        settings["set"] = _sets(settings["set"])
    for k, v in settings.items():
        if isinstance(v, _os.PathLike):
            settings[k] = _os.fspath(v)
    keep = None
    if out is None:
        keep = _tempfile.TemporaryDirectory(prefix="rotorsim-run-")
        out = _Path(keep.name) / "run"
    if progress is True:
        progress = _tqdm_progress()
    elif progress is False:
        progress = None
    folder, summary, last_rev = _native.run(
        str(out), settings=_json.dumps(settings), progress=progress
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


def _read_csv(path, comments=False):
    """A CSV file of the result folder: a DataFrame with pandas (values parsed exactly), else a
    dict of numpy arrays. ``comments``: the file may have ``#`` lines (notes), left out."""
    try:
        import pandas as pd
    except ImportError:
        import csv

        with open(path, newline="") as f:
            rows = [r for r in csv.reader(f) if not (comments and r and r[0].startswith("#"))]
        data = {}
        for i, h in enumerate(rows[0]):
            vals = [r[i] for r in rows[1:]]
            try:
                data[h] = _np.array([float(v) for v in vals])  # exact: Python parses correctly rounded
            except ValueError:
                data[h] = _np.array(vals)  # a text column (a model's name, a file)
        return data
    opts = {"comment": "#"} if comments else {}
    if int(pd.__version__.split(".")[0]) >= 3:
        return pd.read_csv(path, **opts)  # exact by default
    return pd.read_csv(path, float_precision="round_trip", **opts)


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

    @classmethod
    def open(cls, folder):
        """A result folder written earlier (``rotorsim run --out``, a sweep's case): its
        summary and each model's last revolution, as :func:`run` returns them."""
        folder = _Path(folder)
        if not (folder / "summary.json").exists():
            raise FileNotFoundError(f"{folder}: no summary.json (not a complete rotorsim run result folder)")
        last = {m: folder / m / "last_rev.csv" for m in ("linear", "nonlinear", "physical")}
        return cls(folder, folder / "summary.json", {m: p for m, p in last.items() if p.exists()})

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


def _out_folder(out, prefix):
    """The result folder to write, and the temporary folder holding it when none is given."""
    if out is not None:
        return _Path(out), None
    keep = _tempfile.TemporaryDirectory(prefix=prefix)
    return _Path(keep.name) / "out", keep


def _opt(p):
    """An optional path or name as text (None stays None)."""
    return None if p is None else str(p)


def _paths(xs):
    if xs is None:
        return []
    if isinstance(xs, (str, _Path)) or hasattr(xs, "__fspath__"):
        xs = [xs]
    return [str(x) for x in xs]


def bench(damper_deck=None, *, out=None, deck=None, **options):
    """The damper bench of a damper deck, as ``rotorsim bench`` runs it.

    ``damper_deck``: any TOML file with a ``[damper]`` table (``deck`` is its deprecated name).
    ``options`` are the options of ``rotorsim bench`` by their names (rotorsim.BENCH_OPTIONS);
    every one left out takes the command line's default: ``damper`` (physical, linear,
    nonlinear or all; default the deck's ``model``), ``omega`` (27.02 rad/s), ``peak_velocity``
    (0.5, 1, 2, 3, 4, 6, 8, 10), ``velocity_unit`` (in/s, m/s or ft/s), ``cycles`` (10),
    ``steps_per_cycle``, ``substeps``, ``scheme`` (implicit or rk4): all three left out, each
    run is refined from 256 steps per cycle until converged (implicit, 4 sub-steps; the error
    estimate of each output is in the summary); any given, the bench runs as asked,
    ``output_rate`` (samples per second of the sweep; one per step by default). ``measured``:
    bench CSV file(s) to replay instead of the harmonic sweep, ``skip_cycles`` cycles of each
    left out of the error metrics. An unknown name raises TypeError.
    ``out``: the result folder to write (a temporary one, removed with the result, when not
    given).

    Bad input raises FileNotFoundError or ValueError naming the file and key, as the command
    line does. Returns a :class:`BenchResult`.
    """
    if deck is not None:
        _deprecated("deck", "damper_deck")
        damper_deck = deck if damper_deck is None else damper_deck
    options["damper_deck"] = damper_deck
    if options.get("damper") is not None:
        options["damper"] = str(options["damper"])
    if options.get("omega") is not None:
        options["omega"] = float(options["omega"])
    if options.get("peak_velocity") is not None:
        options["peak_velocity"] = [float(v) for v in _np.atleast_1d(options["peak_velocity"])]
    if options.get("output_rate") is not None:
        options["output_rate"] = float(options["output_rate"])
    if "measured" in options:
        options["measured"] = _paths(options["measured"])
    out, keep = _out_folder(out, "rotorsim-bench-")
    settings = _settings("bench", BENCH_OPTIONS, options)
    folder = _native.bench(str(out), settings=settings)
    return BenchResult(folder, keep)


class BenchResult:
    """What :func:`bench` returns: its result folder and tables.

    ``folder`` (a temporary folder, removed with this object, unless ``out`` was given),
    ``replay`` (True for a replay of measured tests), ``summary`` (bench_summary.csv of the
    harmonic sweep: peak forces, storage and loss stiffness, energy per cycle for each model and
    peak velocity; or replay_summary.csv of a replay: each test's error metrics), and
    ``history(peak_velocity_m_s, model=None)`` (a sweep's history file).
    """

    def __init__(self, folder, keep=None):
        self.folder = _Path(folder)
        self._keep = keep
        self.replay = (self.folder / "replay_summary.csv").exists()
        name = "replay_summary.csv" if self.replay else "bench_summary.csv"
        self.summary = _read_csv(self.folder / name)

    def history(self, peak_velocity_m_s, model=None):
        """The sampled history of the sweep at a peak velocity (bench_summary.csv's
        ``peak_velocity_m_s``): time, stroke, velocity, force and the device's channels."""
        rows = self.summary
        v = _np.asarray(rows["peak_velocity_m_s"], dtype=float)
        models = list(rows["model"])
        picks = [i for i in range(len(v)) if _np.isclose(v[i], peak_velocity_m_s, rtol=0, atol=1e-9)
                 and (model is None or models[i] == model)]
        if self.replay or not picks:
            raise ValueError(f"no history at {peak_velocity_m_s} m/s (model {model}) in {self.folder}")
        if model is None and len({models[i] for i in picks}) > 1:
            raise ValueError(f"several models ran: name one ({sorted(set(models))})")
        return _read_csv(self.folder / list(rows["history_file"])[picks[0]])

    def __repr__(self):
        return f"BenchResult({str(self.folder)!r}, replay={self.replay})"


def _sets(set):
    return [] if set is None else [f"{k}={_set_value(v)}" for k, v in dict(set).items()]


def _list(x):
    """A list option as the command line takes it: text as it is, numbers comma separated."""
    if x is None or isinstance(x, str):
        return x
    return ",".join(repr(float(v)) for v in _np.atleast_1d(x))


def stability(rotor, speeds, *, out=None, **options):
    """Ground (or, ``hover=True``, air) resonance of a rotor deck on its airframe over rotor
    speeds, as ``rotorsim stability`` computes it.

    ``speeds`` [rad/s]: "START:STOP:STEP" (inclusive), "a,b,c", or a list of numbers.
    ``options`` are the options of ``rotorsim stability`` by their names
    (rotorsim.STABILITY_OPTIONS); every one left out takes the command line's default:
    ``damper`` (the deck's model), ``time`` (speeds of whole-rotor time-domain runs) with
    ``kick_m_s`` (1e-4), ``time_duration_s`` (20) and ``steps_per_rev`` (512); ``amplitudes_m``
    (stroke amplitudes of the nonlinear amplitude check, a list or "default") at
    ``amplitude_at_rad_s`` (the deck's speed); ``hover`` with ``collective_deg`` (8),
    ``density_kg_m3`` (1.225), ``speed_of_sound_m_s`` (340.3) and ``strips``; ``set`` (deck
    values by dotted key). An unknown name raises TypeError. ``out``: the result folder to
    write (a temporary one, removed with the result, when not given).

    Bad input raises FileNotFoundError or ValueError naming the file and key, as the command
    line does. Returns a :class:`StabilityResult`.
    """
    options.update(rotor=rotor, speeds=_list(speeds))
    for k in ("time", "amplitudes_m"):
        options[k] = _list(options.get(k))
    if options.get("damper") is not None:
        options["damper"] = str(options["damper"])
    if options.get("hover") is not None:
        options["hover"] = bool(options["hover"])
    if "set" in options:
        options["set"] = _sets(options["set"])
    out, keep = _out_folder(out, "rotorsim-stability-")
    settings = _settings("stability", STABILITY_OPTIONS, options)
    folder = _native.stability(str(out), settings=settings)
    return StabilityResult(folder, keep)


class StabilityResult:
    """What :func:`stability` returns: its result folder and tables.

    ``folder`` (a temporary folder, removed with this object, unless ``out`` was given),
    ``summary`` (summary.json as a dict: ``stable``, ``method``, the unstable ranges, the least
    damping), ``modes`` (stability.csv: frequency, damping ratio and growth rate of each mode at
    each speed), ``amplitude`` (amplitude.csv of the amplitude check, or None).
    """

    def __init__(self, folder, keep=None):
        self.folder = _Path(folder)
        self._keep = keep
        with open(self.folder / "summary.json") as f:
            self.summary = _json.load(f)
        self.modes = _read_csv(self.folder / "stability.csv")
        a = self.folder / "amplitude.csv"
        self.amplitude = _read_csv(a) if a.exists() else None

    @property
    def stable(self):
        """Whether every mode is damped at every speed (summary.json's ``stable``)."""
        return self.summary["stable"]

    def __repr__(self):
        return f"StabilityResult({str(self.folder)!r}, stable={self.stable})"


def modes(deck=None, rotor=None, *, out=None, **options):
    """Natural frequencies and mode shapes, as ``rotorsim modes`` computes them: of a model deck
    (``deck``) about its static equilibrium, or the fan plot of a rotor deck (``rotor``).

    Give one of ``deck`` (a model deck; its ``[modes]`` table says how many modes and, with
    ``speeds_rad_s``, at which rotor speeds: a fan) and ``rotor`` (a rotor deck or a
    hinged-blade deck). ``options`` are the other options of ``rotorsim modes`` by their names
    (rotorsim.MODES_OPTIONS); the fan plot of a rotor deck takes, where left out, the command
    line's defaults: ``speeds`` (rotor speeds in rad/s: "START:STOP:STEP" inclusive, "a,b,c",
    or a list of numbers) or ``speed_fractions`` (fractions of the deck's nominal speed, in the
    same forms; default "0:1.2:0.1"), ``reference`` (a digitized reference fan plot drawn over
    the model's and compared with it; default the shipped UH-60A one next to the deck, or a
    hinged-blade deck's own ``[fan_reference]``), ``count`` (modes per speed, 14). A model deck
    does not use them. An unknown name raises TypeError. ``out``: the result folder to write (a
    temporary one, removed with the result, when not given).

    Bad input raises FileNotFoundError or ValueError naming the file and option, as the command
    line does. Returns a :class:`ModesResult`.
    """
    if options.get("speeds") is not None and options.get("speed_fractions") is not None:
        raise ValueError(
            "speeds and speed_fractions: give one (rad/s, or fractions of the nominal speed)"
        )
    options.update(deck=deck, rotor=rotor)
    for k in ("speeds", "speed_fractions"):
        options[k] = _list(options.get(k))
    if options.get("count") is not None:
        options["count"] = int(options["count"])
    out, keep = _out_folder(out, "rotorsim-modes-")
    folder = _native.modes(str(out), settings=_settings("modes", MODES_OPTIONS, options))
    return ModesResult(folder, keep)


class ModesResult:
    """What :func:`modes` returns: its result folder and tables.

    ``folder`` (a temporary folder, removed with this object, unless ``out`` was given),
    ``modes`` (modes.csv: each mode's frequency, damping ratio and flap, lag, torsion and axial
    fractions; of a model deck at rest, of a rotor deck at every speed), ``shapes``
    (mode_shapes.csv of a model deck: each node's displacements in each mode; None for a rotor
    deck), ``fan`` (fan.csv: the frequencies over the rotor speeds; None for a model deck
    without ``[modes] speeds_rad_s``), ``comparison`` (fan_comparison.csv: the tracked modes
    against the reference; None without one) and ``fan_plot`` (the path of fan.svg, or None).
    """

    def __init__(self, folder, keep=None):
        self.folder = _Path(folder)
        self._keep = keep
        self.modes = self._table("modes.csv")
        self.shapes = self._table("mode_shapes.csv")
        self.fan = self._table("fan.csv")
        self.comparison = self._table("fan_comparison.csv")
        plot = self.folder / "fan.svg"
        self.fan_plot = plot if plot.exists() else None

    def _table(self, name):
        """A table of the folder (its ``#`` notes left out), or None when not written."""
        path = self.folder / name
        return _read_csv(path, comments=True) if path.exists() else None

    def __repr__(self):
        return f"ModesResult({str(self.folder)!r}, fan={self.fan is not None})"


# The options of ``rotorsim diagnose`` with their defaults, from the library's one definition.
DIAGNOSE_OPTIONS = _json.loads(_native.diagnose_options())


def diagnose(damper_deck=None, measured=None, *, out=None, progress=None, deck=None, **options):
    """What the damper model gets wrong in measured data, as ``rotorsim diagnose`` finds it:
    the cause named, the model extended, the gain measured on held-out data.

    ``options`` are the options of ``rotorsim diagnose`` by their names (``--fit-cycles`` is
    ``fit_cycles``); every one left out (or None) takes the command line's default. The data:
    ``damper_deck`` (the baseline damper deck) with ``measured`` bench CSV file(s), or
    ``rotor`` (rotor deck; its ``[damper]`` is the baseline unless ``damper_deck``) with
    ``flight`` (a flight record). The others: ``fit_cycles`` (3), ``max_substep`` (3e-5 s),
    ``revs`` (40), ``steps_per_rev`` (256), ``substeps`` (25), ``rotor_check`` (False; the
    rotor-level before/after of a flight record) with ``check_revs`` (75), ``model`` (uh60a or
    rigid, the rotor runs' model). ``write_deck``: also write the extended model as a damper
    deck there. ``deck`` is the deprecated name of ``damper_deck``. An unknown name raises
    TypeError. ``out``: the result folder to write (a temporary one, removed with the result,
    when not given). ``progress``: a callable given each progress line.

    Bad input raises FileNotFoundError or ValueError naming the file and key, as the command
    line does. Returns a :class:`DiagnoseResult`.
    """
    if deck is not None:
        _deprecated("deck", "damper_deck")
        if damper_deck is None:
            damper_deck = deck
    _check_known("diagnose", DIAGNOSE_OPTIONS, options)
    settings = {k: v for k, v in options.items() if v is not None}
    if damper_deck is not None:
        settings["damper_deck"] = damper_deck
    if measured is not None:
        settings["measured"] = _paths(measured)
    if "max_substep" in settings:
        settings["max_substep"] = float(settings["max_substep"])
    if "rotor_check" in settings:
        settings["rotor_check"] = bool(settings["rotor_check"])
    for k, v in settings.items():
        if isinstance(v, _os.PathLike):
            settings[k] = _os.fspath(v)
    out, keep = _out_folder(out, "rotorsim-diagnose-")
    folder = _native.diagnose(str(out), settings=_json.dumps(settings), progress=progress)
    write_deck = settings.get("write_deck")
    return DiagnoseResult(folder, None if write_deck is None else _Path(write_deck), keep)


class DiagnoseResult:
    """What :func:`diagnose` returns: its result folder and diagnosis.

    ``folder`` (a temporary folder, removed with this object, unless ``out`` was given),
    ``diagnosis`` (diagnosis.json as a dict), ``cause`` (the named cause, "none" when the
    baseline explains the data), ``parameters`` (the fitted parameters of the cause), ``gain``
    (held-out improvement), ``candidates`` (every cause tried with its BIC and errors),
    ``deck`` (the extended deck written, when ``write_deck`` was given).
    """

    def __init__(self, folder, deck=None, keep=None):
        self.folder = _Path(folder)
        self.deck = deck
        self._keep = keep
        with open(self.folder / "diagnosis.json") as f:
            self.diagnosis = _json.load(f)

    cause = property(lambda self: self.diagnosis["cause"], doc="The named cause.")
    parameters = property(lambda self: self.diagnosis["parameters"], doc="The cause's fitted parameters.")
    gain = property(lambda self: self.diagnosis["gain"], doc="Held-out improvement.")
    candidates = property(lambda self: self.diagnosis["candidates"], doc="Every cause tried.")

    def __repr__(self):
        return f"DiagnoseResult({str(self.folder)!r}, cause={self.cause!r})"


def _tqdm_sweep_progress():
    """A progress callback drawing one tqdm bar over a sweep's cases, or None without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    bar = []

    def progress(ev):
        if ev["event"] == "start":
            bar.append(tqdm(total=ev["to_run"], desc="sweep", unit="case", leave=False))
        elif ev["event"] == "case" and bar:
            bar[0].update(1)
            if not ev["ok"]:
                bar[0].write(f"case {ev['case']} FAILED: {ev['message']}")
            if bar[0].n >= bar[0].total:
                bar.pop().close()

    return progress


def sweep(plan, out, jobs=None, shard=None, retry_failed=False, warm_start=None, progress=True):
    """Batch forced-response runs from a sweep plan, as ``rotorsim sweep PLAN --out DIR`` runs
    them: every case a ``rotorsim run`` into ``DIR/cases/<id>/``, ``DIR/sweep.csv`` and
    ``DIR/sweep.html`` summarising them.

    ``out`` is required (a sweep resumes: cases found complete are skipped). ``jobs``: cases run
    at once (default SLURM_CPUS_PER_TASK or the machine's CPUs); ``shard``: "K/N" to run one
    shard (default the Slurm array task's, when set); ``retry_failed``: run again the cases that
    failed before; ``warm_start``: True or False warm-starts or starts every case cold whatever
    the plan says (default None: as the plan's ``[sweep] warm_start``). ``progress``: a tqdm bar when
    tqdm is installed (``True``), none (``False``), or a callable given one dict per event:
    ``{"event": "start", "to_run", "total"}``, ``{"event": "case", "case", "ok", "message",
    "wall_s"}``. Ctrl-C stops the sweep (KeyboardInterrupt): running cases are marked
    incomplete, the others do not start; ``retry_failed=True`` finishes it.

    A failed case does not raise: it is in ``.failed`` (and a warning names it), as the command
    line lists it. Bad input raises FileNotFoundError or ValueError naming the plan file, the
    case and the key. Returns a :class:`SweepResult`.
    """
    if progress is True:
        progress = _tqdm_sweep_progress()
    elif progress is False:
        progress = None
    folder, failed = _native.sweep(
        str(plan),
        str(out),
        jobs=None if jobs is None else int(jobs),
        shard=None if shard is None else str(shard),
        retry_failed=bool(retry_failed),
        warm_start=None if warm_start is None else bool(warm_start),
        progress=progress,
    )
    if failed:
        import warnings

        warnings.warn(
            f"{len(failed)} sweep case(s) failed: {', '.join(i for i, _ in failed)} "
            "(SweepResult.failed says why; retry_failed=True runs them again)",
            stacklevel=2,
        )
    return SweepResult(folder, failed)


class SweepResult:
    """What :func:`sweep` returns: its folder and table.

    ``folder``, ``failed`` (the failed cases: a list of (case id, reason)), ``table``
    (sweep.csv: one row per case and model, its varied values and headline results; None for
    a shard, whose table ``rotorsim sweep merge`` writes once every shard has ended), and
    ``case(id)`` (a case's result folder read as a :class:`RunResult`).
    """

    def __init__(self, folder, failed=()):
        self.folder = _Path(folder)
        self.failed = list(failed)
        t = self.folder / "sweep.csv"
        self.table = _read_csv(t) if t.exists() else None

    def case(self, case_id):
        """The result folder of case ``case_id`` (``cases/<id>/``) as a :class:`RunResult`."""
        return RunResult.open(self.folder / "cases" / str(case_id))

    def __repr__(self):
        return f"SweepResult({str(self.folder)!r}, failed={len(self.failed)})"
