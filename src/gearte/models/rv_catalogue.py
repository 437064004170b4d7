"""Catalogue quantities of an RV reducer from a virtual torsion test of the load-sharing model.

The test follows the manufacturers' definitions (Nabtesco *Precision Reduction Gear RV* catalogue,
"Rigidity and lost motion"; the same definitions are used by Sumitomo/Spinea and the Chinese
test standard for robot reducers): the input is locked, a torque is applied to the output and
swept ``0 → +T_r → 0 → −T_r → 0``, the output torsion angle is recorded — the *hysteresis curve*.

* **Torsional rigidity** ``= (T_r/2) / (θ(T_r) − θ(T_r/2))``: slope of the straight line
  through the points at 50 % and 100 % rated torque, averaged over both directions
  [N·mm/rad; reported in N·m/arcmin].
* **Lost motion** ``= θ_mid(+0.03 T_r) − θ_mid(−0.03 T_r)``: torsion angle between the midpoints
  of the hysteresis curve at ±3 % rated torque.
* **Backlash** ``= θ(0⁺) − θ(0⁻)``: width of the curve at zero torque, the free play.
* **Hysteresis loss**: width of the curve at zero torque after unloading from ±T_r.
* **Angular transmission error**: peak-to-peak of the output angle error over one output
  revolution (unloaded: the geometric TE; loaded: the total TE).

The definitions themselves live once in :mod:`gearte.models.catalogue` and are shared with
measured bench curves (:mod:`gearte.io.bench`); this module only produces the virtual curve.

The quasi-static model has no friction, so the loading and unloading branches coincide except
inside the backlash: the midpoints equal the curve, and the hysteresis loss equals the backlash.
These are stated limitations, not fitted quantities.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.geometry.rv import RVReducer
from gearte.models.catalogue import ZERO_TORQUE_FRACTION, hysteresis_values
from gearte.models.rv_load_sharing import (
    PinContactLaw,
    assemble,
    check_reducer_torque,
    contact_law,
    solver_law,
)
from gearte.models.rv_records import CatalogueValues, TorsionTest
from gearte.solvers.rv_batch import solve_positions
from gearte.solvers.rv_equilibrium import ContactLaw

__all__ = [
    "TorsionTest",
    "torque_path",
    "torsion_test",
    "torsion_angles",
    "backlash",
    "CatalogueValues",
    "catalogue_values",
    "read_catalogue",
    "virtual_loop",
]


def torque_path(turning_points: ArrayLike, steps_per_segment: int = 20) -> np.ndarray:
    """Densify a torque sweep given by its turning points (fractions of rated torque).

    Parameters
    ----------
    turning_points : array_like
        Turning points of the torque sweep as fractions of the rated torque [-].
    steps_per_segment : int
        Torque steps between two turning points [-].

    Returns
    -------
    numpy.ndarray
        The densified sweep as fractions of the rated torque [-].

    Raises
    ------
    ParameterError
        If the sweep does not cross zero (it needs both signs to show backlash and lost motion),
        has fewer than two points, or leaves ``[-1.5, 1.5]``.
    """
    tp = np.asarray(turning_points, dtype=float)
    if tp.ndim != 1 or tp.size < 2 or not np.all(np.isfinite(tp)):
        raise ParameterError("torque_sweep", turning_points, "needs >= 2 finite turning points")
    if not (tp.min() < 0.0 < tp.max()):
        raise ParameterError(
            "torque_sweep",
            tp.tolist(),
            "must cross zero torque (contain both positive and negative values)",
        )
    if np.any(np.abs(tp) > 1.5):
        raise ParameterError("torque_sweep", tp.tolist(), "values must be in [-1.5, 1.5] x rated")
    if int(steps_per_segment) != steps_per_segment or steps_per_segment < 2:
        raise ParameterError("steps_per_segment", steps_per_segment, "must be an integer >= 2")
    pieces = [tp[:1]]
    for a, b in zip(tp[:-1], tp[1:], strict=True):
        seg = np.linspace(a, b, steps_per_segment + 1)[1:]
        if a * b < 0:  # make sure zero is approached from both sides
            seg = np.sort(np.concatenate([seg, [0.0]]))[:: 1 if b > a else -1]
        pieces.append(seg)
    return np.concatenate(pieces)


def _rated(reducer: RVReducer) -> float:
    """The rated torque [N·mm], which the virtual test needs (a case may leave it out), checked
    against the reducer's size as the case files check ``reducer.rated_torque_Nm``
    (:func:`gearte.models.rv_load_sharing.check_reducer_torque`)."""
    if reducer.rated_torque is None:
        raise ParameterError(
            "reducer.rated_torque_Nm",
            None,
            "needed by the virtual torsion test (catalogue, backlash, compensation): the torque "
            "sweep is in fractions of the rated torque",
        )
    check_reducer_torque(reducer, reducer.rated_torque, "reducer.rated_torque")
    return float(reducer.rated_torque)


def torsion_angles(
    reducer: RVReducer,
    torques: ArrayLike,
    *,
    theta: float = 0.0,
    law: PinContactLaw | ContactLaw | None = None,
) -> np.ndarray:
    """Output torsion angle [rad] along any torque path [N·mm] (input locked), followed with warm
    starts: :func:`torsion_test` for a path that is not a sweep between turning points (e.g. the
    torque the elements see when a friction torque is added, for synthetic benches).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description.
    torques : array_like, shape (K,)
        Output torque in path order [N·mm]; an exact zero leaves the output free inside its
        backlash (give ±1e-4 T_r, the side the path comes from).
    theta : float
        Output angle of the test [rad].
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own.

    Returns
    -------
    numpy.ndarray, shape (K,)
        Output torsion angle [rad], positive with the torque.
    """
    t = np.asarray(torques, dtype=float)
    law = contact_law(reducer) if law is None else law
    return _follow(reducer, theta, t, law)


def _follow(reducer, theta, torques, law):
    system = assemble(reducer, np.full(torques.size, float(theta)))
    sol = solve_positions(system, torques, solver_law(reducer, system, law))
    # the torque resists the drive: the output turns against it; report angle along the torque
    angle = -sol.q[:, system.layout.output_rotation]
    k_out = reducer.supports.output_torsional_stiffness
    if k_out is not None:  # the output flange's wind-up, in series with the carrier rotation
        angle = angle + np.asarray(torques, dtype=float) / k_out
    return angle


def torsion_test(
    reducer: RVReducer,
    turning_points: ArrayLike = (0.0, 1.0, 0.0, -1.0, 0.0, 1.0),
    *,
    theta: float = 0.0,
    steps_per_segment: int = 20,
    law: PinContactLaw | ContactLaw | None = None,
) -> TorsionTest:
    """Hysteresis curve: output torsion angle along a torque sweep (fractions of rated torque).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    turning_points : array_like
        Turning points of the torque sweep as fractions of the rated torque [-].
    theta : float
        Output angle of the test [rad].
    steps_per_segment : int
        Torque steps between two turning points [-].
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own
        (:func:`gearte.models.rv_load_sharing.contact_law`).

    Returns
    -------
    TorsionTest
        Torque [N·mm] and output torsion angle [rad] along the sweep.

    Raises
    ------
    ParameterError
        The reducer has no rated torque, or one beyond what its pins can carry (named
        ``reducer.rated_torque``; :func:`gearte.models.rv_load_sharing.check_reducer_torque`).
    """
    frac = torque_path(turning_points, steps_per_segment)
    law = contact_law(reducer) if law is None else law
    # a torque of exactly zero leaves the output free inside its backlash; approach it from the
    # side the path comes from (±1e-4 T_r), which is what a frictionless test bench records
    eps = 1e-4
    prev = np.concatenate([[frac[0]], frac[:-1]])
    frac_eff = np.where(frac == 0.0, np.where(prev >= 0.0, eps, -eps), frac)
    if frac_eff[0] == 0.0:
        frac_eff[0] = eps
    tr = _rated(reducer)
    return TorsionTest(torque=frac * tr, angle=_follow(reducer, theta, frac_eff * tr, law))


def backlash(
    reducer: RVReducer, *, theta: ArrayLike = 0.0, law: PinContactLaw | ContactLaw | None = None
) -> float:
    """Backlash θ(0⁺) − θ(0⁻) [rad]; the smallest over the output angles ``theta`` [rad].

    0 (to the elastic deflection at ±1e-4 T_r) when the reducer is preloaded.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    theta : array_like
        Output angles [rad].
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own
        (:func:`gearte.models.rv_load_sharing.contact_law`).

    Returns
    -------
    float
        Backlash [rad].

    Raises
    ------
    ParameterError
        The reducer has no rated torque, or one beyond what its pins can carry (named
        ``reducer.rated_torque``; :func:`gearte.models.rv_load_sharing.check_reducer_torque`).
    """
    law = contact_law(reducer) if law is None else law
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    eps = 1e-4 * _rated(reducer)
    system = assemble(reducer, th)
    out = system.layout.output_rotation
    slaw = solver_law(reducer, system, law)
    pos = -solve_positions(system, eps, slaw).q[:, out]
    neg = -solve_positions(system, -eps, slaw).q[:, out]
    return float(np.min(pos - neg))


def virtual_loop(
    reducer: RVReducer,
    *,
    theta: float = 0.0,
    lost_motion_fraction: float = 0.03,
    law: PinContactLaw | ContactLaw | None = None,
) -> tuple[TorsionTest, np.ndarray]:
    """The virtual hysteresis loop sampled at the torques the catalogue definitions read.

    Descending branch ``+T_r → −T_r`` then ascending ``−T_r → +T_r`` through
    ``±{1, 0.5, f, ε}·T_r`` and zero (where the output stays on the side it comes from), each
    branch followed with warm starts; returns the loop and its branch marks (+1 rising torque).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    theta : float
        Output angle of the test [rad].
    lost_motion_fraction : float
        f of the lost-motion definition [-] (0.03 or 0.05).
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own
        (:func:`gearte.models.rv_load_sharing.contact_law`).

    Returns
    -------
    (TorsionTest, numpy.ndarray)
        The loop and its branch marks [-].

    Raises
    ------
    ParameterError
        The reducer has no rated torque, or one beyond what its pins can carry (named
        ``reducer.rated_torque``; :func:`gearte.models.rv_load_sharing.check_reducer_torque`).
    """
    law = contact_law(reducer) if law is None else law
    tr = _rated(reducer)
    levels = np.array([1.0, 0.5, lost_motion_fraction, ZERO_TORQUE_FRACTION])
    unload_pos = _follow(reducer, theta, levels * tr, law)
    unload_neg = _follow(reducer, theta, -levels * tr, law)
    load_pos = _follow(reducer, theta, levels[::-1] * tr, law)
    load_neg = _follow(reducer, theta, -levels[::-1] * tr, law)
    t_desc = np.concatenate([levels, [0.0], -levels[::-1]]) * tr
    a_desc = np.concatenate([unload_pos, unload_pos[-1:], load_neg])
    t_asc = -t_desc
    a_asc = np.concatenate([unload_neg, unload_neg[-1:], load_pos])
    loop = TorsionTest(
        torque=np.concatenate([t_desc, t_asc]), angle=np.concatenate([a_desc, a_asc])
    )
    direction = np.concatenate([-np.ones(t_desc.size, np.int64), np.ones(t_asc.size, np.int64)])
    return loop, direction


def catalogue_values(
    reducer: RVReducer,
    *,
    theta: float = 0.0,
    turning_points: ArrayLike = (0.0, 1.0, 0.0, -1.0, 0.0, 1.0),
    steps_per_segment: int = 20,
    lost_motion_fraction: float = 0.03,
    law: PinContactLaw | ContactLaw | None = None,
) -> CatalogueValues:
    """Torsional rigidity, lost motion, backlash and hysteresis loss from a virtual test.

    The virtual loop (:func:`virtual_loop`) is read by the shared catalogue definitions
    (:func:`gearte.models.catalogue.hysteresis_values`), the same functions that read a
    measured bench curve.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    theta : float
        Output angle of the test [rad].
    turning_points : array_like
        Turning points of the torque sweep as fractions of the rated torque [-].
    steps_per_segment : int
        Torque steps between two turning points [-].
    lost_motion_fraction : float
        f of the lost-motion definition [-] (0.03 or 0.05).
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own
        (:func:`gearte.models.rv_load_sharing.contact_law`).

    Returns
    -------
    CatalogueValues
        Rigidity [N·mm/rad], lost motion, backlash and hysteresis loss [rad].

    Raises
    ------
    ParameterError
        The reducer has no rated torque, or one beyond what its pins can carry (named
        ``reducer.rated_torque``; :func:`gearte.models.rv_load_sharing.check_reducer_torque`).
    """
    if not 0 < lost_motion_fraction < 0.5:
        raise ParameterError("lost_motion_fraction", lost_motion_fraction, "must be in (0, 0.5)")
    law = contact_law(reducer) if law is None else law
    curve = torsion_test(
        reducer, turning_points, theta=theta, steps_per_segment=steps_per_segment, law=law
    )
    loop, direction = virtual_loop(
        reducer, theta=theta, lost_motion_fraction=lost_motion_fraction, law=law
    )
    return read_catalogue(curve, loop, direction, _rated(reducer), lost_motion_fraction)


def read_catalogue(
    curve: TorsionTest,
    loop: TorsionTest,
    direction: np.ndarray,
    rated_torque: float,
    lost_motion_fraction: float,
) -> CatalogueValues:
    """Catalogue values read from a virtual loop by the shared definitions.

    Parameters
    ----------
    curve : TorsionTest
        The dense torsion sweep kept for plots [N·mm, rad].
    loop : TorsionTest
        The virtual hysteresis loop the values are read from [N·mm, rad].
    direction : ndarray
        Loading direction of each loop point (+1 rising, −1 falling) [-].
    rated_torque : float
        Rated torque [N·mm].
    lost_motion_fraction : float
        f of the lost-motion definition [-].

    Returns
    -------
    CatalogueValues
        Rigidity [N·mm/rad], lost motion, backlash and hysteresis loss [rad]
        (:func:`gearte.models.catalogue.hysteresis_values`), with the curve and loop.
    """
    hv = hysteresis_values(
        loop.torque,
        loop.angle,
        float(rated_torque),
        direction=direction,
        lost_motion_fraction=lost_motion_fraction,
    )
    return CatalogueValues(
        torsional_rigidity=hv.torsional_rigidity,
        lost_motion=hv.lost_motion,
        backlash=hv.backlash,
        hysteresis_loss=hv.hysteresis_loss,
        curve=curve,
        loop=loop,
        loop_direction=direction,
    )
