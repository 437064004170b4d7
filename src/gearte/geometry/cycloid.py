"""Geometry of a modified cycloid disc meshing with a pin wheel (Hu et al. 2020, section 2.1).

Units: mm, rad. Symbols follow the paper: ``z_p`` pins, ``z_c = z_p - 1`` cycloid teeth, ``r_p``
pin-centre-circle radius, ``r_rp`` pin radius, ``a`` eccentricity, ``dr_rp`` equidistant
("isometric") modification Δr_rp, ``dr_p`` shifted ("moving") modification Δr_p and, beyond the
paper, a rotation modification δ_rot [rad].

Sign conventions
----------------
* The disc is ground with the pin-circle radius ``R = r_p + dr_p`` and the pin radius
  ``r = r_rp + dr_rp`` (eq 1–3). ``dr_rp > 0`` and ``dr_p < 0`` remove material (clearance).
* The meshing phase of a pin, φ, is measured from the line of centres; the pin at φ = 0 sits in
  a tooth space (root), the one at φ = π on a tooth tip. Pin ``i`` (1-based) of the reference mesh
  position sits at φ_i = 2π(i − 1)/z_p. For the torque direction of the paper's section 4 the loaded
  flank is sin φ > 0.
* The rotation modification δ_rot thins every tooth by turning each flank towards the tooth centre
  by δ_rot: it removes a normal layer ``l(φ) δ_rot`` from both flanks (l the arm of the contact
  normal), adds 2 δ_rot of lost motion and leaves the loaded-flank clearance after the closing
  rotation (eq 32) unchanged.

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.limits import check_floor

__all__ = [
    "CycloidStage",
    "K1_DEFINITIONS",
    "geometry_radii",
    "short_width_coefficient",
    "meshing_phase",
    "pin_phases",
    "profile_xy",
    "theoretical_profile_xy",
    "root_radius",
    "tip_radius",
    "curvature_radius",
    "min_convex_curvature_radius",
    "normal_arm",
    "true_contact",
    "normal_clearance_unclosed",
    "initial_clearance",
    "closing_rotation",
    "first_contact_phase",
    "envelope_gaps",
    "envelope_clearance",
]


def short_width_coefficient(z_p: int, r_p: float, a: float, dr_p: float = 0.0) -> float:
    """Short-width coefficient K1 after shifted modification (Hu et al. 2020, eq 3).

    Parameters
    ----------
    z_p : int
        Number of pins [-].
    r_p : float
        Pin-centre-circle radius [mm].
    a : float
        Eccentricity [mm].
    dr_p : float
        Shifted ("moving") modification Δr_p [mm].

    Returns
    -------
    float
        K1 = a z_p / (r_p + Δr_p) [-].

    Examples
    --------
    >>> round(short_width_coefficient(40, 76.0, 1.5, -0.0437), 5)
    0.78993

    References
    ----------
    Hu et al. (2020) eq 3, doi:10.3390/app10020481.
    """
    return _k1(z_p, r_p, a, dr_p, "ground")


#: Where the papers differ on K1 (and the radii of the curvature formula): ``"ground"`` (Hu 2020
#: eq 3: K1 = a z_p / (r_p + Δr_p), curvature of the profile as ground with R = r_p + Δr_p and
#: r = r_rp + Δr_rp — gearte's default, the profile actually made) or ``"nominal"`` (Li 2023
#: section 2: K1 = a z_p / r_p and the curvature with r_p, r_rp, the modification entering only
#: through the clearance). They differ by O(Δr_p / r_p): 0.60641 vs 0.60606 for Li's prototype.
K1_DEFINITIONS = ("ground", "nominal")


def geometry_radii(
    r_p: float, r_rp: float, dr_rp: float, dr_p: float, k1_definition: str = "ground"
) -> tuple[float, float]:
    """Pin-circle and pin radii (R, r) [mm] that enter K1, S(φ) and ρ(φ) for a K1 definition.

    Parameters
    ----------
    r_p, r_rp : float
        Nominal pin-centre-circle and pin radius [mm].
    dr_rp, dr_p : float
        Equidistant and shifted modifications [mm].
    k1_definition : {"ground", "nominal"}
        See :data:`K1_DEFINITIONS`: ``"ground"`` gives (r_p + Δr_p, r_rp + Δr_rp) (Hu 2020 eq 3,
        40), ``"nominal"`` gives (r_p, r_rp) (Li 2023).

    References
    ----------
    Hu et al. (2020) eq 3, doi:10.3390/app10020481; Li et al. (2023) section 2,
    doi:10.3390/machines11060626.
    """
    if k1_definition == "ground":
        return r_p + dr_p, r_rp + dr_rp
    if k1_definition == "nominal":
        return r_p, r_rp
    raise ParameterError("k1_definition", k1_definition, "must be 'ground' or 'nominal'")


def _k1(z_p: int, r_p: float, a: float, dr_p: float, k1_definition: str) -> float:
    """K1 = a z_p / R [-], R the pin-circle radius of the K1 definition (:func:`geometry_radii`)."""
    return a * z_p / geometry_radii(r_p, 0.0, 0.0, dr_p, k1_definition)[0]


def _S(K1: float, phi: ArrayLike) -> np.ndarray:
    """S(φ) = (1 + K1² − 2 K1 cos φ)^(1/2) (eq 4, Φ(K1, φ)⁻¹)."""
    return np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(phi))


def meshing_phase(z_p: int, mesh_angle: ArrayLike = 0.0) -> np.ndarray:
    """Meshing phases φ_i [rad] of all pins, wrapped to [0, 2π).

    Parameters
    ----------
    z_p : int
        Number of pins [-].
    mesh_angle : array_like
        Mesh position [rad] as the phase of pin 1; one tooth pitch is 2π/z_p. Arrays broadcast
        against the pin axis (last axis).

    Returns
    -------
    numpy.ndarray
        φ_i = mesh_angle + 2π(i − 1)/z_p mod 2π, shape ``(..., z_p)``.
    """
    theta = np.asarray(mesh_angle, dtype=float)[..., None]
    return np.mod(theta + 2.0 * np.pi * np.arange(z_p) / z_p, 2.0 * np.pi)


pin_phases = meshing_phase


def theoretical_profile_xy(
    phi: ArrayLike, *, z_p: int, R: float, a: float
) -> tuple[np.ndarray, np.ndarray]:
    """Pin-centre path in the disc frame (the 'theoretical' profile; eq 1–2 with r = 0).

    Parameters
    ----------
    phi : array_like
        Profile parameter φ [rad]; φ ∈ [0, 2π z_c) traces the whole disc, each 2π one tooth.
    z_p : int
        Number of pins [-].
    R : float
        Pin-centre-circle radius used [mm].
    a : float
        Eccentricity [mm].

    Returns
    -------
    x, y : numpy.ndarray
        Pin-centre path [mm] in the disc frame.

    References
    ----------
    Hu et al. (2020) eq 1–2, doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    i_h = z_p / (z_p - 1)
    x = R * np.cos((1.0 - i_h) * phi) - a * np.cos(i_h * phi)
    y = R * np.sin((1.0 - i_h) * phi) + a * np.sin(i_h * phi)
    return x, y


