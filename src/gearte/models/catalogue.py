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

Angular TE trace (one output revolution per direction), in gearte's sign convention: TE =
nominal output angle (input angle / ratio) − measured output angle, both in the forward sense, so
a loaded reducer lags in both directions and the forward trace lies above the backward one
(:data:`gearte.io.bench.TE_CONVENTION`; a rig writing the other sign is read with a flag):

* **peak-to-peak per direction** ``max TE − min TE`` [rad];
* **forward–backward difference** ``TE_fwd(φ) − TE_bwd(φ)`` along the revolution, both traces
  interpolated linearly and periodically onto the forward positions [rad]; its mean is the lost
  motion under running conditions.

Load series (TE traces at several output torques ``T_k ≥ 0``, the load opposing the motion in
both directions as a brake does): the forward trace at ``T`` is the reducer loaded to ``+T``, the
backward one loaded to ``−T``, so the running curve ``θ_run(+T) = mean TE_fwd(T)``,
``θ_run(−T) = mean TE_bwd(T)`` is read with the definitions above, ``D(T) = θ_run(+T) −
θ_run(−T)`` the forward–backward mean (:func:`load_series_values`):

* **torsional rigidity** ``(T_r/2)/(θ_run(T_r) − θ_run(T_r/2))`` averaged with the negative side
  ``= T_r / (D(T_r) − D(T_r/2))`` (a series peaking short of ``T_r`` is read at its own peak
  ``T_max``: ``T_max / (D(T_max) − D(T_max/2))``);
* **lost motion** ``θ_run(+f T_r) − θ_run(−f T_r) = D(f T_r)``;
* **hysteresis** ``D(0)``: the jump of the running curve at zero load (play + running friction);
* **backlash** the lost motion less the elastic twist over ``±f T_r`` at that rigidity,
  ``D(f T_r) − 2 f T_r / K``: the free play (for a mid-curve linear outside the play this is
  the hysteresis-loop backlash above).

``D`` between the measured torques is interpolated linearly; nothing is extrapolated.

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
    "torsional_rigidity_error",
    "te_peak_to_peak",
    "forward_backward_difference",
    "LoadSeriesValues",
    "load_series_values",
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


def torsional_rigidity_error(
    torque: ArrayLike,
    angle: ArrayLike,
    rated_torque: float,
    angle_std: float,
    *,
    torque_std: float = 0.0,
    direction: ArrayLike | None = None,
) -> float:
    """Standard error [N·mm/rad] of :func:`torsional_rigidity` from the noise of the readings.

    Every reading ``θ_b(T*)`` of the definition is a linear interpolation between two samples of
    a branch (weights ``1 − w``, ``w``), so the rigidity
    ``½ (N₊/Δ₊ + N₋/Δ₋)``, ``Δ₊ = θ_mid(T_hi) − θ_mid(T_r/2)``, ``N₊ = T_hi − T_r/2`` (and the
    same for the negative side), is a function of a few samples' angles. Each sample carries
    independent errors: the angle's ``σ_θ`` and the torque reading's ``σ_T`` seen through the
    curve's slope (the side's secant ``Δ/N``), ``σ_i² = σ_θ² + (Δ/N)² σ_T²``; the error is
    propagated linearly:
    ``var K = Σ_i (∂K/∂θ_i)² σ_i²``, ``∂K/∂θ_i = −½ (N₊/Δ₊² ∂Δ₊/∂θ_i + N₋/Δ₋² ∂Δ₋/∂θ_i)``.
    The repeatability between runs and any error correlated along the sweep are not in it.

    Parameters
    ----------
    torque : array_like, shape (K,)
        Output torque in recording order [N·mm].
    angle : array_like, shape (K,)
        Output torsion angle [rad].
    rated_torque : float
        Rated torque T_r [N·mm].
    angle_std : float
        Standard deviation of one angle reading ``σ_θ`` [rad] (≥ 0).
    torque_std : float
        Standard deviation of one torque reading ``σ_T`` [N·mm] (≥ 0).
    direction : array_like, optional
        +1 rising / −1 falling torque per sample [-]; inferred when omitted.

    Returns
    -------
    float
        Standard error of the torsional rigidity [N·mm/rad].
    """
    for name, v in (("angle_std", angle_std), ("torque_std", torque_std)):
        if not (np.isfinite(v) and v >= 0):
            raise ParameterError(name, v, "must be finite and >= 0")
    t = np.asarray(torque, dtype=float)
    a = np.asarray(angle, dtype=float)
    if t.shape != a.shape or t.ndim != 1:
        raise ParameterError("angle", a.shape, f"must have the shape of torque {t.shape}")
    # the branches of the sample indices: which sample each reading interpolates
    br = split_branches(t, np.arange(t.size, dtype=float), rated_torque, direction)
    tr = rated_torque
    hi = min(tr, br.asc_torque[-1], br.desc_torque[-1])
    lo = max(-tr, br.asc_torque[0], br.desc_torque[0])
    query = np.array([lo, -0.5 * tr, 0.5 * tr, hi])
    mid = np.zeros((query.size, t.size))  # θ_mid(query) = mid @ angle
    for idx, xp in ((br.asc_angle, br.asc_torque), (br.desc_angle, br.desc_torque)):
        np.add.at(mid.T, idx.astype(np.int64), 0.5 * _interp_weights(query, xp).T)
    grad = np.zeros(t.size)
    slope = np.zeros(t.size)
    for g, n in ((mid[3] - mid[2], hi - 0.5 * tr), (mid[1] - mid[0], -0.5 * tr - lo)):
        d = float(g @ a)
        grad -= 0.5 * n / d**2 * g
        slope = np.where(g != 0, abs(d / n), slope)
    var = (angle_std**2 + (slope * torque_std) ** 2) * grad**2
    return float(np.sqrt(np.sum(var)))


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


