"""Loaded contact of the cycloid–pin pair after Li et al. (2023), section 2 (paper 004).

Hertz line-contact stiffness per pin (eq 2), compatibility (eq 3) and moment equilibrium (eq 4)
give the pins in contact and their forces at one mesh position; the equivalent pressure angle and
the equivalent mesh stiffness (eq 5–7) condense the multi-pin contact into one spring for the lumped
dynamic model (:mod:`gearte.models.rv_dynamics`). Sweeping the mesh position over one mesh period
(2π/z_p of the meshing phase) gives the time-varying stiffness, fitted by a Fourier series.

This is paper 004's method; the paper-000 contact analysis (Hu et al. 2020) lives in
``gearte.models.cycloid_contact``. Both read the geometry (K1, S, arms, eq 32 clearance,
curvature) from one :class:`gearte.geometry.cycloid.CycloidStage` and the pin law from
:mod:`gearte.models.contact_law`.

Units: mm, N, N·mm, MPa, rad. Stiffnesses are returned in N/mm (``*1e3`` → N/m at the edge).

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.geometry.cycloid import CycloidStage
from gearte.models.contact_law import (
    DEFAULT_LAW,
    check_law,
    check_material,
    force_from_coefficients,
    law_coefficients,
    max_contact_pressure,
)
from gearte.models.cycloid_loaded_contact_record import LoadedContact, MeshPeriodContact
from gearte.solvers.contact import solve_rotation as _solve_rotation

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
    "solve_rotation",
    "mesh_period_contact",
    "fourier_fit",
    "fourier_eval",
]


@dataclass(frozen=True, kw_only=True)
class CycloidPinPair:
    """Cycloid–pin pair of one disc (the quantities of paper 004's Table 1) with its material.

    Geometry and material have no defaults (no paper data as code defaults): a missing one is an
    error naming it. Li et al.'s Table 1 pair is data of the bundled ``li2023_rv*`` cases.

    The geometry (K1, S, arms, eq 32 clearance, curvature) is that of the
    :class:`gearte.geometry.cycloid.CycloidStage` built from these fields (:attr:`stage`), the
    contact law that of :mod:`gearte.models.contact_law` — one implementation of each.

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
        E [MPa] and ν [-] of disc and pins (one material, as in paper section 4); E from the
        plausibility floor 1 000 MPa to :data:`gearte.models.contact_law.MAX_YOUNGS_MODULUS_MPA`,
        ν in [0, 0.5) (:func:`gearte.models.contact_law.check_material`).
    pin_radius_modification_mm : float
        Δr_rp, equidistant ("roller radius") modification [mm]; default 0 (unmodified).
    pin_position_modification_mm : float
        Δr_p, shifted ("roller position") modification [mm]; default 0 (unmodified).
    curvature_cap_mm : float or None
        Upper bound of |ρ_c| in the Hertz logarithm [mm]. The profile's curvature radius passes
        through infinity at its inflection (≈ 50.8° for Table 1), next to the most loaded pins;
        the log term of eq 2 would then send the pin stiffness to zero. ``None`` caps at the
        disc's tip radius (:attr:`gearte.geometry.cycloid.CycloidStage.curvature_cap`).
    k1_definition : {"ground", "nominal"}
        K1 = e z_p / (r_p + Δr_p) as for every other analysis of the stage (default) or Li's
        e z_p / r_p (:data:`gearte.geometry.cycloid.K1_DEFINITIONS`).
    contact_law : {"line_contact", "hu2020", "palmgren"}
        The pin contact law (:mod:`gearte.models.contact_law`); eq 2 of the paper is the
        textbook line contact.
    """

    pin_count: int
    pin_radius_mm: float
    pin_circle_radius_mm: float
    eccentricity_mm: float
    face_width_mm: float
    youngs_modulus_MPa: float  # noqa: N815 - unit suffix
    poisson_ratio: float
    pin_radius_modification_mm: float = 0.0
    pin_position_modification_mm: float = 0.0
    curvature_cap_mm: float | None = None
    k1_definition: str = "ground"
    contact_law: str = DEFAULT_LAW

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
        check_material(
            self.youngs_modulus_MPa,
            self.poisson_ratio,
            fields=("youngs_modulus_MPa", "poisson_ratio"),
        )
        if self.curvature_cap_mm is not None and not self.curvature_cap_mm > 0:
            raise ParameterError("curvature_cap_mm", self.curvature_cap_mm, "must be > 0")
        check_law(self.contact_law, "contact_law")
        k1 = self.eccentricity_mm * self.pin_count / self.pin_circle_radius_mm
        if not k1 < 1.0:
            raise ParameterError(
                "eccentricity_mm",
                self.eccentricity_mm,
                f"short-width coefficient K1 = e z_p / r_p = {k1:.4f} must be < 1",
            )
        try:
            stage = CycloidStage(
                z_p=self.pin_count,
                r_p=self.pin_circle_radius_mm,
                r_rp=self.pin_radius_mm,
                a=self.eccentricity_mm,
                b=self.face_width_mm,
                dr_rp=self.pin_radius_modification_mm,
                dr_p=self.pin_position_modification_mm,
                k1_definition=self.k1_definition,
            )
        except ParameterError as exc:
            if exc.field != "dr_rp/dr_p":
                raise
            raise ParameterError(
                "pin_radius_modification_mm/pin_position_modification_mm",
                (self.pin_radius_modification_mm, self.pin_position_modification_mm),
                f"the modification interferes ({exc.reason}); use Δr_rp ≤ 0 with "
                "Δr_p ≤ Δr_rp·(…) as in paper 004 (−0.01, −0.05)",
            ) from None
        object.__setattr__(self, "_stage", stage)

    @property
    def stage(self) -> CycloidStage:
        """The pair's cycloid stage (geometry shared with every other analysis)."""
        return self._stage  # type: ignore[attr-defined]

    @property
    def tooth_count(self) -> int:
        """z_c = z_p − 1 [-]."""
        return self.pin_count - 1

    @property
    def K1(self) -> float:  # noqa: N802 - paper symbol
        """Short-width coefficient of the stage (:attr:`CycloidStage.K1`) [-]."""
        return self.stage.K1

    @property
    def pitch_radius_mm(self) -> float:
        """r_c = e z_c, pitch radius of the disc [mm] (paper 004 after eq 5)."""
        return self.stage.r_c

    @property
    def mesh_pitch_rad(self) -> float:
        """One mesh period in meshing phase, 2π/z_p [rad]."""
        return 2.0 * np.pi / self.pin_count

    @property
    def rho_cap_mm(self) -> float:
        """Cap on |ρ_c| used in the Hertz logarithm [mm]."""
        if self.curvature_cap_mm is not None:
            return float(self.curvature_cap_mm)
        return self.stage.curvature_cap

    @property
    def modified(self) -> bool:
        return self.pin_radius_modification_mm != 0.0 or self.pin_position_modification_mm != 0.0


def pin_geometry(pair: CycloidPinPair, phi: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Arm of each pin's contact normal about the disc centre and S(φ).

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
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
    :meth:`CycloidStage.normal_arm` and :meth:`CycloidStage.S` (Hu 2020 eq 36, 4). Every contact
    normal passes through the pitch point P at distance r_c = e z_c from the disc centre;
    |P − pin centre| = r_p S, hence l = r_c sin φ / S ≤ r_c, with equality at φ0 = arccos K1.

    References
    ----------
    Hu et al. (2020) eq 4 and 36, doi:10.3390/app10020481.
    """
    return pair.stage.normal_arm(phi), pair.stage.S(phi)


def modification_clearance(pair: CycloidPinPair, phi: ArrayLike) -> np.ndarray:
    """Initial normal clearance of each pin from the profile modification [mm].

    Hu et al. (2020) eq 32 (:meth:`CycloidStage.initial_clearance`), which paper 004 uses through
    its ref. [31]; zero at φ0 = arccos K1.

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    phi : array_like
        Meshing phase φ_i of the pins [rad].

    Returns
    -------
    numpy.ndarray
        Δ_i [mm].

    References
    ----------
    Hu et al. (2020) eq 32, doi:10.3390/app10020481; Li et al. (2023) ref. [31],
    doi:10.3390/machines11060626.
    """
    return pair.stage.initial_clearance(phi)


def profile_curvature_radius(pair: CycloidPinPair, phi: ArrayLike) -> np.ndarray:
    """Signed curvature radius of the cycloid profile at the contact with pin φ [mm].

    Hu et al. 2020 eq 40 (:meth:`CycloidStage.curvature_radius`); ρ > 0: concave flank (root
    side), ρ < 0: convex (tip side); |ρ| → ∞ at the inflection.

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    phi : array_like
        Meshing phase φ of the pin [rad].

    Returns
    -------
    numpy.ndarray
        ρ [mm].

    References
    ----------
    Hu et al. (2020) eq 40, doi:10.3390/app10020481.
    """
    return pair.stage.curvature_radius(phi)


def _law_coefficients(
    pair: CycloidPinPair, rho_c: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(a0, a1, a2, a3) of the pair's law, ``δ = F (a0 − a1 ln F) + a2 F^a3``."""
    return law_coefficients(
        pair.contact_law,
        rho_c,
        pair.stage.r,
        pair.youngs_modulus_MPa,
        pair.poisson_ratio,
        pair.face_width_mm,
        rho_cap=pair.rho_cap_mm,
    )


def hertz_line_deflection(pair: CycloidPinPair, force_N: ArrayLike, rho_c: ArrayLike) -> np.ndarray:
    """Normal deflection of a pin–tooth pair under load F (paper 004 eq 2) [mm].

    δ = (2F / (π B)) Σ_{k=c,r} (1 − ν_k²)/E_k · (ln(4 ρ_k / b) − 1/2),
    b = sqrt(4 F R* / (π B E*)),  1/R* = 1/r − 1/ρ_c,  1/E* = Σ (1 − ν_k²)/E_k,

    with ρ_r = r for the pin and ρ_c = min(|ρ_c|, cap) for the disc: the ``"line_contact"`` law of
    :mod:`gearte.models.contact_law` (or the pair's other law).

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    force_N : array_like
        Pin force F [N], > 0.
    rho_c : array_like
        Signed curvature radius of the disc flank at the contact [mm]
        (:func:`profile_curvature_radius`).

    Returns
    -------
    numpy.ndarray
        δ [mm].

    Notes
    -----
    Eq 2 prints ``ln 4ρ/b − 1/2``; b is read as the *half* width of the Hertz strip (the
    classical line-contact approach of a cylinder, Johnson 1985 §5.6), since the full width would
    only shift the log by ln 2. The relative radius uses the sign of ρ_c (concave root flank vs
    convex tip flank). The pin radius is that of the ground profile, r_rp + Δr_rp.

    References
    ----------
    Li et al. (2023) eq 2, doi:10.3390/machines11060626; Johnson (1985) §5.6,
    doi:10.1017/CBO9781139171731.
    """
    f = np.asarray(force_N, dtype=float)
    a0, a1, a2, a3 = _law_coefficients(pair, rho_c)
    return f * (a0 - a1 * np.log(f)) + a2 * f**a3


def hertz_line_force(
    pair: CycloidPinPair, deflection_mm: ArrayLike, rho_c: ArrayLike, *, rtol: float = 1e-12
) -> np.ndarray:
    """Inverse of :func:`hertz_line_deflection`: pin force F [N] for a deflection δ [mm].

    :func:`gearte.models.contact_law.force_from_coefficients`; δ ≤ 0 gives F = 0.

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    deflection_mm : array_like
        Normal deflection δ [mm].
    rho_c : array_like
        Signed curvature radius of the disc flank at the contact [mm].
    rtol : float
        Relative tolerance on F [-].

    Returns
    -------
    numpy.ndarray
        F [N].
    """
    a0, a1, a2, a3 = _law_coefficients(pair, rho_c)
    if np.any(a2 != 0.0):  # the power law (Palmgren's): inverted in closed form (a0 = a1 = 0)
        return (np.maximum(np.asarray(deflection_mm, dtype=float), 0.0) / a2) ** (1.0 / a3)
    return force_from_coefficients(deflection_mm, a0, a1, rtol=rtol)


def solve_rotation(
    arm: np.ndarray,
    clearance: np.ndarray,
    a0: np.ndarray,
    a1: np.ndarray,
    torque_Nmm: float,
    *,
    rtol: float = 1e-11,
    power: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Disc rotation and pin forces that carry ``torque_Nmm`` (compatibility + equilibrium).

    Pin i is compressed by ``δ_i = l_i Δφ − c_i`` (compatibility, Li 2023 eq 3 / Hu 2020 eq 37),
    carries ``F_i = F(δ_i)`` of the law ``δ = F (a0_i − a1_i ln F)`` with its own coefficients
    (its own flank curvature), and ``T = Σ F_i l_i`` (eq 4 / eq 42). T(Δφ) is increasing, so
    Δφ is bracketed by doubling and found by a safeguarded Newton iteration (dT/dΔφ = Σ k_t l²,
    bisection when a step leaves the bracket), vectorised over positions.

    Parameters
    ----------
    arm : ndarray (n, z)
        Arm l_i of each pin's contact normal [mm]; 0 for pins that cannot carry load.
    clearance : ndarray (n, z)
        Normal clearance c_i at Δφ = 0 [mm] (finite).
    a0, a1 : ndarray (n, z)
        Contact-law coefficients (:func:`gearte.models.contact_law.log_law_coefficients`) [mm/N].
    torque_Nmm : float
        Torque on the disc [N·mm], > 0.
    rtol : float
        Relative tolerance on Δφ [-].
    power : (ndarray, ndarray), optional
        ``(a2, a3)`` [mm/N^a3, -] of a power law ``δ = a2 F^a3`` (Palmgren's; a0 = a1 = 0), as
        :func:`gearte.solvers.contact.solve_rotation`.

    Returns
    -------
    rotation : ndarray (n,)
        Δφ [rad]; force : ndarray (n, z) [N].

    Raises
    ------
    ParameterError
        A pin would be loaded beyond the range of the law (δ(F) no longer increasing).

    References
    ----------
    Li et al. (2023) eq 3–4, doi:10.3390/machines11060626; Hu et al. (2020) eq 37–44,
    doi:10.3390/app10020481.
    """
    try:
        return _solve_rotation(arm, clearance, a0, a1, torque_Nmm, rtol=rtol, power=power)
    except ParameterError as exc:  # the solver names its own argument, "torque"
        raise ParameterError("torque_Nmm", torque_Nmm, exc.reason) from None


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
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    torque_Nmm : float
        T, torque carried by this disc [N·mm] (paper: 450 N·m output over 2 discs → 225e3).
    mesh_position : array_like
        Meshing phase of pin 1, p ∈ [0, 2π/z_p) [rad]; pin i sits at φ_i = p + 2π(i−1)/z_p.
    rtol : float
        Relative tolerance on the torque balance [-].

    Returns
    -------
    LoadedContact

    Notes
    -----
    Compatibility (eq 3): pin i's angular backlash relative to the first pin to touch is
    φ_bl,i = Δ_i/l_i − min_j Δ_j/l_j; it is in contact when Δφ_c > φ_bl,i and then
    δ_i = (Δφ_c − φ_bl,i) l_i. Equilibrium (eq 4): T = Σ F_i l_i with F_i = k_n(F_i) δ_i
    (eq 2 inverted per pin). T(Δφ_c) is increasing; Δφ_c is found by :func:`solve_rotation`.

    Equivalent quantities (eq 5–7): F_t = Σ F_i l_i / r_c, F_r = Σ F_i sqrt(1 − (l_i/r_c)²),
    F_cr = hypot(F_t, F_r), β = atan(F_r/F_t). The garbled eq 7 is read as
    k_cr = F_cr / (r_c Δφ_c cos β): the single spring of the dynamic model acts along β at the
    pitch point, its deflection for a disc rotation Δφ_c is r_c Δφ_c cos β, and with this
    reading it reproduces the quasi-static torsional stiffness T/Δφ_c = k_cr r_c² cos²β.

    Examples
    --------
    The unmodified pair of Li et al.'s Table 1 (data of ``examples/li2023_rv_unmodified.toml``)
    at 225 N·m per disc:

    >>> pair = CycloidPinPair(pin_count=40, pin_radius_mm=3.0, pin_circle_radius_mm=85.8,
    ...     eccentricity_mm=1.3, face_width_mm=12.0, youngs_modulus_MPa=2.06e5, poisson_ratio=0.3)
    >>> c = loaded_contact(pair, 225e3, 0.0)
    >>> round(float(np.degrees(c.pressure_angle[0])), 1)
    32.6

    References
    ----------
    Li et al. (2023) §2.2–2.3, eq 2–7, doi:10.3390/machines11060626.
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
    a0, a1, a2, a3 = _law_coefficients(pair, rho)
    la = np.where(loaded, arm, 0.0)
    power = (a2, a3) if np.any(a2 != 0.0) else None
    rot, force = solve_rotation(la, backlash * la, a0, a1, torque_Nmm, rtol=rtol, power=power)
    rc = pair.pitch_radius_mm
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
        pressure=max_contact_pressure(
            force,
            rho,
            pair.stage.r,
            pair.youngs_modulus_MPa,
            pair.poisson_ratio,
            pair.face_width_mm,
        ),
    )


def mesh_period_contact(
    pair: CycloidPinPair, torque_Nmm: float, n_positions: int = 48
) -> MeshPeriodContact:
    """Loaded contact at ``n_positions`` equally spaced positions over one mesh period.

    Parameters
    ----------
    pair : CycloidPinPair
        The cycloid–pin pair of one disc (geometry [mm], material [MPa], contact law).
    torque_Nmm : float
        Torque carried by this disc [N·mm], > 0.
    n_positions : int
        Mesh positions over one period 2π/z_p [-], ≥ 4.

    Returns
    -------
    MeshPeriodContact
        β [rad], k_cr [N/mm] and the contact at each position (paper 004 Fig 9).
    """
    if n_positions < 4:
        raise ParameterError("n_positions", n_positions, "must be ≥ 4")
    return _mesh_period_contact(pair, float(torque_Nmm), int(n_positions))


@lru_cache(maxsize=16)
def _mesh_period_contact(pair: CycloidPinPair, torque_Nmm: float, n_positions: int):
    """:func:`mesh_period_contact`, kept for the last 16 (pair, torque, positions): a pair is a
    frozen set of scalars, and an ``rv_reducer`` run builds its dynamic model twice (the
    preflight's checks, then the analyses), each needing the same 48-position loaded contact
    (~0.12 s of CPU). The result is shared between callers: treat its arrays as read-only."""
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

    Parameters
    ----------
    values : array_like, shape (n,)
        Samples over one period, equally spaced from phase 0 [any unit].
    n_harmonics : int
        Number of harmonics [-], 1 ≤ n_harmonics < n/2.

    Returns
    -------
    mean : float
        Mean of the samples [their unit].
    a, b : numpy.ndarray
        Cosine and sine amplitudes a_l, b_l [their unit].

    References
    ----------
    Li et al. (2023) eq 11 and 13, doi:10.3390/machines11060626.
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
    """Evaluate a :func:`fourier_fit` series at ``phase`` [rad over one period].

    Parameters
    ----------
    mean : float
        Mean term [the series' unit].
    a, b : array_like
        Cosine and sine amplitudes [the series' unit].
    phase : array_like
        Phase s over the period [rad], 2π = one period.

    Returns
    -------
    numpy.ndarray
        v(s) [the series' unit].
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    s = np.asarray(phase, dtype=float)[..., None]
    ll = np.arange(1, a.size + 1)
    return mean + np.sum(a * np.cos(ll * s) + b * np.sin(ll * s), axis=-1)
