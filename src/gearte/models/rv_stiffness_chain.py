"""The RV reducer's stiffness chain: each element's share of the output torsional compliance.

The quasi-static model (:mod:`gearte.models.rv_load_sharing`) holds every element of the load
path as a spring row or a contact row; the elements the chain adds are in series with them:

* pin seat and pin bending: a linear compliance in series with each pin–disc contact
  (:func:`gearte.models.rv_load_sharing.pin_series_compliance`, added to the contact law, so it
  changes the load sharing);
* crank bending at each cam: in series with that cam's needle bearing
  (:func:`gearte.models.rv_load_sharing.cam_row_stiffness`);
* crank torsion between planet and cams: in series with the sun–planet mesh
  (:func:`gearte.models.rv_load_sharing.mesh_row_stiffness`);
* the output flange: in series with the carrier's rotation (a torsional spring added to the
  output angle of the virtual torsion test).

At a torque ``T`` the model is linearised at its equilibrium: every row gets its tangent
stiffness (a pin contact ``dF/dδ`` of its law plus its series compliance; a bearing with
clearance the tangent of ``k (|w| − c)₊``), ``K_t = Σ_e K_e``. The tangent output compliance is
``C = uᵀ K_t⁻¹ u`` (``u``: the generalised force of a unit output torque) and, with
``δq = K_t⁻¹ u``, ``C = Σ_e δqᵀ K_e δq``: each element's term is its share of the compliance
(its share of the strain energy of a torque increment), and the shares sum to 1 exactly. A row
made of parts in series (contact + seat + bending) splits its term in proportion to the parts'
compliances (they carry the same force increment).
"""

from __future__ import annotations

import numpy as np

from gearte.errors import ParameterError
from gearte.geometry.rv import RVReducer
from gearte.models.rv_load_sharing import (
    PinContactLaw,
    assemble,
    contact_law,
    contact_phase,
    load_sharing,
    pin_series_compliance,
)
from gearte.models.rv_records import StiffnessChain
from gearte.solvers.rv_equilibrium import CLEARANCE_RESIDUAL

__all__ = ["ELEMENTS", "StiffnessChain", "stiffness_chain", "left_out_elements"]

#: The elements of the chain, in the order of the power flow from the output back to the input.
ELEMENTS = (
    "output_flange",
    "main_bearing",
    "carrier_bearing",
    "crank_bending",
    "cam_bearing",
    "pin_contact",
    "pin_seat",
    "pin_bending",
    "crank_torsion",
    "first_stage_mesh",
    "sun_support",
)


def left_out_elements(reducer: RVReducer) -> tuple[str, ...]:
    """The chain elements ``reducer`` leaves out (rigid), in :data:`ELEMENTS` order."""
    missing = {
        "output_flange": reducer.supports.output_torsional_stiffness is None,
        "crank_bending": reducer.cranks.bending_compliance is None,
        "pin_seat": reducer.pins.seat_compliance is None,
        "pin_bending": reducer.pins.bending_compliance is None,
        "crank_torsion": reducer.cranks.torsional_stiffness is None,
    }
    return tuple(e for e in ELEMENTS if missing.get(e, False))


def _pair_tangent(w: np.ndarray, k: float, c: float) -> np.ndarray:
    """2×2 tangent stiffness of an isotropic bearing ``k (|w| − c)₊ w/|w|`` [N/mm]
    (with the residual ``CLEARANCE_RESIDUAL k`` the solver keeps inside the clearance)."""
    n = float(np.hypot(w[0], w[1]))
    eps = CLEARANCE_RESIDUAL
    if c <= 0.0:
        return k * np.eye(2)
    if n <= c:
        return eps * k * np.eye(2)
    e = w / n
    radial = np.outer(e, e)
    # f = [eps k + (1 - eps) k (n - c)/n] w
    s = eps * k + (1.0 - eps) * k * (n - c) / n
    return s * np.eye(2) + (1.0 - eps) * k * c / n * radial