@dataclass(frozen=True)
class LoadSeriesValues:
    """Catalogue quantities of one load series (one speed, one temperature) with 95 % intervals.

    ``torsional_rigidity`` [N·mm/rad]; ``lost_motion``, ``hysteresis``, ``backlash`` [rad]; NaN
    where the series does not reach the torque the definition reads (stated in ``missing``).
    ``ci`` maps each name to ``(low, high)`` (NaN without standard errors); ``interpolated`` lists
    the quantities read between measured torques (their interval holds the noise only, not the
    interpolation error); ``rigidity_range`` the torques ``(T_max/2, T_max)`` [N·mm] the rigidity
    was read between.
    """

    torsional_rigidity: float
    lost_motion: float
    hysteresis: float
    backlash: float
    lost_motion_fraction: float
    ci: dict
    interpolated: tuple[str, ...]
    missing: dict
    rigidity_range: tuple[float, float]


def _series_quantities(t, d, tr, f):
    """(K, LM, H, B) from the forward−backward means ``d`` at torques ``t`` (sorted)."""
    t_hi = min(tr, t[-1])
    lo = 0.5 * t_hi
    k = np.nan
    if t[0] <= lo * (1 + 1e-9) and t_hi > 0:
        dd = np.interp(t_hi, t, d) - np.interp(lo, t, d)
        k = t_hi / dd if dd > 0 else np.nan
    lm = float(np.interp(f * tr, t, d)) if t[0] <= f * tr <= t[-1] else np.nan
    h = float(d[0]) if abs(t[0]) <= ZERO_TORQUE_FRACTION * tr else np.nan
    b = lm - 2.0 * f * tr / k if np.isfinite(k) else np.nan
    return np.array([k, lm, h, b])


