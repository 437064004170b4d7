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
manufacturing errors), energy ``k w² / 2``. Isotropic bearings are two rows (x and y); with a
radial clearance ``c`` their energy is ``k (|w| − c)₊² / 2`` (a convex dead band). A pin contact
is a unilateral row: approach ``delta = B · q - g`` with ``g`` the initial normal clearance
(:func:`gearte.geometry.cycloid.normal_clearance_unclosed` of the modified profile, minus the
pin-radius error, plus the pin-centre error projected on the normal), force ``k max(delta, 0)``
with the load-dependent stiffness of Hu 2020 section 4 (:func:`contact_law`).

Pin-contact geometry (derived, not taken from a paper's figure): for disc ``j`` with eccentric
direction ``c_j`` the pitch point is ``P_j = a z_p c_j``; the contact normal of pin ``k`` passes
through ``P_j`` and the pin centre, ``n = (p_k - P_j)/|p_k - P_j|`` with ``|p_k - P_j| = r_p S``,
``S = sqrt(1 + K1² - 2 K1 cos phi)`` — hence the lever ``l = r_c sin(phi)/S`` of Hu 2020 eq 36
and the classical load law ``F ∝ sin(phi)/S`` for a rigid rotation of the disc. On a design
with a shifted modification (Δr_p ≠ 0) the normal is turned to the true contact point of that
profile (:func:`gearte.geometry.cycloid.true_contact`, docs/contact-law.md "Modified profiles").

References
----------
Han L., Xu W., Wang Y., Zhang Y. (2023). JERR 25(8). doi:10.9734/JERR/2023/v25i8970
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

import functools
import math
import weakref
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ConvergenceError, ParameterError
from gearte.geometry.cycloid import CycloidStage, true_contact
from gearte.geometry.rv import RVReducer, pin_contacts
from gearte.limits import check_floor
from gearte.models.contact_law import (
    DEFAULT_LAW,
    HU2020_HALF_WIDTH_FACTOR,
    PALMGREN_COEFFICIENT,
    PALMGREN_FORCE_EXPONENT,
    PALMGREN_LENGTH_EXPONENT,
    check_law,
    check_pin_pressure,
    hertz_half_width,
    implausible_pin_pressure,
    law_coefficients,
    max_contact_pressure,
)
from gearte.models.rv_records import LoadSharing, TransmissionError
from gearte.solvers.rv_batch import solve_positions, solve_system
from gearte.solvers.rv_equilibrium import (
    CLEARANCE_RESIDUAL,
    ContactLaw,
    as_solver_law,
)
from gearte.units import rad_to_deg

__all__ = [
    "DofLayout",
    "RVSystem",
    "dof_layout",
    "cycloid_stage",
    "check_reducer_torque",
    "implausible_reducer_torque",
    "contact_law",
    "PinContactLaw",
    "solver_law",
    "pin_series_compliance",
    "cam_row_stiffness",
    "mesh_row_stiffness",
    "assemble",
    "LoadSharing",
    "load_sharing",
    "check_conformal",
    "CONFORMAL_HALF_WIDTH_LIMIT",
    "PeakPin",
    "peak_pin",
    "ROOT_SQUEEZE_SIN",
    "output_positions",
    "TransmissionError",
    "mesh_period",
    "transmission_error",
]


# ------------------------------------------------------------------------------------------
# The cycloid stage of the reducer and its contact law (reused from gearte.geometry.cycloid and
# gearte.models.cycloid_contact, issue 2: one implementation of Hu 2020 eq 32–40)
# ------------------------------------------------------------------------------------------
def cycloid_stage(reducer: RVReducer) -> CycloidStage:
    """The reducer's cycloid–pin stage as a :class:`gearte.geometry.cycloid.CycloidStage`.

    Its validation (K1 < 1, no undercut, pins fit, non-interfering eq 32 clearance) applies.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).

    Returns
    -------
    CycloidStage
        The stage (K1, clearances and curvature of Hu et al.'s eq 3, 32 and 40).

    References
    ----------
    Hu et al. (2020) eq 1–4, 32–40, doi:10.3390/app10020481.
    """
    # one per reducer: both are frozen, and building a stage validates it (~0.17 ms: the
    # undercut check samples the pin-centre path); a TE analysis asked for it ~27 times
    stage = _STAGES.get(reducer)
    if stage is None:
        stage = CycloidStage(
            z_p=reducer.pins.count,
            r_p=reducer.pins.circle_radius,
            r_rp=reducer.pins.pin_radius,
            a=reducer.cranks.eccentricity,
            b=reducer.discs.face_width,
            dr_rp=reducer.discs.equidistant_modification,
            dr_p=reducer.discs.shift_modification,
        )
        _STAGES[reducer] = stage
    return stage


#: The stage of each reducer alive (:func:`cycloid_stage`), dropped with the reducer.
_STAGES: weakref.WeakKeyDictionary[RVReducer, CycloidStage] = weakref.WeakKeyDictionary()


def implausible_reducer_torque(
    reducer: RVReducer, torque: float, share: float | None = None
) -> str | None:
    """Why no pin of ``reducer`` could carry ``torque`` [N·mm], or ``None`` when one could
    (:func:`gearte.models.contact_law.implausible_pin_pressure` on :func:`cycloid_stage` with
    the discs' E and ν; ``share`` of the torque on one disc, default ``1 / discs.count``).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description.
    torque : float
        Torque [N·mm] (its magnitude counts).
    share : float, optional
        Share of ``torque`` carried by one disc [-] (1 for a torque given per disc).

    Returns
    -------
    str or None
        The reason, in the case files' wording, or ``None``.

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
    """
    stage, share, E, nu = _pin_pressure_inputs(reducer, share)
    return implausible_pin_pressure(stage, torque, share, E, nu)


def _pin_pressure_inputs(
    reducer: RVReducer, share: float | None
) -> tuple[CycloidStage, float, float, float]:
    """(stage, share, E, nu) of the pin-pressure estimate of ``reducer`` (share default
    ``1 / discs.count``)."""
    d = reducer.discs
    share = 1.0 / d.count if share is None else share
    return cycloid_stage(reducer), share, d.youngs_modulus, d.poisson_ratio


def check_reducer_torque(
    reducer: RVReducer, torque: float, field: str = "torque", *, share: float | None = None
) -> None:
    """Refuse an output torque that no pin of ``reducer`` could carry, naming ``field``.

    The check the case files make at validation (``gearte.io.plausibility``): the torque's
    estimated pin pressure (:func:`gearte.models.contact_law.pin_pressure_estimate`: Hu 2020
    eq 30 with the ideal share ``1 / discs.count``, Johnson's line-contact pressure at ρ(φ0) of
    :func:`cycloid_stage`, the discs' E and ν) must not exceed
    :data:`gearte.limits.MAX_CONTACT_PRESSURE_MPA`. Far beyond it the load-sharing equilibrium
    leaves the range of the pin contact law and returns finite numbers whose disc moments no
    longer balance the torque (han2023_rv110e: refused above about 1.4e8 N·mm, the moments
    balance up to 3e8 N·mm).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    torque : float
        Output torque [N·mm] (its magnitude counts).
    field : str
        The argument that carried the torque (named in the error).
    share : float, optional
        Share of ``torque`` carried by one disc [-]; default ``1 / discs.count`` (1 for a
        torque given per disc).

    Raises
    ------
    ParameterError
        ``"torque = 10000000000.0: is implausible for this stage: it gives a pin–disc contact
        pressure of about 84,970 MPa (ideal load share, Hu 2020 eq 30), above the 10,000 MPa
        no steel carries (1e+10 N·mm = 1e+07 N·m)"``.

    References
    ----------
    Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
    """
    stage, share, E, nu = _pin_pressure_inputs(reducer, share)
    check_pin_pressure(field, torque, stage, share, E, nu)


@dataclass(frozen=True)
class PinContactLaw:
    """The pin-contact law of a reducer, by name, with the stage it acts on.

    Attributes
    ----------
    name : {"line_contact", "hu2020", "palmgren", "linear"}
        ``"line_contact"``: the textbook law (:mod:`gearte.models.contact_law`) with each contact's
        own flank curvature, secant stiffness per contact. ``"hu2020"``: Hu 2020 eq 38–39 as
        printed with ρ(φ0) for every pin, one secant stiffness per disc (the paper's scheme).
        ``"palmgren"``: Palmgren's steel line-contact law ``δ = 3.84e-5 F^0.9 / b^0.8`` (Han
        2023's), secant stiffness per contact. ``"linear"``: constant ``stiffness``.
    stage : CycloidStage
        The reducer's cycloid stage (K1, ρ(φ), pin radius r_rp + Δr_rp).
    youngs_modulus, poisson_ratio, face_width : float
        E [MPa], ν [-], b [mm] of the discs and pins.
    stiffness : float
        Start value (or the constant of ``"linear"``) [N/mm]: finite and at least the
        plausibility floor of a linear stiffness (1 N/mm, ``gearte.limits.FLOORS``).
    series_compliance : tuple of float
        Linear compliance in series with every contact of each disc [mm/N] (pin seat + pin
        bending, :func:`pin_series_compliance`); empty: none. It adds to ``a0`` of the log law
        ``δ = F (a0 − a1 ln F)`` exactly (a linear spring carrying the same force), and to the
        compliance of ``"linear"``.
    """

    name: str
    stage: CycloidStage
    youngs_modulus: float
    poisson_ratio: float
    face_width: float
    stiffness: float = 2.0e5
    series_compliance: tuple[float, ...] = ()

    def series_a0(self, a0: np.ndarray, disc: ArrayLike) -> np.ndarray:
        """``a0`` [mm/N] of contacts of disc index ``disc`` (broadcast) plus their series
        compliance."""
        if not self.series_compliance:
            return a0
        return a0 + np.asarray(self.series_compliance, dtype=float)[np.asarray(disc)]

    def __post_init__(self) -> None:
        if not math.isfinite(self.stiffness):
            raise ParameterError("stiffness", self.stiffness, "must be finite [N/mm]")
        check_floor("stiffness", self.stiffness, "linear_stiffness")

    def describe(self) -> str:
        """The law and the constants it uses, in one line (echoed in results)."""
        st, E, nu, b = self.stage, self.youngs_modulus, self.poisson_ratio, self.face_width
        if self.name == "palmgren":
            return (
                f"palmgren: δ = {PALMGREN_COEFFICIENT:g} F^{PALMGREN_FORCE_EXPONENT:g} / "
                f"l^{PALMGREN_LENGTH_EXPONENT:g} (δ mm, F N), l = b = {b:g} mm, secant "
                "stiffness per contact (Palmgren 1959; Harris & Kotzalas 2007 ch. 7)"
            )
        if self.name == "hu2020":
            return (
                f"hu2020: Hu 2020 eq 38-39 as printed (constant {HU2020_HALF_WIDTH_FACTOR:g}), "
                f"ρ(φ0) = {st.rho0:.4g} mm for every pin, r = {st.r:g} mm, E = {E:g} MPa, "
                f"ν = {nu:g}, b = {b:g} mm, one secant stiffness per disc"
            )
        if self.name == "line_contact":
            return (
                "line_contact: Johnson 1985 §5.6 two-cylinder approach with each contact's "
                f"flank curvature, |ρ| capped at {st.curvature_cap:.4g} mm, r = {st.r:g} mm, "
                f"E = {E:g} MPa, ν = {nu:g}, b = {b:g} mm, secant stiffness per contact; "
                f"refused on a concave flank where the Hertz half-width exceeds "
                f"{CONFORMAL_HALF_WIDTH_LIMIT:g} r"
            )
        return f"linear: constant {self.stiffness:g} N/mm"

    def flank_curvature(self, phase: ArrayLike) -> np.ndarray:
        """Signed flank curvature radius [mm] where each pin touches, at meshing phase ``phase``
        (at the true contact point of the modified profile:
        :meth:`gearte.geometry.cycloid.CycloidStage.contact_curvature_radius`)."""
        return self.stage.contact_curvature_radius(phase)

    def coefficients(self, phase: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(a0, a1) of ``δ = F (a0 − a1 ln F)`` per contact at meshing phase ``phase`` [mm/N]
        (the logarithmic laws; :meth:`law_coefficients` for every law)."""
        a0, a1, a2, _ = self.law_coefficients(phase)
        if np.any(a2 != 0.0):
            raise ParameterError(
                "contact_law", self.name, "is a power law: use law_coefficients (a0, a1, a2, a3)"
            )
        return a0, a1

    def law_coefficients(
        self, phase: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(a0, a1, a2, a3) of ``δ = F (a0 − a1 ln F) + a2 F^a3`` per contact at meshing phase
        ``phase`` (:func:`gearte.models.contact_law.law_coefficients`)."""
        phase = np.asarray(phase, dtype=float)
        rho = (
            np.full(phase.shape, self.stage.rho0)
            if self.name == "hu2020"
            else self.flank_curvature(phase)
        )
        return law_coefficients(
            self.name,
            rho,
            self.stage.r,
            self.youngs_modulus,
            self.poisson_ratio,
            self.face_width,
            rho_cap=None if self.name == "hu2020" else self.stage.curvature_cap,
        )

    def for_system(self, system: RVSystem) -> ContactLaw:
        """The solver's :class:`~gearte.solvers.rv_equilibrium.ContactLaw` for ``system``."""
        if self.name == "linear":
            k = self.stiffness
            if any(c > 0.0 for c in self.series_compliance):
                if len(set(self.series_compliance)) > 1:
                    raise ParameterError(
                        "series_compliance",
                        self.series_compliance,
                        "the 'linear' law takes one stiffness: discs with different pin "
                        "compliances need a load-dependent law",
                    )
                k = 1.0 / (1.0 / k + self.series_compliance[0])
            return ContactLaw(kind="linear", stiffness=k, name="linear")
        a0, a1, a2, a3 = self.law_coefficients(contact_phase(system))
        a0 = self.series_a0(a0, system.contact_group)
        kind = "secant_per_disc" if self.name == "hu2020" else "secant_per_contact"
        return ContactLaw(kind=kind, stiffness=self.stiffness, a0=a0, a1=a1, a2=a2, a3=a3,
                          name=self.name)  # fmt: skip


def contact_law(
    reducer: RVReducer, law: str | None = None, stiffness: float = 2.0e5
) -> PinContactLaw:
    """Pin-contact law of the reducer by name (``"line_contact"``, ``"hu2020"``, ``"palmgren"``
    or ``"linear"``).

    ``None`` takes the reducer's own law (``reducer.discs.contact_law``, default the textbook
    ``"line_contact"``).

    The constants (ρ from :meth:`CycloidStage.curvature_radius`, pin radius ``stage.r``, E, ν,
    b) are those the cycloid-stage contact analysis uses, so both analyses share one law.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    law : {"line_contact", "hu2020", "palmgren", "linear"}, optional
        The law's name; ``None``: the reducer's own.
    stiffness : float
        Constant pin-contact stiffness of ``"linear"`` [N/mm] (finite, at least the floor of a
        linear stiffness, 1 N/mm); the start value of the others.

    Returns
    -------
    PinContactLaw
        The law with its constants.
    """
    if law is None:
        law = getattr(reducer.discs, "contact_law", DEFAULT_LAW)
        check_law(law, "discs.contact_law")
    elif law != "linear":
        check_law(law, "contact_law")
    d = reducer.discs
    series = pin_series_compliance(reducer)
    return PinContactLaw(
        name=law,
        stage=cycloid_stage(reducer),
        youngs_modulus=d.youngs_modulus,
        poisson_ratio=d.poisson_ratio,
        face_width=d.face_width,
        stiffness=stiffness,
        series_compliance=tuple(float(c) for c in series) if np.any(series > 0.0) else (),
    )


def solver_law(
    reducer: RVReducer, system: RVSystem, law: PinContactLaw | ContactLaw | None
) -> ContactLaw:
    """The solver law for ``system``: ``law`` as given, or built from a :class:`PinContactLaw`.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).
    system : RVSystem
        The spring and contact rows the law is for.
    law : PinContactLaw or ContactLaw, optional
        The law; ``None``: the reducer's own.

    Returns
    -------
    ContactLaw
        The solver's law.
    """
    return as_solver_law(contact_law(reducer) if law is None else law, system)


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
    spring_B : (P, ns, nd) rows; spring_e : (P, ns) offsets [mm]; spring_k : (ns,) [N/mm];
    spring_c : (ns,) radial clearance [mm] of isotropic bearings (their x and y rows are
    consecutive; 0 = linear spring).
    contact_B : (P, nc, nd) rows; contact_gap : (P, nc) clearances [mm];
    contact_group : (nc,) disc index of each contact; contact_pin : (nc,) pin index.
    contact_phase : (P, nc) meshing phase φ of each contact [rad] (where its flank curvature is
    read).
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
    spring_c: np.ndarray | None = None
    contact_phase: np.ndarray | None = None


def contact_phase(system: RVSystem) -> np.ndarray:
    """Meshing phase of every contact of ``system`` [rad], shape (P, nc)."""
    if system.contact_phase is None:
        raise ParameterError(
            "system.contact_phase", None, "needed for the flank curvature; build it with assemble()"
        )
    return system.contact_phase


def _u(a: np.ndarray) -> np.ndarray:
    """Unit vectors ``(cos a, sin a)`` stacked on the last axis."""
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _rot(v: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v[..., 2]`` by the angles of cosines ``c`` and sines ``s`` (broadcast)."""
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _point_row(r: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Rotation entry ``r × n = r_x n_y − r_y n_x`` of a row ``n · u(point)``, lever ``r``.

    A body (dof x, y, theta) enters the row ``n · u(point)`` with the entries
    ``(n_x, n_y, r × n)``; ``r``, ``n``: ``(..., 2)``, broadcast.
    """
    return r[..., 0] * n[..., 1] - r[..., 1] * n[..., 0]


@functools.lru_cache(maxsize=32)
def _row_pattern(n_cranks: int, n_discs: int) -> tuple[np.ndarray, np.ndarray]:
    """Constant entries of the spring rows and where the angle-dependent ones go.

    Returns ``(B0, index)``: ``B0`` (ns, nd), the rows' entries that do not depend on the
    output angle (the ``±1`` and ``0`` of the rows along ``x`` and ``y``); ``index``, the flat
    indices into (ns, nd) of the others, in the order :func:`assemble` lists their values:
    rotation of the carrier in the carrier crank bearings (crank, x/y), rotation of the crank
    in the cam bearings (crank, disc, x/y), rotation of the disc in the cam bearings (crank,
    disc, x/y), sun (x, y) then crank (x, y, theta) entries of each mesh (crank). Read-only.
    """
    lay = DofLayout(n_cranks, n_discs)
    M, N, nd = n_cranks, n_discs, lay.size
    s_car = 4
    s_cam = s_car + 2 * M
    s_mesh = s_cam + 2 * M * N
    B0 = np.zeros((s_mesh + M, nd))
    for d in range(2):
        B0[d, lay.sun + d] = 1.0
        B0[2 + d, lay.carrier + d] = 1.0
    car_rot: list[tuple[int, int]] = []
    cam_crank: list[tuple[int, int]] = []
    cam_disc: list[tuple[int, int]] = []
    for i in range(M):
        for d in range(2):
            row = s_car + 2 * i + d
            B0[row, lay.crank(i) + d] = 1.0
            B0[row, lay.carrier + d] = -1.0
            car_rot.append((row, lay.carrier + 2))
    for i in range(M):
        for j in range(N):
            for d in range(2):
                row = s_cam + 2 * (i * N + j) + d
                B0[row, lay.crank(i) + d] = 1.0
                B0[row, lay.disc(j) + d] = -1.0
                cam_crank.append((row, lay.crank(i) + 2))
                cam_disc.append((row, lay.disc(j) + 2))
    mesh = [(s_mesh + i, lay.sun + c) for i in range(M) for c in range(2)]
    mesh += [(s_mesh + i, lay.crank(i) + c) for i in range(M) for c in range(3)]
    rc = np.array(car_rot + cam_crank + cam_disc + mesh)
    index = rc[:, 0] * nd + rc[:, 1]
    B0.setflags(write=False)
    index.setflags(write=False)
    return B0, index


def cam_row_stiffness(reducer: RVReducer) -> np.ndarray:
    """Stiffness of the cam-bearing rows of each disc [N/mm], ``(N,)``.

    The cam (needle) bearing in series with the crank's bending at that cam
    (:attr:`~gearte.geometry.rv.Cranks.bending_compliance`; none when left out):
    ``1 / (1 / k_cam + c_bend,j)``.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).

    Returns
    -------
    numpy.ndarray
        ``(N,)`` row stiffness [N/mm].
    """
    k = np.full(reducer.discs.count, float(reducer.cranks.cam_bearing_stiffness))
    c = reducer.cranks.bending_compliance
    return k if c is None else 1.0 / (1.0 / k + np.asarray(c, dtype=float))


def mesh_row_stiffness(reducer: RVReducer) -> float:
    """Stiffness of a sun–planet mesh row along its line of action [N/mm].

    The mesh in series with the crank's torsion between planet and cams
    (:attr:`~gearte.geometry.rv.Cranks.torsional_stiffness` ``k_t``; none when left out): a twist
    ``F r_b2 / k_t`` of the planet against its cams moves the mesh point by ``F r_b2² / k_t``
    along the line of action, so ``1 / (1 / k_m + r_b2² / k_t)``.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).

    Returns
    -------
    float
        Row stiffness [N/mm].
    """
    k = float(reducer.first_stage.mesh_stiffness)
    kt = reducer.cranks.torsional_stiffness
    if kt is None:
        return k
    rb2 = reducer.first_stage.base_radii[1]
    return 1.0 / (1.0 / k + rb2 * rb2 / kt)


def pin_series_compliance(reducer: RVReducer) -> np.ndarray:
    """Linear compliance in series with each disc's pin contacts [mm/N], ``(N,)``.

    The pin's seat in its housing groove plus the pin's bending at that disc
    (:attr:`~gearte.geometry.rv.PinRing.seat_compliance`,
    :attr:`~gearte.geometry.rv.PinRing.bending_compliance`; 0 for those left out).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).

    Returns
    -------
    numpy.ndarray
        ``(N,)`` compliance [mm/N].
    """
    n = reducer.discs.count
    c = np.zeros(n)
    if reducer.pins.seat_compliance is not None:
        c = c + float(reducer.pins.seat_compliance)
    if reducer.pins.bending_compliance is not None:
        c = c + np.asarray(reducer.pins.bending_compliance, dtype=float)
    return c


def _measured(design: float, measured: np.ndarray | None, index) -> float:
    """A bearing's clearance [mm]: the measured one of that bearing if given, else the design's."""
    return design if measured is None else float(measured[index])


def assemble(reducer: RVReducer, theta: ArrayLike) -> RVSystem:
    """Spring and contact rows of ``reducer`` at output angles ``theta`` [rad].

    Each family of rows (sun support, main bearings, carrier crank bearings, cam bearings,
    sun–planet meshes, pin contacts) is computed at once for all angles, cranks, discs and both
    directions ``x``, ``y`` of an isotropic bearing; rows are ordered crank by crank, then disc
    by disc, ``x`` before ``y``.

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
    dirs = np.stack([ex, ey])  # (2, 2): the direction of a bearing's x row, then its y row

    # Row layout: sun support (2: x, y), main bearings (2), carrier crank bearings (2 M),
    # cam bearings (2 M N), sun-planet meshes (M). Every row w = B · q + e is a sum of body
    # entries (n_x, n_y, r × n) (sign -1 for the second body) added to zeros, each (row, dof)
    # once: B = 0.0 + entry, so a zero entry is +0.0; the x/y rows' ±1 and 0 are B0.
    s_car = 4
    s_cam = s_car + 2 * M
    s_mesh = s_cam + 2 * M * N
    ns = s_mesh + M
    labels = {
        "sun_support": slice(0, 2),
        "main_bearing": slice(2, s_car),
        "carrier_bearing": slice(s_car, s_cam),
        "cam_bearing": slice(s_cam, s_mesh),
        "mesh": slice(s_mesh, ns),
    }
    ks: list[float] = [reducer.first_stage.sun_support_stiffness] * 2
    ks += [reducer.supports.carrier_radial_stiffness] * 2
    cs: list[float] = [0.0] * 4
    for i in range(M):
        ks += [reducer.cranks.carrier_bearing_stiffness] * 2
        cs += [_measured(reducer.cranks.carrier_bearing_clearance, err.carrier_clearance, i)] * 2
    k_cam = cam_row_stiffness(reducer)  # (N,): cam bearing in series with crank bending
    for i in range(M):
        for j in range(N):
            ks += [float(k_cam[j])] * 2
            cam_c = _measured(reducer.cranks.cam_bearing_clearance, err.cam_clearance, (i, j))
            cs += [cam_c] * 2
    ks += [mesh_row_stiffness(reducer)] * M
    cs += [0.0] * M

    crank_ang = th[:, None] + 2.0 * np.pi * np.arange(M)[None, :] / M  # (P, M)
    rho = _u(crank_ang)  # (P, M, 2): radial direction of each crank
    crank_pos = Rdc * rho
    ecc1 = -zc * th  # absolute crank angle = eccentric direction of disc 1
    ecc = ecc1[:, None] + 2.0 * np.pi * np.arange(N)[None, :] / N  # (P, N)
    u_ecc = _u(ecc)  # (P, N, 2)
    cam_r = a * u_ecc  # (P, N, 2)

    # sun support: w = u_sun - seat offset (sun assembly error, ground frame);
    # carrier main bearings: w = u_carrier - seat offset (output assembly error)
    spring_e = np.empty((P, ns))
    spring_e[:, :s_car] = [
        -err.sun_seat @ ex,
        -err.sun_seat @ ey,
        -err.output_seat @ ex,
        -err.output_seat @ ey,
    ]

    # carrier crank bearings (crank i; x, y): w = u_crank - u_carrier(bore) - eps_carrier
    car_rot = -1.0 * _point_row(crank_pos[:, :, None, :], dirs)  # (P, M, 2): carrier at bore
    cos_c, sin_c = rho[..., 0].T, rho[..., 1].T  # (M, P)
    neg_eps = -_rot(err.carrier_bore[:, None, :], cos_c, sin_c)  # (M, P, 2)
    e_car = np.stack([neg_eps @ ex, neg_eps @ ey], -1)  # (M, P, 2): one (P, 2) @ d per crank
    spring_e[:, s_car:s_cam] = e_car.transpose(1, 0, 2).reshape(P, 2 * M)

    # cam bearings (crank i, disc j; x, y): w = u_crank(cam) + eps_cam - u_disc(bore) - eps_bore
    cam_rot = 1.0 * _point_row(cam_r[:, :, None, :], dirs)  # (P, N, 2): crank at its cam j
    eps_cam = _rot(err.cam[:, :, None, :], u_ecc[..., 0].T, u_ecc[..., 1].T)  # (M, N, P, 2)
    v = err.disc_bore.transpose(1, 0, 2)[:, :, None, :]  # (M, N, 1, 2)
    de = eps_cam - _rot(v, cos_c[:, None], sin_c[:, None])  # (M, N, P, 2)
    e_cam = np.stack([de @ ex, de @ ey], -1)  # (M, N, P, 2): one (P, 2) @ d per cam
    spring_e[:, s_cam:s_mesh] = e_cam.transpose(2, 0, 1, 3).reshape(P, 2 * M * N)

    # sun-planet meshes along the working line of action (sun drives, counter-clockwise)
    alpha_w = reducer.working_pressure_angle
    rb1, _ = reducer.first_stage.base_radii
    z1, z2 = reducer.first_stage.sun_teeth, reducer.first_stage.planet_teeth
    rw1 = Rdc * z1 / (z1 + z2)
    t = _u(crank_ang + np.pi / 2)
    n = np.cos(alpha_w) * t + np.sin(alpha_w) * rho  # (P, M, 2) force direction on the planet
    pitch = rw1 * rho
    cp = crank_pos
    tp = pitch - np.sum((pitch - cp) * n, axis=-1, keepdims=True) * n
    mesh_crank = -1.0 * np.stack([n[..., 0], n[..., 1], _point_row(tp - cp, n)], -1)
    eps_pl = _rot(err.planet[:, None, :], np.cos(ecc1), np.sin(ecc1)).transpose(1, 0, 2)
    sun_ang = reducer.ratio * th
    eps_sun = _rot(err.sun, np.cos(sun_ang), np.sin(sun_ang))[:, None, :]  # (P, 1, 2)
    spring_e[:, s_mesh:] = np.sum((eps_sun - eps_pl) * n, axis=-1)

    B0, index = _row_pattern(M, N)
    entries = np.concatenate(
        [
            car_rot.reshape(P, 2 * M),
            np.broadcast_to(cam_rot[:, None], (P, M, N, 2)).reshape(P, 2 * M * N),
            np.broadcast_to(car_rot[:, :, None], (P, M, N, 2)).reshape(P, 2 * M * N),
            1.0 * n.reshape(P, 2 * M),  # the sun's (x, y) in each mesh
            mesh_crank.reshape(P, 3 * M),  # the crank's (x, y, theta) in each mesh
        ],
        axis=1,
    )
    entries += 0.0  # added to the zeros of the row (turns -0.0 into +0.0)
    spring_B = np.empty((P, ns, nd))
    spring_B[:] = B0
    spring_B.reshape(P, ns * nd)[:, index] = entries
    spring_k = np.asarray(ks)

    # pin contacts: normals, arms and initial clearances with every error family
    # (gearte.geometry.rv.pin_contacts, the one computation the dynamics reads too)
    pc = pin_contacts(reducer, th)
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
# Analyses over one output revolution
# ------------------------------------------------------------------------------------------


def _postprocess(
    reducer: RVReducer, system: RVSystem, sol, torque: float, law_name: str = ""
) -> LoadSharing:
    M, N, zp = reducer.cranks.count, reducer.discs.count, reducer.pins.count
    P = system.theta.size
    w = np.einsum("psi,pi->ps", system.spring_B, sol.q) + system.spring_e
    f = w * system.spring_k[None, :]
    c = system.spring_c
    if c is not None and np.any(c > 0):  # bearings with radial clearance: k (|w| - c)+ w/|w|
        first = np.flatnonzero(c > 0)[::2]
        wx, wy = w[:, first], w[:, first + 1]
        n = np.hypot(wx, wy)
        kf, eps = system.spring_k[first], CLEARANCE_RESIDUAL
        scale = eps * kf + (1 - eps) * kf * np.maximum(n - c[first], 0.0) / np.where(n > 0, n, 1.0)
        f[:, first] = scale * wx
        f[:, first + 1] = scale * wy
    cam = f[:, system.labels["cam_bearing"]].reshape(P, M, N, 2)
    car = f[:, system.labels["carrier_bearing"]].reshape(P, M, 2)
    mesh = f[:, system.labels["mesh"]]
    pin = sol.contact_force.reshape(P, N, zp)
    lay = system.layout
    # the rotation column of a contact row is the arm of its normal about the disc centre
    arm = np.stack(
        [system.contact_B[:, j * zp : (j + 1) * zp, lay.disc(j) + 2] for j in range(N)], axis=1
    )  # (P, N, zp)
    disc_torque = -np.sum(pin * arm, axis=-1)
    stage = cycloid_stage(reducer)
    d = reducer.discs
    rho = stage.contact_curvature_radius(contact_phase(system)).reshape(P, N, zp)
    pressure = max_contact_pressure(
        pin, rho, stage.r, d.youngs_modulus, d.poisson_ratio, d.face_width
    )
    return LoadSharing(
        theta=system.theta,
        torque=float(torque),
        pin_force=pin,
        pairs_in_mesh=(pin > 0.0).sum(axis=-1),
        cam_bearing_load=np.linalg.norm(cam, axis=-1),
        carrier_bearing_load=np.linalg.norm(car, axis=-1),
        mesh_force=mesh,
        disc_torque=disc_torque,
        output_error=sol.q[:, lay.output_rotation].copy(),
        contact_stiffness=sol.contact_stiffness,
        q=sol.q,
        contact_pressure=pressure,
        contact_law=law_name,
        pin_phase=contact_phase(system).reshape(P, N, zp),
    )


def output_positions(n_positions: int) -> np.ndarray:
    """``n_positions`` equally spaced output angles over one revolution [rad]."""
    if int(n_positions) != n_positions or n_positions < 1:
        raise ParameterError("positions", n_positions, "must be an integer >= 1")
    return np.linspace(0.0, 2.0 * np.pi, int(n_positions), endpoint=False)


def load_sharing(
    reducer: RVReducer,
    torque: float,
    theta: ArrayLike | None = None,
    *,
    law: PinContactLaw | ContactLaw | None = None,
    system: RVSystem | None = None,
    compiled: bool = True,
    start: tuple[np.ndarray, np.ndarray] | None = None,
) -> LoadSharing:
    """Quasi-static load sharing of ``reducer`` under output ``torque`` [N·mm].

    Parameters
    ----------
    reducer : RVReducer
    torque : float
        Output torque [N·mm]; positive resists the drive direction.
    theta : array_like, optional
        Output angles [rad]; default 360 positions over one revolution.
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default :func:`contact_law` (the textbook line contact).
    system : RVSystem, optional
        Pre-assembled rows (re-used across torques).
    compiled : bool
        Use the numba kernel (``False``: plain-Python twin).
    start : (numpy.ndarray, numpy.ndarray), optional
        Warm start of the first position: displacements [mm, rad] and per-disc contact
        stiffness [N/mm] of a nearby solution (``q`` and ``contact_stiffness`` rows of another
        :class:`LoadSharing`); the equilibrium is unique, so only the Newton path changes.

    Raises
    ------
    ParameterError
        ``torque`` not finite, or beyond what the pins can carry (:func:`check_reducer_torque`,
        the case files' plausibility check).
    ConvergenceError
        No equilibrium found at a position (the message names the torque; a pin force beyond
        the range of the contact law is one cause).
    """
    if not np.isfinite(torque):
        raise ParameterError("torque", torque, "must be finite [N·mm]")
    check_reducer_torque(reducer, torque)
    if system is None:
        system = assemble(reducer, output_positions(360) if theta is None else theta)
    q0, k0 = (None, None) if start is None else start
    slaw, sol = _equilibrium(
        reducer, system, torque, law, solve_positions, compiled=compiled, q0=q0, k0=k0
    )
    out = _postprocess(reducer, system, sol, torque, slaw.name)
    if slaw.name == "line_contact":
        check_conformal(reducer, out)
    return out


#: Largest Hertz half-width on a concave flank, relative to the pin radius, for which Johnson's
#: convex line-contact approach (``"line_contact"``) is applied: Hertz's theory needs the contact
#: strip small against the bodies (Johnson 1985 §4.1); on a concave flank of radius close to the
#: pin's (near the tooth root) R* = r ρ/(ρ − r) grows without bound, the strip widens and the
#: law's ln(4ρ/a) term of the disc (a convex cylinder of radius ρ) no longer describes the body.
CONFORMAL_HALF_WIDTH_LIMIT = 0.1


def check_conformal(reducer: RVReducer, load: LoadSharing) -> None:
    """Refuse ``"line_contact"`` results that contain a near-conformal concave contact.

    Every loaded pin on a concave flank (ρ > 0, the root side) must have a Hertz half-width
    ``a ≤ CONFORMAL_HALF_WIDTH_LIMIT · r`` (:data:`CONFORMAL_HALF_WIDTH_LIMIT`, r the pin radius,
    a from :func:`gearte.models.contact_law.hertz_half_width` with the pin's force and flank
    curvature). Beyond it Johnson's convex formula (§5.6) is outside its domain.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description.
    load : LoadSharing
        A solved load sharing (its pin forces and phases).

    Raises
    ------
    ParameterError
        Naming ``contact_law`` and, in the reason, the worst pin: disc, pin, output angle, its
        flank radius, the pin radius and the half-width; with the laws to select instead.

    References
    ----------
    Johnson K.L. (1985). Contact Mechanics, §4.1 (Hertz's assumptions), §5.6.
    doi:10.1017/CBO9781139171731
    """
    if load.pin_phase is None:
        return
    stage = cycloid_stage(reducer)
    d = reducer.discs
    rho = stage.contact_curvature_radius(load.pin_phase)
    concave = (rho > 0.0) & (load.pin_force > 0.0)
    if not np.any(concave):
        return
    a = hertz_half_width(
        np.where(concave, load.pin_force, 0.0),
        np.where(concave, rho, -1.0),
        stage.r,
        d.youngs_modulus,
        d.poisson_ratio,
        d.face_width,
    )
    ratio = np.where(concave, a / stage.r, 0.0)
    if ratio.max() <= CONFORMAL_HALF_WIDTH_LIMIT:
        return
    p, j, k = np.unravel_index(np.argmax(ratio), ratio.shape)
    raise ParameterError(
        "contact_law",
        "line_contact",
        f"disc {j + 1}, pin {k + 1} at output angle {rad_to_deg(float(load.theta[p])):.1f}° "
        f"touches a concave flank of radius {rho[p, j, k]:.3f} mm with pin radius "
        f"{stage.r:.3f} mm under {load.pin_force[p, j, k]:.0f} N: Hertz half-width "
        f"{a[p, j, k]:.3f} mm > {CONFORMAL_HALF_WIDTH_LIMIT:g} r, a near-conformal contact "
        "outside Johnson's convex line-contact formula; select contact_law 'palmgren' "
        "(independent of the curvatures) or 'hu2020' (docs/contact-law.md)",
    )


#: Below this share of its force turning the disc (sin of the angle between the pin force and
#: the radial direction through the pin), the most loaded pin is squeezed radially at the tooth
#: root rather than driving the disc.
ROOT_SQUEEZE_SIN = 0.5


@dataclass(frozen=True)
class PeakPin:
    """The most loaded pin of a load sharing and the direction of its force.

    Attributes
    ----------
    position : int
        Index of the output position [-].
    output_angle : float
        Output angle there [rad].
    disc, pin : int
        Disc and pin numbers, from 1 [-].
    force : float
        Its force [N].
    phase : float
        Its angle from the line of centres (the disc's eccentric direction), in (−π, π] [rad].
    force_angle_from_radial : float
        Angle between its force (the contact normal, through the pitch point) and the radial
        direction through the pin [rad]; ``sin`` of it is ``K1 |sin φ| / S`` (on a shifted
        design profile the normal is turned to the true contact point, see :func:`peak_pin`).
    """

    position: int
    output_angle: float
    disc: int
    pin: int
    force: float
    phase: float
    force_angle_from_radial: float

    @property
    def root_squeeze(self) -> bool:
        """Whether the force is mostly a radial squeeze at the tooth root
        (``sin(force_angle_from_radial) < ROOT_SQUEEZE_SIN``)."""
        return math.sin(self.force_angle_from_radial) < ROOT_SQUEEZE_SIN

    def describe(self) -> str:
        """One line naming the pin and its angles (for warnings)."""
        return (
            f"disc {self.disc}, pin {self.pin} at output angle "
            f"{rad_to_deg(self.output_angle):.1f}°: {self.force:.0f} N, "
            f"{abs(rad_to_deg(self.phase)):.1f}° from the line of centres, force "
            f"{rad_to_deg(self.force_angle_from_radial):.1f}° from radial"
        )


def peak_pin(reducer: RVReducer, load: LoadSharing) -> PeakPin:
    """The most loaded pin of ``load`` (:class:`PeakPin`).

    The contact normal of pin ``k`` passes through the pitch point ``K1 r_p`` on the line of
    centres (Hu 2020 eq 36), so its angle α from the radial direction through the pin has
    ``sin α = K1 |sin φ| / S``, ``S = (1 + K1² − 2 K1 cos φ)^½``: 0 on the line of centres (a
    pure radial squeeze), 1 where ``cos φ = K1`` (the largest arm). On a design with a shifted
    modification the normal is the rows' (turned to the true contact point,
    :func:`gearte.geometry.cycloid.true_contact`) and α is its angle from the radial direction.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description.
    load : LoadSharing
        A solved load sharing with its ``pin_phase``.

    Returns
    -------
    PeakPin

    References
    ----------
    Hu Y. et al. (2020). Applied Sciences 10(2), 481, eq 36. doi:10.3390/app10020481
    """
    if load.pin_phase is None:
        raise ParameterError("load.pin_phase", None, "needed: a load sharing from load_sharing()")
    p, j, k = np.unravel_index(np.argmax(load.pin_force), load.pin_force.shape)
    phi = float(np.angle(np.exp(1j * load.pin_phase[p, j, k])))
    K1 = cycloid_stage(reducer).K1
    S = math.sqrt(1.0 + K1 * K1 - 2.0 * K1 * math.cos(phi))
    alpha = math.asin(min(1.0, K1 * abs(math.sin(phi)) / S))
    dr_p = float(reducer.discs.shift_modification)
    if dr_p != 0.0:  # the rows' normal, turned to the true contact point (pin_contacts)
        turn = float(
            true_contact(
                phi, z_p=reducer.pins.count, r_p=reducer.pins.circle_radius,
                a=reducer.cranks.eccentricity, dr_p=dr_p,
            )[2]
        )  # fmt: skip
        # the rows' eq-36 normal (pitch point a z_p -> pin centre on r_p) in the frame of the
        # line of centres, turned
        k1 = reducer.cranks.eccentricity * reducer.pins.count / reducer.pins.circle_radius
        ux, uy = math.cos(phi) - k1, math.sin(phi)
        norm = math.hypot(ux, uy)
        ux, uy = ux / norm, uy / norm
        vx = math.cos(turn) * ux - math.sin(turn) * uy
        vy = math.sin(turn) * ux + math.cos(turn) * uy
        alpha = math.acos(max(-1.0, min(1.0, vx * math.cos(phi) + vy * math.sin(phi))))
    return PeakPin(int(p), float(load.theta[p]), int(j) + 1, int(k) + 1,
                   float(load.pin_force[p, j, k]), phi, alpha)  # fmt: skip


def _equilibrium(reducer, system, torque, law, solve, **kwargs):
    """``(solver law, solution)``: ``solve(system, torque, <solver law>, **kwargs)``
    (:func:`~gearte.solvers.rv_batch.solve_positions` or ``solve_system``), its
    :class:`ConvergenceError` saying at which torque (the input the user can change)."""
    slaw = solver_law(reducer, system, law)
    try:
        return slaw, solve(system, torque, slaw, **kwargs)
    except ConvergenceError as exc:
        raise ConvergenceError(f"load sharing at torque = {torque:g} N·mm: {exc}") from None


def mesh_period(reducer: RVReducer) -> float:
    """Output angle [rad] after which the pin-contact pattern repeats: ``2π / (z_p z_c)``.

    The eccentric turns ``-z_c θ`` and the pattern repeats when the pin phases have moved by one
    pin pitch ``2π / z_p``; the mesh-stiffness ripple of the TE has this period.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (:class:`gearte.geometry.rv.RVReducer`).

    Returns
    -------
    float
        The mesh period of the output angle [rad].
    """
    return 2.0 * np.pi / (reducer.pins.count * reducer.cycloid_teeth)


def _sweeps(
    reducer: RVReducer,
    torque: float,
    law: PinContactLaw | ContactLaw,
    system: RVSystem,
    coarse: LoadSharing,
    near: list[int],
    length: int,
) -> np.ndarray:
    """Output angle error [rad] at the positions of ``system``: consecutive sweeps of
    ``length`` positions, sweep ``i`` warm-started from position ``near[i]`` of ``coarse``.

    The same values as ``load_sharing(reducer, torque, law=law, system=<sweep i>,
    start=(coarse.q[near[i]], coarse.contact_stiffness[near[i]])).output_error`` for each
    sweep, in one kernel call (:func:`gearte.solvers.rv_batch.solve_system`'s ``restart``): the
    TE's refinement windows (the compensation evaluates ~40 TEs of six windows each)."""
    _, sol = _equilibrium(
        reducer,
        system,
        torque,
        law,
        solve_system,
        q0=coarse.q[near],
        k0=coarse.contact_stiffness[near],
        restart=length,
    )
    return sol.q[:, system.layout.output_rotation]


def transmission_error(
    reducer: RVReducer,
    torque: float,
    theta: ArrayLike | None = None,
    *,
    zero_load_fraction: float = 1e-3,
    mesh_samples: int = 24,
    law: PinContactLaw | ContactLaw | None = None,
) -> TransmissionError:
    """Total (loaded), geometric (zero-load) and elastic output angle error [rad].

    Parameters
    ----------
    reducer : RVReducer
    torque : float
        Output torque [N·mm] (> 0).
    theta : array_like, optional
        Output angles [rad] (default 360 over one revolution).
    zero_load_fraction : float
        [-] The geometric TE is solved at ``zero_load_fraction * torque`` in the same direction, so
        that the contacts close their clearance without deflecting (a zero torque leaves the
        output free within its backlash).
    mesh_samples : int
        Positions per mesh period in the refinement around the extremes (0: no refinement).
    law : PinContactLaw or ContactLaw, optional
        Pin-contact law; default the reducer's own (:func:`contact_law`).

    Returns
    -------
    TransmissionError
        Total, geometric and elastic output angle error [rad] over ``theta``.

    Raises
    ------
    ParameterError
        ``torque`` not > 0, or beyond what the pins can carry (:func:`check_reducer_torque`).
    """
    if not torque > 0:
        raise ParameterError("torque", torque, "must be > 0 N·mm for the TE analysis")
    check_reducer_torque(reducer, torque)
    if not 0 < zero_load_fraction < 0.05:
        raise ParameterError("zero_load_fraction", zero_load_fraction, "must be in (0, 0.05)")
    if int(mesh_samples) != mesh_samples or mesh_samples < 0:
        raise ParameterError("mesh_samples", mesh_samples, "must be an integer >= 0")
    system = assemble(reducer, output_positions(360) if theta is None else theta)
    law = contact_law(reducer) if law is None else law
    loaded = load_sharing(reducer, torque, law=law, system=system)
    unloaded = load_sharing(reducer, zero_load_fraction * torque, law=law, system=system)
    total = loaded.output_error
    geo = unloaded.output_error
    ela = total - geo
    all_t, all_g, all_e = [total], [geo], [ela]
    if mesh_samples:
        centres = {int(np.argmax(x)) for x in (total, geo, ela)}
        centres |= {int(np.argmin(x)) for x in (total, geo, ela)}
        offs = (np.arange(mesh_samples) / mesh_samples - 0.5) * mesh_period(reducer)
        # each refinement window is its own short sweep, warm-started from the coarse
        # solution nearest its first angle: a window warm-started from the end of the previous
        # one (far away) or cold needs > 100 Newton steps when the parts float in measured
        # bearing clearances at the small torque (docs/metrology.md)
        # (all windows in one system and one kernel call per torque: _sweeps)
        fine = [system.theta[c] + offs for c in sorted(centres)]
        near = [int(np.argmin(np.abs(np.angle(np.exp(1j * (system.theta - f[0])))))) for f in fine]
        fsys = assemble(reducer, np.concatenate(fine))
        ft = _sweeps(reducer, torque, law, fsys, loaded, near, mesh_samples)
        fg = _sweeps(reducer, zero_load_fraction * torque, law, fsys, unloaded, near, mesh_samples)
        all_t.append(ft)
        all_g.append(fg)
        all_e.append(ft - fg)
    pp = TransmissionError.peak_to_peak
    return TransmissionError(
        theta=system.theta,
        total=total,
        geometric=geo,
        elastic=ela,
        loaded=loaded,
        unloaded=unloaded,
        total_pp=pp(np.concatenate(all_t)),
        geometric_pp=pp(np.concatenate(all_g)),
        elastic_pp=pp(np.concatenate(all_e)),
    )
