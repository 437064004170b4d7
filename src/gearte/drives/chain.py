"""Drives in series: the chain's stiffness and transmission error at its last output (the joint).

Stage ``k`` of a chain (motor side first) with reduction ``i_k`` turns ``f_k = 1/Π_(j>k) i_j``
times as far as the joint (:func:`gearte.models.lost_motion.stage_transfer_factors`, the factor of
Jiang 2024 eq. 30). The torque on its output is ``f_k T_joint``, its output twists ``f_k T / K_k``
and the joint ``f_k² T / K_k``, so the stiffnesses add in series as

    1/K_joint = Σ_k f_k² / K_k                                            [N·mm/rad]

and the transmission errors as ``TE_joint(θ) = Σ_k f_k TE_k(θ / f_k)`` (stage ``k``'s output angle
is ``θ / f_k`` when the joint is at ``θ``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import Drive
from gearte.errors import ParameterError
from gearte.models.lost_motion import stage_transfer_factors

__all__ = ["joint_stiffness", "joint_te_contributions", "joint_transmission_error"]


def joint_stiffness(stiffness: Sequence[float], ratios: Sequence[float]) -> float:
    """Torsional stiffness of stages in series at the chain's output [N·mm/rad].

    Parameters
    ----------
    stiffness : sequence of float
        Each stage's stiffness at its own output, motor side first [N·mm/rad] (> 0).
    ratios : sequence of float
        Each stage's reduction i = ω_in / ω_out [-] (> 0).

    Returns
    -------
    float
        ``1 / Σ_k f_k² / K_k`` with ``f_k = 1/Π_(j>k) i_j``.

    Examples
    --------
    >>> round(joint_stiffness([1.0e6, 1.0e8], [10.0, 100.0]) / 1e6, 3)  # 1/(1e-10 + 1e-8)
    99.01
    """
    k = np.asarray(stiffness, dtype=float)
    if k.shape != (len(ratios),):
        raise ParameterError("stiffness", list(stiffness), "needs one value per stage ratio")
    if not np.all(np.isfinite(k)) or np.any(k <= 0):
        raise ParameterError("stiffness", k.tolist(), "every stage stiffness must be > 0 N·mm/rad")
    f = stage_transfer_factors(ratios)
    return float(1.0 / np.sum(f * f / k))


def joint_te_contributions(
    drives: Sequence[Drive | None], ratios: Sequence[float], joint_angle: ArrayLike
) -> list[np.ndarray | None]:
    """Each stage's transmission error referred to the chain's output, ``f_k TE_k(θ/f_k)`` [rad].

    Parameters
    ----------
    drives : sequence of Drive or None
        Motor side first; ``None`` for a stage that is not a drive.
    ratios : sequence of float
        Each stage's reduction i = ω_in / ω_out [-] (> 0).
    joint_angle : array_like
        Output angles of the last stage [rad].

    Returns
    -------
    list
        One array per stage [rad], or ``None`` where the stage has no TE model.
    """
    th = np.asarray(joint_angle, dtype=float)
    if len(drives) != len(ratios):
        raise ParameterError("drives", len(drives), f"needs one per stage ratio ({len(ratios)})")
    f = stage_transfer_factors(ratios)
    out: list[np.ndarray | None] = []
    for d, fk in zip(drives, f, strict=True):
        te = None if d is None else d.transmission_error(th / fk)
        out.append(None if te is None else fk * np.asarray(te, dtype=float))
    return out


def joint_transmission_error(
    drives: Sequence[Drive | None], ratios: Sequence[float], joint_angle: ArrayLike
) -> np.ndarray:
    """Transmission error of stages in series at the chain's output [rad].

    ``Σ_k f_k TE_k(θ / f_k)`` over the stages with a TE model (:func:`joint_te_contributions`);
    the others count as exact.

    Parameters
    ----------
    drives : sequence of Drive or None
        Motor side first; ``None`` for a stage that is not a drive.
    ratios : sequence of float
        Each stage's reduction i = ω_in / ω_out [-] (> 0).
    joint_angle : array_like
        Output angles of the last stage [rad].

    Returns
    -------
    numpy.ndarray
        Sum of the stages' TE at the output [rad], shaped like ``joint_angle``.
    """
    th = np.asarray(joint_angle, dtype=float)
    total = np.zeros_like(th)
    for te in joint_te_contributions(drives, ratios, th):
        if te is not None:
            total = total + te
    return total
