"""Calibration of one serial's reduced model to its bench data, and synthetic benches.

Composes the reduced model (:mod:`gearte.models.bench_reduced`) with a bounded least-squares
solver (``scipy.optimize.least_squares``, trust-region reflective). Reports the fit, the
residuals, confidence intervals from the Jacobian, the correlations, and which parameters the
data cannot identify (rank and condition of the Jacobian, huge intervals, parameters at a bound).
:func:`synthetic_bench` generates bench data from known parameters (noise, encoder quantisation,
rig compliance) for tests, the benchmark and the bundled example.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.models.bench_data import HysteresisCurve, TETrace
from gearte.models.bench_reduced import (
    TE_COMMON,
    ReducedRV,
    hysteresis_angle,
    hysteresis_jacobian,
    hysteresis_parameters,
    parameter_names,
    play,
    te_basis,
    te_coefficients,
    te_orders,
    te_trace,
)
from gearte.models.catalogue import (
    branch_directions,
    hysteresis_values,
    torsional_rigidity_error,
)
from gearte.units import arcsec_to_rad

__all__ = [
    "ParameterSpec",
    "parameter_specs",
    "CalibrationResult",
    "calibrate",
    "synthetic_bench",
    "reduced_constants",
    "synthetic_full_model_hysteresis",
    "serial_reducer",
    "ClosedLoop",
    "close_loop",
    "Z95",
    "CONFOUNDED_CORRELATION",
    "hysteresis_noise",
    "catalogue_stiffness_factor",
    "DefinitionEstimate",
]

CONFOUNDED_CORRELATION = 0.99
"""A pair of :data:`CONFOUNDED_PAIRS` correlated beyond this is flagged as confounded [-]."""
CONFOUNDED_PAIRS = (("contact_stiffness_factor", "rig_compliance"),)
"""Parameters a hysteresis curve sees almost only together: the reducer's stiffness and the rig's
compliance are both a compliance on the measured torque, told apart only by the curvature of the
reduced elastic law (on whole-model data their split was off by factors 0.001–8 in 20 seeds)."""

SHAPE_NOTE = (
    "shape term of the elastic law: absorbs what the reduced law lacks so that the other "
    "parameters' intervals hold; describes the curve, not a property of the serial"
)
"""Flag of every shape amplitude (:meth:`gearte.models.bench_reduced.ReducedRV.shape_parameters`):
a nuisance parameter, never reported as identified."""

Z95 = 1.959963984540054
"""Two-sided 95 % normal quantile: confidence interval = ± Z95 × standard error."""


@dataclass(frozen=True)
class ParameterSpec:
    """Unit label (for reports), scale, bounds of one parameter (gearte units)."""

    unit: str
    scale: float
    lower: float
    upper: float


def parameter_specs(model: ReducedRV) -> dict[str, ParameterSpec]:
    """Scales and bounds of every parameter of the reduced model."""
    tr, k = model.rated_torque, model.nominal_rigidity
    specs = {
        "cam_bearing_clearance": ParameterSpec("mm", 0.005, 0.0, 0.2),
        "carrier_bearing_clearance": ParameterSpec("mm", 0.005, 0.0, 0.2),
        "play_transition_torque": ParameterSpec("N·mm", 0.01 * tr, 1e-5 * tr, 0.2 * tr),
        "contact_stiffness_factor": ParameterSpec("-", 1.0, 0.05, 20.0),
        "rig_compliance": ParameterSpec("rad/(N·mm)", 0.1 / k, 0.0, 20.0 / k),
        "friction_torque": ParameterSpec("N·mm", 0.01 * tr, 0.0, 0.3 * tr),
        "angle_offset": ParameterSpec("rad", 1e-4, -0.05, 0.05),
        "te_offset": ParameterSpec("rad", 1e-5, -0.05, 0.05),
        "running_windup": ParameterSpec("rad", 1e-5, -0.01, 0.01),
    }
    for name in model.family_parameters():
        specs[name] = ParameterSpec("rad", 1e-5, -0.005, 0.005)
    for name in model.shape_parameters():
        specs[name] = ParameterSpec("rad", 0.1 * tr / k, -2.0 * tr / k, 2.0 * tr / k)
    return specs


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate` (all values in gearte units, see :func:`parameter_specs`).

    Attributes
    ----------
    params : dict
        Every parameter of the model: fitted ones at their estimate, the others as fixed.
    fitted : tuple of str
    std, ci : dict
        Standard error and 95 % half-width of each fitted parameter (``inf`` where the data
        cannot identify it).
    correlation : ndarray
        Correlation matrix of the fitted parameters (order of ``fitted``).
    flags : dict
        Fitted parameter → why it is not identified (absent: identified).
    groups : list of tuple
        Parameters the data cannot tell apart (each group spans a null direction of J).
    rank, condition : int, float
        Rank and condition number of the column-normalised Jacobian.
    residual_rms : dict
        RMS residual [rad] of the hysteresis and the TE data; ``residuals`` holds them.
    covariance_inflation : float
        Long-run variance over variance of the hysteresis residuals along the sweep [-]: the
        hysteresis rows' information is divided by it (1: independent residuals).
    by_definition : dict
        Parameter → :class:`DefinitionEstimate`: a parameter defined by a catalogue quantity and
        estimated by that definition on the data rather than by the fit (the contact-stiffness
        factor where the rig compliance is given: :func:`catalogue_stiffness_factor`). ``params``
        and ``ci`` keep the fit's values (the reduced model's curve); :meth:`estimate` gives the
        reported ones.
    """

    model: ReducedRV
    params: dict
    fitted: tuple[str, ...]
    std: dict
    ci: dict
    correlation: np.ndarray
    covariance: np.ndarray
    flags: dict
    groups: list
    rank: int
    condition: float
    residual_rms: dict
    residuals: dict = field(repr=False, default_factory=dict)
    cost: float = 0.0
    success: bool = True
    message: str = ""
    fixed: tuple[str, ...] = ()
    covariance_inflation: float = 1.0
    by_definition: dict = field(default_factory=dict)

    def identified(self) -> list[str]:
        return [n for n in self.fitted if n not in self.flags]

    def estimate(self, name: str) -> tuple[float, float]:
        """The reported value and 95 % half-width of a fitted parameter: by its definition on
        the data where :attr:`by_definition` holds it, else the fit's (gearte units)."""
        if name in self.by_definition:
            d = self.by_definition[name]
            return d.value, d.ci
        return float(self.params[name]), float(self.ci[name])


