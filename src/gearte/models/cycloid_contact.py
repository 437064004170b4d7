"""Loaded tooth contact of a cycloid disc on its pins (Hu et al. 2020, section 4, eq 28–47).

Units: mm, N, N·mm, MPa, rad.

Model as read (see docs/validation/hu2020.md for the garbled print)::

    l_i      = r_c sin φ_i / S_i,  r_c = a z_c                                  (36)
    δ_i      = (l_i / r_c) δ_max        normal approach of pin i                (37)
    δ_max    = 2 F_max (1−μ²)/(π E b) · (2/3 + ln(16 r |ρ| / c²))                (38)
    c        = 4.99e-3 · (4 (1−μ²) F_max |ρ| r / (E b (|ρ| + r)))^½              (39, as printed)
    ρ        = curvature radius at φ0 = arccos K1 (eq 40), r = r_rp + Δr_rp
    in mesh  ⇔ δ_i > Δ_i (eq 32 clearance), loaded flank sin φ_i > 0
    F_i      = (δ_i − Δ_i)/δ_max · F_max                                          (41)
    T_c      = Σ F_i l_i   ⇒   F_max = T_c / Σ (l_i/r_c − Δ_i/δ_max) l_i          (42–44)
    T_c      = s T,  s = 0.55 in the paper (uneven split between the two discs)

``F_max`` is the force the model assigns to a pin at the point of largest arm (l = r_c): the
paper's "maximum contact force". The largest force actually carried by a pin at a given mesh
position, ``max_i F_i``, is at most F_max (equal when a pin sits at φ0).

The 4.99e-3 factor of eq 39 is not the classical Hertz half-width constant; the printed form is
kept because it is what reproduces Tables 4–5 and 7–8 (δ_max = 0.0116 mm at 1910.3 N).

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from gearte._jit import kernel
from gearte.errors import ConvergenceError, ParameterError
from gearte.geometry.cycloid import CycloidStage, geometry_radii
from gearte.geometry.cycloid_kernels import pin_mesh_table
from gearte.limits import check_floor, check_load_torque
from gearte.models.contact_law import (
    DEFAULT_LAW,
    HU2020_HALF_WIDTH_FACTOR,
    LOG_LAWS,
    approach,
    check_law,
    check_material,
    contact_modulus,
    force_from_coefficients,
    line_contact_a0_scalar,
    log_law_coefficients,
    max_contact_pressure,
    max_contact_pressure_scalar,
)
from gearte.models.cycloid_contact_record import ToothContact
from gearte.solvers.contact import (
    _LIMIT,
    _OK,
    _beyond_the_law,
    _log_force,
    _rotation_one,
    _solve_one,
    check_status,
    check_torque_balance,
    compliance_limit,
    solve_load_sharing_plain,
    solve_rotation_plain,
)

__all__ = [
    "compliance_constants",
    "half_width",
    "max_normal_deformation",
    "pin_approach",
    "pin_forces",
    "start_force",
    "ToothContact",
    "tooth_contact",
]

#: The constant of eq 39 as printed (defined in :mod:`gearte.models.contact_law`).
HALF_WIDTH_FACTOR = HU2020_HALF_WIDTH_FACTOR


def compliance_constants(
    rho: float, r: float, E: float, mu: float, b: float, *, law: str
) -> tuple[float, float]:
    """Constants (A [mm/N], B [N]) with δ(F) = A F (2/3 + ln(B/F)) for a contact law.

    Parameters
    ----------
    rho : float
        Curvature radius of the disc profile at the contact [mm] (ρ < 0 convex).
    r : float
        Pin radius [mm].
    E : float
        Young's modulus of disc and pins [MPa].
    mu : float
        Poisson's ratio [-].
    b : float
        Face width of one disc [mm].
    law : {"hu2020", "line_contact"}
        The law of :mod:`gearte.models.contact_law` (``"hu2020"``: eq 38–39 as printed); no
        default, the caller names it.

    Notes
    -----
    Both laws have the form δ = F (a0 − a1 ln F) (:func:`gearte.models.contact_law.
    log_law_coefficients`); here A = a1 and B = exp(a0/a1 − 2/3), the form the compiled solver
    of eq 42–44 takes.

    References
    ----------
    Hu et al. (2020) eq 38–39 and 42–44, doi:10.3390/app10020481.
    """
    for name, v in (("rho", abs(rho)), ("r", r), ("b", b)):
        if not (math.isfinite(v) and v > 0.0):
            raise ParameterError(name, v, "must be finite and > 0")
    check_material(E, mu, fields=("E", "mu"))
    a0, a1 = log_law_coefficients(law, rho, r, E, mu, b)
    A = float(a1)
    return A, float(math.exp(float(a0) / A - 2.0 / 3.0))


def half_width(F: ArrayLike, rho: float, r: float, E: float, mu: float, b: float) -> np.ndarray:
    """Contact 'half-width' c of eq 39 as printed [mm].

    ``c = 4.99e-3 (4 (1−μ²) F |ρ| r / (E b (|ρ| + r)))^½`` with F [N], ρ, r, b [mm], E [MPa].
    Not Hertz's half-width (:func:`gearte.models.contact_law.hertz_half_width`); see
    docs/contact-law.md.

    Parameters
    ----------
    F : array_like
        Contact force [N].
    rho : float
        Curvature radius of the disc profile at the contact [mm] (ρ < 0 convex).
    r : float
        Pin radius [mm].
    E : float
        Young's modulus [MPa].
    mu : float
        Poisson's ratio μ [-].
    b : float
        Face width of one disc [mm].

    Returns
    -------
    numpy.ndarray
        c [mm].

    References
    ----------
    Hu et al. (2020) eq 39, doi:10.3390/app10020481.
    """
    check_material(E, mu, fields=("E", "mu"))
    F = np.asarray(F, dtype=float)
    rho = abs(rho)
    return HALF_WIDTH_FACTOR * np.sqrt(4.0 * (1.0 - mu * mu) * F * rho * r / (E * b * (rho + r)))


def max_normal_deformation(
    F: ArrayLike, rho: float, r: float, E: float, mu: float, b: float, *, law: str
) -> np.ndarray:
    """Maximum normal deformation δ_max [mm] under the pin force F [N] (eq 38).

    Parameters
    ----------
    F : array_like
        Maximum contact force F_max [N].
    rho : float
        Curvature radius of the disc profile at the contact [mm] (ρ < 0 convex).
    r : float
        Pin radius [mm].
    E : float
        Young's modulus [MPa].
    mu : float
        Poisson's ratio [-].
    b : float
        Face width of one disc [mm].
    law : {"hu2020", "line_contact"}
        :func:`gearte.models.contact_law.approach` of this law (``"hu2020"``: eq 38–39 as
        printed); no default, the caller names it.

    Returns
    -------
    numpy.ndarray
        δ_max [mm].

    Examples
    --------
    >>> d = max_normal_deformation(1910.3, -43.598, 2.978, 2.06e5, 0.3, 11.0, law="hu2020")
    >>> round(float(d), 4)
    0.0116

    References
    ----------
    Hu et al. (2020) eq 38, doi:10.3390/app10020481.
    """
    check_material(E, mu, fields=("E", "mu"))
    return approach(F, law, rho, r, E, mu, b)


def pin_approach(lr: ArrayLike, delta_max: ArrayLike) -> np.ndarray:
    """Normal approach δ_i = (l_i/r_c) δ_max [mm] (eq 37); negative on the unloaded flank.

    Parameters
    ----------
    lr : array_like
        Arm ratio l_i / r_c of each pin [-].
    delta_max : array_like
        Normal deformation at the largest arm δ_max [mm].

    Returns
    -------
    numpy.ndarray
        δ_i [mm].

    References
    ----------
    Hu et al. (2020) eq 37, doi:10.3390/app10020481.
    """
    return np.asarray(lr, dtype=float) * np.asarray(delta_max, dtype=float)[..., None]


def pin_forces(
    approach: ArrayLike, clearance: ArrayLike, delta_max: ArrayLike, F_max: ArrayLike
) -> np.ndarray:
    """Contact force per pin F_i = max(δ_i − Δ_i, 0)/δ_max · F_max [N] (eq 41).

    Parameters
    ----------
    approach : array_like
        Normal approach δ_i of each pin [mm] (:func:`pin_approach`).
    clearance : array_like
        Initial clearance Δ_i of each pin [mm].
    delta_max : array_like
        Normal deformation at the largest arm δ_max [mm].
    F_max : array_like
        Force at the largest arm [N].

    Returns
    -------
    numpy.ndarray
        F_i [N].

    References
    ----------
    Hu et al. (2020) eq 41, doi:10.3390/app10020481.
    """
    approach = np.asarray(approach, dtype=float)
    gap = np.maximum(approach - np.asarray(clearance, dtype=float), 0.0)
    dm = np.asarray(delta_max, dtype=float)[..., None]
    return gap / dm * np.asarray(F_max, dtype=float)[..., None]


def start_force(T_c: float, K1: float, z_c: int, r_p: float) -> float:
    """The paper's start value F_max⁰ = ½ (F1 + F2) [N] (eq 45–47, sign restored).

    F1 = 4 T_c / (K1 z_c r_p) (eq 30: all z_p/2 pins loaded, no modification) and F2 = T_c / r_p
    (one pin). Any positive start gives the same solution (the fixed point is unique).

    Parameters
    ----------
    T_c : float
        Torque on the analysed disc [N·mm].
    K1 : float
        Short-width coefficient [-].
    z_c : int
        Number of cycloid teeth [-].
    r_p : float
        Pin-centre-circle radius [mm].

    Returns
    -------
    float
        F_max⁰ [N].

    References
    ----------
    Hu et al. (2020) eq 30 and 45–47, doi:10.3390/app10020481.
    """
    return 0.5 * (4.0 * T_c / (K1 * z_c * r_p) + T_c / r_p)


def tooth_contact(
    stage: CycloidStage,
    torque: float,
    *,
    disc_share: float,
    E: float,
    mu: float,
    mesh_angle: ArrayLike = 0.0,
    F_start: float | None = None,
    rtol: float = 1e-12,
    max_iter: int = 200,
    implementation: str = "numba",
    clearance_model: str = "eq32",
    contact_law: str = DEFAULT_LAW,
) -> ToothContact:
    """Tooth contact analysis of one disc (Hu et al. 2020, section 4).

    Parameters
    ----------
    stage : CycloidStage
        The modified stage (face width ``stage.b`` is one disc's).
    torque : float
        Output torque of the stage T [N·mm], at least the plausibility floor of a load torque
        (1 N·mm = 1 mN·m, ``gearte.limits.FLOORS``).
    disc_share : float
        Share s of the torque carried by the analysed disc, T_c = s T [-], in [0.01, 1] (the
        floor of a disc share; Hu et al.: 0.55; required, no paper value as a default).
    E : float
        Young's modulus [MPa], from the floor 1 000 MPa to
        :data:`gearte.models.contact_law.MAX_YOUNGS_MODULUS_MPA`.
    mu : float
        Poisson's ratio [-], in [0, 0.5).
    mesh_angle : array_like
        Mesh position(s) [rad], the phase of pin 1; 0 is the paper's position (pin 1 on the line
        of centres). One tooth pitch is 2π/z_p.
    F_start : float, optional
        Start value of F_max [N]; default the paper's eq 45. The result does not depend on it.
    rtol : float
        Relative tolerance on F_max [-].
    max_iter : int
        Iteration limit; exceeding it raises :class:`gearte.errors.ConvergenceError`.
    implementation : {"numba", "plain"}
        Compiled kernel or the plain per-pin Python twin.
    clearance_model : {"eq32", "envelope"}
        Initial clearances from eq 32 (the paper, first order in the modifications) or from the
        exact envelope construction (:func:`gearte.geometry.cycloid.envelope_clearance`), both
        closed at φ0.
    contact_law : {"line_contact", "hu2020"}
        ``"hu2020"``: the paper's scheme as printed — eq 38–39 at ρ(φ0) for F_max and the
        secant stiffness F_max/δ_max for every pin (eq 41–44). ``"line_contact"`` (default): the
        textbook law (:mod:`gearte.models.contact_law`) with each pin's own flank curvature ρ(φ_i)
        (capped at the tip radius in the logarithm), each pin on its own nonlinear law, the disc
        rotation found from the same compatibility and equilibrium (eq 37, 42;
        :func:`gearte.models.cycloid_loaded_contact.solve_rotation`). ``F_max`` and ``δ_max`` are
        then those of a virtual pin at φ0 (l = r_c), as in the paper.

    Returns
    -------
    ToothContact
        Per-position and per-pin results.

    Raises
    ------
    ParameterError
        An argument out of its range (naming it), or a torque that loads a pin beyond the range
        of the contact law (naming ``torque``).
    ConvergenceError
        The solver did not converge within ``max_iter``.

    References
    ----------
    Hu et al. (2020) section 4, eq 28–47, doi:10.3390/app10020481.
    """
    if not (math.isfinite(torque) and torque > 0.0):
        raise ParameterError("torque", torque, "must be finite and > 0 [N·mm]")
    check_load_torque("torque", torque)
    if not (0.0 < disc_share <= 1.0):
        raise ParameterError("disc_share", disc_share, "must be in (0, 1]")
    check_floor("disc_share", disc_share, "disc_share")
    check_material(E, mu, fields=("E", "mu"))
    if implementation not in ("numba", "plain"):
        raise ParameterError("implementation", implementation, "must be 'numba' or 'plain'")
    if clearance_model not in ("eq32", "envelope"):
        raise ParameterError("clearance_model", clearance_model, "must be 'eq32' or 'envelope'")
    check_law(contact_law, "contact_law")
    if contact_law not in LOG_LAWS:
        raise ParameterError(
            "contact_law",
            contact_law,
            "the cycloid-stage tooth contact solves the logarithmic laws "
            f"{', '.join(repr(x) for x in LOG_LAWS)}; 'palmgren' is available in the "
            "rv_reducer analyses",
        )
    T_c = disc_share * torque
    theta = np.atleast_1d(np.asarray(mesh_angle, dtype=float))
    if not np.all(np.isfinite(theta)):
        raise ParameterError("mesh_angle", mesh_angle, "must be finite")
    if implementation == "plain":
        arrays = _tooth_contact_plain(
            stage, torque, T_c, theta, E, mu, F_start, rtol, max_iter, clearance_model, contact_law
        )
        return _result(theta, arrays, T_c, stage.rho0, contact_law)
    theta = theta.reshape(-1)
    R_g, r_g = geometry_radii(stage.r_p, stage.r_rp, stage.dr_rp, stage.dr_p, stage.k1_definition)
    phase, lr, clr, curvature = pin_mesh_table(
        theta, z_p=stage.z_p, K1=stage.K1, R=R_g, r=r_g, dr_rp=stage.dr_rp, dr_p=stage.dr_p
    )
    if clearance_model == "envelope":
        from gearte.geometry.cycloid import envelope_clearance

        clr = np.ascontiguousarray(envelope_clearance(stage, theta), dtype=float)
    rho = stage.rho0
    E_star = float(contact_modulus(E, mu))
    if contact_law == "hu2020":
        A, B = compliance_constants(rho, stage.r, E, mu, stage.b, law="hu2020")
        warm = F_start is None
        F0 = _default_start(stage, torque, T_c, B) if F_start is None else float(F_start)
        if not (math.isfinite(F0) and 0.0 < F0 < compliance_limit(B)):
            raise ParameterError(
                "F_start",
                F0,
                f"start value must be finite, > 0 and below the compliance limit "
                f"{compliance_limit(B):.4g} N",
            )
        F, dmax, nev, status, approach_i, force, in_mesh, pressure = _hu2020_kernel(
            lr, clr, float(stage.r_c), A, B, F0, warm, float(T_c), float(rtol), int(max_iter),
            curvature, float(stage.r), E_star, float(stage.b),
        )  # fmt: skip
        check_status(status, F, nev, rtol=rtol, T_c=T_c, B=B)
    else:
        cap = stage.curvature_cap
        b0, b1 = log_law_coefficients("line_contact", rho, stage.r, E, mu, stage.b, rho_cap=cap)
        F, dmax, nev, status, approach_i, force, in_mesh, pressure = _line_contact_kernel(
            lr, clr, float(stage.r_c), float(T_c), max(float(rtol), 1e-13), _FORCE_RTOL,
            int(max_iter), curvature, float(stage.r), float(E_star), float(stage.b), float(b1),
            float(cap), float(b0),
        )  # fmt: skip
        bad = np.nonzero(status != _OK)[0]
        if bad.size:
            k = int(bad[0])
            if status[k] == _LIMIT:
                raise _beyond_the_law(torque)
            raise ConvergenceError(
                f"tooth contact (mesh position {k}): the disc rotation did not converge after "
                f"{int(nev[k])} evaluations (tolerance {rtol:g})"
            )
        try:  # the kernel's answer must carry T_c (it does not when a pin left the law's range)
            carried = np.sum(np.where(lr > _LOADED, force * lr, 0.0), axis=1) * stage.r_c
            check_torque_balance(carried, T_c, max(float(rtol), 1e-13))
        except ParameterError:
            raise _beyond_the_law(torque) from None
    _check_deformation(dmax, stage, torque)
    arrays = (phase, lr, clr, curvature, F, dmax, nev, approach_i, force, in_mesh, pressure)
    return _result(theta, arrays, T_c, rho, contact_law)


def _result(
    theta: np.ndarray, arrays: tuple[np.ndarray, ...], T_c: float, rho: float, contact_law: str
) -> ToothContact:
    """The result from (phase, l/r_c, clearance, curvature, F_max, δ_max, evaluations, approach,
    force, in-mesh, pressure) of either implementation."""
    phase, lr, clr, curvature, F, dmax, nev, approach_i, force, in_mesh, pressure = arrays
    return ToothContact(
        mesh_angle=theta,
        phase=phase,
        clearance=np.where(lr > _LOADED, clr, np.nan),
        approach=approach_i,
        force=force,
        in_mesh=in_mesh,
        F_max=F,
        delta_max=dmax,
        n_eval=nev,
        T_c=T_c,
        rho=rho,
        curvature=curvature,
        pressure=pressure,
        contact_law=contact_law,
    )


#: Arm ratio l/r_c above which a pin is on the loaded flank [-].
_LOADED = 1e-12
#: Relative tolerance of each pin's force inside the rotation solve [-].
_FORCE_RTOL = 1e-12


def _default_start(stage: CycloidStage, torque: float, T_c: float, B: float) -> float:
    """The paper's start force (eq 45) of ``"hu2020"``, or a :class:`ParameterError` naming the
    torque when that start already lies beyond the compliance law's range (eq 38)."""
    F0 = start_force(T_c, stage.K1, stage.z_c, stage.r_p)
    if not F0 < compliance_limit(B):
        raise ParameterError(
            "torque",
            torque,
            f"[N·mm] is beyond the range of the compliance law: the paper's start force for "
            f"it (eq 45), {F0:.4g} N, already exceeds the law's limit {compliance_limit(B):.4g} "
            "N (eq 38: ln(16 r |rho| / c^2) must exceed 1/3); lower the torque or widen the face",
        )
    return F0


