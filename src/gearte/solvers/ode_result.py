"""The record of a time integration (:class:`ODEResult`), apart from its kernels.

:func:`gearte.solvers.ode.integrate` makes it; it lives here, in a module that imports no
numba, so that a result holding it (the RV kinds' dynamic transmission error) unpickles without
numba (``NUMBA_FREE_RESULTS`` in :mod:`gearte.plotting.rv_reducer`). It is still importable from
:mod:`gearte.solvers.ode`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["ODEResult"]


@dataclass(frozen=True)
class ODEResult:
    """Result of :func:`gearte.solvers.ode.integrate`.

    t [s] and output (plus the recorded states ``states``, columns = ``record_states``) on the
    recording grid after the settling time — the last ``output_window`` / ``record_window`` rows
    when a window was asked for (``states_t`` [s]: the times of the states' rows); ``records``
    the rows recorded over the whole span (more than ``t.size`` when the window dropped the
    first ones); ``stats`` of the output after settling (min, max, mean,
    rms, peak_to_peak, count); ``envelope`` (buckets × [min, max]) of the output over the span
    after settling, ``envelope_t`` [s] the buckets' centres; ``y_final``; counters and wall
    time [s].
    """

    method: str
    t: np.ndarray
    output: np.ndarray
    states: np.ndarray
    y_final: np.ndarray
    stats: dict[str, float]
    n_steps: int
    n_rhs: int
    wall_time: float
    records: int = 0
    states_t: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    envelope: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    envelope_t: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)

    @property
    def peak_to_peak(self) -> float:
        return self.stats["peak_to_peak"]
