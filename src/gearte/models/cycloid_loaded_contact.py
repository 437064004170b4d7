"""Loaded contact of the cycloid–pin pair after Li et al. (2023), section 2 (paper 004).

Hertz line-contact stiffness per pin (eq 2), compatibility (eq 3) and moment equilibrium (eq 4)
give the pins in contact and their forces at one mesh position; the equivalent pressure angle and
the equivalent mesh stiffness (eq 5–7) condense the multi-pin contact into one spring for the lumped
dynamic model (:mod:`gearte.models.rv_dynamics`). Sweeping the mesh position over one mesh period
(2π/z_p of the meshing phase) gives the time-varying stiffness, fitted by a Fourier series.

This is paper 004's method; the paper-000 contact analysis (Hu et al. 2020) lives in
``gearte.models.cycloid_contact`` and is kept separate on purpose (different deflection formula).

Units: mm, N, N·mm, MPa, rad. Stiffnesses are returned in N/mm (``*1e3`` → N/m at the edge).

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ConvergenceError, ParameterError

__all__ = [
    "CycloidPinPair",
    "LoadedContact",
    "MeshPeriodContact",
    "pin_geometry",
    "modification_clearance",
    "profile_curvature_radius",
    "hertz_line_deflection",
    "hertz_line_force",
    "loaded_contact",
    "mesh_period_contact",
    "fourier_fit",
    "fourier_eval",
    "LI2023_PAIR",
    "LI2023_PAIR_MODIFIED",
]


@dataclass(frozen=True)
class CycloidPinPair:
    """Cycloid–pin pair of one disc (paper 004, Table 1).

    Parameters
    ----------
    pin_count : int
        z_p, number of pins [-]; the disc has z_c = z_p − 1 teeth.
    pin_radius_mm : float
        r_rp, pin (roller) radius [mm].
    pin_circle_radius_mm : float
        r_p, radius of the circle of pin centres [mm].
    eccentricity_mm : float
        e, crank eccentricity [mm].
    face_width_mm : float
        B, disc face width [mm].
    youngs_modulus_MPa, poisson_ratio : float
        E [MPa] and ν [-] of disc and pins (same material, paper section 4).
    pin_radius_modification_mm : float
        Δr_rp, equidistant ("roller radius") modification [mm]; paper: −0.01.
    pin_position_modification_mm : float
        Δr_p, shifted ("roller position") modification [mm]; paper: −0.05.
    curvature_cap_mm : float or None
        Upper bound of |ρ_c| in the Hertz logarithm [mm]. The profile's curvature radius passes
        through infinity at its inflection (≈ 50.8° for Table 1), next to the most loaded pins;
        the log term of eq 2 would then send the pin stiffness to zero. ``None`` caps at the
        disc's tip radius r_p + e − r_rp, the largest dimension of the body that deforms.
    """

    pin_count: int = 40
    pin_radius_mm: float = 3.0
    pin_circle_radius_mm: float = 85.8
    eccentricity_mm: float = 1.3
    face_width_mm: float = 12.0
    youngs_modulus_MPa: float = 2.06e5  # noqa: N815 - unit suffix
    poisson_ratio: float = 0.3
    pin_radius_modification_mm: float = 0.0
    pin_position_modification_mm: float = 0.0
    curvature_cap_mm: float | None = None

    def __post_init__(self) -> None:
        if self.pin_count < 3:
            raise ParameterError("pin_count", self.pin_count, "must be ≥ 3")
        for name in (
            "pin_radius_mm",
            "pin_circle_radius_mm",
            "eccentricity_mm",
            "face_width_mm",
            "youngs_modulus_MPa",
        ):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(name, v, "must be finite and > 0")
        if not 0.0 <= self.poisson_ratio < 0.5:
            raise ParameterError("poisson_ratio", self.poisson_ratio, "must be in [0, 0.5)")
        if not self.K1 < 1.0:
            raise ParameterError(
                "eccentricity_mm",
                self.eccentricity_mm,
                f"short-width coefficient K1 = e z_p / r_p = {self.K1:.4f} must be < 1",
            )
        if self.curvature_cap_mm is not None and not self.curvature_cap_mm > 0:
            raise ParameterError("curvature_cap_mm", self.curvature_cap_mm, "must be > 0")
        phi = np.linspace(1e-4, np.pi - 1e-4, 2001)
        gap = modification_clearance(self, phi)
        if np.min(gap) < -1e-12:
            raise ParameterError(
                "pin_radius_modification_mm/pin_position_modification_mm",
                (self.pin_radius_modification_mm, self.pin_position_modification_mm),
                f"the modification interferes (clearance {np.min(gap):.4g} mm < 0 on the loaded "
                "flank); use Δr_rp ≤ 0 with Δr_p ≤ Δr_rp·(…) as in paper 004 (−0.01, −0.05)",
            )

    @property
    def tooth_count(self) -> int:
        """z_c = z_p − 1 [-]."""
        return self.pin_count - 1

    @property
    def K1(self) -> float:  # noqa: N802 - paper symbol
        """Short-width coefficient K1 = e z_p / r_p [-]."""
        return self.eccentricity_mm * self.pin_count / self.pin_circle_radius_mm

    @property
    def pitch_radius_mm(self) -> float:
        """r_c = e z_c, pitch radius of the disc [mm] (paper 004 after eq 5)."""
        return self.eccentricity_mm * self.tooth_count

    @property
    def mesh_pitch_rad(self) -> float:
        """One mesh period in meshing phase, 2π/z_p [rad]."""
        return 2.0 * np.pi / self.pin_count

    @property
    def rho_cap_mm(self) -> float:
        """Cap on |ρ_c| used in the Hertz logarithm [mm]."""
        if self.curvature_cap_mm is not None:
            return float(self.curvature_cap_mm)
        return self.pin_circle_radius_mm + self.eccentricity_mm - self.pin_radius_mm

    @property
    def modified(self) -> bool:
        return self.pin_radius_modification_mm != 0.0 or self.pin_position_modification_mm != 0.0


def pin_geometry(pair: CycloidPinPair, phi: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Arm of each pin's contact normal about the disc centre and S(φ).

    Parameters
    ----------
    pair : CycloidPinPair
    phi : array_like
        Meshing phase φ_i of the pins [rad], measured from the line of centres; the loaded flank
        is sin φ > 0.

    Returns
    -------
    arm : ndarray
        l_i = r_c sin φ_i / S_i [mm] (signed; negative on the unloaded flank).
    S : ndarray
        S_i = sqrt(1 + K1² − 2 K1 cos φ_i) [-].

    Notes
    -----
    Every contact normal passes through the pitch point P at distance r_c = e z_c from the disc
    centre; |P − pin centre| = r_p S. Hence l = r_c sin φ / S ≤ r_c, with equality at
    φ0 = arccos K1.
    """
    phi = np.asarray(phi, dtype=float)
    k1 = pair.K1
    S = np.sqrt(1.0 + k1 * k1 - 2.0 * k1 * np.cos(phi))
    return pair.pitch_radius_mm * np.sin(phi) / S, S


