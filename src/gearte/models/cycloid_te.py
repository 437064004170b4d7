"""Geometric transmission error of a cycloid–pin stage from nine component errors.

Hu et al. 2020, section 2.2 (eq 5–17) and section 3 (Table 2, eq 18–27). All lengths in mm, angles
in rad; arcmin only at the edges (:mod:`gearte.units`).

The geometric TE here is the *lost motion* of the stage referred to the disc (output) rotation:
positive contributions add backlash, negative ones take it away.

Factors (Table 1 and eq 5–13; ``a`` eccentricity, ``z_c`` cycloid teeth, K1 eq 3)::

    A  equidistant modification Δr_rp          Δθ = +2 Δr_rp / (a z_c)
    B  shifted modification Δr_p               Δθ = −2 Δr_p (1−K1²)^½ / (a z_c)
    C  pin-circle radius error δr_p            Δθ = +2 δr_p (1−K1²)^½ / (a z_c)
    D  pin radius error δr_rp                  Δθ = −2 δr_rp / (a z_c)
    E  pin/groove clearance δ_j                Δθ = +δ_j / (a z_c)
    F  disc radial runout F_r1                 Δθ = +F_r1 / (2 a z_c)
    G  pin-housing position error δt_Σ         Δθ = +2 K1 δt_Σ / (a z_c)
    H  cumulative pitch error ΔF_p             Δθ = −K1 ΔF_p / (a z_c)
    I  modification errors δΔr_rp, δΔr_p and eccentricity error δa
                                               Δθ = +2 δΔr_rp/(a z_c) − 2 δΔr_p (1−K1²)^½/(a z_c)
                                                    + Δθ_ecc(δa)
    rotation modification δ_rot (gearte)      Δθ = +2 δ_rot

Signs: the printed equations lost every minus sign; they are restored from Table 2 (whose
coefficients b, g, h are negative) and from the clearance geometry (A + B = 2 Δ_n(φ0)/r_c, twice
the closing rotation of eq 32).

Eccentricity coefficient (printed k_n lost)
-------------------------------------------
gearte derives it from the profile geometry. An eccentricity error δa moves the pin-centre path
relative to the disc along the profile normal by ``δa (K1 − cos φ)/S`` (differentiate eq 1–2 with
respect to a and project on the normal). This vanishes at the first-contact phase φ0 = arccos K1,
so the linear error coefficient is exactly ``k_n = 0``: to first order an eccentricity error does
not change the lost motion, which agrees with the paper's statement that it is the smallest index
(printed −0.00024, "neglected"). The remaining effect is second order and always negative: the
closing rotation becomes ``min_φ (Δ_n + δa w)/l`` instead of ``Δ_n(φ0)/r_c``; gearte evaluates that
minimum (:func:`eccentricity_te`). The notes' derivative reading ``(a z_c/2) ∂(Δθ_A+Δθ_B)/∂a`` gives
an index −0.054; it is the change of the *modification's* backlash when the design eccentricity
changes (disc re-ground), not the effect of a crank error, so gearte does not use it.

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.geometry.cycloid import CycloidStage

__all__ = [
    "ERROR_FACTORS",
    "TABLE2_ROWS",
    "PAPER_SYMBOLS",
    "MODIFICATION_FACTORS",
    "error_coefficients",
    "te_gradients",
    "sensitivity_indices",
    "eccentricity_te",
    "factor_contributions",
    "factor_tolerances",
    "GeometricTE",
    "geometric_te",
    "Compensation",
    "compensate",
    "ALLOCATION_RULES",
]

#: The nine component errors, in the order of Table 2 (rows a–i).
ERROR_FACTORS: tuple[str, ...] = (
    "pin_circle_radius_error",  # a  δr_p      factor C
    "pin_radius_error",  # b  δr_rp     factor D
    "pin_groove_clearance",  # c  δ_j       factor E
    "radial_runout",  # d  F_r1      factor F
    "pin_housing_position_error",  # e  δt_Σ      factor G
    "equidistant_modification_error",  # f  δΔr_rp    factor I
    "shifted_modification_error",  # g  δΔr_p     factor I
    "cumulative_pitch_error",  # h  ΔF_p      factor H
    "eccentricity_error",  # i  δa        factor I
)
#: Table 2 row letter → factor name.
TABLE2_ROWS: dict[str, str] = dict(zip("abcdefghi", ERROR_FACTORS, strict=True))
#: Factor name → the paper's symbol.
PAPER_SYMBOLS: dict[str, str] = {
    "pin_circle_radius_error": "δr_p",
    "pin_radius_error": "δr_rp",
    "pin_groove_clearance": "δ_j",
    "radial_runout": "F_r1",
    "pin_housing_position_error": "δt_Σ",
    "equidistant_modification_error": "δΔr_rp",
    "shifted_modification_error": "δΔr_p",
    "cumulative_pitch_error": "ΔF_p",
    "eccentricity_error": "δa",
    "equidistant_modification": "Δr_rp",
    "shifted_modification": "Δr_p",
    "rotation_modification": "δ_rot",
}
#: Nominal design modifications, which contribute to the mean TE but carry no tolerance.
MODIFICATION_FACTORS: tuple[str, ...] = (
    "equidistant_modification",
    "shifted_modification",
    "rotation_modification",
)


def error_coefficients(K1: ArrayLike) -> dict[str, np.ndarray | float]:
    """Error coefficients of Table 2 (Hu et al. 2020), the diagonal of A (eq 24) divided by 2.

    Parameters
    ----------
    K1 : array_like
        Short-width coefficient [-].

    Returns
    -------
    dict
        Factor name → coefficient c_j [-], so that ∂Δθ/∂δ_j = 2 c_j / (a z_c) [rad/mm]. The
        eccentricity coefficient is the derived k_n = 0 (module notes).

    Examples
    --------
    >>> round(error_coefficients(0.78993)["pin_housing_position_error"], 5)
    0.78993

    References
    ----------
    Hu et al. (2020) eq 24, Table 2, doi:10.3390/app10020481.
    """
    K1 = np.asarray(K1, dtype=float)
    root = np.sqrt(1.0 - K1 * K1)
    out = {
        "pin_circle_radius_error": root,
        "pin_radius_error": -np.ones_like(K1),
        "pin_groove_clearance": 0.5 * np.ones_like(K1),
        "radial_runout": 0.25 * np.ones_like(K1),
        "pin_housing_position_error": K1 * 1.0,
        "equidistant_modification_error": np.ones_like(K1),
        "shifted_modification_error": -root,
        "cumulative_pitch_error": -K1 / 2.0,
        "eccentricity_error": np.zeros_like(K1),
    }
    return {k: (float(v) if np.ndim(v) == 0 else v) for k, v in out.items()}


def te_gradients(stage: CycloidStage) -> dict[str, float]:
    """Error gains g_j = ∂Δθ/∂δ_j [rad/mm] (eq 21–22): 2 c_j / (a z_c).

    Parameters
    ----------
    stage : CycloidStage
        The stage (fixes K1 and r_c = a z_c).

    Returns
    -------
    dict
        Factor name → g_j [rad/mm].

    References
    ----------
    Hu et al. (2020) eq 21–22, doi:10.3390/app10020481.
    """
    scale = 2.0 / stage.r_c
    return {k: scale * float(v) for k, v in error_coefficients(stage.K1).items()}


def sensitivity_indices(
    stage_or_K1: CycloidStage | float, reference: str = "pin_circle_radius_error"
) -> dict[str, float]:
    """Sensitivity indices S_j = g_j / g_0 (eq 22; Table 2, third column).

    Parameters
    ----------
    stage_or_K1 : CycloidStage or float
        The stage, or K1 [-] directly.
    reference : str
        The reference factor g_0 (the paper: pin-circle radius error, row a).

    Examples
    --------
    >>> round(sensitivity_indices(0.78993)["pin_radius_error"], 4)
    -1.6308

    References
    ----------
    Hu et al. (2020) eq 22, Table 2, doi:10.3390/app10020481.
    """
    K1 = stage_or_K1.K1 if isinstance(stage_or_K1, CycloidStage) else float(stage_or_K1)
    c = error_coefficients(K1)
    if reference not in c:
        raise ParameterError("reference", reference, f"must be one of {list(c)}")
    g0 = float(c[reference])
    if g0 == 0.0:
        raise ParameterError("reference", reference, "has a zero error coefficient")
    return {k: float(v) / g0 for k, v in c.items()}


def _closing_ratio_grid(stage: CycloidStage, n: int = 2001) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(1e-3, np.pi - 1e-3, n)
    K1 = stage.K1
    S = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(phi))
    lr = np.sin(phi) / S  # l / r_c
    dn = stage.dr_rp - stage.dr_p * (1.0 - K1 * np.cos(phi)) / S
    w = (K1 - np.cos(phi)) / S
    return phi, np.stack([dn / lr, w / lr])


def eccentricity_te(stage: CycloidStage, delta_a: ArrayLike) -> np.ndarray | float:
    """Lost-motion change [rad] caused by an eccentricity error δa [mm] (second order).

    Parameters
    ----------
    stage : CycloidStage
        The nominal stage.
    delta_a : array_like
        Eccentricity error δa [mm] (crank eccentricity minus the disc's design eccentricity).

    Returns
    -------
    numpy.ndarray
        Δθ_ecc = 2 (β(δa) − β(0)) [rad], with the closing rotation
        β(δa) = min_φ (Δ_n(φ) + δa (K1 − cos φ)/S) / l(φ) over the loaded flank, r_c = a z_c.
        Δθ_ecc ≤ 0 and = O(δa²): the linear coefficient k_n is zero (module notes). When the
        error opens an interference at the root (δa > root clearance) the minimum sits at the end
        of the flank and the result grows large and negative; that is physical (the disc jams).

    Notes
    -----
    Evaluated on a 2001-point grid of φ with parabolic refinement of the minimum.
    """
    da = np.atleast_1d(np.asarray(delta_a, dtype=float))
    phi, (f, h) = _closing_ratio_grid(stage)

    def _min(vals: np.ndarray) -> np.ndarray:
        k = np.clip(np.argmin(vals, axis=-1), 1, vals.shape[-1] - 2)
        idx = np.arange(vals.shape[0])
        y0, y1, y2 = vals[idx, k - 1], vals[idx, k], vals[idx, k + 1]
        den = y0 - 2.0 * y1 + y2
        with np.errstate(divide="ignore", invalid="ignore"):
            corr = np.where(den > 0.0, (y0 - y2) ** 2 / (8.0 * den), 0.0)
        return y1 - corr

    base = _min(f[None, :])[0]
    out = np.empty_like(da)
    chunk = 4096
    for s in range(0, da.size, chunk):
        vals = f[None, :] + da[s : s + chunk, None] * h[None, :]
        out[s : s + chunk] = 2.0 * (_min(vals) - base) / stage.r_c
    return out.reshape(np.shape(delta_a)) if np.ndim(delta_a) else out[0]


def _check_errors(errors: Mapping[str, float], what: str) -> dict[str, float]:
    unknown = sorted(set(errors) - set(ERROR_FACTORS))
    if unknown:
        raise ParameterError(
            what, unknown, f"unknown error factor(s); known: {list(ERROR_FACTORS)}"
        )
    out = {}
    for k in ERROR_FACTORS:
        v = float(errors.get(k, 0.0))
        if not math.isfinite(v):
            raise ParameterError(f"{what}.{k}", v, "must be finite")
        out[k] = v
    return out


def factor_contributions(
    stage: CycloidStage, errors: Mapping[str, float] | None = None
) -> dict[str, float]:
    """Each factor's contribution Δθ_j [rad] to the geometric TE (eq 5–13).

    Parameters
    ----------
    stage : CycloidStage
        Stage with its nominal modifications.
    errors : mapping
        Factor name (:data:`ERROR_FACTORS`) → mean error [mm]; missing names are 0.

    Returns
    -------
    dict
        The three design modifications (:data:`MODIFICATION_FACTORS`) then the nine errors →
        contribution [rad]. Their sum is the mean geometric TE (eq 16).

    References
    ----------
    Hu et al. (2020) eq 5–13 and 16, doi:10.3390/app10020481.
    """
    e = _check_errors(errors or {}, "errors")
    g = te_gradients(stage)
    root = math.sqrt(1.0 - stage.K1**2)
    out = {
        "equidistant_modification": 2.0 * stage.dr_rp / stage.r_c,
        "shifted_modification": -2.0 * stage.dr_p * root / stage.r_c,
        "rotation_modification": 2.0 * stage.rotation,
    }
    for k in ERROR_FACTORS:
        if k == "eccentricity_error":
            out[k] = float(eccentricity_te(stage, e[k])) if e[k] != 0.0 else 0.0
        else:
            out[k] = g[k] * e[k] + 0.0  # + 0.0: no negative zeros in reports
    return out


def factor_tolerances(
    stage: CycloidStage,
    tolerances: Mapping[str, float],
    means: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Tolerance T_Δθj [rad] of each factor's TE (the full width of its range).

    For the eight linear factors T_Δθj = |g_j| T_j; for the eccentricity error it is the range of
    :func:`eccentricity_te` over [mean − T/2, mean + T/2] (second order).

    Parameters
    ----------
    stage : CycloidStage
        The stage (fixes K1 and r_c = a z_c).
    tolerances : mapping
        Factor name → tolerance band width T_j [mm] (≥ 0; missing names are 0).
    means : mapping, optional
        Factor name → mean error [mm] (only the eccentricity's mean matters).

    Returns
    -------
    dict
        Factor name → T_Δθj [rad].

    References
    ----------
    Hu et al. (2020) eq 17, doi:10.3390/app10020481.
    """
    t = _check_errors(tolerances, "tolerances")
    m = _check_errors(means or {}, "errors")
    for k, v in t.items():
        if v < 0.0:
            raise ParameterError(f"tolerances.{k}", v, "must be >= 0")
    g = te_gradients(stage)
    out = {}
    for k in ERROR_FACTORS:
        if k == "eccentricity_error":
            if t[k] == 0.0:
                out[k] = 0.0
                continue
            xs = m[k] + np.linspace(-0.5, 0.5, 41) * t[k]
            te = eccentricity_te(stage, xs)
            out[k] = float(np.max(te) - np.min(te))
        else:
            out[k] = abs(g[k]) * t[k]
    return out


@dataclass(frozen=True)
class GeometricTE:
    """Result of :func:`geometric_te`; angles in rad.

    Attributes
    ----------
    mean : float
        Mean geometric TE Δθ̄ [rad] (eq 16).
    tolerance : float
        RSS tolerance T_Δθ [rad] (eq 17); the TE lies in mean ± tolerance/2 (eq 15).
    contributions : dict
        Factor → Δθ_j [rad] (modifications and errors).
    tolerances : dict
        Error factor → T_Δθj [rad].
    coefficients, gradients, sensitivity : dict
        Table 2 coefficients [-], gains g_j [rad/mm] and indices S_j [-].
    """

    mean: float
    tolerance: float
    contributions: dict[str, float]
    tolerances: dict[str, float]
    coefficients: dict[str, float]
    gradients: dict[str, float]
    sensitivity: dict[str, float]
    notes: list[str] = field(default_factory=list)

    @property
    def lower(self) -> float:
        """mean − tolerance/2 [rad]."""
        return self.mean - 0.5 * self.tolerance

    @property
    def upper(self) -> float:
        """mean + tolerance/2 [rad]."""
        return self.mean + 0.5 * self.tolerance

    def tolerance_shares(self) -> dict[str, float]:
        """Share of each factor in the RSS tolerance, T_j² / Σ T_k² [-] (sums to 1)."""
        tot = sum(v * v for v in self.tolerances.values())
        return {k: (v * v / tot if tot > 0 else 0.0) for k, v in self.tolerances.items()}


def geometric_te(
    stage: CycloidStage,
    means: Mapping[str, float] | None = None,
    tolerances: Mapping[str, float] | None = None,
) -> GeometricTE:
    """Geometric TE of the stage: mean, RSS tolerance and each factor's share (eq 5–17).

    Parameters
    ----------
    stage : CycloidStage
        The stage with its modifications.
    means : mapping
        Error factor → mean error [mm].
    tolerances : mapping
        Error factor → tolerance band width [mm].

    Returns
    -------
    GeometricTE
        ``mean = Σ Δθ_j`` (eq 16) and ``tolerance = (Σ T_Δθj²)^½`` (eq 17), both [rad]; convert
        with :func:`gearte.units.rad_to_arcmin` (the paper's 180·60/π).

    References
    ----------
    Hu et al. (2020) eq 5–17, doi:10.3390/app10020481.
    """
    contrib = factor_contributions(stage, means)
    tols = factor_tolerances(stage, tolerances or {}, means)
    coeff = {k: float(v) for k, v in error_coefficients(stage.K1).items()}
    return GeometricTE(
        mean=float(sum(contrib.values())),
        tolerance=float(math.sqrt(sum(v * v for v in tols.values()))),
        contributions=contrib,
        tolerances=tols,
        coefficients=coeff,
        gradients=te_gradients(stage),
        sensitivity=sensitivity_indices(stage),
    )


ALLOCATION_RULES: tuple[str, ...] = ("equal_share", "equal_change", "tolerance_weighted")


@dataclass(frozen=True)
class Compensation:
    """Result of :func:`compensate`.

    Attributes
    ----------
    changes : dict
        Factor → change of its mean error Δδ_j [mm] to apply.
    te_changes : dict
        Factor → its TE change g_j Δδ_j [rad]; they sum to the requested change.
    target_change : float
        The requested change of the mean geometric TE [rad].
    rule : str
        The allocation rule used.
    """

    changes: dict[str, float]
    te_changes: dict[str, float]
    target_change: float
    rule: str


def compensate(
    stage: CycloidStage,
    target_change: float,
    factors: Sequence[str] = (
        "pin_radius_error",
        "shifted_modification_error",
        "cumulative_pitch_error",
    ),
    rule: str = "equal_share",
    tolerances: Mapping[str, float] | None = None,
) -> Compensation:
    """Compensation model (Hu et al. 2020, eq 24–27) as an explicit allocation rule.

    Changes the mean errors of the chosen factors so that the mean geometric TE changes by
    ``target_change`` exactly (the forward model is linear in these factors).

    Parameters
    ----------
    stage : CycloidStage
        The stage (fixes K1 and r_c = a z_c).
    target_change : float
        Wanted change of the mean geometric TE [rad] (e.g. −TE to remove it).
    factors : sequence of str
        Factors allowed to change; default the three with negative coefficients (Table 2 rows b,
        g, h) as in the paper. The eccentricity (k_n = 0) cannot compensate anything.
    rule : {"equal_share", "equal_change", "tolerance_weighted"}
        * ``equal_share``: every factor takes the same TE share Δθ_j = target/n, then eq 27
          δ_j = (a z_c / 2) c_j⁻¹ Δθ_j (the diagonal A⁻¹ of eq 27).
        * ``equal_change``: the same magnitude of change for every factor,
          Δδ_j = sign(g_j) target / Σ|g_k| (TE shares ∝ |S_j|).
        * ``tolerance_weighted``: the least change in units of each tolerance,
          min Σ (Δδ_j/T_j)² subject to Σ g_j Δδ_j = target → Δδ_j = T_j² g_j target / Σ T_k² g_k².
    tolerances : mapping, optional
        Factor → tolerance [mm]; needed by ``tolerance_weighted``.

    Returns
    -------
    Compensation
        ``Σ g_j Δδ_j == target_change`` (to rounding).

    Notes
    -----
    The paper assigns 1.4559′ "in inverse proportion" to the three factors; none of these rules
    (nor any split we tried) reproduces Table 6 through eq 27 — see docs/validation/hu2020.md.

    References
    ----------
    Hu et al. (2020) eq 24–27, Table 6, doi:10.3390/app10020481.
    """
    if rule not in ALLOCATION_RULES:
        raise ParameterError("rule", rule, f"must be one of {list(ALLOCATION_RULES)}")
    if not math.isfinite(target_change):
        raise ParameterError("target_change", target_change, "must be finite")
    factors = list(dict.fromkeys(factors))
    if not factors:
        raise ParameterError("factors", factors, "need at least one factor")
    g = te_gradients(stage)
    for k in factors:
        if k not in g:
            raise ParameterError("factors", k, f"unknown factor; known: {list(ERROR_FACTORS)}")
        if g[k] == 0.0:
            raise ParameterError("factors", k, "has a zero error coefficient; cannot compensate")
    if rule == "equal_share":
        te = {k: target_change / len(factors) for k in factors}
        ch = {k: te[k] / g[k] for k in factors}
    elif rule == "equal_change":
        s = sum(abs(g[k]) for k in factors)
        ch = {k: math.copysign(1.0, g[k]) * target_change / s for k in factors}
    else:
        tol = dict(tolerances or {})
        w = {}
        for k in factors:
            t = float(tol.get(k, 0.0))
            if not (t > 0.0 and math.isfinite(t)):
                raise ParameterError(
                    f"tolerances.{k}", t, "must be > 0 for rule 'tolerance_weighted'"
                )
            w[k] = t * t
        s = sum(w[k] * g[k] ** 2 for k in factors)
        ch = {k: w[k] * g[k] * target_change / s for k in factors}
    te = {k: g[k] * ch[k] for k in factors}
    return Compensation(changes=ch, te_changes=te, target_change=float(target_change), rule=rule)
