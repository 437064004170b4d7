"""``assemble`` and ``pin_contacts`` vectorised over cranks, discs and directions: every array
of the system bit-identical (values and bytes, so the sign of a zero too) to the loops they
replaced, kept below verbatim as the reference (only the names of the copies changed; the
reference's pin normals were later turned to the true contact point of a shifted profile, as
the model's)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.typing import ArrayLike

from gearte.cases import list_cases
from gearte.errors import ParameterError
from gearte.geometry.measured import MeasuredDisc
from gearte.geometry.rv import PinContacts, RVReducer, pin_contacts
from gearte.io.case_file import load_case
from gearte.models.rv_load_sharing import (
    RVSystem,
    assemble,
    cam_row_stiffness,
    dof_layout,
    mesh_row_stiffness,
    output_positions,
)


# ------------------------------------------------------------------------------------------
# The reference: gearte.geometry.rv.pin_contacts and gearte.models.rv_load_sharing.assemble
# (with its helpers) as they were before the vectorisation, verbatim.
# ------------------------------------------------------------------------------------------
def _pin_contacts_reference(reducer: RVReducer, theta: np.ndarray) -> PinContacts:
    """Contact normals, arms and initial clearances of all pins of all discs (every error family).

    The one computation of the pin clearances that the quasi-static model
    (:func:`gearte.models.rv_load_sharing.assemble`) and the dynamics
    (:func:`gearte.models.rv_dynamics.disc_rotation_error`) read.

    Parameters
    ----------
    reducer : RVReducer
        The description with its errors (per-pin radius and position, disc run-out and
        cumulative pitch, per-disc modification errors).
    theta : numpy.ndarray
        Output angles [rad], ``(P,)``.

    Returns
    -------
    PinContacts

    Notes
    -----
    Disc ``j``'s eccentric points along ``χ_j = −z_c θ + 2π j / N`` (module conventions); its
    pitch point is ``P_j = a z_p ê(χ_j)``; the normal of pin ``k`` (centre ``p_k`` at
    ``α_k = 2π k / z_p``) passes through ``P_j`` and ``p_k`` (Hu 2020 eq 36), the contact point
    lies ``r_rp`` inside the pin centre on it. The clearance of the modified profile is Hu 2020
    eq 32 (:func:`gearte.geometry.cycloid.normal_clearance_unclosed`). Disc errors are in the
    disc frame, which turns with the carrier (angle ``θ``): the run-out ``r`` translates the
    profile (gap ``−n·r``); the cumulative pitch deviation ``s(ψ) = ΔF_p/2 sin(ψ − angle)`` at
    the contact's disc-frame angle ``ψ`` turns the flank locally by ``s / r_c`` (gap
    ``−arm · s / r_c``).

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481, eq 32, 36.
    doi:10.3390/app10020481
    """
    from gearte.geometry.cycloid import normal_clearance_unclosed, true_contact

    th = np.atleast_1d(np.asarray(theta, dtype=float))
    P = th.size
    N = reducer.discs.count
    pins, err = reducer.pins, reducer.error_set
    zp, zc = pins.count, reducer.cycloid_teeth
    a = reducer.cranks.eccentricity
    alpha_k = 2.0 * np.pi * np.arange(zp) / zp
    pin_dir = np.stack([np.cos(alpha_k), np.sin(alpha_k)], -1)  # (zp, 2)
    pin_pos = pins.circle_radius * pin_dir
    pin_err = pins.radial_position_errors[:, None] * pin_dir + pins.tangential_position_errors[
        :, None
    ] * np.stack([-pin_dir[:, 1], pin_dir[:, 0]], -1)
    ecc = -zc * th[:, None] + 2.0 * np.pi * np.arange(N)[None, :] / N  # (P, N)
    cdir = np.stack([np.cos(ecc), np.sin(ecc)], -1)  # (P, N, 2)
    v = pin_pos[None, None] - (a * zp * cdir)[:, :, None, :]  # (P, N, zp, 2)
    n = v / np.linalg.norm(v, axis=-1, keepdims=True)
    phi = alpha_k[None, None, :] - ecc[:, :, None]
    if reducer.discs.shift_modification != 0.0:
        # added with the true contact point: the normal turned to it on the design's shifted
        # profile (gearte.geometry.cycloid.true_contact), the same for every disc
        turn = true_contact(
            phi, z_p=zp, r_p=pins.circle_radius, a=a, dr_p=reducer.discs.shift_modification
        )[2]
        ct, st = np.cos(turn), np.sin(turn)
        n = np.stack([ct * n[..., 0] - st * n[..., 1], st * n[..., 0] + ct * n[..., 1]], -1)
    lever = pin_pos[None, None] - pins.pin_radius * n - (a * cdir)[:, :, None, :]
    arm = lever[..., 0] * n[..., 1] - lever[..., 1] * n[..., 0]
    gap = np.empty((P, N, zp))
    c, s_ = np.cos(th), np.sin(th)
    for j in range(N):
        d_rp, d_p = err.disc_modification[j]
        g = normal_clearance_unclosed(
            phi[:, j],
            z_p=zp,
            r_p=pins.circle_radius,
            a=a,
            dr_rp=reducer.discs.equidistant_modification + d_rp,
            dr_p=reducer.discs.shift_modification + d_p,
        )
        g = g - pins.radius_errors[None, :] + np.sum(n[:, j] * pin_err[None], axis=-1)
        rx, ry = err.disc_runout[j]
        runout = np.stack([rx * c - ry * s_, rx * s_ + ry * c], -1)  # disc frame -> ground
        g = g - np.sum(n[:, j] * runout[:, None, :], axis=-1)
        fp = float(np.hypot(*err.disc_pitch[j]))
        if fp > 0.0:
            psi = np.arctan2(lever[:, j, :, 1], lever[:, j, :, 0]) - th[:, None]
            ang = np.arctan2(err.disc_pitch[j, 1], err.disc_pitch[j, 0])
            g = g - arm[:, j] * 0.5 * fp * np.sin(psi - ang) / (a * zc)
        measured = None if err.measured_discs is None else err.measured_discs[j]
        if measured is not None:  # measured flank per tooth and pitch per tooth (issue 16)
            g = g + measured.gap_change(np.arange(zp)[None, :], phi[:, j], arm[:, j], a * zc)
        gap[:, j] = g
    return PinContacts(th, n, lever, arm, phi, gap)


def _u_ref(a: np.ndarray) -> np.ndarray:
    """Unit vectors ``(cos a, sin a)`` stacked on the last axis."""
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _rot_ref(v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v[..., 2]`` by angles ``a`` (broadcast)."""
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _point_row_ref(row: np.ndarray, dof: int, r: np.ndarray, n: np.ndarray, sign: float, rot=True):
    """Add ``sign * n · u(point)`` of a body (dof x, y, theta) with lever ``r`` to ``row``.

    ``row``: (P, nd); ``r``, ``n``: (P, 2).
    """
    row[:, dof] += sign * n[:, 0]
    row[:, dof + 1] += sign * n[:, 1]
    if rot:
        row[:, dof + 2] += sign * (r[:, 0] * n[:, 1] - r[:, 1] * n[:, 0])


