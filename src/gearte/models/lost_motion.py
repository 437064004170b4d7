"""Lost motion (return error) of gear pairs and chains; shims; motor-angle compensation.

Units: lengths in mm, angles in rad. Ratios are reductions ``i = ω_in / ω_out > 0``; a chain's
stages are listed from the motor to the joint.

Equations (Jiang et al. 2024, §2.3, §3.3, §4)::

    (14)/(29)  Δφ  = 2 jt / d = 2 jn / (d cos α)        return error of a pair at its output
    (30)       ΔφL = Σₖ Δφₖ / Πⱼ₍ⱼ>ₖ₎ iⱼ                   (paper: Δφ0/(i1 i2) + Δφ1/i2 + Δφ2)
    (31)       ΔZ  = ΔφL · L                               end-effector displacement
    (32)       n_shims · 2 sin α sin δ · ΔP = Δjn          (paper: 2√2 ΔP sin α = Δjn, δ = 45°)
    (33)       Δφc = Σₖ (Πⱼ₍ⱼ≤ₖ₎ iⱼ) Δφₖ,m                (paper: i0 i1 Δφ1m + i0 i1 i2 Δφ2m)

``d`` is the driven gear's pitch diameter (spur) or mean diameter ``dm`` (bevel). The paper's
numeric form ``Δφ[°] = 0.12195 jn[µm] / d[mm]`` is eq. (14) with ``α = 20°``.

After compensating a stage by its mean return error, what remains is the spread about the
mean: ``max(Δφmax − Δφm, Δφm − Δφmin)`` (the paper's ``Δφmax − Δφm``); stages that are not
compensated keep their ``Δφmax``.

References
----------
Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024) Gear backlash modeling and tolerance simulation
of fully gear-coupled robot. J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
doi:10.3785/j.issn.1008-973X.2024.08.001
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.units import rad_to_arcmin, rad_to_deg

__all__ = [
    "return_error",
    "chain_lost_motion",
    "stage_transfer_factors",
    "motor_ratios",
    "end_effector_error",
    "shim_thickness",
    "shim_backlash_reduction",
    "motor_compensation_angle",
    "compensation_residual",
    "StageLostMotion",
    "ChainResult",
    "analyse_chain",
    "compensation_table",
    "compensation_table_csv",
    "compensation_table_json",
    "write_compensation_table",
]


def return_error(jn: ArrayLike, d: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Return error (lost motion) [rad] of a gear pair at its output gear, eqs. (14)/(29).

    Parameters
    ----------
    jn : array_like
        Normal backlash [mm].
    d : array_like
        Pitch diameter of the driven spur gear, or mean diameter ``dm`` of the driven bevel
        gear [mm], ``> 0``.
    alpha : array_like
        Pressure angle [rad].

    Returns
    -------
    Return error [rad]: ``2 jn / (d cos α)``.

    Examples
    --------
    Spur pair of Jiang et al. (2024), 3DCS mean backlash 54 µm on d = 275 mm → 1′26″:

    >>> from gearte.units import rad_to_arcsec
    >>> round(float(rad_to_arcsec(return_error(0.054, 275.0, math.radians(20)))))
    86

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    d = np.asarray(d, dtype=float)
    if np.any(d <= 0):
        raise ParameterError("d", d, "output gear diameter must be > 0 mm")
    return 2.0 * np.asarray(jn, dtype=float) / (d * np.cos(alpha))


def _check_ratios(ratios: Sequence[float], field: str = "ratios") -> np.ndarray:
    r = np.asarray(ratios, dtype=float).ravel()
    if r.size == 0:
        raise ParameterError(field, list(r), "a chain needs at least one stage")
    for k, v in enumerate(r):
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(f"{field}[{k}]", float(v), "a stage ratio must be finite and > 0")
    return r


def stage_transfer_factors(ratios: Sequence[float]) -> np.ndarray:
    """``1 / Πⱼ₍ⱼ>ₖ₎ iⱼ`` [-]: factor by which stage ``k``'s return error appears at the joint.

    ``ratios``: reduction ratio of each stage [-], from the motor to the joint.
    """
    r = _check_ratios(ratios)
    downstream = np.concatenate([np.cumprod(r[::-1])[::-1][1:], [1.0]])
    return 1.0 / downstream


def motor_ratios(ratios: Sequence[float]) -> np.ndarray:
    """``Πⱼ₍ⱼ≤ₖ₎ iⱼ`` [-]: motor angle per unit output angle of stage ``k`` (used in eq. 33).

    ``ratios``: reduction ratio of each stage [-], from the motor to the joint.

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.cumprod(_check_ratios(ratios))


