"""Bench records: a measured (or synthetic) angular-TE trace and a hysteresis curve.

Plain data in gearte's units (rad, N·mm), produced by the readers of :mod:`gearte.io.bench`, by
:func:`gearte.runners.bench_calibration.synthetic_bench`, and read by the catalogue definitions
(:mod:`gearte.models.catalogue`), the order spectrum and the calibration.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["TETrace", "HysteresisCurve"]


@dataclass(frozen=True, eq=False)
class TETrace:
    """Angular transmission error of one operating point, per direction.

    Attributes
    ----------
    source : str
        File it was read from.
    forward_position, forward_te, backward_position, backward_te : ndarray or None
        Output position [rad] and TE [rad] of each direction (``None`` if not measured).
    speed_rpm, torque, oil_temperature : float or None
        Operating point: output speed [rpm], torque [N·mm], oil temperature [°C].
    serial : str or None
    """

    source: str
    forward_position: np.ndarray | None
    forward_te: np.ndarray | None
    backward_position: np.ndarray | None
    backward_te: np.ndarray | None
    speed_rpm: float | None = None
    torque: float | None = None
    oil_temperature: float | None = None
    serial: str | None = None
    metadata: dict = field(default_factory=dict)

    def directions(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """``{"forward": (position, te), "backward": (...)}`` for the measured directions."""
        out = {}
        if self.forward_position is not None and self.forward_te is not None:
            out["forward"] = (self.forward_position, self.forward_te)
        if self.backward_position is not None and self.backward_te is not None:
            out["backward"] = (self.backward_position, self.backward_te)
        return out


@dataclass(frozen=True, eq=False)
class HysteresisCurve:
    """Torque [N·mm] and output torsion angle [rad] in recording order, with branch marks.

    ``branch`` is ``None`` (to be inferred) or an int array: +1 ascending torque, −1 descending.
    """

    source: str
    torque: np.ndarray
    angle: np.ndarray
    branch: np.ndarray | None = None
    serial: str | None = None
    metadata: dict = field(default_factory=dict)
