"""Compensation of the total TE through the whole-reducer model.

Hu et al. 2020 (sections 3 and 5) allocate a measured total TE to the error factors with negative
sensitivity through a linear error-coefficient model (eq 26–27) and check the result in Adams.
Here the allocation is replaced by an explicit optimisation of the *same* quasi-static model that
predicts the TE: the designer names the parameters that may change and their ranges,

* ``equidistant_modification`` — Δr_rp of the disc profile [mm],
* ``shift_modification`` — Δr_p of the disc profile [mm],
* ``pin_radius`` — a uniform change of the pin radius [mm] (disc unchanged),
* ``pin_circle_radius`` — a uniform change of the pin-centre circle radius, a pitch-circle
  correction of the housing [mm],

and gearte minimises the chosen TE measure (peak-to-peak total TE over a revolution, or the mean
loaded output lag) subject to ``backlash >= min_backlash`` (lubrication clearance), the backlash
being the smallest of the virtual torsion test (:func:`gearte.models.rv_catalogue.backlash`) at
eight output angles over the revolution (with errors it varies with the angle). The search is a
coarse grid over the box followed by a compass (pattern) search with halving steps, which
copes with the backlash constraint's cliff and with infeasible (interfering) profiles; the
constraint enters as an exact penalty.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np

from gearte.errors import ParameterError
from gearte.geometry.rv import PinRing, RVReducer
from gearte.models.rv_catalogue import backlash
from gearte.models.rv_load_sharing import output_positions, transmission_error
from gearte.models.rv_records import Compensation, DesignPoint

__all__ = ["VARIABLES", "apply_changes", "DesignPoint", "Compensation", "compensate"]

VARIABLES = ("equidistant_modification", "shift_modification", "pin_radius", "pin_circle_radius")


def apply_changes(reducer: RVReducer, changes: dict[str, float]) -> RVReducer:
    """The reducer with design changes [mm] added to its parameters."""
    bad = [k for k in changes if k not in VARIABLES]
    if bad:
        raise ParameterError("variables", bad, f"unknown design variable(s); allowed {VARIABLES}")
    d, p = reducer.discs, reducer.pins
    discs = dataclasses.replace(
        d,
        equidistant_modification=d.equidistant_modification
        + changes.get("equidistant_modification", 0.0),
        shift_modification=d.shift_modification + changes.get("shift_modification", 0.0),
    )
    pins = PinRing(
        p.count,
        p.pin_radius,
        p.circle_radius,
        p.radius_errors + changes.get("pin_radius", 0.0),
        p.radial_position_errors + changes.get("pin_circle_radius", 0.0),
        p.tangential_position_errors,
    )
    return reducer.replace(discs=discs, pins=pins)


def _evaluate(reducer, changes, torque, theta) -> DesignPoint:
    red = apply_changes(reducer, changes)
    te = transmission_error(red, torque, theta, mesh_samples=12)
    ls = te.loaded
    return DesignPoint(
        changes=dict(changes),
        total_te_peak_to_peak=te.total_pp,
        mean_lag=float(-te.total.mean()),
        backlash=backlash(red, theta=theta[:: max(1, theta.size // 8)]),
        peak_pin_load=ls.peak_pin_load,
        pairs_in_mesh_min=int(ls.pairs_in_mesh.min()),
        pairs_in_mesh_max=int(ls.pairs_in_mesh.max()),
        load=ls,
    )


def compensate(
    reducer: RVReducer,
    torque: float,
    bounds: dict[str, tuple[float, float]],
    *,
    min_backlash: float,
    objective: str = "total_te_peak_to_peak",
    positions: int = 72,
    grid: int = 3,
    maxiter: int = 400,
    xtol: float = 5e-5,
) -> Compensation:
    """Find the design change minimising the total TE with at least ``min_backlash``.

    Parameters
    ----------
    reducer : RVReducer
    torque : float
        Output torque of the TE evaluation [N·mm].
    bounds : dict
        ``{variable: (lower, upper)}`` change ranges [mm]; variables from :data:`VARIABLES`.
    min_backlash : float
        Smallest admissible backlash [rad] (lubrication).
    objective : {"total_te_peak_to_peak", "mean_lag"}
    positions : int
        Output positions per revolution in each evaluation.
    grid : int
        Points per variable of the initial grid.
    maxiter : int
        Iteration limit of the compass search.
    xtol : float
        Final step of the compass search [mm].
    """
    if objective not in ("total_te_peak_to_peak", "mean_lag"):
        raise ParameterError(
            "objective", objective, "must be 'total_te_peak_to_peak' or 'mean_lag'"
        )
    if not bounds:
        raise ParameterError("bounds", bounds, "name at least one design variable")
    names = list(bounds)
    for n in names:
        if n not in VARIABLES:
            raise ParameterError(f"bounds.{n}", n, f"unknown design variable; allowed {VARIABLES}")
        lo, hi = bounds[n]
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ParameterError(f"bounds.{n}", (lo, hi), "need finite lower < upper [mm]")
    if not min_backlash >= 0:
        raise ParameterError("min_backlash", min_backlash, "must be >= 0 rad")
    theta = output_positions(positions)
    count = [0]
    cache: dict[tuple, DesignPoint] = {}

    def point(x) -> DesignPoint:
        key = tuple(np.round(x, 9))
        if key not in cache:
            count[0] += 1
            cache[key] = _evaluate(
                reducer, dict(zip(names, map(float, x), strict=True)), torque, theta
            )
        return cache[key]

    before = _evaluate(reducer, {}, torque, theta)
    scale = max(getattr(before, objective), 1e-9)

    def cost(x) -> float:
        try:
            dp = point(x)
        except ParameterError:  # an interfering or undercut profile: not a design
            return 1e6
        val = getattr(dp, objective) / scale
        if objective != "mean_lag":  # ties (TE dominated by errors) go to the smaller lag
            val += 1e-3 * dp.mean_lag / max(before.mean_lag, 1e-12)
        short = max(min_backlash - dp.backlash, 0.0)
        return val + 1e3 * short / max(min_backlash, 1e-6) + (1e3 if short > 0 else 0.0)

    axes = [np.linspace(*bounds[n], grid) for n in names]
    x = np.array(min(itertools.product(*axes), key=cost), dtype=float)
    lower = np.array([bounds[n][0] for n in names])
    upper = np.array([bounds[n][1] for n in names])
    step = (upper - lower) / (2.0 * max(grid - 1, 1))
    fx = cost(x)
    # compass (pattern) search: robust to the backlash cliff and to infeasible profiles
    for _ in range(maxiter):
        improved = False
        for i in range(len(names)):
            for sgn in (1.0, -1.0):
                y = x.copy()
                y[i] = np.clip(y[i] + sgn * step[i], lower[i], upper[i])
                fy = cost(y)
                if fy < fx - 1e-12:
                    x, fx, improved = y, fy, True
                    break
        if not improved:
            step = step / 2.0
            if np.all(step < xtol):
                break
    best = point(x)
    return Compensation(
        before=before,
        after=best,
        objective=objective,
        min_backlash=float(min_backlash),
        evaluations=count[0],
    )
