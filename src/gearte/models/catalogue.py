"""One definition per catalogue quantity of a precision reducer, for measured and virtual curves.

The same functions read a hysteresis curve or a TE trace whether it comes from a test bench
(:mod:`gearte.io.bench`) or from gearte's own virtual test (:mod:`gearte.models.rv_catalogue`),
so a measured serial and a simulated one are compared by identical arithmetic.

Hysteresis curve (input locked, output torque ``T`` swept ``0 → +T_r → −T_r → +T_r``, output
torsion angle ``θ``), after the manufacturers' catalogues (Nabtesco RV "rigidity and lost
motion"; the same definitions are in GB/T 35089):

* the curve is split into its **ascending** branch (torque rising) and **descending** branch
  (torque falling) — :func:`split_branches`; each is a function ``θ(T)`` read by linear
  interpolation between samples;
* the **mid-curve** ``θ_mid(T) = (θ_asc(T) + θ_desc(T)) / 2``;
* **torsional rigidity** ``b/a``: ``(T_r/2)/(θ_mid(T_r) − θ_mid(T_r/2))`` and the same for
  ``−T_r``, averaged [N·mm/rad];
* **lost motion** ``θ_mid(+f T_r) − θ_mid(−f T_r)``, ``f = 0.03`` (configurable, e.g. 0.05) [rad];
* **backlash at zero torque**: the hysteresis loss less the friction width ``w_f`` (the loop
  width at ``±T_r/2``, where only friction separates the branches): the free play [rad];
* **hysteresis loss** ``θ_desc(0) − θ_asc(0)``: the width of the loop at zero torque after
  unloading from ``±T_r`` (free play plus friction) [rad].

Angular TE trace (output angle minus input angle / ratio, one output revolution per direction):

* **peak-to-peak per direction** ``max TE − min TE`` [rad];
* **forward–backward difference** ``TE_fwd(φ) − TE_bwd(φ)`` along the revolution, both traces
  interpolated linearly and periodically onto the forward positions [rad]; its mean is the lost
  motion under running conditions.

References
----------
Nabtesco Corporation, *Precision Reduction Gear RV* catalogue, "Rigidity (torsional rigidity,
lost motion) and hysteresis". GB/T 35089-2018, *Precision gear reducers for robots*.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.limits import check_load_torque

__all__ = [
    "ZERO_TORQUE_FRACTION",
    "Branches",
    "branch_directions",
    "split_branches",
    "torsional_rigidity",
    "lost_motion",
    "backlash_at_zero",
    "hysteresis_loss",
    "HysteresisValues",
    "hysteresis_values",
    "hysteresis_values_many",
    "te_peak_to_peak",
    "forward_backward_difference",
]

ZERO_TORQUE_FRACTION = 1e-4
"""``ε``: a virtual test samples ``±ε T_r`` on either side of zero torque."""


@dataclass(frozen=True)
class Branches:
    """Ascending and descending branches, each sorted by torque [N·mm] with angles [rad]."""

    asc_torque: np.ndarray
    asc_angle: np.ndarray
    desc_torque: np.ndarray
    desc_angle: np.ndarray

    def ascending(self, torque: ArrayLike) -> np.ndarray:
        """``θ_asc(T)`` [rad] by linear interpolation."""
        return np.interp(np.asarray(torque, dtype=float), self.asc_torque, self.asc_angle)

    def descending(self, torque: ArrayLike) -> np.ndarray:
        """``θ_desc(T)`` [rad] by linear interpolation."""
        return np.interp(np.asarray(torque, dtype=float), self.desc_torque, self.desc_angle)

    def mid(self, torque: ArrayLike) -> np.ndarray:
        """Mid-curve ``(θ_asc + θ_desc)/2`` [rad]."""
        return 0.5 * (self.ascending(torque) + self.descending(torque))


def branch_directions(torque: ArrayLike, threshold: float = 0.02) -> np.ndarray:
    """Infer the branch of each sample of a torque sweep: +1 torque rising, −1 falling.

    A turning point is declared when the torque retreats from its running extreme by more than
    ``threshold`` × the sweep's range (so noise on the torque reading does not split a branch);
    samples up to the extreme belong to the branch that reached it.

    Parameters
    ----------
    torque : array_like, shape (K,)
        Torque in recording order [N·mm] (any consistent unit).
    threshold : float
        Retreat that marks a turning point, as a fraction of the sweep's range [-].

    Returns
    -------
    numpy.ndarray of int, shape (K,)
        +1 / −1 per sample [-].
    """
    t = np.asarray(torque, dtype=float)
    n = t.size
    out = np.empty(n, dtype=np.int64)
    thr = threshold * float(np.ptp(t)) if n else 0.0
    direction = 0
    start = 0
    ext_i = 0
    for k in range(1, n):
        if direction == 0:
            if abs(t[k] - t[0]) > thr:
                direction = 1 if t[k] > t[0] else -1
                ext_i = k
            continue
        if (t[k] - t[ext_i]) * direction > 0:
            ext_i = k
        elif (t[ext_i] - t[k]) * direction > thr:
            out[start : ext_i + 1] = direction
            start = ext_i + 1
            direction = -direction
            ext_i = k
    out[start:] = direction if direction != 0 else 1
    return out


def _runs(direction: np.ndarray) -> list[tuple[int, int, int]]:
    edges = np.nonzero(np.diff(direction))[0] + 1
    bounds = np.concatenate([[0], edges, [direction.size]])
    return [
        (int(a), int(b), int(direction[a])) for a, b in zip(bounds[:-1], bounds[1:], strict=True)
    ]


def _check_rated_torque(rated_torque: float, branches: Branches | None = None) -> None:
    """A :class:`ParameterError` naming ``rated_torque`` unless it is finite, at least the
    plausibility floor of a load torque (1 N·mm, ``gearte.limits.FLOORS``; far below it the
    readings at T_r/2 and T_r coincide and the rigidity is 0/0) and, with ``branches``, no more
    than twice their reach (the readings at ±T_r/2 must lie on them, not beyond their ends)."""
    if not np.isfinite(rated_torque) or rated_torque <= 0:
        raise ParameterError("rated_torque", rated_torque, "must be finite and > 0 [N·mm]")
    check_load_torque("rated_torque", rated_torque)
    if branches is None:
        return
    reach = min(
        -branches.asc_torque[0],
        branches.asc_torque[-1],
        -branches.desc_torque[0],
        branches.desc_torque[-1],
    )
    if not reach > 0.5 * rated_torque:
        raise ParameterError(
            "rated_torque",
            rated_torque,
            f"[N·mm] is more than twice the reach of the branches (±{reach:.6g} N·mm): their "
            "readings at ±T_r/2 would lie beyond their ends; split the sweep with this rated "
            "torque (split_branches)",
        )


def split_branches(
    torque: ArrayLike,
    angle: ArrayLike,
    rated_torque: float,
    direction: ArrayLike | None = None,
    *,
    reach: float = 0.98,
) -> Branches:
    """Split a hysteresis sweep into its ascending and descending branches.

    Parameters
    ----------
    torque : (K,) [N·mm], in recording order
    angle : (K,) output torsion angle [rad]
    rated_torque : float
        ``T_r`` [N·mm], at least the floor of a load torque (1 N·mm).
    direction : (K,) ints, optional
        +1 rising / −1 falling torque per sample [-] (a marked branch); inferred by
        :func:`branch_directions` when omitted.
    reach : float
        Each branch must span ``[−reach T_r, +reach T_r]``.

    Returns
    -------
    Branches
        For each direction the *last* contiguous run of samples that spans ``±reach T_r``
        (the virgin loading ``0 → +T_r`` of a standard sweep is thereby skipped), sorted by torque
        (stable, so a repeated torque keeps its recording order).

    Raises
    ------
    ParameterError
        If no run of a direction spans ``±reach T_r``.
    """
    t = np.asarray(torque, dtype=float)
    a = np.asarray(angle, dtype=float)
    if t.shape != a.shape or t.ndim != 1:
        raise ParameterError("angle", a.shape, f"must have the shape of torque {t.shape}")
    _check_rated_torque(rated_torque)
    d = branch_directions(t) if direction is None else np.asarray(direction)
    lo, hi = -reach * rated_torque, reach * rated_torque
    chosen: dict[int, tuple[int, int]] = {}
    for s, e, sgn in _runs(d):
        seg = t[s:e]
        if seg.size >= 2 and seg.min() <= lo and seg.max() >= hi:
            chosen[sgn] = (s, e)
    for sgn, name in ((1, "ascending"), (-1, "descending")):
        if sgn not in chosen:
            raise ParameterError(
                "hysteresis",
                f"torque range [{t.min():.6g}, {t.max():.6g}] N·mm",
                f"no {name} branch spans ±{reach:g} × rated torque {rated_torque:.6g} N·mm "
                "(sweep -T_r → +T_r and back, or lower the rated torque)",
            )
    out = []
    for sgn in (1, -1):
        s, e = chosen[sgn]
        seg_t, seg_a = t[s:e], a[s:e]
        if sgn < 0:  # keep the recording order among equal torques after sorting
            seg_t, seg_a = seg_t[::-1], seg_a[::-1]
        order = np.argsort(seg_t, kind="stable")
        out += [seg_t[order], seg_a[order]]
    return Branches(*out)


def torsional_rigidity(branches: Branches, rated_torque: float) -> float:
    """Torsional rigidity b/a [N·mm/rad]: ``(T_r/2)/(θ_mid(T_r) − θ_mid(T_r/2))``, both signs
    averaged.

    A measured sweep whose peak torque falls short of ``T_r`` (within the ``reach`` that
    :func:`split_branches` accepts) is read at its own peak ``T_hi``:
    ``(T_hi − T_r/2)/(θ_mid(T_hi) − θ_mid(T_r/2))`` — nothing is extrapolated.

    Parameters
    ----------
    branches : Branches
        Ascending and descending branches of the sweep (:func:`split_branches`).
    rated_torque : float
        Rated torque T_r [N·mm], at least the floor of a load torque (1 N·mm).

    Returns
    -------
    float
        b/a [N·mm/rad].
    """
    _check_rated_torque(rated_torque, branches)
    tr = rated_torque
    hi = min(tr, branches.asc_torque[-1], branches.desc_torque[-1])
    lo = max(-tr, branches.asc_torque[0], branches.desc_torque[0])
    th = branches.mid(np.array([lo, -0.5 * tr, 0.5 * tr, hi]))
    k_pos = (hi - 0.5 * tr) / (th[3] - th[2])
    k_neg = (-0.5 * tr - lo) / (th[1] - th[0])
    return float(0.5 * (k_pos + k_neg))


def lost_motion(branches: Branches, rated_torque: float, fraction: float = 0.03) -> float:
    """Lost motion ``θ_mid(+f T_r) − θ_mid(−f T_r)`` [rad], ``f`` = ``fraction`` (0.03 or 0.05).

    Parameters
    ----------
    branches : Branches
        Ascending and descending branches of the sweep (:func:`split_branches`).
    rated_torque : float
        Rated torque T_r [N·mm], at least the floor of a load torque (1 N·mm).
    fraction : float
        f [-], in (0, 0.5).

    Returns
    -------
    float
        Lost motion [rad].
    """
    _check_rated_torque(rated_torque, branches)
    if not 0 < fraction < 0.5:
        raise ParameterError("lost_motion_fraction", fraction, "must be in (0, 0.5)")
    th = branches.mid(np.array([-fraction, fraction]) * rated_torque)
    return float(th[1] - th[0])


def backlash_at_zero(branches: Branches, rated_torque: float) -> float:
    """Backlash at zero torque [rad]: the hysteresis loss less the friction width.

    ``(θ_desc(0) − θ_asc(0)) − w_f`` with the friction width ``w_f`` the mean loop width at
    ``±T_r/2``, where the reducer is closed and only friction separates the branches. The free
    play without friction; equal to the hysteresis loss for a frictionless (virtual) curve.

    Parameters
    ----------
    branches : Branches
        Ascending and descending branches of the sweep (:func:`split_branches`).
    rated_torque : float
        Rated torque T_r [N·mm], at least the floor of a load torque (1 N·mm).

    Returns
    -------
    float
        Backlash [rad].
    """
    _check_rated_torque(rated_torque, branches)
    half = np.array([-0.5, 0.5]) * rated_torque
    w_f = float(np.mean(branches.descending(half) - branches.ascending(half)))
    return hysteresis_loss(branches) - w_f


def hysteresis_loss(branches: Branches) -> float:
    """Hysteresis loss ``θ_desc(0) − θ_asc(0)`` [rad]: loop width at zero torque.

    Parameters
    ----------
    branches : Branches
        Ascending and descending branches of the sweep (:func:`split_branches`).

    Returns
    -------
    float
        Hysteresis loss [rad].
    """
    return float(branches.descending(0.0) - branches.ascending(0.0))


@dataclass(frozen=True)
class HysteresisValues:
    """Catalogue quantities of one hysteresis curve [N·mm/rad, rad]."""

    torsional_rigidity: float
    lost_motion: float
    backlash: float
    hysteresis_loss: float
    lost_motion_fraction: float


def hysteresis_values(
    torque: ArrayLike,
    angle: ArrayLike,
    rated_torque: float,
    *,
    direction: ArrayLike | None = None,
    lost_motion_fraction: float = 0.03,
) -> HysteresisValues:
    """All hysteresis catalogue quantities of a sweep (see the module docstring).

    Parameters
    ----------
    torque : array_like, shape (K,)
        Output torque in recording order [N·mm].
    angle : array_like, shape (K,)
        Output torsion angle [rad].
    rated_torque : float
        Rated torque T_r [N·mm], at least the floor of a load torque (1 N·mm).
    direction : array_like, optional
        +1 rising / −1 falling torque per sample [-]; inferred when omitted
        (:func:`split_branches`).
    lost_motion_fraction : float
        f of :func:`lost_motion` [-].

    Returns
    -------
    HysteresisValues
        Rigidity [N·mm/rad], lost motion, backlash and hysteresis loss [rad].
    """
    br = split_branches(torque, angle, rated_torque, direction)
    return HysteresisValues(
        torsional_rigidity=torsional_rigidity(br, rated_torque),
        lost_motion=lost_motion(br, rated_torque, lost_motion_fraction),
        backlash=backlash_at_zero(br, rated_torque),
        hysteresis_loss=hysteresis_loss(br),
        lost_motion_fraction=lost_motion_fraction,
    )


def _interp_weights(query: np.ndarray, xp: np.ndarray) -> np.ndarray:
    """``W`` (len(query), len(xp)) with ``W @ fp == np.interp(query, xp, fp)`` for every ``fp``
    (interpolation is linear in the ordinates)."""
    return np.stack([np.interp(query, xp, e) for e in np.eye(xp.size)], axis=1)


def hysteresis_values_many(
    torque: ArrayLike,
    angles: ArrayLike,
    rated_torque: float,
    *,
    direction: ArrayLike | None = None,
    lost_motion_fraction: float = 0.03,
) -> dict[str, np.ndarray]:
    """:func:`hysteresis_values` of many curves sampled at the same torques, at once.

    The branches and the interpolation depend on the torque sequence only, so they are found
    once (:func:`split_branches`) and every reading is a fixed linear combination of the
    angles; the quantities then follow by the same formulas as for one curve.

    Parameters
    ----------
    torque : array_like, shape (K,)
        Output torque in recording order, shared by every curve [N·mm].
    angles : array_like, shape (S, K)
        Output torsion angle of each curve [rad].
    rated_torque : float
        Rated torque T_r [N·mm], at least the floor of a load torque (1 N·mm).
    direction : array_like, optional
        +1 rising / −1 falling torque per sample [-]; inferred when omitted.
    lost_motion_fraction : float
        f of :func:`lost_motion` [-].

    Returns
    -------
    dict
        ``"torsional_rigidity"`` [N·mm/rad], ``"lost_motion"``, ``"backlash"``,
        ``"hysteresis_loss"`` [rad]: arrays of shape (S,).
    """
    t = np.asarray(torque, dtype=float)
    a = np.atleast_2d(np.asarray(angles, dtype=float))
    if a.ndim != 2 or a.shape[1] != t.size:
        raise ParameterError("angles", a.shape, f"must be (curves, {t.size}) for {t.size} torques")
    f = lost_motion_fraction
    if not 0 < f < 0.5:
        raise ParameterError("lost_motion_fraction", f, "must be in (0, 0.5)")
    # the branches of the sample indices: which sample sits where on each branch
    br = split_branches(t, np.arange(t.size, dtype=float), rated_torque, direction)
    tr = rated_torque
    hi = min(tr, br.asc_torque[-1], br.desc_torque[-1])
    lo = max(-tr, br.asc_torque[0], br.desc_torque[0])
    query = np.array([lo, -0.5 * tr, 0.5 * tr, hi, -f * tr, f * tr, 0.0])
    asc = a[:, br.asc_angle.astype(np.int64)] @ _interp_weights(query, br.asc_torque).T
    desc = a[:, br.desc_angle.astype(np.int64)] @ _interp_weights(query, br.desc_torque).T
    mid = 0.5 * (asc + desc)
    k_pos = (hi - 0.5 * tr) / (mid[:, 3] - mid[:, 2])
    k_neg = (-0.5 * tr - lo) / (mid[:, 1] - mid[:, 0])
    loss = desc[:, 6] - asc[:, 6]
    w_f = 0.5 * ((desc[:, 1] - asc[:, 1]) + (desc[:, 2] - asc[:, 2]))
    return {
        "torsional_rigidity": 0.5 * (k_pos + k_neg),
        "lost_motion": mid[:, 5] - mid[:, 4],
        "backlash": loss - w_f,
        "hysteresis_loss": loss,
    }


def te_peak_to_peak(te: ArrayLike) -> float:
    """Peak-to-peak of a TE trace [same unit as ``te``]."""
    v = np.asarray(te, dtype=float)
    return float(v.max() - v.min())


def forward_backward_difference(
    forward_position: ArrayLike,
    forward_te: ArrayLike,
    backward_position: ArrayLike,
    backward_te: ArrayLike,
) -> np.ndarray:
    """``TE_fwd(φ) − TE_bwd(φ)`` [rad] at the forward positions ``φ`` [rad].

    The backward trace is interpolated linearly and periodically (period 2π) onto the forward
    positions; either trace may run in either sense.

    Parameters
    ----------
    forward_position : array_like
        Positions φ of the forward trace [rad].
    forward_te : array_like
        Forward TE [rad].
    backward_position : array_like
        Positions of the backward trace [rad].
    backward_te : array_like
        Backward TE [rad].

    Returns
    -------
    numpy.ndarray
        TE_fwd − TE_bwd at ``forward_position`` [rad].
    """
    bp = np.asarray(backward_position, dtype=float)
    bt = np.asarray(backward_te, dtype=float)
    back = np.interp(np.asarray(forward_position, dtype=float), bp, bt, period=2 * np.pi)
    return np.asarray(forward_te, dtype=float) - back