def chain_lost_motion(stage_errors: ArrayLike, ratios: Sequence[float]) -> np.ndarray | float:
    """Return error at the joint [rad] of a chain of any length, eq. (30).

    Parameters
    ----------
    stage_errors : array_like, shape (..., n_stages)
        Return error of each stage at its own output [rad], stages from motor to joint.
    ratios : sequence of float
        Reduction ratio of each stage [-] (``> 0``).

    Returns
    -------
    ``Σₖ Δφₖ / Πⱼ₍ⱼ>ₖ₎ iⱼ`` [rad] — the worst case when the ``Δφₖ`` are maxima.

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    f = stage_transfer_factors(ratios)
    e = np.asarray(stage_errors, dtype=float)
    if e.shape[-1] != f.size:
        raise ParameterError("stage_errors", e.shape, f"last axis must have {f.size} stages")
    return e @ f


def end_effector_error(joint_error: ArrayLike, lever_length: ArrayLike) -> np.ndarray | float:
    """End-effector displacement ``ΔZ = ΔφL·L`` [mm], eq. (31).

    ``joint_error`` ΔφL [rad], ``lever_length`` L [mm].

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    L = np.asarray(lever_length, dtype=float)
    if np.any(L <= 0):
        raise ParameterError("lever_length", lever_length, "must be > 0 mm")
    return np.asarray(joint_error, dtype=float) * L


def shim_backlash_reduction(
    thickness: ArrayLike, alpha: float, shim_sensitivity: float | None = None
) -> np.ndarray | float:
    """Normal-backlash reduction [mm] of shims of ``thickness`` [mm] under both bevel gears.

    ``shim_sensitivity`` [-] (mm of backlash per mm of shim) defaults to ``2√2 sin α`` (two
    shims, 45° cones, eq. 32), α the pressure angle [rad]; pass
    :meth:`gearte.models.backlash.BevelPair.shim_sensitivity` for other cone angles.

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    k = 2.0 * math.sqrt(2.0) * math.sin(alpha) if shim_sensitivity is None else shim_sensitivity
    return k * np.asarray(thickness, dtype=float)


def shim_thickness(
    current_min: float,
    target_min: float,
    alpha: float,
    *,
    shim_sensitivity: float | None = None,
    min_limit: float = 0.0,
) -> float:
    """Shim thickness ``ΔP`` [mm] that lowers a bevel pair's minimum normal backlash, eq. (32).

    Parameters
    ----------
    current_min : float
        Current minimum normal backlash [mm] (at the chosen confidence).
    target_min : float
        Wanted minimum normal backlash [mm]; ``min_limit ≤ target_min < current_min``.
    alpha : float
        Pressure angle [rad].
    shim_sensitivity : float, optional
        Backlash change per unit shim thickness [-] (default ``2√2 sin α``).
    min_limit : float
        Minimum limit normal backlash of the pair [mm].

    Examples
    --------
    The paper: 70 µm → 24 µm, Δjn = 46 µm → ΔP = 0.048 mm.

    >>> round(shim_thickness(0.070, 0.024, math.radians(20)), 3)
    0.048

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    if not target_min < current_min:
        raise ParameterError(
            "shim.target_min_backlash",
            target_min,
            f"must be below the current minimum backlash {current_min:.6g} mm "
            "(a shim can only reduce backlash)",
        )
    if target_min < min_limit:
        raise ParameterError(
            "shim.target_min_backlash",
            target_min,
            f"must be >= the minimum limit normal backlash {min_limit:.6g} mm",
        )
    reduction = current_min - target_min
    k = 2.0 * math.sqrt(2.0) * math.sin(alpha) if shim_sensitivity is None else shim_sensitivity
    if not k > 0:
        raise ParameterError("shim_sensitivity", k, "must be > 0")
    return reduction / k