def modification_clearance(pair: CycloidPinPair, phi: ArrayLike) -> np.ndarray:
    """Initial normal clearance of each pin from the profile modification [mm].

    Δ(φ) = Δr_rp (1 − sin φ / S) − Δr_p (1 − K1 cos φ − sqrt(1 − K1²) sin φ) / S,
    zero at φ0 = arccos K1 (after the rigid rotation that closes the first contact); the same
    expression as Hu et al. (2020) eq 32, which paper 004 uses through its ref. [31].
    """
    phi = np.asarray(phi, dtype=float)
    k1 = pair.K1
    S = np.sqrt(1.0 + k1 * k1 - 2.0 * k1 * np.cos(phi))
    drr = pair.pin_radius_modification_mm
    drp = pair.pin_position_modification_mm
    return (
        drr * (1.0 - np.sin(phi) / S)
        - drp * (1.0 - k1 * np.cos(phi) - np.sqrt(1.0 - k1 * k1) * np.sin(phi)) / S
    )


def profile_curvature_radius(pair: CycloidPinPair, phi: ArrayLike) -> np.ndarray:
    """Signed curvature radius of the cycloid profile at the contact with pin φ [mm].

    ρ(φ) = r_p S³ / (K1 (z_p + 1) cos φ − (1 + z_p K1²)) + r_rp  (Hu et al. 2020 eq 40);
    ρ > 0: concave flank (root side), ρ < 0: convex (tip side); |ρ| → ∞ at the inflection.
    """
    phi = np.asarray(phi, dtype=float)
    k1, zp = pair.K1, pair.pin_count
    S = np.sqrt(1.0 + k1 * k1 - 2.0 * k1 * np.cos(phi))
    den = k1 * (zp + 1) * np.cos(phi) - (1.0 + zp * k1 * k1)
    with np.errstate(divide="ignore"):
        rho = pair.pin_circle_radius_mm * S**3 / den + pair.pin_radius_mm
    return rho


