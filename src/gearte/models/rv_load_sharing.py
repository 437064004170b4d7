"""Quasi-static load sharing of a whole RV reducer: springs, unilateral pin contacts, errors.

The reducer is a planar assembly of rigid bodies connected by springs (Han et al. 2023, Fig 2,
section 3.1 — here derived from kinematics and equilibrium, with inertia dropped):

==========  ==================================  ===============================================
body        degrees of freedom (ground frame)    connected by
==========  ==================================  ===============================================
sun         ``x_s, y_s`` (rotation prescribed)   support spring ``k_s``; meshes with planets
crank i     ``x_pi, y_pi, theta_pi``             mesh ``k_m`` (line of action), carrier bearing
                                                 ``k_b`` (isotropic), cam bearings ``k_cam``
disc j      ``x_dj, y_dj, theta_dj``             cam bearings, unilateral pin contacts
carrier     ``x_c, y_c, theta_c``                crank bearings, main bearings ``k_ca``
==========  ==================================  ===============================================

All coordinates are small displacements from the ideal kinematic position at output angle
``theta``; the input (sun) rotation is held at its kinematic value and the output torque ``T``
acts on the carrier against the drive direction. The carrier's rotation deviation
``theta_c`` is then the loaded output angle error, the total transmission error (TE).

Every connection is a scalar "spring row": ``w = B · q + e`` (deflection, ``e`` from
manufacturing errors), energy ``k w² / 2``. Isotropic bearings are two rows (x and y). A pin
contact is a unilateral row: approach ``delta = B · q - g`` with ``g`` the initial normal
clearance, force ``k max(delta, 0)``.

Pin-contact geometry (derived, not taken from a paper's figure): for disc ``j`` with eccentric
direction ``c_j`` the pitch point is ``P_j = a z_p c_j``; the contact normal of pin ``k`` passes
through ``P_j`` and the pin centre, ``n = (p_k - P_j)/|p_k - P_j|`` with ``|p_k - P_j| = r_p S``,
``S = sqrt(1 + K1² - 2 K1 cos phi)`` — hence the lever ``l = r_c sin(phi)/S`` of Hu 2020 eq 41
and the classical load law ``F ∝ sin(phi)/S`` for a rigid rotation of the disc.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.geometry.rv import RVReducer

__all__ = [
    "DofLayout",
    "RVSystem",
    "dof_layout",
    "hu2020_contact_deformation",
    "unrotated_clearance",
    "loaded_flank_clearance",
    "profile_curvature_radius",
    "assemble",
]


# ------------------------------------------------------------------------------------------
# Contact law and clearance (Hu et al. 2020, section 4)
# ------------------------------------------------------------------------------------------
def hu2020_contact_deformation(
    force: ArrayLike,
    rho: ArrayLike,
    pin_radius: float,
    youngs_modulus: float,
    poisson_ratio: float,
    face_width: float,
) -> np.ndarray:
    """Normal contact deformation of a pin on the cycloid disc [mm] (Hu 2020 eq 33–36).

    Parameters
    ----------
    force : array_like
        Contact force ``F`` [N] (> 0).
    rho : array_like
        Curvature radius of the disc profile at the contact ``ρ`` [mm] (sign ignored).
    pin_radius : float
        ``r_rp`` [mm].
    youngs_modulus : float
        ``E`` [MPa].
    poisson_ratio : float
        ``μ`` [-].
    face_width : float
        ``b`` [mm].

    Returns
    -------
    numpy.ndarray
        ``δ`` [mm].

    Notes
    -----
    ``δ = 2 F (1-μ²)/(π E b) [2/3 + ln(16 r_rp |ρ| / c²)]`` with the half-width as printed,
    ``c = 4.99e-3 sqrt(4 (1-μ²) F |ρ| r_rp / (E b (|ρ| + r_rp)))``. This is the reading of
    ``/work/shared/models/hu2020.md`` (it reproduces δ_max = 0.0116 mm at F = 1910.3 N of
    Table 4). Issue 2 (branch ``issue2``, ``gearte.models.cycloid_contact``) implements the
    same law for the cycloid stage alone; this copy exists because that branch was not yet
    committed when the RV model was written.

    Examples
    --------
    >>> float(np.round(hu2020_contact_deformation(1910.3, 43.57, 3.0, 2.06e5, 0.3, 11.0), 4))
    0.0116
    """
    f = np.asarray(force, dtype=float)
    r = np.abs(np.asarray(rho, dtype=float))
    one_mu2 = 1.0 - poisson_ratio**2
    c2 = (4.99e-3) ** 2 * (
        4.0 * one_mu2 * f * r * pin_radius / (youngs_modulus * face_width * (r + pin_radius))
    )
    return (
        2.0
        * f
        * one_mu2
        / (np.pi * youngs_modulus * face_width)
        * (2.0 / 3.0 + np.log(16.0 * pin_radius * r / c2))
    )


def unrotated_clearance(phi: ArrayLike, K1: float, d_rrp: float, d_rp: float) -> np.ndarray:  # noqa: N803
    """Normal clearance between a modified disc and pin ``phi`` in the nominal position [mm].

    Parameters
    ----------
    phi : array_like
        Meshing phase of the pin, measured from the line of centres [rad].
    K1 : float
        Short-width coefficient ``a z_p/(r_p + Δr_p)`` [-].
    d_rrp, d_rp : float
        Equidistant ``Δr_rp`` and shift ``Δr_p`` modifications [mm] (Hu 2020 convention).

    Returns
    -------
    numpy.ndarray
        ``Δ_u(φ) = Δr_rp − Δr_p (1 − K1 cos φ)/S`` [mm]; symmetric in ``±φ`` (both flanks).

    Notes
    -----
    Hu 2020 eq 32 gives the clearance *after* the disc has been turned to close the first
    contact; it equals ``Δ_u(φ) − (Δr_rp − Δr_p sqrt(1−K1²)) sin φ / S``, i.e. ``Δ_u`` minus
    the normal approach of a rigid rotation ``r_c β₀ = Δr_rp − Δr_p sqrt(1−K1²)`` that closes
    the gap at ``φ₀ = arccos K1``. The RV model needs the clearance before any rotation
    (the rotation is an unknown of the equilibrium, and both flanks matter for backlash), hence
    this form; ``loaded_flank_clearance`` checks it against eq 32.
    """
    p = np.asarray(phi, dtype=float)
    s = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(p))
    return d_rrp - d_rp * (1.0 - K1 * np.cos(p)) / s


def loaded_flank_clearance(phi: ArrayLike, K1: float, d_rrp: float, d_rp: float) -> np.ndarray:  # noqa: N803
    """Hu 2020 eq 32: clearance after the rotation that closes the first contact [mm]."""
    p = np.asarray(phi, dtype=float)
    s = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(p))
    return (
        d_rrp * (1.0 - np.sin(p) / s)
        - d_rp * (1.0 - K1 * np.cos(p) - np.sqrt(1.0 - K1 * K1) * np.sin(p)) / s
    )


def profile_curvature_radius(phi: ArrayLike, K1: float, pin_count: int, r_p: float, r_rp: float):  # noqa: N803
    """Curvature radius of the cycloid profile [mm], Hu 2020 eq 40.

    ``ρ(φ) = r_p S³ / (K1 (z_p+1) cos φ − (1 + z_p K1²)) + r_rp``; at ``φ₀ = arccos K1`` it is
    ``−r_p sqrt(1−K1²) + r_rp`` (negative = concave).
    """
    p = np.asarray(phi, dtype=float)
    s = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(p))
    return r_p * s**3 / (K1 * (pin_count + 1) * np.cos(p) - (1.0 + pin_count * K1 * K1)) + r_rp


# ------------------------------------------------------------------------------------------
# Degrees of freedom and assembly
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DofLayout:
    """Index layout of the displacement vector ``q``."""

    n_cranks: int
    n_discs: int

    @property
    def sun(self) -> int:
        return 0

    def crank(self, i: int) -> int:
        return 2 + 3 * i

    def disc(self, j: int) -> int:
        return 2 + 3 * self.n_cranks + 3 * j

    @property
    def carrier(self) -> int:
        return 2 + 3 * self.n_cranks + 3 * self.n_discs

    @property
    def size(self) -> int:
        return self.carrier + 3

    @property
    def output_rotation(self) -> int:
        """Index of the carrier rotation (the output angle error)."""
        return self.carrier + 2


def dof_layout(reducer: RVReducer) -> DofLayout:
    """DOF layout of a reducer."""
    return DofLayout(reducer.cranks.count, reducer.discs.count)


@dataclass(frozen=True)
class RVSystem:
    """Spring rows and contact rows of a reducer at ``P`` output positions.

    Attributes
    ----------
    theta : (P,) output angles [rad].
    spring_B : (P, ns, nd) rows; spring_e : (P, ns) offsets [mm]; spring_k : (ns,) [N/mm].
    contact_B : (P, nc, nd) rows; contact_gap : (P, nc) clearances [mm];
    contact_group : (nc,) disc index of each contact; contact_pin : (nc,) pin index.
    unit_load : (nd,) generalised force of a unit output torque [1/mm per N·mm].
    labels : dict of slices into the spring rows (``"cam"``, ``"carrier_bearing"``, ``"mesh"``...).
    """

    theta: np.ndarray
    spring_B: np.ndarray
    spring_e: np.ndarray
    spring_k: np.ndarray
    contact_B: np.ndarray
    contact_gap: np.ndarray
    contact_group: np.ndarray
    contact_pin: np.ndarray
    unit_load: np.ndarray
    labels: dict
    layout: DofLayout


def _u(a: np.ndarray) -> np.ndarray:
    """Unit vectors ``(cos a, sin a)`` stacked on the last axis."""
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _rot(v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v[..., 2]`` by angles ``a`` (broadcast)."""
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _point_row(row: np.ndarray, dof: int, r: np.ndarray, n: np.ndarray, sign: float, rot=True):
    """Add ``sign * n · u(point)`` of a body (dof x, y, theta) with lever ``r`` to ``row``.

    ``row``: (P, nd); ``r``, ``n``: (P, 2).
    """
    row[:, dof] += sign * n[:, 0]
    row[:, dof + 1] += sign * n[:, 1]
    if rot:
        row[:, dof + 2] += sign * (r[:, 0] * n[:, 1] - r[:, 1] * n[:, 0])