def _measured_ref(design: float, measured: np.ndarray | None, index) -> float:
    """A bearing's clearance [mm]: the measured one of that bearing if given, else the design's."""
    return design if measured is None else float(measured[index])


def _assemble_reference(reducer: RVReducer, theta: ArrayLike) -> RVSystem:
    """Spring and contact rows of ``reducer`` at output angles ``theta`` [rad].

    Parameters
    ----------
    reducer : RVReducer
    theta : array_like
        Output (carrier) angles [rad], shape ``(P,)``.

    Returns
    -------
    RVSystem
    """
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    if th.ndim != 1 or not np.all(np.isfinite(th)):
        raise ParameterError("theta", theta, "must be a finite 1-D array of angles [rad]")
    P = th.size
    lay = dof_layout(reducer)
    nd = lay.size
    M, N = reducer.cranks.count, reducer.discs.count
    zp, zc = reducer.pins.count, reducer.cycloid_teeth
    a = reducer.cranks.eccentricity
    Rdc = reducer.cranks.circle_radius
    err = reducer.errors
    assert err is not None  # RVReducer.__post_init__ fills in zero errors
    ex, ey = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    zero2 = np.zeros((P, 2))

    rows: list[np.ndarray] = []
    offs: list[np.ndarray] = []
    ks: list[float] = []
    cs: list[float] = []
    labels: dict[str, slice] = {}

    def add(row, off, k, c=0.0):
        rows.append(row)
        offs.append(off)
        ks.append(k)
        cs.append(c)

    # sun support (2 rows): w = u_sun - seat offset (sun assembly error, ground frame)
    start = len(rows)
    for d in (ex, ey):
        r = np.zeros((P, nd))
        _point_row_ref(r, lay.sun, zero2, np.broadcast_to(d, (P, 2)), 1.0, rot=False)
        add(r, np.full(P, -err.sun_seat @ d), reducer.first_stage.sun_support_stiffness)
    labels["sun_support"] = slice(start, len(rows))

    # carrier main bearings (2 rows): w = u_carrier - seat offset (output assembly error)
    start = len(rows)
    for d in (ex, ey):
        r = np.zeros((P, nd))
        _point_row_ref(r, lay.carrier, zero2, np.broadcast_to(d, (P, 2)), 1.0)
        add(r, np.full(P, -err.output_seat @ d), reducer.supports.carrier_radial_stiffness)
    labels["main_bearing"] = slice(start, len(rows))

    crank_ang = th[:, None] + 2.0 * np.pi * np.arange(M)[None, :] / M  # (P, M)
    crank_pos = Rdc * _u_ref(crank_ang)  # (P, M, 2)
    ecc1 = -zc * th  # absolute crank angle = eccentric direction of disc 1
    ecc = ecc1[:, None] + 2.0 * np.pi * np.arange(N)[None, :] / N  # (P, N)

    # carrier crank bearings: w = u_crank - u_carrier(bore) - eps_carrier
    start = len(rows)
    for i in range(M):
        eps = _rot_ref(np.broadcast_to(err.carrier_bore[i], (P, 2)), crank_ang[:, i])
        for d in (ex, ey):
            r = np.zeros((P, nd))
            dd = np.broadcast_to(d, (P, 2))
            _point_row_ref(r, lay.crank(i), zero2, dd, 1.0)
            _point_row_ref(r, lay.carrier, crank_pos[:, i], dd, -1.0)
            add(
                r,
                -eps @ d,
                reducer.cranks.carrier_bearing_stiffness,
                _measured_ref(reducer.cranks.carrier_bearing_clearance, err.carrier_clearance, i),
            )
    labels["carrier_bearing"] = slice(start, len(rows))

    # cam bearings: w = u_crank(cam) + eps_cam - u_disc(bore) - eps_bore
    start = len(rows)
    for i in range(M):
        for j in range(N):
            cam_r = a * _u_ref(ecc[:, j])
            eps_cam = _rot_ref(np.broadcast_to(err.cam[i, j], (P, 2)), ecc[:, j])
            eps_bore = _rot_ref(np.broadcast_to(err.disc_bore[j, i], (P, 2)), crank_ang[:, i])
            for d in (ex, ey):
                r = np.zeros((P, nd))
                dd = np.broadcast_to(d, (P, 2))
                _point_row_ref(r, lay.crank(i), cam_r, dd, 1.0)
                _point_row_ref(r, lay.disc(j), crank_pos[:, i], dd, -1.0)
                add(
                    r,
                    (eps_cam - eps_bore) @ d,
                    # the cam bearing in series with the crank's bending (stiffness chain;
                    # the one change to the verbatim reference)
                    float(cam_row_stiffness(reducer)[j]),
                    _measured_ref(reducer.cranks.cam_bearing_clearance, err.cam_clearance, (i, j)),
                )
    labels["cam_bearing"] = slice(start, len(rows))

    # sun-planet meshes along the working line of action (sun drives, counter-clockwise)
    start = len(rows)
    alpha_w = reducer.working_pressure_angle
    rb1, _ = reducer.first_stage.base_radii
    z1, z2 = reducer.first_stage.sun_teeth, reducer.first_stage.planet_teeth
    rw1 = Rdc * z1 / (z1 + z2)
    for i in range(M):
        rho = _u_ref(crank_ang[:, i])
        t = _u_ref(crank_ang[:, i] + np.pi / 2)
        n = np.cos(alpha_w) * t + np.sin(alpha_w) * rho  # force direction on the planet
        pitch = rw1 * rho
        cp = crank_pos[:, i]
        tp = pitch - np.sum((pitch - cp) * n, axis=-1, keepdims=True) * n
        r = np.zeros((P, nd))
        _point_row_ref(r, lay.sun, zero2, n, 1.0, rot=False)
        _point_row_ref(r, lay.crank(i), tp - cp, n, -1.0)
        eps_pl = _rot_ref(np.broadcast_to(err.planet[i], (P, 2)), ecc1)
        eps_sun = _rot_ref(np.broadcast_to(err.sun, (P, 2)), reducer.ratio * th)
        # the mesh in series with the crank's torsion (stiffness chain)
        add(r, np.sum((eps_sun - eps_pl) * n, axis=-1), mesh_row_stiffness(reducer))
    labels["mesh"] = slice(start, len(rows))

    spring_B = np.stack(rows, axis=1)
    spring_e = np.stack(offs, axis=1)
    spring_k = np.asarray(ks)

    # pin contacts: normals, arms and initial clearances with every error family
    # (gearte.geometry.rv.pin_contacts, the one computation the dynamics reads too)
    pc = _pin_contacts_reference(reducer, th)
    cB = np.zeros((P, N * zp, nd))
    group = np.repeat(np.arange(N), zp)
    pin_index = np.tile(np.arange(zp), N)
    for j in range(N):
        dof = lay.disc(j)
        sl = slice(j * zp, (j + 1) * zp)
        cB[:, sl, dof] = pc.normal[:, j, :, 0]
        cB[:, sl, dof + 1] = pc.normal[:, j, :, 1]
        cB[:, sl, dof + 2] = pc.arm[:, j]
    cg = pc.gap.reshape(P, N * zp)
    cphase = pc.phase.reshape(P, N * zp)

    unit = np.zeros(nd)
    unit[lay.output_rotation] = -1.0  # load torque resists the drive
    return RVSystem(
        th,
        spring_B,
        spring_e,
        spring_k,
        cB,
        cg,
        group,
        pin_index,
        unit,
        labels,
        lay,
        np.asarray(cs),
        cphase,
    )