@dataclass(frozen=True)
class _TERow:
    """One direction of one trace, compressed exactly for least squares on the linear TE model.

    With ``A`` the basis at the samples and ``ĉ`` the least-squares coefficients,
    ``‖A c − y‖² = rss0 + ‖R (c − ĉ)‖²`` (``R`` the Cholesky factor of ``AᵀA``), so the fit
    sees ``1 + 2U`` rows instead of thousands of samples and loses nothing.
    """

    direction: int
    c_hat: np.ndarray
    r: np.ndarray
    rss0: float
    samples: int


def _te_rows(model, traces: list[TETrace]) -> list[_TERow]:
    rows = []
    for tr in traces:
        for d, (pos, te) in tr.directions().items():
            a = te_basis(model, pos)
            ata = a.T @ a  # normal equations: the basis is well conditioned over a revolution
            try:
                r = np.linalg.cholesky(ata).T
                c_hat = np.linalg.solve(ata, a.T @ te)
            except np.linalg.LinAlgError:
                raise ParameterError(
                    "te",
                    tr.source,
                    "too few samples to resolve the orders of the TE model "
                    f"(highest order {max(te_orders(model))} needs > {2 * max(te_orders(model))} "
                    "samples per revolution)",
                ) from None
            rss0 = float(np.sum((a @ c_hat - te) ** 2))
            rows.append(_TERow(1 if d == "forward" else -1, c_hat, r, rss0, te.size))
    return rows


def _initial(model, hyst, direction, te_rows, fixed):
    """Starting point: catalogue values of the curve; TE coefficients by linear least squares."""
    p = dict.fromkeys(parameter_names(model), 0.0)
    tr = model.rated_torque
    g = sum(model.backlash_per_clearance)
    if hyst is not None:
        hv = hysteresis_values(hyst.torque, hyst.angle, tr, direction=direction)
        beta = max(hv.backlash, 1e-7)
        c0 = model.design_clearances
        g_cam, g_car = model.backlash_per_clearance
        common = (beta - model.design_backlash + g_cam * c0[0] + g_car * c0[1]) / g
        p["cam_bearing_clearance"] = p["carrier_bearing_clearance"] = max(common, 1e-4)
        k_meas = hv.torsional_rigidity
        p["rig_compliance"] = 0.05 / k_meas
        p["contact_stiffness_factor"] = float(
            np.clip(1.0 / ((1.0 / k_meas - p["rig_compliance"]) * model.nominal_rigidity),
                    0.1, 10.0)
        )  # fmt: skip
        width = max(hv.hysteresis_loss - hv.backlash, 0.0)
        p["friction_torque"] = max(0.5 * width * k_meas, 1e-4 * tr)
        p["play_transition_torque"] = 0.01 * tr
        p["angle_offset"] = float(
            np.median(hyst.angle[np.abs(hyst.torque) < 0.05 * tr])
            if np.any(np.abs(hyst.torque) < 0.05 * tr)
            else 0.0
        )
    else:
        p["contact_stiffness_factor"] = 1.0
        p["play_transition_torque"] = 0.01 * tr
    if te_rows:
        orders = te_orders(model)
        fwd = [r.c_hat for r in te_rows if r.direction > 0]
        bwd = [r.c_hat for r in te_rows if r.direction < 0]
        mean = np.mean([r.c_hat for r in te_rows], axis=0)
        p["te_offset"] = float(mean[0])
        if fwd and bwd:
            p["running_windup"] = float(np.mean(fwd, 0)[0] - np.mean(bwd, 0)[0]) - (
                hysteresis_play(model, p)
            )
        taken: set = set()
        for fam, n in model.families.items():  # an order's amplitude goes to its first family
            if n in taken:
                continue
            taken.add(n)
            k = 1 + 2 * orders.index(int(n))
            key = fam.replace(" ", "_")
            p[f"{key}_cos"], p[f"{key}_sin"] = float(mean[k]), float(mean[k + 1])
    p.update(fixed)
    return p


def hysteresis_play(model: ReducedRV, p: dict) -> Any:
    """The free play β [rad] (:func:`gearte.models.bench_reduced.play`)."""
    return play(model, p)