def _hertz_coefficients(pair: CycloidPinPair, rho_c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """a0, a1 of δ(F) = F (a0 − a1 ln F) for a pin–tooth pair (eq 2), see hertz_line_deflection."""
    B = pair.face_width_mm
    c = (1.0 - pair.poisson_ratio**2) / pair.youngs_modulus_MPa  # per body [1/MPa]
    e_star = 1.0 / (2.0 * c)
    r_r = pair.pin_radius_mm
    # relative curvature: convex pin against a concave (ρ>0) or convex (ρ<0) flank
    curv = 1.0 / r_r - np.where(np.isfinite(rho_c), 1.0 / rho_c, 0.0)
    r_star = 1.0 / curv
    rho_abs = np.minimum(np.abs(rho_c), pair.rho_cap_mm)
    # b = sqrt(q F) with q = 4 R* / (π B E*)  →  ln(4ρ/b) = ln(4ρ) − ½ ln q − ½ ln F
    lnq = np.log(4.0 * r_star / (np.pi * B * e_star))
    pref = 2.0 / (np.pi * B)
    a0 = pref * c * (np.log(4.0 * rho_abs) + np.log(4.0 * r_r) - lnq - 1.0)
    a1 = pref * c  # two bodies × ½ ln F
    return a0, np.broadcast_to(a1, np.shape(a0))


def hertz_line_deflection(pair: CycloidPinPair, force_N: ArrayLike, rho_c: ArrayLike) -> np.ndarray:
    """Normal deflection of a pin–tooth pair under load F (paper 004 eq 2) [mm].

    δ = (2F / (π B)) Σ_{k=c,r} (1 − ν_k²)/E_k · (ln(4 ρ_k / b) − 1/2),
    b = sqrt(4 F R* / (π B E*)),  1/R* = 1/r_rp − 1/ρ_c,  1/E* = Σ (1 − ν_k²)/E_k,

    with ρ_r = r_rp for the pin and ρ_c = min(|ρ_c|, cap) for the disc. The pin stiffness of eq 2
    is k_n = F / δ. ``force_N`` must be > 0.

    Notes
    -----
    Eq 2 prints ``ln 4ρ/b − 1/2``; b is read as the *half* width of the Hertz strip (the
    classical line-contact approach of a cylinder, Johnson 1985 §5.6), since the full width would
    only shift the log by ln 2. The relative radius uses the sign of ρ_c (concave root flank vs
    convex tip flank).
    """
    f = np.asarray(force_N, dtype=float)
    a0, a1 = _hertz_coefficients(pair, np.asarray(rho_c, dtype=float))
    return f * (a0 - a1 * np.log(f))


def hertz_line_force(
    pair: CycloidPinPair, deflection_mm: ArrayLike, rho_c: ArrayLike, *, rtol: float = 1e-12
) -> np.ndarray:
    """Inverse of :func:`hertz_line_deflection`: pin force F [N] for a deflection δ [mm].

    δ(F) = F (a0 − a1 ln F) is increasing for b < 4ρ/e (any realistic load), so a safeguarded
    Newton iteration from the linear estimate converges in a few steps. δ ≤ 0 gives F = 0.
    """
    d = np.asarray(deflection_mm, dtype=float)
    a0, a1 = _hertz_coefficients(pair, np.asarray(rho_c, dtype=float))
    d, a0, a1 = np.broadcast_arrays(d, a0, a1)
    out = np.zeros(d.shape)
    pos = d > 0
    if not np.any(pos):
        return out
    dd, b0, b1 = d[pos], a0[pos], a1[pos]
    f = dd / b0
    for _ in range(6):  # fixed point on the slowly varying log (contracting: a1/(a0-a1 ln F) ≪ 1)
        f = dd / (b0 - b1 * np.log(f))
    for _ in range(50):
        r = f * (b0 - b1 * np.log(f)) - dd
        dr = b0 - b1 * np.log(f) - b1
        step = r / dr
        f_new = np.where(f - step > 0, f - step, 0.5 * f)
        if np.all(np.abs(f_new - f) <= rtol * f_new):
            f = f_new
            break
        f = f_new
    else:
        raise ConvergenceError(
            f"hertz_line_force: Newton did not converge in 50 iterations (max residual "
            f"{np.max(np.abs(r)):.3g} mm, tolerance {rtol:g} relative)"
        )
    out[pos] = f
    return out


@dataclass(frozen=True)
class LoadedContact:
    """Loaded contact at one or more mesh positions (arrays over positions × pins).

    Attributes (units in brackets)
    ----------------------------------
    phi : meshing phase of each pin [rad], shape (n_pos, z_p)
    arm : l_i [mm]; clearance : Δ_i [mm]; backlash : φ_bl,i [rad]
    force : F_i [N] (0 out of contact); in_contact : bool mask
    rotation : Δφ_c, elastic rotation from first contact [rad], shape (n_pos,)
    tangential_force, radial_force : F_t, F_r [N] (eq 5, F_r summed without sign as printed)
    radial_force_signed : Σ F_i (K1 − cos φ_i)/S_i [N], the physical resultant's radial part
    pressure_angle : β = atan(F_r/F_t) [rad] (eq 7)
    mesh_stiffness : k_cr = F_cr / (r_c Δφ_c cos β) [N/mm] (eq 7, reading A)
    torsional_stiffness : T / Δφ_c [N·mm/rad]
    """

    phi: np.ndarray
    arm: np.ndarray
    clearance: np.ndarray
    backlash: np.ndarray
    force: np.ndarray
    in_contact: np.ndarray
    rotation: np.ndarray
    tangential_force: np.ndarray
    radial_force: np.ndarray
    radial_force_signed: np.ndarray
    pressure_angle: np.ndarray
    mesh_stiffness: np.ndarray
    torsional_stiffness: np.ndarray
    pins_in_contact: np.ndarray = field(default=None)  # type: ignore[arg-type]  # set in __post_init__


def loaded_contact(
    pair: CycloidPinPair,
    torque_Nmm: float,
    mesh_position: ArrayLike = 0.0,
    *,
    rtol: float = 1e-11,
) -> LoadedContact:
    """Loaded tooth contact of one disc at the given mesh positions (paper 004 §2.2–2.3).

    Parameters
    ----------
    pair : CycloidPinPair
    torque_Nmm : float
        T, torque carried by this disc [N·mm] (paper: 450 N·m output over 2 discs → 225e3).
    mesh_position : array_like
        Meshing phase of pin 1, p ∈ [0, 2π/z_p) [rad]; pin i sits at φ_i = p + 2π(i−1)/z_p.
    rtol : float
        Relative tolerance on the torque balance.

    Returns
    -------
    LoadedContact

    Notes
    -----
    Compatibility (eq 3): pin i's angular backlash relative to the first pin to touch is
    φ_bl,i = Δ_i/l_i − min_j Δ_j/l_j; it is in contact when Δφ_c > φ_bl,i and then
    δ_i = (Δφ_c − φ_bl,i) l_i. Equilibrium (eq 4): T = Σ F_i l_i with F_i = k_n(F_i) δ_i
    (eq 2 inverted per pin). T(Δφ_c) is increasing, so Δφ_c is found by bisection.

    Equivalent quantities (eq 5–7): F_t = Σ F_i l_i / r_c, F_r = Σ F_i sqrt(1 − (l_i/r_c)²),
    F_cr = hypot(F_t, F_r), β = atan(F_r/F_t). The garbled eq 7 is read as
    k_cr = F_cr / (r_c Δφ_c cos β): the single spring of the dynamic model acts along β at the
    pitch point, its deflection for a disc rotation Δφ_c is r_c Δφ_c cos β, and with this
    reading it reproduces the quasi-static torsional stiffness T/Δφ_c = k_cr r_c² cos²β.

    Examples
    --------
    >>> c = loaded_contact(LI2023_PAIR, 225e3, 0.0)
    >>> 31.5 < float(np.degrees(c.pressure_angle[0])) < 33.5
    True
    """
    if not np.isfinite(torque_Nmm) or torque_Nmm <= 0:
        raise ParameterError("torque_Nmm", torque_Nmm, "must be finite and > 0")
    p = np.atleast_1d(np.asarray(mesh_position, dtype=float))
    zp = pair.pin_count
    phi = p[:, None] + pair.mesh_pitch_rad * np.arange(zp)[None, :]
    phi = np.mod(phi, 2.0 * np.pi)
    arm, S = pin_geometry(pair, phi)
    loaded = arm > 1e-9 * pair.pitch_radius_mm
    gap = np.where(loaded, modification_clearance(pair, phi), np.inf)
    ang = np.where(loaded, gap / np.where(loaded, arm, 1.0), np.inf)
    backlash = np.where(loaded, ang - np.min(ang, axis=1, keepdims=True), 0.0)
    rho = profile_curvature_radius(pair, phi)

    def torque_at(rot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        delta = np.where(loaded, (rot[:, None] - backlash) * arm, 0.0)
        f = hertz_line_force(pair, delta, rho)
        return np.sum(f * np.where(loaded, arm, 0.0), axis=1), f

    # bracket: grow the rotation until the torque exceeds T
    n = p.size
    lo = np.zeros(n)
    hi = np.full(n, 1e-6)
    for _ in range(200):
        t_hi, _ = torque_at(hi)
        short = t_hi < torque_Nmm
        if not np.any(short):
            break
        lo = np.where(short, hi, lo)
        hi = np.where(short, hi * 2.0, hi)
    else:  # pragma: no cover - only for absurd loads
        raise ConvergenceError("loaded_contact: could not bracket the elastic rotation")
    for it in range(200):  # noqa: B007 - reported on failure
        mid = 0.5 * (lo + hi)
        t_mid, _ = torque_at(mid)
        above = t_mid > torque_Nmm
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
        if np.all(hi - lo <= rtol * hi):
            break
    else:  # pragma: no cover
        raise ConvergenceError(
            f"loaded_contact: bisection stopped after {it + 1} iterations "
            f"(bracket {np.max((hi - lo) / hi):.3g} relative, tolerance {rtol:g})"
        )
    rot = 0.5 * (lo + hi)
    _, force = torque_at(rot)
    rc = pair.pitch_radius_mm
    la = np.where(loaded, arm, 0.0)
    f_t = np.sum(force * la, axis=1) / rc
    f_r = np.sum(force * np.sqrt(np.clip(1.0 - (la / rc) ** 2, 0.0, None)), axis=1)
    f_r_signed = np.sum(force * (pair.K1 - np.cos(phi)) / S, axis=1)
    beta = np.arctan2(f_r, f_t)
    f_cr = np.hypot(f_t, f_r)
    k_cr = f_cr / (rc * rot * np.cos(beta))
    in_contact = force > 0
    return LoadedContact(
        phi=phi,
        arm=arm,
        clearance=np.where(loaded, gap, np.nan),
        backlash=np.where(loaded, backlash, np.nan),
        force=force,
        in_contact=in_contact,
        rotation=rot,
        tangential_force=f_t,
        radial_force=f_r,
        radial_force_signed=f_r_signed,
        pressure_angle=beta,
        mesh_stiffness=k_cr,
        torsional_stiffness=torque_Nmm / rot,
        pins_in_contact=np.sum(in_contact, axis=1),
    )


@dataclass(frozen=True)
class MeshPeriodContact:
    """Equivalent pressure angle and mesh stiffness over one mesh period (paper 004 Fig 9)."""

    mesh_position: np.ndarray  # [rad], over [0, 2π/z_p)
    pressure_angle: np.ndarray  # β [rad]
    mesh_stiffness: np.ndarray  # k_cr [N/mm]
    pins_in_contact: np.ndarray
    max_force: np.ndarray  # [N]
    contact: LoadedContact

    @property
    def pressure_angle_mean(self) -> float:
        """Mean β over the mesh period [rad]."""
        return float(np.mean(self.pressure_angle))

    @property
    def mesh_stiffness_mean(self) -> float:
        """Mean k_cr over the mesh period [N/mm]."""
        return float(np.mean(self.mesh_stiffness))


def mesh_period_contact(
    pair: CycloidPinPair, torque_Nmm: float, n_positions: int = 48
) -> MeshPeriodContact:
    """Loaded contact at ``n_positions`` equally spaced positions over one mesh period."""
    if n_positions < 4:
        raise ParameterError("n_positions", n_positions, "must be ≥ 4")
    p = np.arange(n_positions) * pair.mesh_pitch_rad / n_positions
    c = loaded_contact(pair, torque_Nmm, p)
    return MeshPeriodContact(
        mesh_position=p,
        pressure_angle=c.pressure_angle,
        mesh_stiffness=c.mesh_stiffness,
        pins_in_contact=c.pins_in_contact,
        max_force=np.max(c.force, axis=1),
        contact=c,
    )


def fourier_fit(values: ArrayLike, n_harmonics: int) -> tuple[float, np.ndarray, np.ndarray]:
    """Fourier series of equally spaced samples over one period (paper 004 eq 11/13 form).

    Returns (mean, a_l, b_l) such that v(s) ≈ mean + Σ_l a_l cos(l s) + b_l sin(l s), with s the
    phase over the period in [0, 2π), l = 1..n_harmonics.
    """
    v = np.asarray(values, dtype=float)
    n = v.size
    if not 1 <= n_harmonics < n / 2:
        raise ParameterError("n_harmonics", n_harmonics, f"must be in [1, {n // 2 - 1}]")
    c = np.fft.rfft(v) / n
    a = 2.0 * c.real[1 : n_harmonics + 1]
    b = -2.0 * c.imag[1 : n_harmonics + 1]
    return float(c.real[0]), a, b


def fourier_eval(mean: float, a: ArrayLike, b: ArrayLike, phase: ArrayLike) -> np.ndarray:
    """Evaluate a :func:`fourier_fit` series at ``phase`` [rad over one period]."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    s = np.asarray(phase, dtype=float)[..., None]
    ll = np.arange(1, a.size + 1)
    return mean + np.sum(a * np.cos(ll * s) + b * np.sin(ll * s), axis=-1)


LI2023_PAIR = CycloidPinPair()
"""Paper 004 Table 1 pair without modification."""
LI2023_PAIR_MODIFIED = CycloidPinPair(
    pin_radius_modification_mm=-0.01, pin_position_modification_mm=-0.05
)
"""Paper 004 Table 1 pair with the section 4.1 modification (Δr_p = −0.05, Δr_rp = −0.01 mm)."""