def profile_xy(
    phi: ArrayLike,
    *,
    z_p: int,
    r_p: float,
    r_rp: float,
    a: float,
    dr_rp: float = 0.0,
    dr_p: float = 0.0,
    rotation: float = 0.0,
    flank: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Modified cycloid profile (Hu et al. 2020, eq 1–3).

    Parameters
    ----------
    phi : array_like
        Meshing phase / profile parameter φ [rad]; one tooth spans 2π, the whole disc 2π z_c.
    z_p : int
        Number of pins [-]; z_c = z_p − 1, i_H = z_p / z_c.
    r_p : float
        Pin-centre-circle radius [mm].
    r_rp : float
        Pin radius [mm].
    a : float
        Eccentricity [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].
    rotation : float
        Rotation modification δ_rot [rad]. With ``flank = 0`` it is ignored (flank-free profile);
        ``flank = +1`` turns the loaded flank (sin φ > 0), ``flank = -1`` the other one, each
        towards its tooth centre; ``flank = 2`` applies both by the sign of sin φ.
    flank : int
        Which flank the rotation modification is applied to (see ``rotation``).

    Returns
    -------
    x, y : numpy.ndarray
        Profile coordinates [mm] in the disc frame O_c-x_c y_c.

    Notes
    -----
    With R = r_p + Δr_p, r = r_rp + Δr_rp, K1 = a z_p / R and S = (1 + K1² − 2K1 cos φ)^½::

        x = (R − r/S) cos((1 − i_H)φ) − (a − K1 r/S) cos(i_H φ)       (1)
        y = (R − r/S) sin((1 − i_H)φ) + (a − K1 r/S) sin(i_H φ)       (2)

    (the printed eq 1–2 lost the minus signs and the fraction a/(r_p+Δr_p); this is the standard
    form that gives root radius R − a − r and tip radius R + a − r).

    Examples
    --------
    >>> x, y = profile_xy(0.0, z_p=40, r_p=76.0, r_rp=3.0, a=1.5, dr_rp=-0.022, dr_p=-0.0437)
    >>> round(float(np.hypot(x, y)), 4)
    71.4783

    References
    ----------
    Hu et al. (2020) eq 1–3, doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    R = r_p + dr_p
    r = r_rp + dr_rp
    K1 = a * z_p / R
    i_h = z_p / (z_p - 1)
    S = _S(K1, phi)
    x = (R - r / S) * np.cos((1.0 - i_h) * phi) - (a - K1 * r / S) * np.cos(i_h * phi)
    y = (R - r / S) * np.sin((1.0 - i_h) * phi) + (a - K1 * r / S) * np.sin(i_h * phi)
    if rotation and flank:
        s = np.sin(phi)
        if flank == 2:
            ang = -np.sign(s) * rotation
        else:
            ang = np.where(np.sign(s) == np.sign(flank), -np.sign(flank) * rotation, 0.0)
        # turning a flank towards its tooth centre: the disc frame is rotated by -ang
        c, sn = np.cos(ang), np.sin(ang)
        x, y = c * x - sn * y, sn * x + c * y
    return x, y


def root_radius(r_p: float, r_rp: float, a: float, dr_rp: float = 0.0, dr_p: float = 0.0) -> float:
    """Root radius of the modified disc, R − a − r [mm] (eq 1–2 at φ = 0).

    Parameters
    ----------
    r_p : float
        Pin-centre-circle radius r_p [mm].
    r_rp : float
        Pin radius r_rp [mm].
    a : float
        Eccentricity a [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].

    Returns
    -------
    float
        R − a − r [mm] with R = r_p + Δr_p, r = r_rp + Δr_rp.

    References
    ----------
    Hu et al. (2020) eq 1–2, doi:10.3390/app10020481.
    """
    return (r_p + dr_p) - a - (r_rp + dr_rp)


def tip_radius(r_p: float, r_rp: float, a: float, dr_rp: float = 0.0, dr_p: float = 0.0) -> float:
    """Tip radius of the modified disc, R + a − r [mm] (eq 1–2 at φ = π).

    Parameters
    ----------
    r_p : float
        Pin-centre-circle radius r_p [mm].
    r_rp : float
        Pin radius r_rp [mm].
    a : float
        Eccentricity a [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].

    Returns
    -------
    float
        R + a − r [mm] with R = r_p + Δr_p, r = r_rp + Δr_rp.

    References
    ----------
    Hu et al. (2020) eq 1–2, doi:10.3390/app10020481.
    """
    return (r_p + dr_p) + a - (r_rp + dr_rp)


def curvature_radius(
    phi: ArrayLike,
    *,
    z_p: int,
    r_p: float,
    r_rp: float,
    a: float,
    dr_rp: float = 0.0,
    dr_p: float = 0.0,
    k1_definition: str = "ground",
) -> np.ndarray:
    """Curvature radius of the (modified) cycloid profile (Hu et al. 2020, eq 40).

    Parameters
    ----------
    phi : array_like
        Meshing phase φ [rad].
    z_p, r_p, r_rp, a, dr_rp, dr_p
        As in :func:`profile_xy` ([-], [mm]).
    k1_definition : {"ground", "nominal"}
        Radii used in K1 and eq 40 (:func:`geometry_radii`); default the profile as ground.

    Returns
    -------
    numpy.ndarray
        ρ(φ) [mm]; negative where the tooth is convex (the working flank near φ0), positive where
        it is concave (around the root).

    Notes
    -----
    ``ρ = R S³ / (K1 (z_p + 1) cos φ − (1 + z_p K1²)) + r``  (eq 40), R = r_p + Δr_p and
    r = r_rp + Δr_rp: gearte evaluates the curvature of the profile actually ground (the paper
    prints r_p, r_rp; the difference is ≈ 0.03 mm on 43.6 mm for Table 3). At φ0 = arccos K1 it
    reduces to ``ρ(φ0) = −R (1 − K1²)^½ + r``.

    References
    ----------
    Hu et al. (2020) eq 40, doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    R, r = geometry_radii(r_p, r_rp, dr_rp, dr_p, k1_definition)
    K1 = a * z_p / R
    S = _S(K1, phi)
    with np.errstate(divide="ignore"):
        return R * S**3 / (K1 * (z_p + 1) * np.cos(phi) - (1.0 + z_p * K1 * K1)) + r


def min_convex_curvature_radius(z_p: int, R: float, a: float) -> float:
    """Smallest |curvature radius| [mm] of the convex part of the pin-centre path.

    The disc is free of undercut (no loop or cusp) when the grinding pin radius r is smaller than
    this value (first-order undercut condition of cycloid gearing).

    Parameters
    ----------
    z_p : int
        Number of pins [-].
    R : float
        Pin-centre-circle radius of the path, r_p + Δr_p [mm].
    a : float
        Eccentricity [mm].

    Returns
    -------
    float
        min |ρ| over the convex part of the path [mm] (``inf`` if it has none).
    """
    K1 = a * z_p / R
    phi = np.linspace(0.0, np.pi, 4001)
    den = K1 * (z_p + 1) * np.cos(phi) - (1.0 + z_p * K1 * K1)
    S = _S(K1, phi)
    convex = den < 0.0
    if not np.any(convex):  # pragma: no cover - K1 < 1 always has a convex part
        return math.inf
    return float(np.min(R * S[convex] ** 3 / -den[convex]))


def normal_arm(phi: ArrayLike, *, z_p: int, a: float, K1: float) -> np.ndarray:
    """Arm of the contact normal about the disc centre, l = r_c sin φ / S [mm] (eq 36).

    r_c = a z_c is the cycloid pitch radius; l is largest, = r_c, at φ0 = arccos K1.

    Parameters
    ----------
    phi : array_like
        Meshing phase φ [rad].
    z_p : int
        Number of pins [-] (z_c = z_p − 1).
    a : float
        Eccentricity [mm].
    K1 : float
        Short-width coefficient [-].

    Returns
    -------
    numpy.ndarray
        l(φ) [mm], signed like sin φ.

    References
    ----------
    Hu et al. (2020) eq 36, doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    return a * (z_p - 1) * np.sin(phi) / _S(K1, phi)


def _centre_path(t: np.ndarray, R: float, a: float, z_p: int) -> tuple[np.ndarray, ...]:
    """Pin-centre path in the disc frame and its unit normal at parameter ``t`` (eq 1–2 with
    r = 0): ``(x, y, n_x, n_y)``; the profile of a pin of radius r is ``(x, y) − r n``."""
    i_h = z_p / (z_p - 1.0)
    A, B = (1.0 - i_h) * t, i_h * t
    K1 = a * z_p / R
    S = _S(K1, t)
    cA, sA, cB, sB = np.cos(A), np.sin(A), np.cos(B), np.sin(B)
    return (R * cA - a * cB, R * sA + a * sB, (cA - K1 * cB) / S, (sA + K1 * sB) / S)


def true_contact(
    phi: ArrayLike,
    *,
    z_p: int,
    r_p: float,
    a: float,
    dr_p: float = 0.0,
    tol: float = 1e-13,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where a pin really touches a modified profile: profile parameter, arm and normal turn.

    The disc is ground by pins of radius ``r_rp + Δr_rp`` on the circle ``R = r_p + Δr_p``; the
    real pin (radius r_rp, centre on the circle r_p) at meshing phase φ touches that profile
    where the profile's normal passes through the pin's centre — at the profile parameter t,
    not at φ (on a modified profile they differ by 1–3° near the root). The equidistant
    modification Δr_rp moves the profile along its normal and does not change t. The RV load
    sharing reads the curvature there (:meth:`CycloidStage.contact_curvature_radius`), and its
    rows take the normal and arm there for the design's Δr_p
    (:func:`gearte.geometry.rv.pin_contacts`; docs/contact-law.md, "Modified profiles").

    Parameters
    ----------
    phi : array_like
        Meshing phase φ of the pin [rad] (disc frame; :func:`profile_xy`'s parameter).
    z_p : int
        Number of pins [-].
    r_p : float
        Pin-centre-circle radius [mm].
    a : float
        Eccentricity [mm].
    dr_p : float
        Shifted modification Δr_p [mm].
    tol : float
        Tolerance on t [rad].

    Returns
    -------
    t : numpy.ndarray
        Profile parameter of the contact point [rad] (= φ on an unshifted profile): its
        curvature is ``curvature_radius(t)`` (eq 40).
    arm : numpy.ndarray
        Arm of the contact normal about the disc centre [mm], signed as :func:`normal_arm`
        (eq 36, which it equals on an unshifted profile).
    turn : numpy.ndarray
        Angle [rad] from the unmodified normal (through the pitch point) to the true normal,
        counter-clockwise in the disc frame.

    Notes
    -----
    With the pin-centre paths ``C(t; R)`` and their unit normals ``n(t; R)`` (eq 1–2 with the
    pin radius set to 0), t solves ``(C(φ; r_p) − C(t; R)) × n(t; R) = 0`` (Newton from t = φ with
    the exact derivative); ``arm = C(φ; r_p) × n(t; R)``. The disc's closing
    rotation (a few 1e-4 rad) is neglected, as in eq 32.

    Examples
    --------
    >>> t, arm, turn = true_contact(0.2, z_p=40, r_p=76.0, a=1.5, dr_p=-0.0437)
    >>> round(float(np.degrees(t - 0.2)), 2), round(float(arm), 2)
    (2.84, 47.35)

    References
    ----------
    Hu et al. (2020) eq 1–4, 36, 40, doi:10.3390/app10020481; Litvin F.L., Fuentes A. (2004).
    Gear Geometry and Applied Theory, 2nd ed., ch. 6 (envelope: the normal through the
    generating centre). doi:10.1017/CBO9780511547126
    """
    phi_in = np.asarray(phi, dtype=float)
    solve = _true_contact_flat if phi_in.size <= _REMEMBER_UP_TO else _true_contact_flat.__wrapped__
    out = solve(
        np.ascontiguousarray(phi_in).tobytes(), int(z_p), float(r_p), float(a), float(dr_p), tol
    )
    return tuple(v.reshape(phi_in.shape).copy() for v in out)  # type: ignore[return-value]


#: Phase arrays up to this size [-] are remembered by :func:`true_contact`, the last 32 of them
#: (at most 32 MB: phases and three answers; the RV cases' arrays are 320-28 800 phases).
_REMEMBER_UP_TO = 1 << 15


@functools.lru_cache(maxsize=32)
def _true_contact_flat(
    phi_bytes: bytes, z_p: int, r_p: float, a: float, dr_p: float, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`true_contact` of the phases ``phi_bytes`` (float64, flat), remembered: an RV
    analysis asks for the same phases of the same design several times (the rows and the
    contact law of each equilibrium; the candidates of a compensation), and each answer is a
    Newton iteration over every pin and position."""
    phi_in = np.frombuffer(phi_bytes, dtype=float)
    # the profile repeats from tooth to tooth: solve within the tooth, φ in (−π, π]
    phi = np.angle(np.exp(1j * phi_in))
    R = r_p + dr_p
    cx, cy, mx, my = _centre_path(phi, r_p, a, z_p)

    i_h = z_p / (z_p - 1.0)
    K1 = a * z_p / R

    def newton_step(t: np.ndarray) -> np.ndarray:
        # g(t) = (C(φ) − C(t)) × N(t) with the unnormalised normal N = S n (same root as with
        # n) and its exact derivative g' = −C'(t) × N(t) + (C(φ) − C(t)) × N'(t)
        A, B = (1.0 - i_h) * t, i_h * t
        cA, sA, cB, sB = np.cos(A), np.sin(A), np.cos(B), np.sin(B)
        dx, dy = cx - (R * cA - a * cB), cy - (R * sA + a * sB)
        nx_, ny_ = cA - K1 * cB, sA + K1 * sB
        xt, yt = -R * (1.0 - i_h) * sA + a * i_h * sB, R * (1.0 - i_h) * cA + a * i_h * cB
        nxt, nyt = -(1.0 - i_h) * sA + K1 * i_h * sB, (1.0 - i_h) * cA + K1 * i_h * cB
        g = dx * ny_ - dy * nx_
        dg = -xt * ny_ + yt * nx_ + dx * nyt - dy * nxt
        return g / dg

    t = phi.copy()
    if dr_p != 0.0:
        for _ in range(50):
            step = newton_step(t)
            t = t - step
            if np.all(np.abs(step) <= tol):
                break
        else:  # pragma: no cover - Newton from φ converges in a few steps
            bad = float(phi_in.flat[int(np.argmax(np.abs(step)))])
            raise ParameterError("phi", bad, "no true contact point found near φ")
    _, _, nx, ny = _centre_path(t, R, a, z_p)
    arm = cx * ny - cy * nx
    turn = np.arctan2(mx * ny - my * nx, mx * nx + my * ny)
    return phi_in + (t - phi), arm, turn


def normal_clearance_unclosed(
    phi: ArrayLike,
    *,
    z_p: int,
    r_p: float,
    a: float,
    dr_rp: float = 0.0,
    dr_p: float = 0.0,
    rotation: float = 0.0,
    k1_definition: str = "ground",
) -> np.ndarray:
    """Normal clearance of each flank before the closing rotation [mm] (first order).

    ``Δ_n(φ) = Δr_rp − Δr_p (1 − K1 cos φ)/S + l(φ) δ_rot`` — the normal distance between the
    modified profile and a nominal pin (radius r_rp on radius r_p) at the disc's nominal position,
    the same on both flanks (the profile is symmetric about φ = 0).

    Parameters
    ----------
    phi : array_like
        Meshing phase φ [rad].
    z_p : int
        Number of pins [-].
    r_p : float
        Pin-centre-circle radius [mm].
    a : float
        Eccentricity [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].
    rotation : float
        Rotation modification δ_rot [rad].
    k1_definition : {"ground", "nominal"}
        K1 from the ground or the nominal pin circle, as in :func:`geometry_radii`.

    Returns
    -------
    numpy.ndarray
        Δ_n(φ) [mm].

    References
    ----------
    Hu et al. (2020) eq 32 (its unclosed part), doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    K1 = _k1(z_p, r_p, a, dr_p, k1_definition)
    S = _S(K1, phi)
    out = dr_rp - dr_p * (1.0 - K1 * np.cos(phi)) / S
    if np.ndim(rotation) == 0 and rotation == 0.0:  # the arm's term is 0: skip it (same bits)
        return out
    l_abs = np.abs(normal_arm(phi, z_p=z_p, a=a, K1=K1))
    return out + l_abs * rotation


def closing_rotation(
    *,
    z_p: int,
    r_p: float,
    a: float,
    dr_rp: float = 0.0,
    dr_p: float = 0.0,
    rotation: float = 0.0,
    k1_definition: str = "ground",
) -> float:
    """Rotation of the disc [rad] that closes the first contact on the loaded flank.

    β0 = Δ_n(φ0) / r_c = (Δr_rp − Δr_p (1 − K1²)^½)/(a z_c) + δ_rot. Negative when the nominal
    modification leaves no backlash (the disc is then preloaded on both flanks).

    Parameters
    ----------
    z_p : int
        Number of pins [-].
    r_p : float
        Pin-centre-circle radius [mm].
    a : float
        Eccentricity [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].
    rotation : float
        Rotation modification δ_rot [rad].
    k1_definition : {"ground", "nominal"}
        K1 from the ground or the nominal pin circle, as in :func:`geometry_radii`.

    Returns
    -------
    float
        β0 [rad].

    References
    ----------
    Hu et al. (2020) eq 32–34, doi:10.3390/app10020481.
    """
    K1 = _k1(z_p, r_p, a, dr_p, k1_definition)
    return (dr_rp - dr_p * math.sqrt(1.0 - K1 * K1)) / (a * (z_p - 1)) + rotation


def first_contact_phase(K1: float) -> float:
    """φ0 = arccos K1 [rad]: where the initial clearance is zero and the arm is r_c (eq 33–34).

    Parameters
    ----------
    K1 : float
        Short-width coefficient [-], 0 < K1 < 1.

    Returns
    -------
    float
        φ0 [rad].

    References
    ----------
    Hu et al. (2020) eq 33–34, doi:10.3390/app10020481.
    """
    return math.acos(K1)


def initial_clearance(
    phi: ArrayLike,
    *,
    z_p: int,
    r_p: float,
    a: float,
    dr_rp: float = 0.0,
    dr_p: float = 0.0,
    k1_definition: str = "ground",
) -> np.ndarray:
    """Initial normal clearance per pin after the closing rotation (Hu et al. 2020, eq 32).

    Parameters
    ----------
    phi : array_like
        Meshing phase φ_i of each pin [rad].
    z_p : int
        Number of pins [-].
    r_p : float
        Pin-centre-circle radius [mm].
    a : float
        Eccentricity [mm].
    dr_rp, dr_p : float
        Equidistant Δr_rp and shifted Δr_p modifications [mm].
    k1_definition : {"ground", "nominal"}
        K1 of eq 3 (Hu 2020, default) or a z_p / r_p (Li 2023); see :func:`geometry_radii`.

    Returns
    -------
    numpy.ndarray
        Δ(φ) [mm] on the loaded flank (sin φ > 0); by symmetry the same function of |φ| describes
        the gap of the unloaded flank to a disc closed the other way.

    Notes
    -----
    Eq 32 as read (the second Δr_rp of the printed text is Δr_p)::

        Δ(φ) = Δr_rp (1 − sin φ / S) − Δr_p (1 − K1 cos φ − (1 − K1²)^½ sin φ) / S

    It equals Δ_n(φ) − (l(φ)/r_c) Δ_n(φ0): the unclosed normal clearance minus what the closing
    rotation β0 = Δ_n(φ0)/r_c takes up. A rotation modification adds l(φ) δ_rot to Δ_n and the
    same to the closing rotation, so it cancels here. Δ(φ0) = 0 at φ0 = arccos K1 (eq 33–34).

    References
    ----------
    Hu et al. (2020) eq 32–34, doi:10.3390/app10020481.
    """
    phi = np.asarray(phi, dtype=float)
    K1 = _k1(z_p, r_p, a, dr_p, k1_definition)
    S = _S(K1, phi)
    s = np.sin(phi)
    return (
        dr_rp * (1.0 - s / S) - dr_p * (1.0 - K1 * np.cos(phi) - math.sqrt(1.0 - K1 * K1) * s) / S
    )


def envelope_gaps(
    stage: CycloidStage,
    mesh_angle: ArrayLike,
    beta: ArrayLike,
    *,
    phases: ArrayLike | None = None,
    newton_steps: int = 30,
) -> np.ndarray:
    """Exact gaps [mm] between nominal pins and the modified profile (envelope construction).

    The nominal pins (radius r_rp, centres on the unmodified pin-centre path of r_p and a) are
    placed in the disc frame, the disc is turned by ``beta`` (positive closes the loaded flank),
    and the distance from each pin centre to the modified profile curve (eq 1–3) minus r_rp is
    found by a damped Newton iteration on the foot point, vectorised over pins and positions.

    Parameters
    ----------
    stage : CycloidStage
        The stage (modifications of the disc; pins are nominal).
    mesh_angle : array_like, shape (n,)
        Mesh position(s) [rad] (phase of pin 1).
    beta : array_like, shape (n,)
        Disc rotation [rad] at each position.
    phases : array_like, optional
        Instead of the z_p pins, virtual pins at these meshing phases [rad], shape (n, m).
    newton_steps : int
        Newton iterations of the foot-point search.

    Returns
    -------
    numpy.ndarray, shape (n, z_p) or (n, m)
        Gap [mm] (negative: overlap).

    References
    ----------
    Hu et al. (2020) eq 1–3 (the profile whose gaps are measured), doi:10.3390/app10020481.
    """
    theta = np.atleast_1d(np.asarray(mesh_angle, dtype=float))
    beta = np.broadcast_to(np.asarray(beta, dtype=float), theta.shape)
    zp, zc = stage.z_p, stage.z_c
    if phases is None:
        k = (-np.arange(zp)) % zp
        t0 = theta[:, None] + 2.0 * np.pi * k[None, :] * zc / zp
    else:
        t0 = np.asarray(phases, dtype=float).reshape(theta.shape[0], -1)
    px, py = theoretical_profile_xy(t0, z_p=zp, R=stage.r_p, a=stage.a)
    c, s = np.cos(-beta)[:, None], np.sin(-beta)[:, None]
    qx, qy = c * px - s * py, s * px + c * py
    kw = stage._profile_kw
    t = t0.copy()
    h = 1e-4
    for _ in range(newton_steps):
        x, y = profile_xy(t, **kw)
        xp, yp = profile_xy(t + h, **kw)
        xm, ym = profile_xy(t - h, **kw)
        dx, dy = (xp - xm) / (2 * h), (yp - ym) / (2 * h)
        ddx, ddy = (xp - 2 * x + xm) / h**2, (yp - 2 * y + ym) / h**2
        f = (x - qx) * dx + (y - qy) * dy
        fp = dx * dx + dy * dy + (x - qx) * ddx + (y - qy) * ddy
        step = np.where(fp > 0.0, -f / np.where(fp > 0.0, fp, 1.0), -0.05 * np.sign(f))
        step = np.clip(step, -0.1, 0.1)
        t = t + step
        if np.max(np.abs(step)) < 1e-13:
            break
    x, y = profile_xy(t, **kw)
    return np.hypot(x - qx, y - qy) - stage.r_rp


def envelope_clearance(stage: CycloidStage, mesh_angle: ArrayLike = 0.0) -> np.ndarray:
    """Initial clearance per pin from the exact envelope, closed at φ0 like eq 32 [mm].

    The disc is turned until a (virtual) pin at φ0 = arccos K1 touches — the closing convention of
    eq 32 — and the exact gap of every loaded-flank pin is returned (NaN on the unloaded flank).
    Eq 32 is its first-order approximation; they agree to ~0.1 µm in the working zone and differ
    by up to ~1.7 µm towards the root for Table 3 (docs/validation/hu2020.md).

    Parameters
    ----------
    stage : CycloidStage
        The stage.
    mesh_angle : array_like
        Mesh position(s) [rad].

    Returns
    -------
    numpy.ndarray, shape (n, z_p)
        Clearance [mm].

    References
    ----------
    Hu et al. (2020) eq 32–34 (the closing convention), doi:10.3390/app10020481.
    """
    theta = np.atleast_1d(np.asarray(mesh_angle, dtype=float))
    phi0 = np.full((theta.shape[0], 1), stage.phi0)
    beta = np.full(theta.shape, stage.backlash_per_flank - stage.rotation)
    slope = -stage.r_c  # d gap / d beta at phi0
    for _ in range(8):  # Newton on the virtual pin's gap, slope ~ -r_c
        g = envelope_gaps(stage, theta, beta, phases=phi0)[:, 0]
        beta = beta + g / -slope
        if np.max(np.abs(g)) < 1e-13:
            break
    gaps = envelope_gaps(stage, theta, beta)
    phase = stage.pin_phases(theta)
    return np.where(np.sin(phase) > 1e-12, gaps, np.nan)


@dataclass(frozen=True)
class CycloidStage:
    """A cycloid–pin stage with its profile modifications (Hu et al. 2020, Tables 3 and 6).

    Parameters
    ----------
    z_p : int
        Number of pins [-] (z_c = z_p − 1 cycloid teeth).
    r_p : float
        Pin-centre-circle radius [mm].
    r_rp : float
        Pin radius [mm].
    a : float
        Eccentricity [mm].
    b : float
        Face width of one disc [mm].
    dr_rp : float
        Equidistant ("isometric") modification Δr_rp [mm].
    dr_p : float
        Shifted ("moving") modification Δr_p [mm].
    rotation : float
        Rotation modification δ_rot [rad] (≥ 0 thins the teeth; see module notes).
    z_c : int or None
        Number of cycloid teeth; ``None`` means z_p − 1. Any other value is rejected.
    k1_definition : {"ground", "nominal"}
        Where the papers differ: K1 and the radii of eq 40 from the profile as ground (Hu 2020
        eq 3, default) or from the nominal pin circle (Li 2023); see :data:`K1_DEFINITIONS`.
        Every analysis of one stage reads K1, S, ρ and the clearances from this object.

    Raises
    ------
    ParameterError
        Non-positive sizes, z_c ≠ z_p − 1, K1 ≥ 1, an undercut profile (grinding pin radius not
        below the smallest convex curvature radius of the pin-centre path), a pin that does not
        fit between its neighbours, or a modification that interferes (negative initial clearance
        eq 32 on the loaded flank).

    Examples
    --------
    >>> s = CycloidStage(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
    >>> round(s.K1, 5), s.z_c
    (0.78993, 39)
    """

    z_p: int
    r_p: float
    r_rp: float
    a: float
    b: float
    dr_rp: float = 0.0
    dr_p: float = 0.0
    rotation: float = 0.0
    z_c: int = None  # type: ignore[assignment]  # z_p - 1 when omitted (__post_init__)
    k1_definition: str = "ground"

    def __post_init__(self) -> None:
        geometry_radii(0.0, 0.0, 0.0, 0.0, self.k1_definition)  # validates the name
        for name in ("r_p", "r_rp", "a", "b", "dr_rp", "dr_p", "rotation"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                raise ParameterError(name, v, "must be a real number")
            if not math.isfinite(float(v)):
                raise ParameterError(name, v, "must be finite")
            object.__setattr__(self, name, float(v))
        if isinstance(self.z_p, bool) or not isinstance(self.z_p, (int, np.integer)):
            raise ParameterError("z_p", self.z_p, "must be an integer")
        object.__setattr__(self, "z_p", int(self.z_p))
        if self.z_p < 4:
            raise ParameterError("z_p", self.z_p, "must be >= 4")
        if self.z_c is None:
            object.__setattr__(self, "z_c", self.z_p - 1)
        elif int(self.z_c) != self.z_p - 1:
            raise ParameterError(
                "z_c",
                self.z_c,
                f"must equal z_p - 1 = {self.z_p - 1} (single-tooth-difference stage)",
            )
        for name in ("r_p", "r_rp", "a", "b"):
            if getattr(self, name) <= 0.0:
                raise ParameterError(name, getattr(self, name), "must be > 0")
        check_floor("a", self.a, "eccentricity", unit="mm")
        if self.r_rp + self.dr_rp <= 0.0:
            raise ParameterError(
                "dr_rp", self.dr_rp, f"r_rp + dr_rp must be > 0 (r_rp = {self.r_rp})"
            )
        if self.r_p + self.dr_p <= 0.0:
            raise ParameterError("dr_p", self.dr_p, f"r_p + dr_p must be > 0 (r_p = {self.r_p})")
        if abs(self.rotation) >= 0.05:
            raise ParameterError("rotation", self.rotation, "must be within (-0.05, 0.05) rad")
        K1 = self.K1
        if not K1 < 1.0:
            raise ParameterError(
                "K1", K1, f"short-width coefficient a*z_p/(r_p+dr_p) must be < 1 (a = {self.a})"
            )
        # pins must not overlap their neighbours on the pin circle
        half_pitch = self.r_p * math.sin(math.pi / self.z_p)
        if self.r_rp >= half_pitch:
            raise ParameterError(
                "r_rp", self.r_rp, f"must be < r_p sin(pi/z_p) = {half_pitch:.4g} mm (pins overlap)"
            )
        rho_min = min_convex_curvature_radius(self.z_p, self.R, self.a)
        if self.r >= rho_min:
            raise ParameterError(
                "r_rp",
                self.r_rp,
                f"undercut: grinding pin radius r_rp + dr_rp = {self.r:.4g} mm must be < the "
                f"smallest convex curvature radius of the pin-centre path, {rho_min:.4g} mm",
            )
        phi = np.linspace(0.0, np.pi, 721)[1:-1]
        delta = self.initial_clearance(phi)
        tol = 1e-9 * max(1.0, abs(self.dr_rp) + abs(self.dr_p))
        if np.min(delta) < -tol:
            k = int(np.argmin(delta))
            raise ParameterError(
                "dr_rp/dr_p",
                (self.dr_rp, self.dr_p),
                "interfering modification: initial clearance (eq 32) is "
                f"{delta[k]:.3g} mm < 0 on the loaded flank at phi = "
                f"{math.degrees(phi[k]):.1f} deg; "
                "need dr_rp - dr_p >= 0 and dr_rp - dr_p/sqrt(1-K1^2) >= 0",
            )

    # derived quantities --------------------------------------------------------------------
    @property
    def R(self) -> float:  # noqa: N802 - paper symbol
        """Pin-circle radius the disc is ground for, r_p + Δr_p [mm]."""
        return self.r_p + self.dr_p

    @property
    def r(self) -> float:
        """Pin radius the disc is ground for, r_rp + Δr_rp [mm]."""
        return self.r_rp + self.dr_rp

    @property
    def K1(self) -> float:  # noqa: N802 - paper symbol
        """Short-width coefficient (eq 3, or a z_p / r_p with ``k1_definition="nominal"``) [-]."""
        return _k1(self.z_p, self.r_p, self.a, self.dr_p, self.k1_definition)

    @property
    def i_h(self) -> float:
        """Ratio i_H = z_p / z_c [-]."""
        return self.z_p / (self.z_p - 1)

    @property
    def r_c(self) -> float:
        """Cycloid pitch radius r_c = a z_c [mm] (the largest normal arm)."""
        return self.a * (self.z_p - 1)

    @property
    def phi0(self) -> float:
        """First-contact phase φ0 = arccos K1 [rad]."""
        return first_contact_phase(self.K1)

    @property
    def root_radius(self) -> float:
        """Root radius R − a − r [mm]."""
        return root_radius(self.r_p, self.r_rp, self.a, self.dr_rp, self.dr_p)

    @property
    def tip_radius(self) -> float:
        """Tip radius R + a − r [mm]."""
        return tip_radius(self.r_p, self.r_rp, self.a, self.dr_rp, self.dr_p)

    @property
    def rho0(self) -> float:
        """Curvature radius at φ0 (eq 40) [mm], negative (convex)."""
        return float(self.curvature_radius(self.phi0))

    @property
    def backlash_per_flank(self) -> float:
        """Closing rotation β0 = Δ_n(φ0)/r_c + δ_rot [rad] (negative: preloaded)."""
        return closing_rotation(rotation=self.rotation, **self._clearance_kw)

    @property
    def curvature_cap(self) -> float:
        """Cap on |ρ| in the line-contact logarithm: the tip radius R + a − r [mm].

        The flank curvature radius passes through infinity at the inflection of the profile; the
        deforming body is no larger than the disc, so |ρ| is bounded by its tip radius there
        (Li 2023's treatment, gearte's choice for every line-contact analysis).
        """
        return self.tip_radius

    # bound functions -------------------------------------------------------------------------
    @property
    def _profile_kw(self) -> dict[str, Any]:
        """The stage's sizes and radial modifications as keywords of :func:`profile_xy`."""
        return dict(
            z_p=self.z_p, r_p=self.r_p, r_rp=self.r_rp, a=self.a, dr_rp=self.dr_rp, dr_p=self.dr_p
        )

    @property
    def _clearance_kw(self) -> dict[str, Any]:
        """The keywords the clearance functions (eq 32–34, 40) take from the stage."""
        return dict(
            z_p=self.z_p,
            r_p=self.r_p,
            a=self.a,
            dr_rp=self.dr_rp,
            dr_p=self.dr_p,
            k1_definition=self.k1_definition,
        )

    def pin_phases(self, mesh_angle: ArrayLike = 0.0) -> np.ndarray:
        """Meshing phase of every pin [rad] at the given mesh position(s)."""
        return meshing_phase(self.z_p, mesh_angle)

    def profile_xy(self, phi: ArrayLike, *, modified: bool = True, flank: int = 0):
        """Profile coordinates [mm]; ``modified=False`` gives the unmodified profile."""
        if modified:
            return profile_xy(phi, rotation=self.rotation, flank=flank, **self._profile_kw)
        return profile_xy(phi, z_p=self.z_p, r_p=self.r_p, r_rp=self.r_rp, a=self.a)

    def curvature_radius(self, phi: ArrayLike) -> np.ndarray:
        """Curvature radius (eq 40) [mm]."""
        return curvature_radius(phi, r_rp=self.r_rp, **self._clearance_kw)

    def S(self, phi: ArrayLike) -> np.ndarray:  # noqa: N802 - paper symbol
        """S(φ) = (1 + K1² − 2 K1 cos φ)^½ [-] (eq 4); |pitch point − pin centre| = r_p S."""
        return _S(self.K1, phi)

    def true_contact(self, phi: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Profile parameter, arm [mm] and normal turn [rad] of the true contact of the real pin
        at phase φ on the ground profile (:func:`true_contact`)."""
        return true_contact(phi, z_p=self.z_p, r_p=self.r_p, a=self.a, dr_p=self.dr_p)

    def contact_curvature_radius(self, phi: ArrayLike) -> np.ndarray:
        """Curvature radius (eq 40) [mm] of the ground profile where the real pin at phase φ
        touches it (at :func:`true_contact`'s parameter; ``curvature_radius(φ)`` without a
        shifted modification)."""
        t = self.true_contact(phi)[0] if self.dr_p != 0.0 else phi
        return self.curvature_radius(t)

    def normal_arm(self, phi: ArrayLike) -> np.ndarray:
        """Arm of the contact normal l(φ) [mm] (eq 36)."""
        return normal_arm(phi, z_p=self.z_p, a=self.a, K1=self.K1)

    def initial_clearance(self, phi: ArrayLike) -> np.ndarray:
        """Initial normal clearance after the closing rotation, eq 32 [mm]."""
        return initial_clearance(phi, **self._clearance_kw)

    def normal_clearance_unclosed(self, phi: ArrayLike) -> np.ndarray:
        """Normal clearance of each flank before the closing rotation [mm]."""
        return normal_clearance_unclosed(phi, rotation=self.rotation, **self._clearance_kw)