def calibrate(
    model: ReducedRV,
    hysteresis: HysteresisCurve | None,
    traces: list[TETrace],
    *,
    fit: list[str] | tuple[str, ...] | None = None,
    fixed: dict | None = None,
    max_relative_ci: float = 0.25,
    torque_noise: float = 0.0,
) -> CalibrationResult:
    """Fit the chosen parameters of the reduced model to one serial's hysteresis and TE data.

    Parameters
    ----------
    model : ReducedRV
    hysteresis : HysteresisCurve or None
    traces : list of TETrace
        One or more TE traces of the serial (their torque/speed are not modelled: use the
        traces of one operating point).
    fit : names, optional
        Parameters to fit (default: all whose data are given); the others are held at ``fixed``
        or at their starting value.
    fixed : dict, optional
        Values [gearte units] of parameters held fixed (e.g. ``{"rig_compliance": 1e-10}`` from
        a calibration shaft, ``{"encoder_eccentricity_cos": 0, ...}`` from a reversal test).
    torque_noise : float
        Standard deviation of the torque reading as a fraction of ``T_r`` (the sensor's
        specification) [-]; near zero torque, where the curve is steep, it dominates the angle
        error and the hysteresis residuals are weighted by the effective variance.
    max_relative_ci : float
        A parameter whose 95 % half-width exceeds this fraction of its bound range is flagged
        [-].

    Returns
    -------
    CalibrationResult

    Notes
    -----
    Residuals are weighted by each block's noise (hysteresis angle, TE), estimated from a first
    fit; the covariance is ``s² (JᵀJ)⁺`` at the weighted solution with ``s²`` the reduced
    chi-square, so the interval of any identified parameter is valid whatever the null space.
    Where the hysteresis residuals are correlated along the sweep (a law the reduced model
    lacks), its rows count as ``n σ²/σ_LR²`` independent samples, ``σ_LR²`` their long-run
    variance (Bartlett window of 5 % of the samples).

    With the rig compliance given (in ``fixed``) and a hysteresis curve, the contact-stiffness
    factor is also estimated by its definition (:func:`catalogue_stiffness_factor`) and
    reported so (``by_definition``, :meth:`CalibrationResult.estimate`); the fitted factor stays
    the reduced law's parameter (``params``).
    """
    from scipy.optimize import least_squares

    fixed = dict(fixed or {})
    names = parameter_names(model)
    specs = parameter_specs(model)
    unknown = [n for n in (*(fit or ()), *fixed) if n not in names]
    if unknown:
        raise ParameterError("calibration.fit", unknown, f"unknown parameter(s); known: {names}")
    te_rows = _te_rows(model, traces)
    if hysteresis is None and not te_rows:
        raise ParameterError("calibration", None, "needs a hysteresis curve or a TE trace")
    direction: Any = None
    if hysteresis is not None:
        direction = (
            hysteresis.branch
            if hysteresis.branch is not None
            else branch_directions(hysteresis.torque)
        )
    available = []
    if hysteresis is not None:
        available += list(hysteresis_parameters(model))
    if te_rows:
        available += [*TE_COMMON, *model.family_parameters()]
        for c in ("cam_bearing_clearance", "carrier_bearing_clearance"):
            if c not in available:
                available.append(c)
    fit = tuple(n for n in (fit or available) if n not in fixed)
    if not fit:
        raise ParameterError("calibration.fit", [], "nothing to fit")
    p0 = _initial(model, hysteresis, direction, te_rows, fixed)
    scale = np.array([specs[n].scale for n in fit])
    lo = np.array([specs[n].lower for n in fit]) / scale
    hi = np.array([specs[n].upper for n in fit]) / scale
    x0 = np.clip(np.array([p0[n] for n in fit]) / scale, lo, hi)
    x0 = np.clip(x0, lo + 1e-6 * (hi - lo), hi - 1e-6 * (hi - lo))

    def unpack(x):
        p = dict(p0)
        p.update(zip(fit, x * scale, strict=True))
        return p

    def te_map(direction):
        base = unpack(np.zeros(len(fit)))
        c0 = te_coefficients(model, base, direction)
        cx = np.empty((c0.size, len(fit)))
        for j in range(len(fit)):
            e = np.zeros(len(fit))
            e[j] = 1.0
            cx[:, j] = te_coefficients(model, unpack(e), direction) - c0
        return c0, cx

    te_maps = [te_map(r.direction) for r in te_rows]

    def blocks(x):
        p = unpack(x)
        out = {}
        if hysteresis is not None:
            out["hysteresis"] = hysteresis_angle(model, p, hysteresis.torque, direction) - (
                hysteresis.angle
            )
        if te_rows:  # the TE coefficients are linear in the parameters: c = c0 + C x
            out["te"] = np.concatenate([r.r @ (c0 + cx @ x - r.c_hat) for r, (c0, cx) in
                                        zip(te_rows, te_maps, strict=True)])  # fmt: skip
        return out

    weights = dict.fromkeys(("hysteresis", "te"), 1.0 / arcsec_to_rad(1.0))

    def fun(x):
        return np.concatenate([weights[k] * v for k, v in blocks(x).items()])

    def jac(x):
        """Analytic Jacobian of ``fun`` in the scaled parameters (hysteresis: the model's
        derivatives; TE: its linear map)."""
        rows = []
        if hysteresis is not None:
            d = hysteresis_jacobian(model, unpack(x), hysteresis.torque, direction)
            w = np.asarray(weights["hysteresis"])
            block = np.zeros((hysteresis.torque.size, len(fit)))
            for j, nm in enumerate(fit):
                if nm in d:
                    block[:, j] = d[nm] * scale[j]
            rows.append(block * (w[:, None] if w.ndim else w))
        if te_rows:
            te_j = [r.r @ cx for r, (_, cx) in zip(te_rows, te_maps, strict=True)]
            rows.append(weights["te"] * np.vstack(te_j))
        return np.vstack(rows)

    res = least_squares(
        fun, x0, bounds=(lo, hi), method="trf", x_scale=1.0, jac=jac, tr_solver="lsmr"
    )
    counts = {"hysteresis": 0 if hysteresis is None else hysteresis.torque.size,
              "te": sum(r.samples for r in te_rows)}  # fmt: skip
    rss0 = {"hysteresis": 0.0, "te": sum(r.rss0 for r in te_rows)}

    def block_rms(b):
        return {k: float(np.sqrt((np.sum(v**2) + rss0[k]) / counts[k])) for k, v in b.items()}

    for k, v in block_rms(blocks(res.x)).items():  # reweight by each block's noise, refit
        weights[k] = 1.0 / max(v, 1e-15)
    if hysteresis is not None and torque_noise > 0:
        # effective variance: the torque reading's noise seen through the curve's local slope
        p1 = unpack(res.x)
        dt = min(0.1 * p1["play_transition_torque"], 1e-3 * model.rated_torque)
        slope = (
            hysteresis_angle(model, p1, hysteresis.torque + dt, direction)
            - hysteresis_angle(model, p1, hysteresis.torque - dt, direction)
        ) / (2 * dt)
        var_t = (slope * torque_noise * model.rated_torque) ** 2
        r2 = float(np.mean(blocks(res.x)["hysteresis"] ** 2))
        var_a = max(r2 - float(np.mean(var_t)), 0.0025 * r2)
        weights["hysteresis"] = 1.0 / np.sqrt(var_a + var_t)
    res = least_squares(
        fun, res.x, bounds=(lo, hi), method="trf", x_scale=1.0, jac=jac, tr_solver="lsmr"
    )
    nfev = res.nfev
    b = blocks(res.x)
    n = len(fit)
    jmat = np.array(res.jac, dtype=float)
    inflation = 1.0
    if hysteresis is not None:
        # residuals along the sweep that are correlated (a law the reduced model lacks) carry
        # less information than as many independent ones: the hysteresis rows count for
        # n_eff = n σ²/σ_LR² samples, σ_LR² the residuals' long-run variance
        rh = b["hysteresis"] * np.asarray(weights["hysteresis"])
        if rh.size > 8 and np.std(rh) > 0:
            inflation = _long_run_ratio(rh)
            jmat[: rh.size] /= np.sqrt(inflation)
    norms = np.linalg.norm(jmat, axis=0)
    norms = np.where(norms > 0, norms, 1.0)
    jn = jmat / norms
    # singular values/vectors of Jn from the small Gram matrix (LAPACK on the tall Jn is slow)
    ev, evec = np.linalg.eigh(jn.T @ jn)
    order = np.argsort(ev)[::-1]
    sv = np.sqrt(np.clip(ev[order], 0.0, None))
    vt = evec[:, order].T
    tol = sv[0] * 1e-6 if sv.size else 0.0  # Gram matrix: sqrt of eps-level eigenvalues
    rank = int(np.sum(sv > tol))
    condition = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    m_all = sum(counts[k] for k in b)
    chi2 = float(np.sum(res.fun**2)) + float(sum(np.mean(weights[k] ** 2) * rss0[k] for k in b))
    s2 = chi2 / max(m_all - rank, 1)
    inv = np.where(sv > tol, 1.0 / np.where(sv > tol, sv, 1.0) ** 2, 0.0)
    cov_n = s2 * (vt.T * inv) @ vt  # (JnᵀJn)⁺ on the identified subspace
    cov_x = cov_n / np.outer(norms, norms)
    cov = cov_x * np.outer(scale, scale)
    std_arr = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    flags: dict = {}
    groups: list = []
    # null space of J: P = V0 V0ᵀ is independent of the basis chosen within it; a parameter with
    # a share of P_ii is not identifiable, and two are confounded where P_ij != 0
    v0 = vt[rank:].T
    proj = v0 @ v0.T
    weak = [i for i in range(n) if proj[i, i] > 1e-2]
    seen: set = set()
    for i in weak:
        if i in seen:
            continue
        members = [j for j in weak if abs(proj[i, j]) > 1e-3]
        seen.update(members)
        group = tuple(fit[j] for j in members)
        groups.append(group)
        for nm in group:
            others = [o for o in group if o != nm]
            flags[nm] = (
                "not identifiable: the data see only its combination with " + ", ".join(others)
                if others
                else "not identifiable: no data depends on it"
            )
    std = {}
    ci = {}
    for i, nm in enumerate(fit):
        if nm in flags:
            std[nm] = ci[nm] = float("inf")
            continue
        std[nm] = float(std_arr[i])
        ci[nm] = Z95 * std[nm]
        rng = specs[nm].upper - specs[nm].lower
        xi = res.x[i]
        if ci[nm] > max_relative_ci * rng:
            flags[nm] = (
                f"poorly identified: 95 % interval ±{ci[nm]:.3g} {specs[nm].unit} exceeds "
                f"{max_relative_ci:g} of its range"
            )
        elif min(xi - lo[i], hi[i] - xi) < 1e-6 * (hi[i] - lo[i]):
            flags[nm] = "at a bound: interval not valid (the data push it past its range)"
    for nm in model.shape_parameters():  # nuisance: what the reduced law lacks, no property
        if nm in fit and nm not in flags:
            flags[nm] = SHAPE_NOTE
    d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    corr = cov / np.outer(d, d)
    # two identified parameters the data see almost only together: their split rests on the
    # reduced model's assumed laws (e.g. the reducer's stiffness and the rig's compliance, told
    # apart only by the curvature of the elastic law), so neither interval is trusted alone
    for a_, b_ in CONFOUNDED_PAIRS:
        if a_ in fit and b_ in fit:
            i, j = fit.index(a_), fit.index(b_)
            if a_ in flags or b_ in flags or abs(corr[i, j]) <= CONFOUNDED_CORRELATION:
                continue
            for x, y in ((a_, b_), (b_, a_)):
                flags[x] = (
                    f"confounded with {y} (correlation {corr[i, j]:+.4f}): only their combination "
                    "is determined; the split rests on the reduced model's laws (fix one from "
                    "another measurement)"
                )
            groups.append((a_, b_))
    by_definition = {}
    f_name = "contact_stiffness_factor"
    if (hysteresis is not None and "rig_compliance" in fixed and f_name in fit
            and f_name not in flags and hysteresis_noise(hysteresis) is not None):  # fmt: skip
        # f is DEFINED as the reducer's catalogue rigidity over K_nom: with the rig's compliance
        # known, read it by that definition (the reduced law's fit of the curve is not the
        # definition at the catalogue points: its bias exceeded its interval)
        value, se = catalogue_stiffness_factor(
            model, hysteresis, float(fixed["rig_compliance"]), torque_noise=torque_noise
        )
        i = fit.index(f_name)
        by_definition[f_name] = DefinitionEstimate(
            value=value, std=se, ci=Z95 * se, fit_value=float(res.x[i] * scale[i]),
            fit_ci=ci[f_name],
            note="by its definition: the catalogue rigidity of the curve less the given rig "
                 "compliance's twist, over K_nom; interval from the data's noise",
        )  # fmt: skip
    return CalibrationResult(
        model=model,
        params=unpack(res.x),
        fitted=fit,
        std=std,
        ci=ci,
        correlation=corr,
        covariance=cov,
        flags=flags,
        groups=groups,
        rank=rank,
        condition=condition,
        residual_rms=block_rms(b),
        residuals=_residuals(model, unpack(res.x), hysteresis, direction, traces),
        cost=float(res.cost),
        success=bool(res.success),
        message=f"{res.message} ({nfev} evaluations)",
        fixed=tuple(fixed),
        covariance_inflation=inflation,
        by_definition=by_definition,
    )