def motor_compensation_angle(
    mean_errors: Sequence[float], ratios: Sequence[float], compensate: Sequence[bool]
) -> float:
    """Motor-angle offset [rad] applied when the load torque reverses, eq. (33).

    ``Δφc = Σₖ cₖ (Πⱼ₍ⱼ≤ₖ₎ iⱼ) Δφₖ,m`` with ``cₖ = 1`` for the stages compensated:
    ``mean_errors`` Δφₖ,m [rad] per stage, ``ratios`` iⱼ [-], ``compensate`` cₖ per stage.

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    m = motor_ratios(ratios)
    e = np.asarray(mean_errors, dtype=float)
    c = np.asarray(compensate, dtype=bool)
    if not (e.size == c.size == m.size):
        raise ParameterError("mean_errors", e.size, f"need one value per stage ({m.size})")
    return float(np.sum(np.where(c, m * np.nan_to_num(e), 0.0)))


def compensation_residual(
    err_min: float | None, err_mean: float | None, err_max: float, compensated: bool
) -> float:
    """Largest return error [rad] left at a stage's output after compensation by its mean.

    ``err_min``, ``err_mean``, ``err_max``: the stage's return error [rad] (min and mean may be
    None: unknown); ``compensated``: whether the stage is compensated.
    """
    if not compensated:
        return float(err_max)
    if err_mean is None:
        raise ParameterError("mean", None, "a compensated stage needs a mean return error")
    lo = err_mean if err_min is None else err_min
    return float(max(err_max - err_mean, err_mean - lo))


@dataclass(frozen=True)
class StageLostMotion:
    """Return error of one chain stage at its output [rad].

    ``mean``/``min`` may be ``None`` when only a maximum is known (e.g. a catalogue reducer);
    such a stage cannot be compensated.
    """

    name: str
    ratio: float
    max: float
    mean: float | None = None
    min: float | None = None
    compensate: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.ratio) and self.ratio > 0):
            raise ParameterError(f"{self.name}.ratio", self.ratio, "must be finite and > 0")
        vals = [v for v in (self.min, self.mean, self.max) if v is not None]
        if any(v < 0 or not math.isfinite(v) for v in vals):
            raise ParameterError(f"{self.name}.lost_motion", vals, "must be finite and >= 0")
        if vals != sorted(vals):
            raise ParameterError(f"{self.name}.lost_motion", vals, "needs min <= mean <= max")
        if self.compensate and self.mean is None:
            raise ParameterError(
                f"{self.name}.compensate", True, "a stage without a mean cannot be compensated"
            )


@dataclass(frozen=True)
class ChainResult:
    """Lost motion of a chain at the joint and at the end effector, before/after compensation."""

    stages: tuple[StageLostMotion, ...]
    lever_length: float
    transfer: np.ndarray
    motor_ratios: np.ndarray
    joint_max: float
    joint_mean: float | None
    end_effector_max: float
    motor_compensation: float
    residuals: np.ndarray
    joint_max_after: float
    end_effector_max_after: float

    def shares(self) -> dict[str, float]:
        """Share of each stage in the joint's maximum return error (fractions)."""
        parts = np.array([s.max for s in self.stages]) * self.transfer
        return {s.name: float(p / self.joint_max) for s, p in zip(self.stages, parts, strict=True)}