def stiffness_chain(
    reducer: RVReducer,
    torque: float | None = None,
    *,
    theta: float = 0.0,
    law: PinContactLaw | None = None,
) -> StiffnessChain:
    """Each element's share of the output torsional compliance at ``torque``.

    Parameters
    ----------
    reducer : RVReducer
        The reducer with its stiffness chain (:mod:`gearte.geometry.rv`).
    torque : float, optional
        Output torque [N·mm] (> 0); default the rated torque.
    theta : float
        Output angle [rad].
    law : PinContactLaw, optional
        Pin-contact law; default the reducer's own.

    Returns
    -------
    StiffnessChain
        Compliance per element [rad/(N·mm)] and the elements left out.

    Raises
    ------
    ParameterError
        No torque and no rated torque (``reducer.rated_torque_Nm``), or a pin force beyond the
        range where its law's tangent is positive.

    Notes
    -----
    The pin-contact term uses each loaded contact's own tangent ``dδ/dF = a0 − a1 (ln F + 1)``
    of its law ``δ = F (a0 − a1 ln F)`` (:func:`gearte.models.contact_law.log_law_coefficients`)
    at the solved force; with the per-contact secant scheme (``line_contact``) the solved forces
    satisfy that law exactly and ``C`` is the derivative of the model's output angle (tested
    against a finite difference), with the per-disc scheme (``hu2020``) it is the law's own
    tangent at the forces of that scheme.
    """
    if torque is None:
        if reducer.rated_torque is None:
            raise ParameterError(
                "reducer.rated_torque_Nm", None, "needed for the stiffness chain at rated torque"
            )
        torque = float(reducer.rated_torque)
    if not np.isfinite(torque) or torque <= 0.0:
        raise ParameterError("torque", torque, "must be finite and > 0 N·mm")
    law = contact_law(reducer) if law is None else law
    system = assemble(reducer, np.array([float(theta)]))
    ls = load_sharing(reducer, torque, law=law, system=system)
    q = ls.q[0]
    nd = q.size
    B = system.spring_B[0]
    e = system.spring_e[0]
    k = system.spring_k
    c = np.zeros_like(k) if system.spring_c is None else system.spring_c
    w = B @ q + e

    # tangent stiffness of every row (pairs of isotropic bearings as 2x2 blocks)
    blocks: list[tuple[str, np.ndarray, np.ndarray]] = []  # (label, rows B, tangent matrix)
    for label, sl in system.labels.items():
        rows = np.arange(sl.start, sl.stop)
        if label == "mesh":
            for r in rows:
                blocks.append((label, B[r : r + 1], np.array([[k[r]]])))
            continue
        for r in rows[::2]:  # x and y rows of one isotropic bearing
            kt = _pair_tangent(w[r : r + 2], float(k[r]), float(c[r]))
            blocks.append((label, B[r : r + 2], kt))

    # pin contacts: tangent of the law + the series compliance
    force = ls.pin_force[0].reshape(-1)
    active = force > 0.0
    group = system.contact_group
    series = pin_series_compliance(reducer)[group]
    if law.name == "linear":
        law_c = np.full(force.shape, 1.0 / law.stiffness)
    else:
        # dδ/dF of δ = F (a0 − a1 ln F) + a2 F^a3 (every law's form, contact_law.law_coefficients)
        a0, a1, a2, a3 = law.law_coefficients(contact_phase(system)[0])
        f_safe = np.where(active, force, 1.0)
        with np.errstate(divide="ignore"):
            law_c = a0 - a1 * (np.log(f_safe) + 1.0) + a2 * a3 * f_safe ** (a3 - 1.0)
        if np.any(law_c[active] <= 0.0):
            raise ParameterError(
                "torque",
                torque,
                "drives a pin force beyond the range where its contact law stiffens with load",
            )
    kc = np.where(active, 1.0 / (law_c + series), 0.0)
    Bc = system.contact_B[0]

    K = np.zeros((nd, nd))
    for _, Br, Kt in blocks:
        K += Br.T @ Kt @ Br
    K += (Bc * kc[:, None]).T @ Bc
    u = system.unit_load
    dq = np.linalg.solve(K, u)

    terms: dict[str, float] = dict.fromkeys(ELEMENTS, 0.0)
    cam_series = _cam_split(reducer)
    mesh_split = _mesh_split(reducer)
    M, N = reducer.cranks.count, reducer.discs.count
    cam_idx = 0
    for label, Br, Kt in blocks:
        dw = Br @ dq
        energy = float(dw @ Kt @ dw)
        if label == "cam_bearing":
            j = cam_idx % N  # cam rows: crank by crank, then disc by disc
            cam_idx += 1
            bearing_part = cam_series[j]
            terms["cam_bearing"] += energy * bearing_part
            terms["crank_bending"] += energy * (1.0 - bearing_part)
        elif label == "mesh":
            terms["first_stage_mesh"] += energy * mesh_split
            terms["crank_torsion"] += energy * (1.0 - mesh_split)
        elif label == "sun_support":
            terms["sun_support"] += energy
        else:
            terms[label] += energy
    assert cam_idx == M * N  # noqa: S101 - the row layout of assemble()
    dd = Bc @ dq
    energy_c = kc * dd * dd  # per contact
    seat = 0.0 if reducer.pins.seat_compliance is None else float(reducer.pins.seat_compliance)
    bend = (
        np.zeros(N)
        if reducer.pins.bending_compliance is None
        else np.asarray(reducer.pins.bending_compliance, dtype=float)
    )[group]
    total_c = np.where(active, law_c + series, 1.0)
    terms["pin_contact"] = float(np.sum(energy_c * law_c / total_c))
    terms["pin_seat"] = float(np.sum(energy_c * seat / total_c))
    terms["pin_bending"] = float(np.sum(energy_c * bend / total_c))
    k_out = reducer.supports.output_torsional_stiffness
    if k_out is not None:
        terms["output_flange"] = 1.0 / k_out
    out = left_out_elements(reducer)
    return StiffnessChain(
        torque=float(torque),
        theta=float(theta),
        compliance={e: float(terms[e]) for e in ELEMENTS if e not in out},
        left_out=out,
        cam_bearing_load=float(ls.cam_bearing_load.max()),
        carrier_bearing_load=float(ls.carrier_bearing_load.max()),
    )


def _cam_split(reducer: RVReducer) -> np.ndarray:
    """Share of each disc's cam row compliance that is the bearing's (the rest: crank bending)."""
    cb = 1.0 / float(reducer.cranks.cam_bearing_stiffness)
    bend = reducer.cranks.bending_compliance
    if bend is None:
        return np.ones(reducer.discs.count)
    return cb / (cb + np.asarray(bend, dtype=float))


def _mesh_split(reducer: RVReducer) -> float:
    """Share of the mesh row's compliance that is the mesh's (the rest: crank torsion)."""
    kt = reducer.cranks.torsional_stiffness
    if kt is None:
        return 1.0
    cm = 1.0 / float(reducer.first_stage.mesh_stiffness)
    rb2 = reducer.first_stage.base_radii[1]
    return cm / (cm + rb2 * rb2 / kt)