def hysteresis_noise(hysteresis: HysteresisCurve) -> float | None:
    """The angle noise of a hysteresis curve [rad], independent of any model.

    Along each run of the sweep (contiguous samples of one branch: torque rising or falling),
    sorted by torque, the angles are differenced twice; for independent errors of ``σ`` the
    second difference has variance ``6 σ²``, and the smooth curve adds almost nothing at a bench's
    sampling. The few second differences where the curve bends (the play, the turning points) are
    left out: those beyond 5 robust deviations (1.4826 MAD) of their median; ``σ² = mean(Δ²θ²)/6``
    of the others, pooled over the runs. (Runs are differenced apart: two runs over the same
    torques interleaved by sorting alternate between them, and their second differences carry the
    curve's slope times the step. The MAD alone is not the estimate: on angles quantised by an
    encoder it takes only multiples of half a count.)

    Parameters
    ----------
    hysteresis : HysteresisCurve
        The measured curve (torque [N·mm], angle [rad], branch marks or inferred).

    Returns
    -------
    float or None
        ``σ`` [rad]; None with fewer than 6 second differences.
    """
    direction = (
        hysteresis.branch if hysteresis.branch is not None else branch_directions(hysteresis.torque)
    )
    d = np.asarray(direction)
    edges = np.concatenate([[0], np.nonzero(np.diff(d))[0] + 1, [d.size]])
    parts = []
    for s, e in zip(edges[:-1], edges[1:], strict=True):
        if e - s >= 3:
            a = hysteresis.angle[s:e][np.argsort(hysteresis.torque[s:e], kind="stable")]
            parts.append(a[2:] - 2 * a[1:-1] + a[:-2])
    if sum(p.size for p in parts) < 6:
        return None
    d2 = np.concatenate(parts)
    dev = np.abs(d2 - np.median(d2))
    mad = 1.4826 * float(np.median(dev))
    keep = dev <= 5.0 * mad if mad > 0 else np.ones(d2.size, dtype=bool)
    return float(np.sqrt(np.mean(d2[keep] ** 2) / 6.0))


