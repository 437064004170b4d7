"""Records of the RV runners, apart from the modules that compute them: the dynamic transmission
error of one run (:mod:`gearte.runners.rv_dynamics_sim`) and a measured lot, its score table
and assembly (:mod:`gearte.runners.selective_assembly`).

Kept apart from those modules, which import the compiled dynamic model, the integrators and the
equilibrium solvers: a result of the RV kinds (the lot's included) unpickles, and its figures
draw, without numba (``NUMBA_FREE_RESULTS`` in :mod:`gearte.plotting.rv_reducer` and
:mod:`gearte.plotting.rv_lot`). Each record is still importable from the module that makes it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from gearte.errors import ParameterError

if TYPE_CHECKING:  # annotations only
    from gearte.geometry.measured import MeasuredDisc
    from gearte.geometry.rv import RVReducer
    from gearte.solvers.ode_result import ODEResult

__all__ = ["DTEResult", "Lot", "Orientation", "ScoreTable", "Assembly"]


@dataclass(frozen=True)
class DTEResult:
    """Dynamic transmission error of one run (after settling).

    ``peak_to_peak``, ``rms`` [arcsec] and ``dte_mean`` [arcsec] (the static wind-up) come
    from the DTE at every integration step over the whole span. The recorded trace — t [s] and
    dte [arcsec] (mean removed) every ``record_dt`` [s] — is the whole span when it has at most
    ``trace_points`` samples, else its last ``trace_points`` (``covers_span`` tells which); the
    recorded states (columns ``state_names``, times ``states_t`` [s]) likewise with
    ``record_points`` rows. Memory is independent of the duration. ``envelope_t`` [s],
    ``envelope`` [arcsec] (buckets × [min, max], mean removed): the full-rate DTE's extremes in
    equal buckets over the whole span. ``solver``: the solver result; ``dt`` [s] the RK4 step.
    """

    t: np.ndarray
    dte: np.ndarray
    dte_mean: float
    peak_to_peak: float
    rms: float
    states: np.ndarray
    state_names: list[str]
    solver: ODEResult
    dt: float
    record_dt: float = float("nan")
    covers_span: bool = True
    states_t: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    envelope_t: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    envelope: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)

    @property
    def recorded_span(self) -> float:
        """Span of the recorded trace [s] (the spectrum's window: resolution 1/this)."""
        return float(self.t[-1] - self.t[0]) + self.record_dt if self.t.size else 0.0

    @property
    def states_span(self) -> float:
        """Span of the recorded states [s] (trajectories and phase portraits)."""
        t = self.states_t
        return float(t[-1] - t[0]) + self.record_dt if t.size else 0.0

    @property
    def states_cover_span(self) -> bool:
        """Whether the recorded states cover the whole span after settling."""
        return self.states_t.size == self.solver.records


@dataclass(frozen=True, eq=False)  # holds arrays
class Lot:
    """A lot of measured parts: ``K_d`` disc sets and ``K_c`` crank sets.

    Attributes
    ----------
    disc_serials : list of tuple of str
        Per disc set, the serials of its ``N`` discs.
    discs : list of tuple of MeasuredDisc
        Per disc set, the measured flanks / pitch of each disc (None: design flank).
    disc_bores : numpy.ndarray or None
        ``(K_d, N, M, 2)`` crank-bore centres of each disc, disc frame [mm].
    crank_serials : list of tuple of str
        Per crank set, the serials of its ``M`` cranks (planet mounted on each).
    cam_eccentricity, cam_phase : numpy.ndarray
        ``(K_c, M, N)`` cam eccentricity [mm] and phase from nominal [rad].
    planet_runout : numpy.ndarray or None
        ``(K_c, M, 2)`` run-out [mm] and high-point angle [rad] of each crank's planet.
    cam_clearance, carrier_clearance : numpy.ndarray or None
        ``(K_c, M, N)`` and ``(K_c, M)`` measured bearing clearances [mm].
    """

    disc_serials: list[tuple[str, ...]]
    discs: list[tuple[MeasuredDisc | None, ...]]
    disc_bores: np.ndarray | None
    crank_serials: list[tuple[str, ...]]
    cam_eccentricity: np.ndarray
    cam_phase: np.ndarray
    planet_runout: np.ndarray | None = None
    cam_clearance: np.ndarray | None = None
    carrier_clearance: np.ndarray | None = None

    @property
    def disc_sets(self) -> int:
        """``K_d`` [-]."""
        return len(self.disc_serials)

    @property
    def crank_sets(self) -> int:
        """``K_c`` [-]."""
        return len(self.crank_serials)

    def check(self, design: RVReducer) -> None:
        """Shapes against the design; raises :class:`ParameterError` naming the array."""
        m, n = design.cranks.count, design.discs.count
        kd, kc = self.disc_sets, self.crank_sets
        want = {
            "disc_bores": (self.disc_bores, (kd, n, m, 2)),
            "cam_eccentricity": (self.cam_eccentricity, (kc, m, n)),
            "cam_phase": (self.cam_phase, (kc, m, n)),
            "planet_runout": (self.planet_runout, (kc, m, 2)),
            "cam_clearance": (self.cam_clearance, (kc, m, n)),
            "carrier_clearance": (self.carrier_clearance, (kc, m)),
        }
        for name, (arr, shape) in want.items():
            if arr is not None and np.shape(arr) != shape:
                raise ParameterError(f"lot.{name}", np.shape(arr), f"must have shape {shape}")
        for k, s in enumerate(self.disc_serials):
            if len(s) != n or len(self.discs[k]) != n:
                raise ParameterError(f"lot.disc_sets[{k}]", s, f"needs {n} discs")
        for k, s in enumerate(self.crank_serials):
            if len(s) != m:
                raise ParameterError(f"lot.crank_sets[{k}]", s, f"needs {m} cranks")


@dataclass(frozen=True)
class Orientation:
    """How the parts of one reducer are put together.

    Attributes
    ----------
    disc_shift : int
        Disc ``(j + disc_shift) mod N`` of the set goes into slot ``j`` (which disc on which
        side) [-].
    disc_index : int
        Each disc turned by ``disc_index · 2π/M`` (its bore ``i`` on crank position ``i +
        disc_index``; only when ``z_c`` is a multiple of ``M``) [-].
    crank_shift : int
        Crank ``(i − crank_shift) mod M`` of the set goes into carrier position ``i`` [-].
    planet_index : int
        Every planet turned on its crank's spline by ``planet_index · 2π/Q`` (planet phasing;
        ``Q`` indexings, the same for the reducer's planets) [-].
    planet_indexings : int
        ``Q`` [-] (1: planets mounted as measured).
    """

    disc_shift: int = 0
    disc_index: int = 0
    crank_shift: int = 0
    planet_index: int = 0
    planet_indexings: int = 1


@dataclass(frozen=True, eq=False)
class ScoreTable:
    """TE peak-to-peak [rad] of every pairing and orientation.

    Attributes
    ----------
    pp : (K_d, O_d, K_c, O_c) peak-to-peak of the loaded output angle error [rad].
    disc_orientations : list of (disc_shift, disc_index).
    crank_orientations : list of (crank_shift, planet_index).
    planet_indexings : int
        ``Q`` of the planet indexing [-].
    """

    pp: np.ndarray
    disc_orientations: list[tuple[int, int]]
    crank_orientations: list[tuple[int, int]]
    planet_indexings: int = 1

    def best(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per pairing ``(K_d, K_c)``: the best peak-to-peak [rad] and its disc and crank
        orientation indices."""
        kd, od, kc, oc = self.pp.shape
        flat = self.pp.transpose(0, 2, 1, 3).reshape(kd, kc, od * oc)
        i = np.argmin(flat, axis=-1)
        return np.take_along_axis(flat, i[..., None], -1)[..., 0], i // oc, i % oc

    def orientation(self, od: int, oc: int) -> Orientation:
        """The :class:`Orientation` of orientation indices ``od``, ``oc``."""
        s, r = self.disc_orientations[od]
        c, q = self.crank_orientations[oc]
        return Orientation(s, r, c, q, self.planet_indexings)


@dataclass(frozen=True)
class Assembly:
    """Which parts form each reducer.

    Attributes
    ----------
    disc_set, crank_set : numpy.ndarray
        ``(R,)`` 0-based indices of the reducers' disc and crank sets [-].
    disc_orientation, crank_orientation : numpy.ndarray
        ``(R,)`` orientation indices into the :class:`ScoreTable` lists [-].
    pp : numpy.ndarray
        ``(R,)`` TE peak-to-peak of each reducer [rad].
    """

    disc_set: np.ndarray
    crank_set: np.ndarray
    disc_orientation: np.ndarray
    crank_orientation: np.ndarray
    pp: np.ndarray

    def in_spec(self, limit: float) -> int:
        """Reducers with TE peak-to-peak ≤ ``limit`` [rad] [-]."""
        return int(np.sum(self.pp <= limit))