def analyse_chain(stages: Sequence[StageLostMotion], lever_length: float) -> ChainResult:
    """Eqs. (30), (31), (33) for a chain of any length and order.

    Parameters
    ----------
    stages : sequence of StageLostMotion
        From the motor to the joint.
    lever_length : float
        Distance ``L`` from the joint axis to the end effector [mm].

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    if not stages:
        raise ParameterError("chain.stages", [], "a chain needs at least one stage")
    names = [s.name for s in stages]
    if len(set(names)) != len(names):
        raise ParameterError("chain.stages", names, "stage names must be unique")
    ratios = [s.ratio for s in stages]
    for k, r in enumerate(ratios):
        if not (math.isfinite(r) and r > 0):
            raise ParameterError(f"chain.stages[{k}].ratio", r, "must be finite and > 0")
    f = stage_transfer_factors(ratios)
    m = motor_ratios(ratios)
    maxima = np.array([s.max for s in stages])
    joint_max = float(maxima @ f)
    means = [s.mean for s in stages]
    joint_mean = None if any(v is None for v in means) else float(np.array(means) @ f)
    comp = motor_compensation_angle(
        [np.nan if s.mean is None else s.mean for s in stages],
        ratios,
        [s.compensate for s in stages],
    )
    res = np.array([compensation_residual(s.min, s.mean, s.max, s.compensate) for s in stages])
    after = float(res @ f)
    return ChainResult(
        stages=tuple(stages),
        lever_length=float(lever_length),
        transfer=f,
        motor_ratios=m,
        joint_max=joint_max,
        joint_mean=joint_mean,
        end_effector_max=float(end_effector_error(joint_max, lever_length)),
        motor_compensation=comp,
        residuals=res,
        joint_max_after=after,
        end_effector_max_after=float(end_effector_error(after, lever_length)),
    )


# ------------------------------------------------------------------------------------------------
# compensation table a controller can load
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Row:
    stage: str
    ratio: float
    motor_ratio: float
    compensated: bool
    lost_motion_mean_arcmin: float | None
    motor_offset_deg: float
    residual_max_arcmin: float


def compensation_table(result: ChainResult) -> dict:
    """The motor-angle compensation of a chain ``result`` as plain data (JSON-able dict).

    ``rows``: one per stage with its ratio, motor ratio ``Πiⱼ``, mean return error [arcmin] and
    the motor offset it contributes [deg]; ``motor_compensation_angle_deg`` is their sum, to be
    added to the motor command (in the direction of motion) whenever the load torque on the
    joint reverses (for the paper's shoulder: when the arm crosses the vertical).
    """
    rows = []
    for s, mr, res in zip(result.stages, result.motor_ratios, result.residuals, strict=True):
        offset = mr * s.mean if (s.compensate and s.mean is not None) else 0.0
        rows.append(
            _Row(
                stage=s.name,
                ratio=s.ratio,
                motor_ratio=float(mr),
                compensated=bool(s.compensate),
                lost_motion_mean_arcmin=None if s.mean is None else float(rad_to_arcmin(s.mean)),
                motor_offset_deg=float(rad_to_deg(offset)),
                residual_max_arcmin=float(rad_to_arcmin(res)),
            )
        )
    return {
        "trigger": "load torque reversal at the joint",
        "motor_compensation_angle_deg": float(rad_to_deg(result.motor_compensation)),
        "rows": [asdict(r) for r in rows],
    }


def compensation_table_csv(table: dict) -> str:
    """CSV text of a ``table`` from :func:`compensation_table` (one row per stage, a total last)."""
    buf = io.StringIO()
    rows = table["rows"]
    w = csv.DictWriter(buf, fieldnames=list(rows[0].keys()), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: "" if v is None else v for k, v in r.items()})
    buf.write(f"# motor_compensation_angle_deg,{table['motor_compensation_angle_deg']}\n")
    return buf.getvalue()


def compensation_table_json(table: dict) -> str:
    """JSON text of a ``table`` from :func:`compensation_table`."""
    return json.dumps(table, indent=2)


def write_compensation_table(table: dict, path: str | Path) -> Path:
    """Write the table as ``.csv`` or ``.json`` (chosen by the suffix); returns the path."""
    p = Path(path)
    if p.suffix.lower() == ".csv":
        text = compensation_table_csv(table)
    elif p.suffix.lower() == ".json":
        text = compensation_table_json(table)
    else:
        raise ParameterError("path", str(p), "suffix must be .csv or .json")
    tmp = p.with_suffix(p.suffix + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(p)
    return p