def _check_deformation(dmax: np.ndarray, stage: CycloidStage, torque: float) -> None:
    if np.max(dmax) > 0.1 * stage.r:
        raise ParameterError(
            "torque",
            torque,
            f"gives a normal deformation of {np.max(dmax):.3g} mm, beyond the elastic contact "
            f"model's range (at most 0.1 x pin radius = {0.1 * stage.r:.3g} mm)",
        )


@njit(cache=True, nogil=True, inline="always")
def _outputs(n, z):  # pragma: no cover - compiled
    """F_max, δ_max, evaluations, status (n,); approach, force, in-mesh, pressure (n, z)."""
    return (
        np.empty(n),
        np.empty(n),
        np.empty(n, dtype=np.int64),
        np.empty(n, dtype=np.int64),
        np.empty((n, z)),
        np.zeros((n, z)),
        np.zeros((n, z), dtype=np.bool_),
        np.zeros((n, z)),
    )


@kernel
def _hu2020_kernel(
    lr, clr, r_c, A, B, F0, warm, T_c, rtol, max_iter, rho, r, E_star, b
):  # pragma: no cover - compiled
    """Eq 41–44 at every position (solver: Illinois on eq 44), then eq 37, 41 and the pressure.

    Positions in order; with ``warm`` each starts from the previous one's F_max."""
    n, z = lr.shape
    F, dmax, nev, status, approach, force, in_mesh, pressure = _outputs(n, z)
    cl = np.empty(z)
    log_b = math.log(B)
    start = F0
    for k in range(n):
        for i in range(z):
            cl[i] = clr[k, i] if lr[k, i] > _LOADED else 1e300
        f, it, st = _solve_one(lr[k], cl, T_c, r_c, A, B, start, rtol, max_iter)
        F[k] = f
        nev[k] = it
        status[k] = st
        if st != _OK:
            dmax[k] = np.nan
            approach[k, :] = np.nan
            continue
        if warm:
            start = f
        k_sec = 1.0 / (A * (2.0 / 3.0 + log_b - math.log(f)))  # F_max/δ_max, eq 41 [N/mm]
        dm = f / k_sec
        dmax[k] = dm
        for i in range(z):
            a = lr[k, i] * dm  # eq 37
            approach[k, i] = a
            if lr[k, i] > _LOADED and a > clr[k, i]:
                fi = (a - clr[k, i]) * k_sec  # eq 41
                force[k, i] = fi
                in_mesh[k, i] = True
                pressure[k, i] = max_contact_pressure_scalar(fi, rho[k, i], r, E_star, b)
    return F, dmax, nev, status, approach, force, in_mesh, pressure