@dataclass(frozen=True)
class DefinitionEstimate:
    """A quantity estimated by its definition on the data rather than by the fit.

    Attributes
    ----------
    value, std, ci : float
        Estimate, standard error and 95 % half-width (gearte units of the parameter).
    fit_value, fit_ci : float
        The reduced model's fitted parameter and its 95 % half-width, for comparison.
    note : str
        How it was found.
    """

    value: float
    std: float
    ci: float
    fit_value: float
    fit_ci: float
    note: str


def catalogue_stiffness_factor(
    model: ReducedRV,
    hysteresis: HysteresisCurve,
    rig_compliance: float,
    *,
    torque_noise: float = 0.0,
    angle_noise: float | None = None,
) -> tuple[float, float]:
    """The contact-stiffness factor by its definition: the reducer's catalogue rigidity over
    ``K_nom``, read from the curve with the rig's twist removed.

    ``f = K_cat(θ − C_rig T) / K_nom``: the shared catalogue definition
    (:func:`gearte.models.catalogue.hysteresis_values`) on the measured torques and the angles
    less the given rig compliance's twist; its standard error from the data's noise by
    :func:`gearte.models.catalogue.torsional_rigidity_error` (the angle noise estimated by
    :func:`hysteresis_noise` unless given, the torque reading's from ``torque_noise``).

    Parameters
    ----------
    model : ReducedRV
        ``K_nom`` [N·mm/rad] and ``T_r`` [N·mm].
    hysteresis : HysteresisCurve
        The measured curve (torque [N·mm], angle [rad]).
    rig_compliance : float
        ``C_rig`` [rad/(N·mm)], known (a calibration shaft).
    torque_noise : float
        Standard deviation of the torque reading as a fraction of ``T_r`` [-].
    angle_noise : float, optional
        Standard deviation of the angle reading [rad] (default: :func:`hysteresis_noise`).

    Returns
    -------
    (float, float)
        ``f`` and its standard error [-].

    Raises
    ------
    ParameterError
        Too few samples to estimate the angle noise, and none given.
    """
    if not (np.isfinite(rig_compliance) and rig_compliance >= 0):
        raise ParameterError("rig_compliance", rig_compliance, "must be finite and >= 0")
    tr = model.rated_torque
    direction = (
        hysteresis.branch if hysteresis.branch is not None else branch_directions(hysteresis.torque)
    )
    angle = hysteresis.angle - rig_compliance * hysteresis.torque
    k = hysteresis_values(hysteresis.torque, angle, tr, direction=direction).torsional_rigidity
    sigma = hysteresis_noise(hysteresis) if angle_noise is None else angle_noise
    if sigma is None:
        raise ParameterError(
            "hysteresis", hysteresis.torque.size,
            "samples: too few to estimate the angle noise (give angle_noise)",
        )  # fmt: skip
    se = torsional_rigidity_error(
        hysteresis.torque, angle, tr, sigma, torque_std=torque_noise * tr,
        direction=direction,
    )  # fmt: skip
    return k / model.nominal_rigidity, se / model.nominal_rigidity