def load_series_values(
    torque: ArrayLike,
    difference: ArrayLike,
    rated_torque: float,
    *,
    standard_error: ArrayLike | None = None,
    lost_motion_fraction: float = 0.03,
) -> LoadSeriesValues:
    """Rigidity, lost motion, hysteresis and backlash of a load series of TE traces.

    Parameters
    ----------
    torque : array_like, shape (K,)
        Load torque of each operating point, opposing the motion in both directions [N·mm]
        (≥ 0; repeated torques are averaged).
    difference : array_like, shape (K,)
        ``D``: mean forward TE − mean backward TE of each operating point [rad] (gearte's sign
        convention: positive for a lagging reducer).
    rated_torque : float
        ``T_r`` [N·mm].
    standard_error : array_like, optional
        Standard error of each ``D`` [rad] (e.g. from the traces' noise); gives the intervals
        by linear propagation (the rigidity's through its compliance).
    lost_motion_fraction : float
        ``f`` [-].

    Returns
    -------
    LoadSeriesValues

    Notes
    -----
    Definitions in the module docstring (the hysteresis-curve definitions applied to the running
    curve of the series). Example: ``D = 2 (b/2 + T/K)`` (play ``b``, linear stiffness ``K``)
    gives back ``K``, lost motion ``b + 2 f T_r/K``, hysteresis ``b`` and backlash ``b``.

    References
    ----------
    Nabtesco Corporation, *Precision Reduction Gear RV* catalogue, "Rigidity (torsional rigidity,
    lost motion) and hysteresis". GB/T 35089-2018, *Precision gear reducers for robots*.
    """
    t = np.asarray(torque, dtype=float).ravel()
    dv = np.asarray(difference, dtype=float).ravel()
    if t.size != dv.size or t.size < 2:
        raise ParameterError("torque", t.size, "needs >= 2 operating points, one D each")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(dv))):
        raise ParameterError("difference", dv, "must be finite")
    if np.any(t < 0):
        raise ParameterError("torque", float(t.min()), "load magnitudes must be >= 0 N·mm")
    _check_rated_torque(rated_torque)
    f = float(lost_motion_fraction)
    se = None if standard_error is None else np.asarray(standard_error, dtype=float).ravel()
    # average repeated torques (their standard errors combine as for a mean)
    uniq, inv = np.unique(t, return_inverse=True)
    cnt = np.bincount(inv)
    d = np.bincount(inv, dv) / cnt
    se_u = None if se is None else np.sqrt(np.bincount(inv, se**2)) / cnt
    if uniq.size < 2:
        raise ParameterError("torque", uniq.tolist(), "needs >= 2 distinct torques")
    q = _series_quantities(uniq, d, rated_torque, f)
    names = ("torsional_rigidity", "lost_motion", "hysteresis", "backlash")
    ci = {n: (np.nan, np.nan) for n in names}
    if se_u is not None:
        # linear propagation; the rigidity through its compliance 1/K (linear in D)
        jac = np.empty((4, uniq.size))
        for j in range(uniq.size):
            h = np.zeros(uniq.size)
            h[j] = 1e-9 + 1e-6 * abs(d[j])
            up = _series_quantities(uniq, d + h, rated_torque, f)
            down = _series_quantities(uniq, d - h, rated_torque, f)
            jac[:, j] = (up - down) / (2 * h[j])
        jac[0] = -jac[0] / q[0] ** 2 if np.isfinite(q[0]) else np.nan  # d(1/K)/dD
        half = 1.959963984540054 * np.sqrt((jac**2) @ se_u**2)
        c = 1.0 / q[0]
        ci["torsional_rigidity"] = (1.0 / (c + half[0]), 1.0 / (c - half[0]) if c > half[0]
                                    else np.inf)  # fmt: skip
        for i in (1, 2, 3):
            ci[names[i]] = (q[i] - half[i], q[i] + half[i])
    missing = {}
    if not np.isfinite(q[0]):
        missing["torsional_rigidity"] = (
            f"needs torques down to T_max/2 = {0.5 * min(rated_torque, uniq[-1]):.6g} N·mm"
        )
    if not np.isfinite(q[1]):
        missing["lost_motion"] = (
            f"needs torques on both sides of f T_r = {f * rated_torque:.6g} N·mm"
        )
    if not np.isfinite(q[2]):
        missing["hysteresis"] = "needs an operating point at zero load"
    if not np.isfinite(q[3]) and "lost_motion" not in missing:
        missing["backlash"] = "needs the rigidity"
    t_hi = min(rated_torque, uniq[-1])
    interp = []
    on_grid = lambda x: bool(np.any(np.isclose(uniq, x, rtol=1e-6, atol=1e-9)))  # noqa: E731
    if np.isfinite(q[0]) and not (on_grid(t_hi) and on_grid(0.5 * t_hi)):
        interp.append("torsional_rigidity")
    if np.isfinite(q[1]) and not on_grid(f * rated_torque):
        interp += ["lost_motion", "backlash"]
    return LoadSeriesValues(
        torsional_rigidity=float(q[0]), lost_motion=float(q[1]), hysteresis=float(q[2]),
        backlash=float(q[3]), lost_motion_fraction=f, ci=ci, interpolated=tuple(interp),
        missing=missing, rigidity_range=(0.5 * t_hi, t_hi),
    )  # fmt: skip