def assemble(reducer: RVReducer, theta: ArrayLike) -> RVSystem:
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
    ex, ey = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    zero2 = np.zeros((P, 2))

    rows: list[np.ndarray] = []
    offs: list[np.ndarray] = []
    ks: list[float] = []
    labels: dict[str, slice] = {}

    def add(row, off, k):
        rows.append(row)
        offs.append(off)
        ks.append(k)

    # sun support (2 rows)
    start = len(rows)
    for d in (ex, ey):
        r = np.zeros((P, nd))
        _point_row(r, lay.sun, zero2, np.broadcast_to(d, (P, 2)), 1.0, rot=False)
        add(r, np.zeros(P), reducer.first_stage.sun_support_stiffness)
    labels["sun_support"] = slice(start, len(rows))

    # carrier main bearings (2 rows)
    start = len(rows)
    for d in (ex, ey):
        r = np.zeros((P, nd))
        _point_row(r, lay.carrier, zero2, np.broadcast_to(d, (P, 2)), 1.0)
        add(r, np.zeros(P), reducer.supports.carrier_radial_stiffness)
    labels["main_bearing"] = slice(start, len(rows))

    crank_ang = th[:, None] + 2.0 * np.pi * np.arange(M)[None, :] / M  # (P, M)
    crank_pos = Rdc * _u(crank_ang)  # (P, M, 2)
    ecc1 = -zc * th  # absolute crank angle = eccentric direction of disc 1
    ecc = ecc1[:, None] + 2.0 * np.pi * np.arange(N)[None, :] / N  # (P, N)

    # carrier crank bearings: w = u_crank - u_carrier(bore) - eps_carrier
    start = len(rows)
    for i in range(M):
        eps = _rot(np.broadcast_to(err.carrier_bore[i], (P, 2)), crank_ang[:, i])
        for d in (ex, ey):
            r = np.zeros((P, nd))
            dd = np.broadcast_to(d, (P, 2))
            _point_row(r, lay.crank(i), zero2, dd, 1.0)
            _point_row(r, lay.carrier, crank_pos[:, i], dd, -1.0)
            add(r, -eps @ d, reducer.cranks.carrier_bearing_stiffness)
    labels["carrier_bearing"] = slice(start, len(rows))

    # cam bearings: w = u_crank(cam) + eps_cam - u_disc(bore) - eps_bore
    start = len(rows)
    for i in range(M):
        for j in range(N):
            cam_r = a * _u(ecc[:, j])
            eps_cam = _rot(np.broadcast_to(err.cam[i, j], (P, 2)), ecc[:, j])
            eps_bore = _rot(np.broadcast_to(err.disc_bore[j, i], (P, 2)), crank_ang[:, i])
            for d in (ex, ey):
                r = np.zeros((P, nd))
                dd = np.broadcast_to(d, (P, 2))
                _point_row(r, lay.crank(i), cam_r, dd, 1.0)
                _point_row(r, lay.disc(j), crank_pos[:, i], dd, -1.0)
                add(r, (eps_cam - eps_bore) @ d, reducer.cranks.cam_bearing_stiffness)
    labels["cam_bearing"] = slice(start, len(rows))

    # sun-planet meshes along the working line of action (sun drives, counter-clockwise)
    start = len(rows)
    alpha_w = reducer.working_pressure_angle
    rb1, _ = reducer.first_stage.base_radii
    z1, z2 = reducer.first_stage.sun_teeth, reducer.first_stage.planet_teeth
    rw1 = Rdc * z1 / (z1 + z2)
    for i in range(M):
        rho = _u(crank_ang[:, i])
        t = _u(crank_ang[:, i] + np.pi / 2)
        n = np.cos(alpha_w) * t + np.sin(alpha_w) * rho  # force direction on the planet
        pitch = rw1 * rho
        cp = crank_pos[:, i]
        tp = pitch - np.sum((pitch - cp) * n, axis=-1, keepdims=True) * n
        r = np.zeros((P, nd))
        _point_row(r, lay.sun, zero2, n, 1.0, rot=False)
        _point_row(r, lay.crank(i), tp - cp, n, -1.0)
        eps_pl = _rot(np.broadcast_to(err.planet[i], (P, 2)), ecc1)
        add(r, -np.sum(eps_pl * n, axis=-1), reducer.first_stage.mesh_stiffness)
    labels["mesh"] = slice(start, len(rows))

    spring_B = np.stack(rows, axis=1)
    spring_e = np.stack(offs, axis=1)
    spring_k = np.asarray(ks)

    # pin contacts
    pins = reducer.pins
    alpha_k = 2.0 * np.pi * np.arange(zp) / zp
    pin_pos = pins.circle_radius * _u(alpha_k)  # (zp, 2)
    pin_err = pins.radial_position_errors[:, None] * _u(alpha_k) + pins.tangential_position_errors[
        :, None
    ] * _u(alpha_k + np.pi / 2)
    K1m = reducer.K1
    cB = np.zeros((P, N * zp, nd))
    cg = np.zeros((P, N * zp))
    group = np.repeat(np.arange(N), zp)
    pin_index = np.tile(np.arange(zp), N)
    for j in range(N):
        cdir = _u(ecc[:, j])  # (P, 2)
        ppt = a * zp * cdir
        centre = a * cdir
        v = pin_pos[None, :, :] - ppt[:, None, :]  # (P, zp, 2)
        n = v / np.linalg.norm(v, axis=-1, keepdims=True)
        contact = pin_pos[None] - pins.pin_radius * n
        lever = contact - centre[:, None, :]
        dof = lay.disc(j)
        sl = slice(j * zp, (j + 1) * zp)
        cB[:, sl, dof] = n[..., 0]
        cB[:, sl, dof + 1] = n[..., 1]
        cB[:, sl, dof + 2] = lever[..., 0] * n[..., 1] - lever[..., 1] * n[..., 0]
        phi = alpha_k[None, :] - ecc[:, j][:, None]
        gap = unrotated_clearance(
            phi, K1m, reducer.discs.equidistant_modification, reducer.discs.shift_modification
        )
        gap = gap - pins.radius_errors[None, :] + np.sum(n * pin_err[None], axis=-1)
        cg[:, sl] = gap

    unit = np.zeros(nd)
    unit[lay.output_rotation] = -1.0  # load torque resists the drive
    return RVSystem(th, spring_B, spring_e, spring_k, cB, cg, group, pin_index, unit, labels, lay)