LONG_RUN_BANDWIDTH = 0.05
"""Bartlett bandwidth of :func:`_long_run_ratio` as a fraction of the samples [-]."""


def _long_run_ratio(r: np.ndarray) -> float:
    """Long-run variance of a residual series over its variance (Bartlett / Newey–West window
    of ``LONG_RUN_BANDWIDTH`` × n lags), at least 1: how many times fewer independent samples
    correlated residuals are worth."""
    x = r - r.mean()
    n = x.size
    var = float(x @ x) / n
    lags = max(1, int(LONG_RUN_BANDWIDTH * n))
    acc = var
    for k in range(1, min(lags, n - 1) + 1):
        acc += 2.0 * (1.0 - k / (lags + 1)) * float(x[k:] @ x[:-k]) / n
    return max(acc / var, 1.0) if var > 0 else 1.0


def _residuals(model, p, hysteresis, direction, traces) -> dict:
    """Measured minus model [rad]: hysteresis per sample, TE per trace and direction."""
    out = {}
    if hysteresis is not None:
        out["hysteresis"] = hysteresis.angle - hysteresis_angle(
            model, p, hysteresis.torque, direction
        )
    for k, tr in enumerate(traces):
        for d, (pos, te) in tr.directions().items():
            out[f"te {k} {d}"] = te - te_trace(model, p, pos, 1 if d == "forward" else -1)
    return out


# ---- synthetic benches --------------------------------------------------------------------
def synthetic_bench(
    model: ReducedRV,
    params: dict,
    rng: np.random.Generator,
    *,
    samples_per_revolution: int = 4096,
    hysteresis_points: int = 400,
    angle_noise: float = arcsec_to_rad(0.3),
    torque_noise: float = 2e-4,
    encoder_counts: int = 2**21,
    speed_rpm: float = 15.0,
    oil_temperature: float = 40.0,
    serial: str = "synthetic",
) -> tuple[HysteresisCurve, TETrace]:
    """Bench data of a serial with known parameters: hysteresis sweep and one TE trace.

    The hysteresis sweep runs ``0 → +T_r → −T_r → +T_r`` (``hysteresis_points`` per half
    branch); the torque reading has Gaussian noise of ``torque_noise`` × ``T_r``, the angles
    Gaussian noise ``angle_noise`` [rad] and are quantised to the encoder's ``encoder_counts``
    per revolution (TE: both encoders). The TE trace spans one output revolution forward and
    backward with ``samples_per_revolution`` samples each.

    Parameters
    ----------
    model : ReducedRV
        The reduced model.
    params : dict
        Its parameters (:func:`gearte.models.bench_reduced.parameter_names`), gearte units.
    rng : numpy.random.Generator
        Source of the noise.
    samples_per_revolution : int
        TE samples per revolution and direction [-].
    hysteresis_points : int
        Samples per half branch of the sweep [-].
    angle_noise : float
        Standard deviation of the angle readings [rad].
    torque_noise : float
        Standard deviation of the torque reading as a fraction of T_r [-].
    encoder_counts : int
        Encoder counts per revolution [-].
    speed_rpm : float
        Output speed written with the trace [rpm] (not modelled).
    oil_temperature : float
        Oil temperature written with the trace [°C] (not modelled).
    serial : str
        Serial number written with the data.

    Returns
    -------
    (HysteresisCurve, TETrace)
        The synthetic bench data.
    """
    tr = model.rated_torque
    h = hysteresis_points
    t_true = np.concatenate([
        np.linspace(0.0, tr, h, endpoint=False),
        np.linspace(tr, -tr, 2 * h, endpoint=False),
        np.linspace(-tr, tr, 2 * h + 1),
    ])  # fmt: skip
    direction = np.concatenate([np.ones(h), -np.ones(2 * h), np.ones(2 * h + 1)]).astype(np.int64)
    q = 2 * np.pi / encoder_counts
    angle = hysteresis_angle(model, params, t_true, direction)
    angle = q * np.round((angle + rng.normal(0.0, angle_noise, angle.size)) / q)
    torque = t_true + rng.normal(0.0, torque_noise * tr, t_true.size)
    hyst = HysteresisCurve("synthetic", torque, angle, direction, serial=serial)
    n = samples_per_revolution
    pos_f = 2 * np.pi * np.arange(n) / n
    pos_b = pos_f[::-1].copy()

    def measured(pos, d):
        te = te_trace(model, params, pos, d) + rng.normal(0.0, angle_noise, pos.size)
        return q * np.round(te / q)

    trace = TETrace(
        "synthetic", pos_f, measured(pos_f, 1), pos_b, measured(pos_b, -1),
        speed_rpm=speed_rpm, torque=0.0, oil_temperature=oil_temperature, serial=serial,
    )  # fmt: skip
    return hyst, trace


