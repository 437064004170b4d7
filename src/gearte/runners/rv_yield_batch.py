"""Many assembled RV reducers at once: drawn errors → catalogue test, TE, pin loads (batched).

The per-sample path (:meth:`gearte.runners.yield_models.RVReducerYield.one`) builds each
reducer, assembles its rows (:func:`gearte.models.rv_load_sharing.assemble`) and solves 88
equilibria one call at a time. Here the same physics is organised for a batch:

1. **Rows.** The rows ``B`` of the load-sharing model depend on the geometry and the output
   angle only; the manufacturing errors enter the spring offsets ``e`` and the contact
   clearances ``g`` *linearly* (eccentricity vectors, pin radius and position, disc run-out and
   cumulative pitch), except the per-disc modification errors, which enter ``g`` through
   :func:`gearte.geometry.cycloid.normal_clearance_unclosed`. The linear maps are taken from
   the model itself: :func:`~gearte.models.rv_load_sharing.assemble` of the reducer with the
   drawn errors at zero, and once more with each error component at 1 µm (a basis); a sample's
   ``e`` and ``g`` are then ``e0 + X E``, ``g0 + X Γ`` (one matrix product per batch), plus the
   exact modification term. The assembly checks that every basis reducer has the same rows.
2. **Steps.** Per sample: the catalogue's virtual hysteresis loop (the four branches of
   :func:`gearte.models.rv_catalogue.virtual_loop`, ±{1, 0.5, f, ε}·T_r, each a cold-started
   sequence at θ = 0), the loaded TE and the unloaded (geometric) TE at the output positions
   (each a sequence warm-started along the positions), solved by
   :func:`gearte.solvers.rv_batch.solve_batch` in one compiled call for the whole batch.
3. **Read-out.** The loop is read by the catalogue definitions
   (:func:`gearte.models.catalogue.hysteresis_values`, the same as a measured curve), the TE as
   peak-to-peak, the pin loads and Hertz pressures (:func:`gearte.models.contact_law.
   max_contact_pressure`, each pin with its own flank curvature) at the TE torque.

The per-case dense hysteresis curve that :func:`~gearte.models.rv_catalogue.catalogue_values`
also computes (for plots) is not needed by the catalogue quantities and is skipped.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.solvers.rv_batch import BatchProblem

__all__ = ["RVBatchPlan", "plan", "cached_plan", "batch_inputs", "batch_quantities"]

_UNIT_UM = 1.0  # basis error [µm]
_PLAN_LOCK = threading.Lock()


def _vector_key(key: str, vector_parts: Sequence[str]) -> bool:
    """Whether ``key`` is an eccentricity vector (magnitude + ``<key>_phase_rad``)."""
    return key.split(".")[0] in vector_parts


@dataclass(frozen=True)
class RVBatchPlan:
    """The shared part of a batch: solver problem, base inputs and linear maps.

    ``components``: (key, axis) per column of ``X`` (axis 0/1: x/y of a vector key [mm];
    -1: a scalar key [mm]); ``h0`` (G, nd), ``en0`` (G, nm, 2), ``gap0`` (G, nc) at the drawn errors
    set to zero; ``h_map`` (ncomp, G·nd), ``en_map`` (ncomp, G·nm·2), ``gap_map`` (ncomp, G·nc)
    per mm of each component; ``modification`` per disc ``j``: the keys of its equidistant and
    shifted modification errors (or ``None``) with their base values [mm].
    """

    problem: BatchProblem
    theta: np.ndarray
    components: tuple[tuple[str, int], ...]
    h0: np.ndarray
    en0: np.ndarray
    gap0: np.ndarray
    h_map: np.ndarray
    en_map: np.ndarray
    gap_map: np.ndarray
    modification: tuple
    phase: np.ndarray
    rho: np.ndarray
    step_g: np.ndarray
    step_T: np.ndarray
    cold: np.ndarray
    start: np.ndarray
    record: np.ndarray
    n_loop: int


def plan(model, keys: Sequence[str]) -> RVBatchPlan:
    """Build the batch plan of ``model`` for the drawn ``keys``.

    ``model``: a :class:`gearte.runners.yield_models.RVReducerYield` (its ``reducer``,
    ``reducer_for``, ``theta``, torques and its ``vector_parts`` / ``modification_families``).
    """
    from gearte.models.catalogue import ZERO_TORQUE_FRACTION
    from gearte.models.rv_load_sharing import assemble, contact_law, contact_phase, cycloid_stage

    RV_VECTOR_PARTS, MODIFICATION_FAMILIES = model.vector_parts, model.modification_families
    from gearte.solvers.rv_batch import problem_from_system
    from gearte.solvers.rv_equilibrium import _linear_parts

    keys = [k for k in keys if not k.endswith("_phase_rad")]
    zero = {k: 0.0 for k in keys}
    base = model.reducer_for(zero)
    theta_all = np.concatenate([[0.0], model.theta])
    sys0 = assemble(base, theta_all)
    lin = (sys0.spring_c if sys0.spring_c is not None else np.zeros(sys0.spring_k.size)) == 0.0
    problem, h0, en0, gap0 = problem_from_system(sys0, contact_law(base))
    G, nd = theta_all.size, sys0.layout.size
    nc = sys0.contact_gap.shape[1]
    kn = problem.bearing_k
    mod_keys: dict[str, list[str]] = {f: [] for f in MODIFICATION_FAMILIES}
    components: list[tuple[str, int]] = []
    for k in keys:
        fam = k.rsplit(".", 1)[0]
        if fam in MODIFICATION_FAMILIES:
            mod_keys[fam].append(k)
        elif _vector_key(k, RV_VECTOR_PARTS):
            components += [(k, 0), (k, 1)]
        else:
            components.append((k, -1))
    unit_mm = _UNIT_UM * 1e-3
    h_rows, en_rows, gap_rows = [], [], []
    de_x, dg_x = np.zeros_like(sys0.spring_e), np.zeros_like(sys0.contact_gap)
    for k, axis in components:
        errs = dict(zero)
        errs[k] = _UNIT_UM
        if axis >= 0:
            errs[f"{k}_phase_rad"] = 0.0 if axis == 0 else 0.5 * np.pi
        sk = assemble(model.reducer_for(errs), theta_all)
        if not (
            np.array_equal(sk.spring_B, sys0.spring_B)
            and np.array_equal(sk.contact_B, sys0.contact_B)
        ):
            raise ParameterError(k, _UNIT_UM, "changes the model's rows: no batched solution")
        de = (sk.spring_e - sys0.spring_e) / unit_mm
        dg = (sk.contact_gap - sys0.contact_gap) / unit_mm
        if axis == 1:  # cos(π/2) is 6e-17, not 0: remove that trace of the x component
            de -= np.cos(0.5 * np.pi) * de_x
            dg -= np.cos(0.5 * np.pi) * dg_x
        de_x, dg_x = de, dg
        dh = -_linear_parts(sys0.spring_B[:, lin], de[:, lin], sys0.spring_k[lin], 0.0)[1]
        first = np.flatnonzero(~lin)[::2]
        den = np.stack([de[:, first], de[:, first + 1]], axis=2)
        h_rows.append(dh.ravel())
        en_rows.append(den.ravel())
        gap_rows.append(dg.ravel())
    ncomp = len(components)
    nm = kn.size

    def stack(rows, width):
        return np.array(rows).reshape(ncomp, width) if rows else np.zeros((0, width))

    # per-disc modification errors (non-linear in the clearance): base values and keys
    err = base.errors
    ndisc = base.discs.count
    modification = []
    for j in range(ndisc):
        ke = f"discs.equidistant_modification_errors.d{j + 1}"
        ks = f"discs.shift_modification_errors.d{j + 1}"
        drawn = (
            ke if ke in mod_keys["discs.equidistant_modification_errors"] else None,
            ks if ks in mod_keys["discs.shift_modification_errors"] else None,
        )
        modification.append((drawn, tuple(float(v) for v in err.disc_modification[j])))
    stage = cycloid_stage(base)
    ph = contact_phase(sys0)
    P = model.theta.size
    # each pin's flank curvature where it really touches the design's profile, as the per-case
    # read-out (CycloidStage.contact_curvature_radius)
    rho = stage.contact_curvature_radius(ph[1:]).reshape(P, ndisc, base.pins.count)
    # steps: virtual loop (4 cold sequences at theta = 0), loaded TE, unloaded TE
    tr = float(model.reducer.rated_torque)
    levels = np.array([1.0, 0.5, model.lost_motion_fraction, ZERO_TORQUE_FRACTION])
    loop_T = [levels * tr, -levels * tr, levels[::-1] * tr, -levels[::-1] * tr]
    step_g = [np.zeros(4, np.int64)] * 4 + [np.arange(1, P + 1)] * 2
    step_T = loop_T + [
        np.full(P, model.te_torque),
        np.full(P, model.zero_load_fraction * model.te_torque),
    ]
    cold = [np.eye(1, s.size, dtype=bool)[0] for s in step_g]
    # starts: each sequence from its previous step; the rising branches (levels reversed)
    # from the falling branches' solutions at the same torques (the same equilibria)
    steps = np.arange(16 + 2 * P)
    start = np.where(np.concatenate(cold), -1, steps - 1)
    start[8:12] = [3, 2, 1, 0]
    start[12:16] = [7, 6, 5, 4]
    record = [np.zeros(4, bool)] * 4 + [np.ones(P, bool), np.zeros(P, bool)]
    return RVBatchPlan(
        problem=problem,
        theta=theta_all,
        components=tuple(components),
        h0=h0[0],
        en0=en0[0],
        gap0=gap0[0],
        h_map=stack(h_rows, G * nd),
        en_map=stack(en_rows, G * nm * 2),
        gap_map=stack(gap_rows, G * nc),
        modification=tuple(modification),
        phase=ph,
        rho=rho,
        step_g=np.concatenate(step_g),
        step_T=np.concatenate(step_T),
        cold=np.concatenate(cold),
        start=start,
        record=np.concatenate(record),
        n_loop=16,
    )


def cached_plan(model, keys: Sequence[str]) -> RVBatchPlan:
    """:func:`plan`, built once per model and set of keys (thread-safe)."""
    sig = tuple(sorted(k for k in keys if not k.endswith("_phase_rad")))
    with _PLAN_LOCK:
        cache = model.__dict__.setdefault("_batch_plans", {})
        if sig not in cache:
            cache[sig] = plan(model, sig)
        return cache[sig]


def component_matrix(p: RVBatchPlan, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
    """``X`` (n, ncomp) [mm] of drawn errors (magnitudes [µm], phases [rad])."""
    X = np.empty((n, len(p.components)))
    for c, (k, axis) in enumerate(p.components):
        r = np.asarray(errors[k], dtype=float) * 1e-3
        if axis < 0:
            X[:, c] = r
        else:
            ph = np.asarray(errors.get(f"{k}_phase_rad", np.zeros(n)), dtype=float)
            X[:, c] = r * (np.cos(ph) if axis == 0 else np.sin(ph))
    return X


def batch_inputs(model, p: RVBatchPlan, errors: Mapping[str, np.ndarray], n: int):
    """Per-sample solver inputs ``(h, bearing offsets, gaps)`` of a batch.

    Parameters
    ----------
    model : RVReducerYield
        The yield model (its reducer and keys).
    p : RVBatchPlan
        Its plan for these keys (:func:`cached_plan`).
    errors : mapping
        Drawn errors, key → (n,) values [µm; phases in rad].
    n : int
        Samples in the batch.
    """
    from gearte.geometry.cycloid import normal_clearance_unclosed

    X = component_matrix(p, errors, n)
    G, nd = p.h0.shape
    h = p.h0[None] + (X @ p.h_map).reshape(n, G, nd)
    en = p.en0[None] + (X @ p.en_map).reshape((n,) + p.en0.shape)
    gap = p.gap0[None] + (X @ p.gap_map).reshape((n,) + p.gap0.shape)
    red = model.reducer
    zp = red.pins.count
    for j, ((ke, ks), (b_rp, b_p)) in enumerate(p.modification):
        if ke is None and ks is None:
            continue
        d_rp = np.full(n, b_rp) if ke is None else np.asarray(errors[ke], dtype=float) * 1e-3
        d_p = np.full(n, b_p) if ks is None else np.asarray(errors[ks], dtype=float) * 1e-3
        phi = p.phase[:, j * zp : (j + 1) * zp]
        kw = {"z_p": zp, "r_p": red.pins.circle_radius, "a": red.cranks.eccentricity}
        nominal = normal_clearance_unclosed(
            phi,
            dr_rp=red.discs.equidistant_modification + b_rp,
            dr_p=red.discs.shift_modification + b_p,
            **kw,
        )
        # every sample at once: its modifications broadcast against the (positions, pins) phases
        new = normal_clearance_unclosed(
            phi[None],
            dr_rp=red.discs.equidistant_modification + d_rp[:, None, None],
            dr_p=red.discs.shift_modification + d_p[:, None, None],
            **kw,
        )
        gap[:, :, j * zp : (j + 1) * zp] += new - nominal[None]
    return h, en, gap


def batch_quantities(
    model,
    errors: Mapping[str, np.ndarray],
    n: int,
    *,
    compiled: bool = True,
    exact: bool = True,
    solver=None,
) -> dict[str, np.ndarray]:
    """The yield quantities of ``n`` assembled reducers (see ``RVReducerYield``).

    Parameters
    ----------
    model : RVReducerYield
        The yield model.
    errors : mapping
        Drawn errors, key → (n,) values [µm; phases in rad].
    n : int
        Samples in the batch.
    compiled : bool
        ``False`` runs the solver's plain-Python twin.
    exact : bool
        Newton on the exact pin law (default) or the per-case secant fixed point.
    solver : callable, optional
        A replacement for :func:`gearte.solvers.rv_batch.solve_batch` with its signature
        (benchmarks time a plain numpy solver through the same inputs and read-out).
    """
    from gearte.models.catalogue import hysteresis_values_many
    from gearte.models.contact_law import max_contact_pressure, relative_radius
    from gearte.models.rv_load_sharing import cycloid_stage
    from gearte.solvers.rv_batch import solve_batch
    from gearte.units import Nmm_to_Nm, arcmin_to_rad, rad_to_arcmin

    p = cached_plan(model, list(errors))
    h, en, gap = batch_inputs(model, p, errors, n)
    solve = solve_batch if solver is None else solver
    # the per-case algorithm (exact=False) starts every branch cold, as the per-case solver
    if exact:
        sol = solve(p.problem, h, en, gap, p.step_g, p.step_T, p.cold, p.record,
                    compiled=compiled, exact=exact, start=p.start)  # fmt: skip
    else:
        sol = solve(p.problem, h, en, gap, p.step_g, p.step_T, p.cold, p.record,
                    compiled=compiled, exact=exact)  # fmt: skip
    red = model.reducer
    tr = float(red.rated_torque)
    angle = -sol.output[:, : p.n_loop]  # the four loop branches, 4 levels each
    up, un, lp, ln = (angle[:, 4 * i : 4 * i + 4] for i in range(4))
    levels_T = p.step_T[:4]
    t_desc = np.concatenate([levels_T, [0.0], -levels_T[::-1]])
    torque = np.concatenate([t_desc, -t_desc])
    direction = np.concatenate([-np.ones(9, np.int64), np.ones(9, np.int64)])
    P = model.theta.size
    loaded = sol.output[:, p.n_loop : p.n_loop + P]
    unloaded = sol.output[:, p.n_loop + P :]
    hv = hysteresis_values_many(
        torque,
        np.concatenate([up, up[:, -1:], ln, un, un[:, -1:], lp], axis=1),
        tr,
        direction=direction,
        lost_motion_fraction=model.lost_motion_fraction,
    )
    out = {
        "lost_motion [arcmin]": np.asarray(rad_to_arcmin(hv["lost_motion"]), dtype=float),
        "torsional_rigidity [Nm/arcmin]": np.asarray(Nmm_to_Nm(hv["torsional_rigidity"]))
        * float(arcmin_to_rad(1.0)),
        "backlash [arcmin]": np.asarray(rad_to_arcmin(hv["backlash"]), dtype=float),
        "hysteresis_loss [arcmin]": np.asarray(rad_to_arcmin(hv["hysteresis_loss"]), dtype=float),
    }
    out["angular_te [arcmin]"] = np.asarray(rad_to_arcmin(np.ptp(unloaded, axis=1)), dtype=float)
    out["loaded_te [arcmin]"] = np.asarray(rad_to_arcmin(np.ptp(loaded, axis=1)), dtype=float)
    F = sol.forces.reshape(n, -1)
    out["peak_pin_load [N]"] = F.max(axis=1)
    # the largest Hertz pressure: p0 = (F E*/(π b R*))^½ grows with F at each contact, so it
    # is the pressure of the contact with the largest F / R* (found once per sample)
    stage = cycloid_stage(red)
    d = red.discs
    rho = p.rho.reshape(-1)  # (P, N, zp): the order of the recorded forces
    top = np.argmax(F / relative_radius(rho, stage.r)[None], axis=1)
    pr = max_contact_pressure(F[np.arange(n), top], rho[top], stage.r, d.youngs_modulus,
                              d.poisson_ratio, d.face_width)  # fmt: skip
    out["max_contact_pressure [MPa]"] = np.asarray(pr, dtype=float)
    return out
