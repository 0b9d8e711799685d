"""rotorsim: rotor-blade aeroelastic loads with physics-based hydraulic lead-lag dampers.

The computations run in the rotorsim library (Rust); this package converts arrays and results.
"""
import numpy as _np

from . import _native

__version__ = _native.__version__
__all__ = ["Damper"]


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