def reduced_constants(reducer, families: dict[str, int], *, clearance: float = 0.005) -> ReducedRV:
    """The reduced model's constants of a whole RV reducer, from its own virtual tests.

    ``K_nom`` is the catalogue rigidity of the reducer as described (its clearances included);
    ``g_cam``, ``g_car`` [rad/mm] are the backlash added per mm of radial clearance of the cam
    and carrier crank bearings, by finite difference of the virtual backlash with ``clearance``
    [mm] added to each in turn; ``B0`` is the design's own backlash and ``c0`` its clearances
    (the reduced play is linearised about them).

    Parameters
    ----------
    reducer : RVReducer
        The reducer type as described.
    families : dict
        Error family name → its order per output revolution [-].
    clearance : float
        Clearance step of the finite difference [mm].

    Returns
    -------
    ReducedRV
        ``K_nom`` [N·mm/rad], ``(g_cam, g_car)`` [rad/mm] and the families.
    """
    from gearte.models.rv_catalogue import backlash, catalogue_values

    base = backlash(reducer)
    k_nom = catalogue_values(reducer, steps_per_segment=2).torsional_rigidity
    c = reducer.cranks
    g = []
    for name in ("cam_bearing_clearance", "carrier_bearing_clearance"):
        changed = reducer.replace(
            cranks=type(c)(**{**c.__dict__, name: getattr(c, name) + clearance})
        )
        g.append((backlash(changed) - base) / clearance)
    return ReducedRV(
        rated_torque=reducer.rated_torque,
        nominal_rigidity=k_nom,
        backlash_per_clearance=(g[0], g[1]),
        families=dict(families),
        design_backlash=base,
        design_clearances=(c.cam_bearing_clearance, c.carrier_bearing_clearance),
    )


# ---- closing the loop: the calibrated serial through the whole model ------------------------
def serial_reducer(reducer, stiffness_scale: float, clearances: tuple[float, float]):
    """The reducer with every stiffness of its load path scaled and the crank-bearing clearances
    set.

    Parameters
    ----------
    reducer : RVReducer
        The design.
    stiffness_scale : float
        Factor on the cam and carrier bearing stiffnesses, the carrier support stiffness, the
        involute mesh stiffness, the Young's modulus of discs and pins and every element of the
        stiffness chain (crank bending and torsion, pin seat and bending, output flange) [-]
        (1: the design).
    clearances : (float, float)
        Radial clearance of the cam and carrier crank bearings [mm].

    Returns
    -------
    RVReducer
    """
    if not (np.isfinite(stiffness_scale) and stiffness_scale > 0):
        raise ParameterError("stiffness_scale", stiffness_scale, "must be > 0")
    s = float(stiffness_scale)
    c, d, sup, fs = reducer.cranks, reducer.discs, reducer.supports, reducer.first_stage
    p = reducer.pins

    def soft(compliance):  # a compliance (or per-disc tuple) of the stiffness chain, scaled
        if compliance is None:
            return None
        if isinstance(compliance, tuple):
            return tuple(x / s for x in compliance)
        return compliance / s

    def stiff(k):
        return None if k is None else s * k

    return reducer.replace(
        cranks=type(c)(**{**c.__dict__,
                          "cam_bearing_stiffness": s * c.cam_bearing_stiffness,
                          "carrier_bearing_stiffness": s * c.carrier_bearing_stiffness,
                          "cam_bearing_clearance": float(clearances[0]),
                          "carrier_bearing_clearance": float(clearances[1]),
                          "bending_compliance": soft(c.bending_compliance),
                          "torsional_stiffness": stiff(c.torsional_stiffness)}),
        pins=type(p)(**{**p.__dict__,
                        "seat_compliance": soft(p.seat_compliance),
                        "bending_compliance": soft(p.bending_compliance)}),
        discs=type(d)(**{**d.__dict__, "youngs_modulus": s * d.youngs_modulus}),
        supports=type(sup)(**{**sup.__dict__,
                              "carrier_radial_stiffness": s * sup.carrier_radial_stiffness,
                              "output_torsional_stiffness": stiff(sup.output_torsional_stiffness)}),
        first_stage=type(fs)(**{**fs.__dict__, "mesh_stiffness": s * fs.mesh_stiffness}),
    )  # fmt: skip


@dataclass
class ClosedLoop:
    """Outcome of :func:`close_loop`.

    Attributes
    ----------
    stiffness_scale : float
        Factor on every stiffness of the load path [-] (:func:`serial_reducer`).
    clearances : (float, float)
        Cam and carrier crank-bearing clearances [mm].
    values : CatalogueValues
        The whole model's catalogue numbers of the serial (reducer alone).
    iterations : int
    converged : bool
    notes : list of str
        What could not be matched, and why.
    """

    stiffness_scale: float
    clearances: tuple[float, float]
    values: Any
    iterations: int
    converged: bool
    notes: list = field(default_factory=list)