@kernel
def _line_contact_kernel(
    lr, clr, r_c, T_c, rtol, frtol, max_iter, rho, r, E_star, b, a1, rho_cap, b0
):  # pragma: no cover - compiled
    """Each pin on its own line-contact law (eq 37, 42), the disc rotation from the solver,
    F_max of a virtual pin at φ0, forces and pressures. Positions in order, each started from
    the previous one's pin forces and from its rotation extrapolated linearly from the two
    previous positions' (2.0 instead of 3.0 evaluations per position over a Hu 2020 pitch)."""
    n, z = lr.shape
    F, dmax, nev, status, approach, force, in_mesh, pressure = _outputs(n, z)
    arm = np.zeros(z)
    cl = np.zeros(z)
    a0 = np.ones(z)
    a1v = np.full(z, a1)
    u = np.full(z, np.nan)
    f = np.zeros(z)
    rot = np.nan
    rot_before = np.nan  # the rotation two positions back: the start is extrapolated linearly
    u_max = np.nan
    for k in range(n):
        for i in range(z):
            if lr[k, i] > _LOADED:
                arm[i] = lr[k, i] * r_c
                cl[i] = clr[k, i]
                a0[i] = line_contact_a0_scalar(rho[k, i], r, E_star, b, a1, rho_cap)
            else:
                arm[i] = 0.0
                cl[i] = 0.0
        start = 2.0 * rot - rot_before if 2.0 * rot - rot_before > 0.0 else rot
        rk, it, st = _rotation_one(arm, cl, a0, a1v, T_c, start, u, f, rtol, frtol, max_iter)
        nev[k] = it
        if st == _OK:
            for i in range(z):
                if not f[i] < math.inf:
                    st = _LIMIT
        status[k] = st
        if st != _OK:
            F[k] = np.nan
            dmax[k] = np.nan
            approach[k, :] = np.nan
            continue
        rot_before = rot
        rot = rk
        dm = r_c * rk
        dmax[k] = dm
        F[k], u_max = _log_force(dm, b0, a1, u_max, frtol)  # virtual pin at φ0 (l = r_c)
        for i in range(z):
            a = lr[k, i] * dm  # eq 37
            approach[k, i] = a
            if lr[k, i] > _LOADED and a > clr[k, i]:
                force[k, i] = f[i]
                in_mesh[k, i] = True
                pressure[k, i] = max_contact_pressure_scalar(f[i], rho[k, i], r, E_star, b)
    return F, dmax, nev, status, approach, force, in_mesh, pressure


