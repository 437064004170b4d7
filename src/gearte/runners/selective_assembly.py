"""Selective assembly of a lot of measured RV parts (issue 16): which disc set goes with which
crank set, in which orientation, so that most reducers meet a TE spec — and pin grading.

Method (``docs/selective-assembly.md``)
---------------------------------------
1. **Score every pairing with the model, linearised.** The loaded output angle error of the
   one RV model (:func:`gearte.models.rv_load_sharing.load_sharing`) is solved once for the
   design at the output angles ``theta``. At that equilibrium the tangent stiffness ``K_t``
   (springs, bearings beyond their clearance, loaded pin contacts with the tangent of their
   contact law) gives the sensitivity of the output angle to every spring offset and every pin
   clearance: ``y = K_t⁻¹ e_out``, ``∂θ/∂e_s = −k_s B_s·y``, ``∂θ/∂g_c = k_c B_c·y``. A part's
   errors change the offsets and clearances *exactly linearly* (they are built by the same
   :func:`~gearte.models.rv_load_sharing.assemble`, from unit errors, and by
   :meth:`~gearte.geometry.measured.MeasuredDisc.gap_change` for measured flanks), so each
   oriented disc set and each oriented crank set has its own TE contribution ``t(θ)``, and a
   pairing's TE trace is ``θ0(θ) + t_disc(θ) + t_crank(θ)`` — its peak-to-peak for every disc
   set × orientation × crank set × orientation is one vectorised array operation.
2. **Choose the orientation per pairing** (the best of disc slot order × disc indexing by
   ``2π/M`` when ``z_c`` is a multiple of ``M`` × crank-to-bore indexing × planet indexing on
   the crank splines, ``Q`` positions, the same for the reducer's planets).
3. **Solve the assignment** exactly: for the most reducers in spec,
   :func:`scipy.optimize.linear_sum_assignment` on the cost ``pp/limit + BIG·[pp > limit]``
   (``BIG`` larger than any sum of in-spec costs: the count is maximised first, then the total
   TE); for the best worst reducer, a bottleneck assignment (bisection on the threshold with
   :func:`scipy.sparse.csgraph.maximum_bipartite_matching`, then the sum at that threshold).
4. **Verify** the chosen reducers with the full non-linear model (measured clearances
   included).

Pin grading: the backlash of each assembled reducer from the model's virtual torsion test
(:func:`gearte.models.rv_catalogue.catalogue_values`) for each pin diameter grade; the grade
whose backlash falls inside the window (nearest its centre) is chosen.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.geometry.measured import (
    MeasuredDisc,
    apply_measurements,
    bore_errors,
    cam_errors,
    runout_errors,
)
from gearte.geometry.rv import RVReducer
from gearte.models.rv_load_sharing import (
    RVSystem,
    assemble,
    check_reducer_torque,
    load_sharing,
    solver_law,
)
from gearte.runners.rv_records import Assembly, Lot, Orientation, ScoreTable
from gearte.solvers.rv_batch import solve_positions
from gearte.solvers.rv_equilibrium import CLEARANCE_RESIDUAL

__all__ = [
    "Lot",
    "Orientation",
    "LinearTE",
    "linear_te_model",
    "ScoreTable",
    "score_lot",
    "score_lot_loop",
    "Assembly",
    "assign",
    "assign_rescored",
    "Rescored",
    "brute_force",
    "brute_force_pairings",
    "random_assemblies",
    "orientation_only",
    "assembled_reducer",
    "full_model_te",
    "pin_grades",
    "check_reducer",
]


def _disc_orientations(design: RVReducer) -> list[tuple[int, int]]:
    m, n, zc = design.cranks.count, design.discs.count, design.cycloid_teeth
    turns = m if zc % m == 0 else 1
    return [(s, r) for s in range(n) for r in range(turns)]


@functools.lru_cache(maxsize=1024)
def _turned(disc: MeasuredDisc | None, shift: int) -> MeasuredDisc | None:
    """The disc turned so that tooth ``t`` becomes tooth ``t + shift``.

    Kept for the next candidate assembly with the same disc and turn (a disc is frozen and
    hashed by identity; building one checks every tooth's trace: ~0.4 ms for 39 teeth)."""
    if disc is None or shift == 0:
        return disc
    z = disc.teeth

    def roll(seq):
        return None if seq is None else tuple(seq[(t - shift) % z] for t in range(z))

    cp = None if disc.cumulative_pitch is None else np.roll(disc.cumulative_pitch, shift)
    return MeasuredDisc(z, roll(disc.profile_phase), roll(disc.profile_deviation), cp, disc.serial)


def _oriented_discs(lot: Lot, k: int, shift: int, index: int, design: RVReducer):
    """``(discs per slot, bore centres (N, M, 2))`` of disc set ``k`` in an orientation."""
    m, n, zc = design.cranks.count, design.discs.count, design.cycloid_teeth
    slots = [(j + shift) % n for j in range(n)]
    discs = tuple(_turned(lot.discs[k][s], index * zc // m) for s in slots)
    bores = None
    if lot.disc_bores is not None:
        xy = lot.disc_bores[k][slots]  # (N, M, 2)
        rho = 2.0 * np.pi * index / m
        c, s_ = np.cos(rho), np.sin(rho)
        turned = np.stack([c * xy[..., 0] - s_ * xy[..., 1], s_ * xy[..., 0] + c * xy[..., 1]], -1)
        bores = np.roll(turned, index, axis=1)
    return discs, bores


def _oriented_cranks(
    lot: Lot, k: int, shift: int, planet_turn: float = 0.0
) -> dict[str, np.ndarray | None]:
    def roll(a):
        return None if a is None else np.roll(a[k], shift, axis=0)

    planets = roll(lot.planet_runout)
    if planets is not None and planet_turn:
        planets = planets + np.array([0.0, planet_turn])  # high point turned with the planet
    return {
        "cam_eccentricity": roll(lot.cam_eccentricity),
        "cam_phase": roll(lot.cam_phase),
        "planet_runout": planets,
        "cam_clearance": roll(lot.cam_clearance),
        "carrier_clearance": roll(lot.carrier_clearance),
    }


def assembled_reducer(
    design: RVReducer, lot: Lot, disc_set: int, crank_set: int, orientation: Orientation
) -> RVReducer:
    """The reducer assembled from disc set ``disc_set`` and crank set ``crank_set``.

    Parameters
    ----------
    design : RVReducer
        The design (nominal parts, pins, housing).
    lot : Lot
        The measured parts.
    disc_set, crank_set : int
        0-based indices into the lot [-].
    orientation : Orientation
        How the parts are put together.
    """
    discs, bores = _oriented_discs(
        lot, disc_set, orientation.disc_shift, orientation.disc_index, design
    )
    turn = 2.0 * np.pi * orientation.planet_index / orientation.planet_indexings
    cr = _oriented_cranks(lot, crank_set, orientation.crank_shift, turn)
    return apply_measurements(design, discs=list(discs), disc_bores=bores, **cr)


# ---- the linearised model ------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class LinearTE:
    """The loaded output angle error of the design and its sensitivities at ``P`` angles.

    Attributes
    ----------
    theta : (P,) output angles [rad].
    base : (P,) output angle error of the design [rad].
    d_offset : (P, ns) ∂θ/∂e of every spring offset [rad/mm].
    d_gap : (P, nc) ∂θ/∂g of every pin clearance [rad/mm].
    system : RVSystem of the design at ``theta``.
    d_cam_clearance : (M, N, P) ∂θ/∂c of each cam bearing's radial clearance [rad/mm].
    d_carrier_clearance : (M, P) ∂θ/∂c of each crank's carrier bearing clearance [rad/mm].
    """

    theta: np.ndarray
    base: np.ndarray
    d_offset: np.ndarray
    d_gap: np.ndarray
    system: RVSystem
    d_cam_clearance: np.ndarray
    d_carrier_clearance: np.ndarray

    def response(self, d_offset: np.ndarray, d_gap: np.ndarray) -> np.ndarray:
        """Output angle change [rad] of offset changes ``(..., P, ns)`` and clearance changes
        ``(..., P, nc)`` [mm]."""
        return np.einsum("...ps,ps->...p", d_offset, self.d_offset) + np.einsum(
            "...pc,pc->...p", d_gap, self.d_gap
        )


def linear_te_model(design: RVReducer, torque: float, theta: np.ndarray) -> LinearTE:
    """The design's loaded TE and its tangent sensitivities (module docstring, step 1).

    Parameters
    ----------
    design : RVReducer
        The design the lot's parts were made to (its own errors, if any, included).
    torque : float
        Output torque [N·mm].
    theta : numpy.ndarray
        Output angles [rad].

    Raises
    ------
    ParameterError
        Naming ``torque`` when it is more than the pins carry (the case files' pin-pressure
        ceiling, :func:`gearte.models.rv_load_sharing.check_reducer_torque`).
    """
    check_reducer_torque(design, torque)
    system = assemble(design, theta)
    law = solver_law(design, system, None)
    sol = solve_positions(system, torque, law)
    P, nd = sol.q.shape
    out = system.layout.output_rotation
    k, c = system.spring_k, system.spring_c if system.spring_c is not None else 0 * system.spring_k
    w = np.einsum("psi,pi->ps", system.spring_B, sol.q) + system.spring_e
    F = sol.contact_force
    # tangent of the pin law δ(F): dF/dδ = 1/δ'(F) (the solver law's own)
    kc = np.zeros_like(F)
    act = F > 0
    if law.kind == "secant_per_contact":
        kc[act] = law.tangent_stiffness(np.where(act, F, 1.0))[act]
    else:
        assert sol.pin_stiffness is not None  # noqa: S101 - the solver fills it in
        kc[act] = sol.pin_stiffness[act]
    d_off = np.zeros((P, k.size))
    d_gap = np.zeros_like(F)
    lin = c == 0.0
    first = np.flatnonzero(~lin)[::2]
    for p in range(P):
        B = system.spring_B[p]
        K = (B[lin].T * k[lin]) @ B[lin]
        T_pairs = []
        for s in first:
            wx, wy = w[p, s], w[p, s + 1]
            r = np.hypot(wx, wy)
            if r > c[s]:
                nvec = np.array([wx, wy]) / r
                T = k[s] * ((1 - c[s] / r) * np.eye(2) + (c[s] / r) * np.outer(nvec, nvec))
            else:
                T = CLEARANCE_RESIDUAL * k[s] * np.eye(2)
            Bp = B[[s, s + 1]]
            K += Bp.T @ T @ Bp
            T_pairs.append(T)
        Bc = system.contact_B[p]
        K += (Bc.T * kc[p]) @ Bc
        e = np.zeros(nd)
        e[out] = 1.0
        y = np.linalg.solve(K, e)
        d_off[p, lin] = -k[lin] * (B[lin] @ y)
        for s, T in zip(first, T_pairs, strict=True):
            d_off[p, [s, s + 1]] = -(T @ (B[[s, s + 1]] @ y))
        d_gap[p] = kc[p] * (Bc @ y)
    base = sol.q[:, out].copy()
    # a loaded bearing's radial clearance c acts as the offset -c n along its load direction n
    # (k (|w| - c) n = k (w - c n)): linear in c
    m, n = design.cranks.count, design.discs.count

    def per_unit_clearance(rows: slice, shape: tuple[int, ...]) -> np.ndarray:
        ww = w[:, rows].reshape(P, -1, 2)
        nrm = ww / np.maximum(np.linalg.norm(ww, axis=-1, keepdims=True), 1e-300)
        d = -np.sum(d_off[:, rows].reshape(P, -1, 2) * nrm, axis=-1)  # (P, bearings)
        return np.moveaxis(d, 0, -1).reshape(*shape, P)

    d_cam = per_unit_clearance(system.labels["cam_bearing"], (m, n))
    d_car = per_unit_clearance(system.labels["carrier_bearing"], (m,))
    return LinearTE(system.theta, base, d_off, d_gap, system, d_cam, d_car)


def _unit_responses(design: RVReducer, model: LinearTE, field: str, shape: tuple) -> np.ndarray:
    """Output angle change per unit error [rad/mm] of every component of error array
    ``field``: ``shape + (P,)``; the offsets come from :func:`assemble` (exactly linear)."""
    theta = model.system.theta
    h = 1e-3  # mm; any value: the offsets are linear in the errors
    changes: dict = {field: np.zeros(shape)}
    zero = design.with_errors(dataclasses.replace(design.error_set, **changes))
    sys0 = assemble(zero, theta)
    out = np.zeros((*shape, theta.size))
    for idx in itertools.product(*(range(s) for s in shape)):
        arr = np.zeros(shape)
        arr[idx] = h
        changes[field] = arr
        red = design.with_errors(dataclasses.replace(design.error_set, **changes))
        s1 = assemble(red, theta)
        out[idx] = model.response(
            (s1.spring_e - sys0.spring_e) / h, (s1.contact_gap - sys0.contact_gap) / h
        )
    return out


def _contributions(design: RVReducer, lot: Lot, model: LinearTE, planet_indexings: int = 1):
    """TE contributions ``t_disc (K_d, O_d, P)`` and ``t_crank (K_c, O_c, P)`` [rad]."""
    m, n, zc = design.cranks.count, design.discs.count, design.cycloid_teeth
    zp = design.pins.count
    sys0 = model.system
    P = sys0.theta.size
    d_orients = _disc_orientations(design)
    q_max = planet_indexings if lot.planet_runout is not None else 1
    c_orients = [(c, q) for c in range(m) for q in range(q_max)]
    u_bore = _unit_responses(design, model, "disc_bore", (n, m, 2))
    u_cam = _unit_responses(design, model, "cam", (m, n, 2))
    u_planet = _unit_responses(design, model, "planet", (m, 2))
    # measured flanks: per disc, slot and turn
    cache: dict[tuple[int, int, int, int], np.ndarray] = {}

    def flank(k: int, disc: int, slot: int, index: int) -> np.ndarray:
        key = (k, disc, slot, index)
        if key not in cache:
            md = _turned(lot.discs[k][disc], index * zc // m)
            if md is None:
                cache[key] = np.zeros(P)
            else:
                sl = slice(slot * zp, (slot + 1) * zp)
                arm = sys0.contact_B[:, sl, sys0.layout.disc(slot) + 2]
                assert sys0.contact_phase is not None  # noqa: S101 - assemble fills it in
                dg = md.gap_change(
                    np.arange(zp)[None, :], sys0.contact_phase[:, sl], arm,
                    design.cranks.eccentricity * zc,
                )  # fmt: skip
                cache[key] = np.einsum("pc,pc->p", dg, model.d_gap[:, sl])
        return cache[key]

    t_disc = np.zeros((lot.disc_sets, len(d_orients), P))
    for k in range(lot.disc_sets):
        for o, (s, r) in enumerate(d_orients):
            t = sum(flank(k, (j + s) % n, j, r) for j in range(n))
            _, bores = _oriented_discs(lot, k, s, r, design)
            if bores is not None:
                err = bore_errors(bores, design.cranks.circle_radius)
                t = t + np.einsum("jid,jidp->p", err, u_bore)
            t_disc[k, o] = t
    t_crank = np.zeros((lot.crank_sets, len(c_orients), P))
    for k in range(lot.crank_sets):
        for o, (c, q) in enumerate(c_orients):
            cr = _oriented_cranks(lot, k, c, 2.0 * np.pi * q / planet_indexings)
            ecc, phase = cr["cam_eccentricity"], cr["cam_phase"]
            assert ecc is not None and phase is not None  # noqa: S101 - a lot always has cams
            cam = cam_errors(ecc, phase, design.cranks.eccentricity)
            t = np.einsum("ijd,ijdp->p", cam, u_cam)
            if cr["planet_runout"] is not None:
                t = t + np.einsum("id,idp->p", runout_errors(cr["planet_runout"]), u_planet)
            if cr["cam_clearance"] is not None:
                dc = cr["cam_clearance"] - design.cranks.cam_bearing_clearance
                t = t + np.einsum("ij,ijp->p", dc, model.d_cam_clearance)
            if cr["carrier_clearance"] is not None:
                dc = cr["carrier_clearance"] - design.cranks.carrier_bearing_clearance
                t = t + np.einsum("i,ip->p", dc, model.d_carrier_clearance)
            t_crank[k, o] = t
    return t_disc, t_crank, d_orients, c_orients


def score_lot(
    design: RVReducer, lot: Lot, model: LinearTE, planet_indexings: int = 1
) -> ScoreTable:
    """TE peak-to-peak of every disc set × orientation × crank set × orientation (vectorised).

    Parameters
    ----------
    design : RVReducer
        The design.
    lot : Lot
        The measured parts.
    model : LinearTE
        :func:`linear_te_model` of the design.
    planet_indexings : int
        Spline indexings ``Q`` of the planets on their cranks to choose from [-] (1: none).
    """
    if int(planet_indexings) != planet_indexings or not 1 <= planet_indexings <= 360:
        raise ParameterError("planet_indexings", planet_indexings, "must be an integer 1..360")
    lot.check(design)
    t_disc, t_crank, d_or, c_or = _contributions(design, lot, model, planet_indexings)
    pp = np.empty((lot.disc_sets, len(d_or), lot.crank_sets, len(c_or)))
    for k in range(lot.disc_sets):
        x = model.base + t_disc[k][:, None, None, :] + t_crank[None]
        pp[k] = x.max(axis=-1) - x.min(axis=-1)
    return ScoreTable(pp, d_or, c_or, planet_indexings)


def score_lot_loop(
    design: RVReducer, lot: Lot, model: LinearTE, planet_indexings: int = 1
) -> ScoreTable:
    """The plain baseline of :func:`score_lot`: one linearised evaluation per pairing and
    orientation, each building its reducer and its offsets with :func:`assemble` (what a user
    of the model without the separation into part contributions would write).

    Parameters
    ----------
    design : RVReducer
        The design.
    lot : Lot
        The measured parts.
    model : LinearTE
        :func:`linear_te_model` of the design.
    planet_indexings : int
        As :func:`score_lot` [-].
    """
    d_or = _disc_orientations(design)
    q_max = planet_indexings if lot.planet_runout is not None else 1
    c_or = [(c, q) for c in range(design.cranks.count) for q in range(q_max)]
    sys0 = model.system
    pp = np.empty((lot.disc_sets, len(d_or), lot.crank_sets, len(c_or)))
    for kd, (od, (s, r)), kc, (oc, (c, q)) in itertools.product(
        range(lot.disc_sets), enumerate(d_or), range(lot.crank_sets), enumerate(c_or)
    ):
        red = assembled_reducer(design, lot, kd, kc, Orientation(s, r, c, q, planet_indexings))
        err = red.error_set
        red = red.with_errors(dataclasses.replace(err, cam_clearance=None, carrier_clearance=None))
        s1 = assemble(red, sys0.theta)
        x = model.base + model.response(
            s1.spring_e - sys0.spring_e, s1.contact_gap - sys0.contact_gap
        )
        if err.cam_clearance is not None:
            dc = err.cam_clearance - design.cranks.cam_bearing_clearance
            x = x + np.einsum("ij,ijp->p", dc, model.d_cam_clearance)
        if err.carrier_clearance is not None:
            dc = err.carrier_clearance - design.cranks.carrier_bearing_clearance
            x = x + np.einsum("i,ip->p", dc, model.d_carrier_clearance)
        pp[kd, od, kc, oc] = x.max() - x.min()
    return ScoreTable(pp, d_or, c_or, planet_indexings)


# ---- assignment ----------------------------------------------------------------------------


def _finish(table: ScoreTable, rows: np.ndarray, cols: np.ndarray) -> Assembly:
    best, od, oc = table.best()
    return Assembly(rows, cols, od[rows, cols], oc[rows, cols], best[rows, cols])


def assign(table: ScoreTable, limit: float, objective: str = "count_in_spec") -> Assembly:
    """The optimal assembly of the lot (module docstring, step 3).

    Parameters
    ----------
    table : ScoreTable
        Scores of every pairing and orientation.
    limit : float
        TE peak-to-peak spec [rad].
    objective : {"count_in_spec", "worst"}
        Most reducers with ``pp <= limit`` (then the least total TE), or the smallest largest
        ``pp`` (then the least total TE).
    """
    from scipy.optimize import linear_sum_assignment
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import maximum_bipartite_matching

    if not limit > 0:
        raise ParameterError("limit", limit, "must be > 0 rad")
    best, _, _ = table.best()
    kd, kc = best.shape
    r = min(kd, kc)
    if objective == "count_in_spec":
        x = best / limit
        big = r * float(x.max()) + 1.0
        cost = x + big * (best > limit)
    elif objective == "worst":
        values = np.unique(best)
        lo, hi = 0, values.size - 1
        while lo < hi:  # smallest threshold with a matching of all r reducers
            mid = (lo + hi) // 2
            graph = csr_matrix((best <= values[mid]).astype(np.int8))
            match = maximum_bipartite_matching(graph, perm_type="column")
            if np.sum(match >= 0) >= r:
                hi = mid
            else:
                lo = mid + 1
        cost = np.where(best <= values[lo], best, 1e6 * (1.0 + best.max()))
    else:
        raise ParameterError("objective", objective, "must be 'count_in_spec' or 'worst'")
    rows, cols = linear_sum_assignment(cost)
    return _finish(table, rows, cols)


@dataclass(frozen=True)
class Rescored:
    """An assembly whose claimed scores are the full model's (:func:`assign_rescored`).

    Attributes
    ----------
    assembly : Assembly
        The final assembly; its ``pp`` is the full model's TE of each reducer [rad].
    linearised : numpy.ndarray
        ``(R,)`` the linearised score of each final reducer [rad].
    first : Assembly
        The assembly chosen on the linearised scores alone (the first round).
    rounds : int
        Assignments solved [-].
    stable : bool
        The chosen reducers' full-model objective equals the optimum found on the scores of
        the last round.
    full : dict
        ``(disc set, disc orientation, crank set, crank orientation) → full-model TE [rad]`` of
        every pairing evaluated.
    margin : float
        The largest over-estimate of a TE by the linearisation seen (≥ 0) [rad].
    certified : bool
        The rounds with the pairings not scored counted at their linearised score less
        ``margin`` settled too: no pairing left unscored could beat the assembly unless the
        linearisation errs by more than it has erred so far.
    """

    assembly: Assembly
    linearised: np.ndarray
    first: Assembly
    rounds: int
    stable: bool
    full: dict
    margin: float = 0.0
    certified: bool = False


def assign_rescored(
    table: ScoreTable,
    limit: float,
    full_te,
    objective: str = "count_in_spec",
    max_rounds: int = 30,
) -> Rescored:
    """:func:`assign` with the chosen pairings re-scored by the full model until stable.

    Round 1 assigns on the linearised scores. The full model scores every chosen pairing and
    orientation not yet scored, and their linearised scores are replaced by the full model's.
    A round is stable when the chosen reducers' full-model objective (count in spec, or worst
    TE) is as good as the optimum the assignment found on the scores it was given; otherwise
    the assignment is solved again on the corrected scores (at most ``max_rounds`` times).
    Then the same rounds once more with every pairing not yet scored counted at its
    linearised score less the largest over-estimate the full model has shown (``margin``:
    linearised − full over every scored pairing, ≥ 0): the scores the assignment sees are then
    optimistic wherever the linearisation errs by no more than it has erred so far, and a
    stable round there is optimal for the full model too (every other assignment scores at
    least as well on those scores as on the full model, and none beats the chosen one there)
    — ``certified``. Of every round, the assembly best by the full model is kept (objective,
    then the least total TE); the claimed TE of every reducer is the full model's, so the count
    in spec claimed is the full model's count. The secondary criterion (least total TE) is not
    iterated.

    Parameters
    ----------
    table : ScoreTable
        Linearised scores of every pairing and orientation.
    limit : float
        TE spec [rad].
    full_te : callable
        ``full_te(keys) -> (len(keys),)`` full-model TE peak-to-peak [rad] of the pairings
        ``keys`` = ``[(disc set, disc orientation, crank set, crank orientation), ...]`` (NaN:
        no equilibrium, scored out of spec).
    objective : {"count_in_spec", "worst"}
        As :func:`assign`.
    max_rounds : int
        Most assignments solved in each of the two phases [-].
    """
    if int(max_rounds) != max_rounds or max_rounds < 1:
        raise ParameterError("max_rounds", max_rounds, "must be an integer >= 1")
    pp = table.pp.copy()
    fail = 10.0 * float(np.max(pp)) + limit  # a pairing with no equilibrium: out of spec
    full: dict[tuple[int, int, int, int], float] = {}

    def keys_of(a: Assembly) -> list[tuple[int, int, int, int]]:
        return [
            (int(d), int(od), int(c), int(oc))
            for d, od, c, oc in zip(
                a.disc_set, a.disc_orientation, a.crank_set, a.crank_orientation, strict=True
            )
        ]

    scored = np.zeros(pp.shape, dtype=bool)
    margin = 0.0

    def score(keys: list[tuple[int, int, int, int]]) -> None:
        nonlocal margin
        new = [k for k in keys if k not in full]
        if new:
            for k, v in zip(new, np.asarray(full_te(new), dtype=float), strict=True):
                full[k] = float(v)
                pp[k] = v if np.isfinite(v) else fail
                scored[k] = True
                if np.isfinite(v):  # the most the linearisation has over-estimated a TE
                    margin = max(margin, float(table.pp[k] - v))

    def primary(values: np.ndarray) -> float:
        """What the objective maximises (count in spec) or minimises (the worst TE)."""
        return (
            float(np.sum(values <= limit))
            if objective == "count_in_spec"
            else -float(np.max(values))
        )

    first = None
    rounds = 0
    kept: tuple[tuple[float, float], Assembly] | None = None  # the best round by the full model

    def settle(with_margin: bool) -> bool:
        """Rounds until the chosen reducers' full-model objective is the optimum found on the
        scores given (pairings not scored: linearised, less ``margin`` if ``with_margin``)."""
        nonlocal first, rounds, kept
        for _ in range(int(max_rounds)):
            rounds += 1
            view = np.where(scored, pp, table.pp - (margin if with_margin else 0.0))
            a = assign(dataclasses.replace(table, pp=view), limit, objective)
            first = first or a
            believed = primary(a.pp)  # the optimum on the scores as they stood
            keys = keys_of(a)
            score(keys)
            got = np.array([pp[k] for k in keys])
            rank = (primary(got), -float(np.sum(got)))
            if kept is None or rank > kept[0]:
                kept = (rank, a)
            if primary(got) >= believed:
                return True
        return False

    stable = settle(False)
    # the certificate: again, with the pairings not scored made as good as the largest
    # over-estimate seen allows (it keeps the better assembly; it settles where no pairing
    # that could beat it is left unscored)
    certified = settle(True)
    assert kept is not None and first is not None  # noqa: S101 - at least one round
    a = kept[1]
    keys = keys_of(a)
    claimed = np.array([full[k] for k in keys])
    return Rescored(
        assembly=dataclasses.replace(a, pp=claimed),
        linearised=np.array([table.pp[k] for k in keys]),
        first=first,
        rounds=rounds,
        stable=stable,
        full=dict(full),
        margin=margin,
        certified=certified,
    )


def brute_force_pairings(best: np.ndarray, limit: float, objective: str = "count_in_spec") -> float:
    """The optimum over every pairing of a square table of per-pairing scores (each pairing in
    its best orientation): the largest count in spec, or the smallest worst peak-to-peak [rad].
    Both objectives only improve when one reducer's TE falls, so the best orientation per
    pairing is optimal (:func:`brute_force` checks it over every orientation too).

    Parameters
    ----------
    best : numpy.ndarray
        ``(K, K)`` TE peak-to-peak of each pairing [rad], ``K <= 8``.
    limit : float
        TE spec [rad].
    objective : {"count_in_spec", "worst"}
        As :func:`assign`.
    """
    k = best.shape[0]
    if best.shape != (k, k) or k > 8:
        raise ParameterError("best", best.shape, "brute force needs a square table, K <= 8")
    perms = np.array(list(itertools.permutations(range(k))))
    chosen = best[np.arange(k)[None, :], perms]  # (K!, K)
    if objective == "count_in_spec":
        return float(np.max(np.sum(chosen <= limit, axis=1)))
    return float(np.min(np.max(chosen, axis=1)))


def brute_force(table: ScoreTable, limit: float, objective: str = "count_in_spec") -> float:
    """The optimum by enumeration of every assignment *and every orientation* (tests; tiny
    lots only): the largest count in spec, or the smallest worst peak-to-peak [rad].

    Parameters
    ----------
    table : ScoreTable
        Scores; ``K_d = K_c <= 6``.
    limit : float
        TE spec [rad].
    objective : {"count_in_spec", "worst"}
        As :func:`assign`.
    """
    kd, od, kc, oc = table.pp.shape
    if kd != kc or kd > 6:
        raise ParameterError("table", table.pp.shape, "brute force needs K_d = K_c <= 6")
    flat = table.pp.transpose(0, 2, 1, 3).reshape(kd, kc, od * oc)
    best_value = -np.inf if objective == "count_in_spec" else np.inf
    combos = np.array(list(itertools.product(range(od * oc), repeat=kd)))  # (C, K)
    for perm in itertools.permutations(range(kc)):
        vals = flat[np.arange(kd), list(perm)]  # (K, O)
        chosen = vals[np.arange(kd)[None, :], combos]  # (C, K)
        if objective == "count_in_spec":
            best_value = max(best_value, float(np.max(np.sum(chosen <= limit, axis=1))))
        else:
            best_value = min(best_value, float(np.min(np.max(chosen, axis=1))))
    return best_value


def random_assemblies(
    table: ScoreTable, limit: float, count: int, rng: np.random.Generator
) -> np.ndarray:
    """Reducers in spec of ``count`` random assemblies (random pairing, random orientation).

    Parameters
    ----------
    table : ScoreTable
        Scores.
    limit : float
        TE spec [rad].
    count : int
        Number of random assemblies [-].
    rng : numpy.random.Generator
        Random source.
    """
    kd, od, kc, oc = table.pp.shape
    r = min(kd, kc)
    out = np.empty(count, dtype=np.int64)
    for i in range(count):
        rows = rng.permutation(kd)[:r]
        cols = rng.permutation(kc)[:r]
        pp = table.pp[rows, rng.integers(od, size=r), cols, rng.integers(oc, size=r)]
        out[i] = np.sum(pp <= limit)
    return out


def orientation_only(table: ScoreTable) -> Assembly:
    """The parts paired as they come (disc set ``k`` with crank set ``k``), each reducer in its
    best orientation — the best rule that chooses orientation only.

    Parameters
    ----------
    table : ScoreTable
        Scores.
    """
    r = min(table.pp.shape[0], table.pp.shape[2])
    idx = np.arange(r)
    return _finish(table, idx, idx)


# ---- full model and pin grading --------------------------------------------------------------
def full_model_te(reducer: RVReducer, torque: float, theta: np.ndarray) -> float:
    """Peak-to-peak [rad] of the loaded output angle error of the full non-linear model at
    ``theta``.

    Parameters
    ----------
    reducer : RVReducer
        An assembled reducer.
    torque : float
        Output torque [N·mm].
    theta : numpy.ndarray
        Output angles [rad].
    """
    x = load_sharing(reducer, torque, theta).output_error
    return float(x.max() - x.min())


def pin_grades(
    reducer: RVReducer, grades: np.ndarray, window: tuple[float, float]
) -> tuple[int | None, np.ndarray]:
    """The pin diameter grade that brings the reducer's backlash into ``window``.

    Parameters
    ----------
    reducer : RVReducer
        An assembled reducer (its pins' own radius errors are kept and the grade added).
    grades : numpy.ndarray
        Available pin diameter oversizes [mm].
    window : (float, float)
        Backlash window [rad].

    Returns
    -------
    (int or None, numpy.ndarray)
        Index of the chosen grade (backlash inside the window, nearest its centre; None when no
        grade fits) and the backlash of every grade [rad] (the catalogue definition on the
        model's virtual hysteresis loop, :func:`gearte.models.rv_catalogue.virtual_loop`; NaN
        where the model finds no equilibrium).
    """
    from gearte.errors import ConvergenceError
    from gearte.models.catalogue import hysteresis_values
    from gearte.models.rv_catalogue import virtual_loop

    lo, hi = window
    if not 0 <= lo < hi:
        raise ParameterError("window", window, "needs 0 <= lower < upper [rad]")
    if reducer.rated_torque is None:
        raise ParameterError("reducer.rated_torque_Nm", None, "needed by the pin grading")
    backlash = np.full(len(grades), np.nan)
    for g, over in enumerate(np.asarray(grades, dtype=float)):
        pins = dataclasses.replace(
            reducer.pins, radius_errors=reducer.pins.radius_errors + 0.5 * over
        )
        try:
            loop, direction = virtual_loop(reducer.replace(pins=pins))
        except ConvergenceError:  # no equilibrium (a grade far into interference): unusable
            continue
        hv = hysteresis_values(loop.torque, loop.angle, reducer.rated_torque, direction=direction)
        backlash[g] = hv.backlash
    ok = np.isfinite(backlash)
    inside = np.flatnonzero(ok & (backlash >= lo) & (backlash <= hi))
    if inside.size == 0:
        return None, backlash
    centre = 0.5 * (lo + hi)
    return int(inside[np.argmin(np.abs(backlash[inside] - centre))]), backlash


def check_reducer(task: tuple) -> tuple[float, int | None, np.ndarray | None]:
    """Full-model TE and pin grade of one assembled reducer (a task of
    :func:`gearte.execution.map_chunks`; module level, so any backend can run it).

    Parameters
    ----------
    task : tuple
        ``(reducer, torque [N·mm], theta [rad], verify, grades [mm] or None, window [rad] or
        None)``.

    Returns
    -------
    (float, int or None, numpy.ndarray or None)
        TE peak-to-peak of the full model [rad] (NaN when ``verify`` is false), the chosen grade
        and the backlash of every grade [rad] (None without grades).
    """
    reducer, torque, theta, verify, grades, window = task
    te = full_model_te(reducer, torque, theta) if verify else float("nan")
    if grades is None or window is None:
        return te, None, None
    g, backlash = pin_grades(reducer, grades, window)
    return te, g, backlash