def close_loop(
    reducer,
    rigidity: float,
    backlash: float,
    *,
    start_clearances: tuple[float, float] = (0.0, 0.0),
    lost_motion_fraction: float = 0.03,
    rtol: float = 2e-3,
    max_iter: int = 12,
) -> ClosedLoop:
    """Stiffness scale and clearances with which the whole model gives a rigidity and backlash.

    Fixed-point iteration on the whole model's virtual test
    (:func:`gearte.models.rv_catalogue.catalogue_values`): the stiffness scale by the ratio of
    rigidities, both clearances shifted by the backlash gap over ``g_cam + g_car`` (their
    difference kept, as the bench sees only their play).

    Parameters
    ----------
    reducer : RVReducer
        The design.
    rigidity : float
        Target catalogue rigidity of the reducer alone [N·mm/rad].
    backlash : float
        Target backlash [rad].
    start_clearances : (float, float)
        Starting clearances [mm] (their difference is kept).
    lost_motion_fraction : float
        ``f`` of the lost-motion definition [-].
    rtol : float
        Relative tolerance on rigidity and backlash [-].
    max_iter : int
        Largest number of whole-model evaluations [-].

    Returns
    -------
    ClosedLoop
        A clearance that would have to be negative is held at 0 and said so in ``notes``.
    """
    from gearte.models.rv_catalogue import catalogue_values

    if not (rigidity > 0 and np.isfinite(rigidity)):
        raise ParameterError("rigidity", rigidity, "must be a finite value > 0 N·mm/rad")
    if not (backlash >= 0 and np.isfinite(backlash)):
        raise ParameterError("backlash", backlash, "must be a finite value >= 0 rad")
    scale = 1.0
    cl = np.maximum(np.asarray(start_clearances, dtype=float), 0.0)
    notes: list[str] = []
    g = None
    prev = None
    converged = False
    it = 0
    for it in range(1, max_iter + 1):  # noqa: B007 - the count is returned
        cv = catalogue_values(
            serial_reducer(reducer, scale, (cl[0], cl[1])), steps_per_segment=4,
            lost_motion_fraction=lost_motion_fraction,
        )  # fmt: skip
        ok_k = abs(cv.torsional_rigidity / rigidity - 1.0) <= rtol
        ok_b = abs(cv.backlash - backlash) <= rtol * max(backlash, 1e-9)
        if ok_k and ok_b:
            converged = True
            break
        if prev is not None and abs(np.sum(cl - prev[0])) > 0:
            g = (cv.backlash - prev[1]) / float(np.mean(cl - prev[0]))
        if g is None or not (g > 0):
            g = 2.0 * 0.047  # rad per mm of both clearances: a first guess, refined above
        prev = (cl.copy(), cv.backlash)
        scale *= rigidity / cv.torsional_rigidity
        shift = (backlash - cv.backlash) / g
        new = cl + shift
        if np.any(new < 0):
            new = np.maximum(new, 0.0)
            if np.all(cl <= 0):
                notes.append(
                    "the bench's backlash is below the design's backlash without crank-bearing "
                    "clearance: the play sits in another part (pins, profile modifications); "
                    "clearances written 0, backlash not reproduced"
                )
                cv = catalogue_values(
                    serial_reducer(reducer, scale, (0.0, 0.0)), steps_per_segment=4,
                    lost_motion_fraction=lost_motion_fraction,
                )  # fmt: skip
                break
        cl = new
    return ClosedLoop(scale, (float(cl[0]), float(cl[1])), cv, it, converged, notes)


def synthetic_full_model_hysteresis(
    reducer,
    rng: np.random.Generator,
    *,
    friction_torque: float = 0.0,
    rig_compliance: float = 0.0,
    steps_per_segment: int = 120,
    angle_noise: float = arcsec_to_rad(0.3),
    torque_noise: float = 2e-4,
    encoder_counts: int = 2**21,
    serial: str = "synthetic full model",
) -> HysteresisCurve:
    """A bench hysteresis curve from the WHOLE model of a serial (not the reduced one).

    The sweep ``0 → +T_r → −T_r → +T_r``; the elements see the measured torque less a Coulomb
    friction torque opposing the twist (``T − s T_fr``, s = +1 rising); the rig adds
    ``C_rig T``; Gaussian angle and torque-reading noise and encoder quantisation as in
    :func:`synthetic_bench`.

    Parameters
    ----------
    reducer : RVReducer
        The serial (e.g. :func:`serial_reducer` of a design).
    rng : numpy.random.Generator
        Source of the noise.
    friction_torque : float
        ``T_fr`` [N·mm].
    rig_compliance : float
        ``C_rig`` [rad/(N·mm)].
    steps_per_segment : int
        Samples per quarter sweep [-].
    angle_noise : float
        Standard deviation of the angle readings [rad].
    torque_noise : float
        Standard deviation of the torque reading as a fraction of T_r [-].
    encoder_counts : int
        Encoder counts per revolution [-].
    serial : str
        Serial number written with the data.

    Returns
    -------
    HysteresisCurve
        Measured torque [N·mm], angle [rad], branch marks.
    """
    from gearte.models.rv_catalogue import torque_path, torsion_angles

    tr = reducer.rated_torque
    t_true = torque_path((0.0, 1.0, 0.0, -1.0, 0.0, 1.0), steps_per_segment) * tr
    d = np.sign(np.diff(t_true, prepend=t_true[0] - 1.0)).astype(np.int64)
    d[d == 0] = 1
    t_eff = t_true - d * friction_torque
    t_eff = np.where(t_eff == 0.0, -d * 1e-4 * tr, t_eff)
    q = 2 * np.pi / encoder_counts
    angle = torsion_angles(reducer, t_eff) + rig_compliance * t_true
    angle = q * np.round((angle + rng.normal(0.0, angle_noise, angle.size)) / q)
    torque = t_true + rng.normal(0.0, torque_noise * tr, t_true.size)
    return HysteresisCurve(serial, torque, angle, d, serial=serial)