def compile_line_contact_kernel() -> None:
    """Compile (or load from numba's cache) the tooth-contact kernel of the line-contact law.

    The rv_reducer kind's warm-up case (``hu2020_rv80e_initial_reducer``) analyses its cycloid
    stage with the Hu 2020 law; a case on the line-contact law (``li2023_rv_errors``) compiled
    this kernel on its first run after ``gearte warm-cache``, which calls this function after
    that case (:data:`gearte.warm.WARM_ALSO`). A one-position call with the argument types of
    :func:`tooth_contact`'s (its numbers are not used)."""
    one = np.ones((1, 3))
    _line_contact_kernel(
        one, 0.0 * one, 1.0, 1.0, 1e-12, 1e-12, 1, one.copy(), 1.0, 1.0, 1.0, 1.0, 1.0, 1.0
    )


def _tooth_contact_plain(
    stage: CycloidStage,
    torque: float,
    T_c: float,
    theta: np.ndarray,
    E: float,
    mu: float,
    F_start: float | None,
    rtol: float,
    max_iter: int,
    clearance_model: str,
    contact_law: str,
) -> tuple[np.ndarray, ...]:
    """The plain twin of the compiled tooth contact: numpy geometry (gearte.geometry.cycloid),
    the law's numpy functions and the plain solvers; the reference the kernels are tested
    against."""
    phase = stage.pin_phases(theta)
    K1 = stage.K1
    S = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(phase))
    lr = np.sin(phase) / S
    loaded = lr > _LOADED
    if clearance_model == "eq32":
        clr = np.where(loaded, stage.initial_clearance(phase), np.inf)
    else:
        from gearte.geometry.cycloid import envelope_clearance

        clr = np.where(loaded, envelope_clearance(stage, theta), np.inf)
    rho = stage.rho0
    curvature = stage.curvature_radius(phase)
    if contact_law == "hu2020":
        A, B = compliance_constants(rho, stage.r, E, mu, stage.b, law="hu2020")
        if F_start is None:
            F_start = _default_start(stage, torque, T_c, B)
        F, nev = solve_load_sharing_plain(
            lr,
            np.where(loaded, clr, 1e300),
            T_c=T_c,
            r_c=stage.r_c,
            A=A,
            B=B,
            F_start=F_start,
            rtol=rtol,
            max_iter=max_iter,
        )
        k_sec = 1.0 / (A * (2.0 / 3.0 + math.log(B) - np.log(F)))  # F_max/δ_max, eq 41 [N/mm]
        dmax = F / k_sec
    else:
        cap = stage.curvature_cap
        a0, a1 = log_law_coefficients(
            "line_contact", curvature, stage.r, E, mu, stage.b, rho_cap=cap
        )
        arm = np.where(loaded, lr * stage.r_c, 0.0)
        try:
            rot, _ = solve_rotation_plain(
                arm,
                np.where(loaded, clr, 0.0),
                a0,
                a1,
                T_c,
                rtol=max(rtol, 1e-13),
                force_rtol=_FORCE_RTOL,
                max_iter=max_iter,
            )
        except ParameterError:  # T_c > 0 is finite: a pin beyond the law's range, on T_c
            raise _beyond_the_law(torque) from None
        dmax = stage.r_c * rot
        b0, b1 = log_law_coefficients("line_contact", rho, stage.r, E, mu, stage.b, rho_cap=cap)
        F = force_from_coefficients(dmax, b0, b1)
        nev = np.zeros(theta.shape, dtype=np.int64)
    _check_deformation(dmax, stage, torque)
    approach_i = lr * dmax[:, None]
    in_mesh = loaded & (approach_i > clr)
    if contact_law == "hu2020":
        force = np.where(in_mesh, (approach_i - clr) * k_sec[:, None], 0.0)
    else:
        force = np.where(
            in_mesh, force_from_coefficients(np.where(in_mesh, approach_i - clr, 0.0), a0, a1), 0.0
        )
    pressure = max_contact_pressure(force, curvature, stage.r, E, mu, stage.b)
    return phase, lr, clr, curvature, F, dmax, nev, approach_i, force, in_mesh, pressure
