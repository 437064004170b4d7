"""Diagnosis of one serial: which parts most likely cause its TE and its lost motion.

Reads a :class:`gearte.runners.bench_calibration.CalibrationResult`: each TE error family is a
harmonic at its characteristic order (:mod:`gearte.models.orders`), each lost-motion contributor
a term of the reduced hysteresis model (:mod:`gearte.models.bench_reduced`). The candidates are
ranked by their contribution, and the confidence of each is the probability that it is the
largest, from parameter draws of the calibration's Gaussian (estimate, covariance). Candidates
that the data cannot tell apart — families at the same order (the reducer's output eccentricity
and the encoder's), parameters in one null direction of the Jacobian, or strongly correlated
ones — are merged and the merge is stated.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearte.models.bench_reduced import STIFFNESS_EXPONENT
from gearte.runners.bench_calibration import CalibrationResult, hysteresis_play
from gearte.units import rad_to_arcsec

__all__ = ["FAMILY_PARTS", "Diagnosis", "diagnose"]

FAMILY_PARTS = {
    "output rotation": "output side: main bearings, carrier crank-bore position errors",
    "input rotation": "input shaft / sun eccentricity",
    "crank rotation": "crankshafts: cam eccentricity, disc crank-bores, planet eccentricity, "
    "crank bearings",
    "2× crank rotation": "crankshafts: cam/bore ovality, phase errors between the two cams",
    "involute mesh": "first stage: sun/planet tooth profile and pitch",
    "cycloid mesh": "cycloid discs / pins: profile and pitch",
    "cycloid lobes": "cycloid discs: lobe-to-lobe profile or pitch errors (z_c lobes)",
    "encoder eccentricity": "rig: output encoder eccentricity or mounting",
}
"""Error family (source name of its order) → the parts it points to."""


@dataclass
class Diagnosis:
    """Ranked candidates for TE and lost motion, with their confidence.

    Each ranking is a list of dicts ``{"source", "parts", "contribution" [rad],
    "contribution_ci" [rad] (95 % half-width), "probability_largest", "indistinguishable"}``,
    most likely first; ``statements`` summarises in words.
    """

    te: list[dict] = field(default_factory=list)
    lost_motion: list[dict] = field(default_factory=list)
    statements: list[str] = field(default_factory=list)


def _draws(cal: CalibrationResult, n: int, seed: int) -> dict:
    """Parameter draws as a dict of arrays (fitted) and scalars (held fixed)."""
    rng = np.random.default_rng(seed)
    mean = np.array([cal.params[k] for k in cal.fitted])
    cov = np.nan_to_num(cal.covariance, nan=0.0, posinf=0.0, neginf=0.0)
    x = rng.multivariate_normal(mean, cov, size=n, method="eigh")
    p = dict(cal.params)
    p.update({k: x[:, i] for i, k in enumerate(cal.fitted)})
    return p


def _rank(cands: list[dict], samples: np.ndarray) -> list[dict]:
    """Attach the 95 % spread and P(largest) from ``samples`` (draws × candidates), sort."""
    if not cands:
        return []
    largest = np.argmax(samples, axis=1)
    for j, c in enumerate(cands):
        c["probability_largest"] = float(np.mean(largest == j))
        c["contribution_ci"] = float(
            0.5 * (np.percentile(samples[:, j], 97.5) - np.percentile(samples[:, j], 2.5))
        )
    return sorted(cands, key=lambda c: (-c["contribution"], -c["probability_largest"]))


def _te_candidates(cal: CalibrationResult):
    model = cal.model
    by_order: dict[int, list[str]] = {}
    for fam, n in (*model.families.items(), ("encoder eccentricity", 1)):
        by_order.setdefault(int(n), []).append(fam)
    groups = []
    for n, fams in by_order.items():
        keys = [f.replace(" ", "_") for f in fams]
        live = [
            (f, k) for f, k in zip(fams, keys, strict=True)
            if f"{k}_cos" in cal.fitted or cal.params[f"{k}_cos"] or cal.params[f"{k}_sin"]
        ]  # fmt: skip
        if not live:
            continue
        groups.append((n, [f for f, _ in live], [k for _, k in live]))

    def amp(p, keys):
        return np.hypot(sum(p[f"{k}_cos"] for k in keys), sum(p[f"{k}_sin"] for k in keys))

    return groups, amp


def diagnose(
    cal: CalibrationResult,
    spectrum: list[dict] | None = None,
    *,
    lost_motion_fraction: float = 0.03,
    draws: int = 2000,
    seed: int = 0,
    correlation_limit: float = 0.95,
    unexplained_limit: float | None = None,
) -> Diagnosis:
    """Rank the error families behind the TE and the contributors to the lost motion.

    Parameters
    ----------
    cal : CalibrationResult
    spectrum : list of dict, optional
        Labelled orders of the measured TE (:func:`gearte.models.orders.labelled_orders`, amplitude
        [rad]); strong lines no family explains are reported.
    lost_motion_fraction : float
        ``f`` of the lost-motion definition [-].
    draws, seed : int
        Parameter draws for the confidences (seeded: the same serial gives the same answer).
    correlation_limit : float
        Two lost-motion contributors whose parameters correlate beyond this are merged [-].
    unexplained_limit : float, optional
        Amplitude [rad] from which a line of ``spectrum`` that no source explains is stated
        (e.g. a share of the trace's peak-to-peak, :func:`gearte.models.orders.unexplained_lines`);
        without it no such statement is made.

    Notes
    -----
    Data only: a ranking is made only from the data that can decide it. Without a hysteresis
    curve no lost-motion culprit is named (the TE traces see the play only together with the
    running wind-up), without a TE trace no TE culprit; the statements say which file would
    decide it. A candidate whose parameters were neither fitted nor held at a measured value
    (``cal.fixed``) is left out.

    Returns
    -------
    Diagnosis
        TE candidates: amplitude of each order's harmonic [rad] (its peak-to-peak share is twice
        that); lost-motion candidates: their part of ``θ_mid(+f T_r) − θ_mid(−f T_r)`` [rad].
    """
    model = cal.model
    sample = _draws(cal, draws, seed)
    diag = Diagnosis()
    has_hyst = "hysteresis" in cal.residuals
    has_te = any(k.startswith("te ") for k in cal.residuals)
    known = set(cal.fitted) | set(cal.fixed)

    # --- TE: one candidate per distinct order (families sharing it cannot be told apart)
    groups, amp = _te_candidates(cal) if has_te else ([], None)
    groups = [g for g in groups if all(f"{k}_cos" in known for k in g[2])]
    te_c = []
    for n, fams, keys in groups:
        te_c.append({
            "source": " or ".join(fams),
            "order": n,
            "parts": "; ".join(FAMILY_PARTS.get(f, f) for f in fams),
            "contribution": float(amp(cal.params, keys)),
            "indistinguishable": fams if len(fams) > 1 else [],
        })  # fmt: skip
    if te_c:
        s = np.column_stack([np.broadcast_to(amp(sample, keys), (draws,))
                             for _, _, keys in groups])  # fmt: skip
        diag.te = _rank(te_c, s)

    # --- lost motion: play, reducer elasticity, rig compliance
    tr = model.rated_torque
    f = lost_motion_fraction
    cp = 0.5 / (1.0 - 0.5**STIFFNESS_EXPONENT)

    def elastic(p):
        return (
            2.0
            * tr
            * cp
            * f**STIFFNESS_EXPONENT
            / (p["contact_stiffness_factor"] * model.nominal_rigidity)
        )

    def rig(p):
        return 2.0 * f * tr * p["rig_compliance"]

    terms = {
        "bearing clearances": (hysteresis_play, ["cam_bearing_clearance",
                                                 "carrier_bearing_clearance"]),
        "reducer contact stiffness": (lambda m, p: elastic(p), ["contact_stiffness_factor"]),
        "rig compliance": (lambda m, p: rig(p), ["rig_compliance"]),
    }  # fmt: skip
    parts = {
        "bearing clearances": "radial clearance of the cam (crank–disc) and carrier crank bearings",
        "reducer contact stiffness": "pin–disc contacts and bearings softer than designed",
        "rig compliance": "rig: shafts, couplings, encoder mount (not the reducer)",
    }
    if not has_hyst:
        diag.statements.append(
            "lost motion: no culprit named — without a hysteresis curve the data cannot separate "
            "the play (bearing clearances), the reducer's contact stiffness and the rig's "
            "compliance; a hysteresis file (output torque against torsion angle, input locked: "
            "[data] hysteresis) would decide it"
        )
    elif any(k in cal.fitted for _, ks in terms.values() for k in ks):
        terms = {n: v for n, v in terms.items() if all(k in known for k in v[1])}
        names = list(terms)
        merged: list[list[str]] = [[n] for n in names]
        fitted = list(cal.fitted)
        a, b = "contact_stiffness_factor", "rig_compliance"
        if a in fitted and b in fitted:
            ia, ib = fitted.index(a), fitted.index(b)
            if a in cal.flags or b in cal.flags or abs(cal.correlation[ia, ib]) > correlation_limit:
                merged = [["bearing clearances"], ["reducer contact stiffness", "rig compliance"]]
        lm_c = []
        funcs = []
        for grp in merged:
            fns = [terms[g][0] for g in grp]

            def total(p, fns=fns):
                return sum(fn(model, p) for fn in fns)

            note = []
            if grp == ["bearing clearances"] and (
                "cam_bearing_clearance" in cal.flags or "carrier_bearing_clearance" in cal.flags
            ):
                note = ["cam bearing clearance", "carrier bearing clearance"]
            if len(grp) > 1:
                note = grp
            lm_c.append({
                "source": " or ".join(grp),
                "parts": "; ".join(parts[g] for g in grp),
                "contribution": float(total(cal.params)),
                "indistinguishable": note,
            })  # fmt: skip
            funcs.append(total)
        s = np.column_stack([np.broadcast_to(fn(sample), (draws,)) for fn in funcs])
        diag.lost_motion = _rank(lm_c, s)

    # --- statements
    for title, ranking in (("TE", diag.te), ("lost motion", diag.lost_motion)):
        if not ranking:
            continue
        top = ranking[0]
        what = f"{top['source']}" + (f" (order {top['order']})" if "order" in top else "")
        diag.statements.append(
            f"{title}: most likely {what} — {top['parts']}; probability it is the largest "
            f"contributor {top['probability_largest']:.2f}"
        )
        for c in ranking:
            if c["indistinguishable"]:
                diag.statements.append(
                    f"{title}: the data cannot tell apart {' and '.join(c['indistinguishable'])}"
                    + (" (same order)" if "order" in c else "")
                )
    if not has_te:
        diag.statements.append(
            "TE: no culprit named — no TE trace; a TE file (forward/backward over one output "
            "revolution: [data] te) would decide it"
        )
    if spectrum and unexplained_limit is not None:
        for line in spectrum:
            if line["source"] == "unidentified" and line["amplitude"] >= unexplained_limit:
                diag.statements.append(
                    f"TE: order {line['order']} carries {rad_to_arcsec(line['amplitude']):.3g}″ "
                    f"(limit {rad_to_arcsec(unexplained_limit):.3g}″) and matches no order of "
                    "this drive's tooth numbers (the rig, or a part not modelled)"
                )
    return diag