# ------------------------------------------------------------------------------------------
# Comparison
# ------------------------------------------------------------------------------------------
SYSTEM_ARRAYS = (
    "theta",
    "spring_B",
    "spring_e",
    "spring_k",
    "spring_c",
    "contact_B",
    "contact_gap",
    "contact_group",
    "contact_pin",
    "contact_phase",
    "unit_load",
)
CONTACT_ARRAYS = ("theta", "normal", "lever", "arm", "phase", "gap")


def _identical(got, want, what: str) -> None:
    """Same dtype, shape, values and bytes (``-0.0`` differs from ``+0.0``)."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.dtype == want.dtype, f"{what}: dtype {got.dtype} != {want.dtype}"
    assert got.shape == want.shape, f"{what}: shape {got.shape} != {want.shape}"
    assert np.array_equal(got, want, equal_nan=True), f"{what}: values differ"
    assert got.tobytes() == want.tobytes(), f"{what}: bytes differ (sign of a zero?)"


def _same_system(got: RVSystem, want: RVSystem, what: str) -> None:
    for name in SYSTEM_ARRAYS:
        _identical(getattr(got, name), getattr(want, name), f"{what}: {name}")
    assert got.labels == want.labels, f"{what}: labels"
    assert list(got.labels) == list(want.labels), f"{what}: label order"
    assert got.layout == want.layout, f"{what}: layout"


def _same_contacts(got: PinContacts, want: PinContacts, what: str) -> None:
    for name in CONTACT_ARRAYS:
        _identical(getattr(got, name), getattr(want, name), f"{what}: {name}")


# ------------------------------------------------------------------------------------------
# Reducers and angles
# ------------------------------------------------------------------------------------------
THETAS = {
    "P1": np.array([0.0]),
    "P1_negative": np.array([-0.3]),
    "P1_over_2pi": np.array([7.1]),
    "P7": np.array([-7.0, -math.pi, -0.0, 0.0, 0.5, 2.0 * math.pi, 9.5]),
    "P12_window": 0.37 + np.linspace(-0.02, 0.02, 12),
    "P360": output_positions(360),
    "P360_shifted": np.linspace(-7.0, 13.0, 360),
}

RV_MODULES = ("rv_reducer", "rv_serial", "rv_bench", "rv_lot")


def _case_reducers(name: str) -> dict[str, RVReducer]:
    """The reducers a bundled case builds (none for a case of another kind)."""
    case = load_case(list_cases()[name])
    kind = type(case).__module__.rsplit(".", 1)[-1]
    if kind == "rv_reducer":
        from gearte.studies.rv_reducer import build_reducer

        return {name: build_reducer(case.reducer)}
    if kind == "rv_serial":
        from gearte.studies.rv_serial import build_serial

        _, red, _ = build_serial(case)
        return {name: red}
    if kind == "rv_bench":
        from gearte.studies.rv_bench import _reducer

        return {name: _reducer(case.reducer)[0]}
    if kind == "rv_lot":
        from gearte.runners.selective_assembly import Orientation, assembled_reducer
        from gearte.studies.rv_lot import build_lot

        design, lot = build_lot(case)
        out = {f"{name} design": design}
        for kd, kc, o in (
            (0, 0, Orientation()),
            (3, 5, Orientation(disc_shift=1, disc_index=2, crank_shift=1)),
            (lot.disc_sets - 1, 2, Orientation(crank_shift=2, planet_index=1, planet_indexings=3)),
        ):
            out[f"{name} {kd}/{kc} {o}"] = assembled_reducer(design, lot, kd, kc, o)
        return out
    return {}


def _every_error(red: RVReducer, seed: int, n_discs: int | None = None) -> RVReducer:
    """``red`` (optionally with another disc count) with random errors of every family, some
    components exactly zero or negative zero, and bearing clearances (design and measured)."""
    rng = np.random.default_rng(seed)
    m = red.cranks.count
    n = red.discs.count if n_discs is None else n_discs
    zp, zc = red.pins.count, red.cycloid_teeth

    def e(*shape: int) -> np.ndarray:
        v = rng.uniform(-0.02, 0.02, shape)
        flat = v.reshape(-1)
        flat[2::7] = 0.0
        flat[4::11] = -0.0
        if flat.size >= 6:  # one whole vector of negative zeros
            flat[:2] = -0.0
        return v

    measured = tuple(
        MeasuredDisc(
            zc,
            tuple(np.linspace(-0.5, 0.5, 7) for _ in range(zc)),
            tuple(rng.uniform(-0.003, 0.003, 7) for _ in range(zc)),
            rng.uniform(-0.01, 0.01, zc),
            f"D{j}",
        )
        if j % 2 == 0
        else None
        for j in range(n)
    )
    err = type(red.error_set)(
        e(m, 2),
        e(n, m, 2),
        e(m, n, 2),
        e(m, 2),
        e(2),
        e(2),
        e(2),
        e(n, 2),
        np.vstack([np.zeros((1, 2)), e(n - 1, 2)]) if n > 1 else e(n, 2),
        e(n, 2) * 0.1,
        measured,
        np.abs(e(m, n)) * 0.2,
        np.abs(e(m)) * 0.2,
    )
    pins = dataclasses.replace(
        red.pins,
        radius_errors=e(zp) * 0.2,
        radial_position_errors=e(zp) * 0.3,
        tangential_position_errors=e(zp) * 0.3,
    )
    cranks = dataclasses.replace(
        red.cranks,
        cam_bearing_clearance=0.004,
        carrier_bearing_clearance=0.003,
        bending_compliance=None if red.cranks.bending_compliance is None else (7e-7,) * n,
    )
    discs = dataclasses.replace(red.discs, count=n)
    return red.replace(pins=pins, cranks=cranks, discs=discs, errors=err)


def _synthetic_reducers() -> dict[str, RVReducer]:
    from gearte.studies.rv_reducer import build_reducer

    out = {}
    for k, name in enumerate(("han2023_rv110e", "hu2020_rv80e_initial_reducer")):
        red = build_reducer(load_case(list_cases()[name]).reducer)
        out[f"{name} every error"] = _every_error(red, 10 + k)
        out[f"{name} every error, 1 disc"] = _every_error(red, 20 + k, n_discs=1)
        out[f"{name} every error, 3 discs"] = _every_error(red, 30 + k, n_discs=3)
        # design clearances without measured ones (the other branch of the clearance lookup)
        red = _every_error(red, 40 + k)
        out[f"{name} design clearances"] = red.with_errors(
            dataclasses.replace(red.error_set, cam_clearance=None, carrier_clearance=None)
        )
    return out


def _check(red: RVReducer, what: str) -> None:
    for key, theta in THETAS.items():
        _same_contacts(
            pin_contacts(red, theta), _pin_contacts_reference(red, theta), f"{what} {key}"
        )
        _same_system(assemble(red, theta), _assemble_reference(red, theta), f"{what} {key}")
    # lists (of floats, of ints), a scalar and no angle, as callers may pass them
    for theta in ([0.1, -0.2], [1, 2, 3], 0.25, np.array([])):
        _same_system(assemble(red, theta), _assemble_reference(red, theta), f"{what} {theta}")


# ------------------------------------------------------------------------------------------
# Tests
# ------------------------------------------------------------------------------------------
def _rv_case_names() -> list[str]:
    """The bundled cases of the kinds that build an RV reducer (their ``[case] kind`` read from
    the TOML, unvalidated)."""
    import tomllib

    kinds = {"rv_reducer", "rv_serial", "rv_bench", "rv_lot"}
    return sorted(
        name
        for name, path in list_cases().items()
        if tomllib.loads(path.read_text(encoding="utf-8")).get("case", {}).get("kind") in kinds
    )


@pytest.mark.parametrize("name", _rv_case_names())
def test_bundled_case_bit_identical(name):
    reducers = _case_reducers(name)
    assert reducers, f"{name} builds no RV reducer"
    for what, red in reducers.items():
        _check(red, what)


def test_every_error_family_and_clearances_bit_identical():
    reducers = _synthetic_reducers()
    # the variants do carry every family (a zero family would test nothing)
    for red in reducers.values():
        e = red.error_set
        for name in (
            "planet",
            "disc_bore",
            "cam",
            "carrier_bore",
            "sun",
            "sun_seat",
            "output_seat",
            "disc_runout",
            "disc_modification",
        ):
            assert np.any(getattr(e, name) != 0.0), name
        assert np.any(red.pins.radius_errors != 0.0)
        assert red.cranks.cam_bearing_clearance > 0.0
    for what, red in reducers.items():
        _check(red, what)


def test_comparison_catches_a_changed_row_and_the_sign_of_zero():
    red = _synthetic_reducers()["han2023_rv110e every error"]
    theta = THETAS["P7"]
    want = _assemble_reference(red, theta)
    flipped = dataclasses.replace(want, spring_B=want.spring_B.copy())
    flipped.spring_B[:, 5] *= -1.0
    with pytest.raises(AssertionError, match="spring_B"):
        _same_system(flipped, want, "flipped row")
    moved = dataclasses.replace(want, spring_e=want.spring_e.copy())
    moved.spring_e[3, -1] += 1e-15
    with pytest.raises(AssertionError, match="spring_e"):
        _same_system(moved, want, "moved offset")
    with pytest.raises(AssertionError, match="bytes"):
        _identical(np.array([-0.0]), np.array([0.0]), "zero")


@pytest.mark.parametrize("theta", [[np.nan], [[0.0, 1.0]], [0.0, np.inf]])
def test_same_errors_as_the_reference(theta):
    from gearte.studies.rv_reducer import build_reducer

    red = build_reducer(load_case(list_cases()["han2023_rv110e"]).reducer)
    with pytest.raises(ParameterError) as want:
        _assemble_reference(red, theta)
    with pytest.raises(ParameterError) as got:
        assemble(red, theta)
    assert str(got.value) == str(want.value)


def test_sum2_is_numpy_sum_bit_for_bit():
    """``gearte.geometry.rv._sum2`` is ``np.sum`` over a last axis of two, signs of zeros too."""
    from gearte.geometry.rv import _sum2

    v = np.array([-0.0, 0.0, 1e-300, -1e-300, 5e-324, 1.5, -1.5, 3.0, -np.inf])
    x, y = (a.ravel() for a in np.meshgrid(v, v))
    _identical(_sum2(x, y), np.sum(np.stack([x, y], -1), axis=-1), "sum of two")
    _identical(_sum2(x[:, None], y[:, None]), np.sum(np.stack([x, y], -1)[:, None], -1), "2-D")
