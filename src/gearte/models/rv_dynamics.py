"""Translational–torsional lumped dynamic model of an RV reducer (Li et al. 2023, section 3).

6M + 3N + 6 degrees of freedom (M cranks/planets, N cycloid discs): x, y, θ of the sun, of each
planet, of each crank, of each disc and of the output disc (carrier). With M = 3, N = 2: 30 DOF.

How it is built (see docs/validation/li2023.md for the derivation and every assumption):

* Coordinates are deviations from the nominal rigid motion, translations in the fixed frame and
  rotations **absolute** (measured from the housing), so the rigid kinematics are testable: with the
  input shaft spring removed the stiffness matrix has exactly one null vector, θ_s : θ_p : θ_H :
  θ_c : θ_o = 121 : −39 : −39 : 1 : 1 (plus the translations of the carried bodies).
* Every connection is an element spring (+ damper) acting on the *material points* of its two
  bodies at a contact point: a line element (involute mesh, equivalent cycloid–pin contact) along a
  direction n, or an isotropic bearing (two directions, optional radial clearance as piecewise
  stiffness), or a torsion spring. Deflection = projection of the relative displacement of the
  material points + the error offsets of the features involved.
* The geometry (planet positions on the carrier, crank eccentric direction, the pitch point of the
  cycloid–pin pair and its line of action) is evaluated on the nominal configuration at time t: the
  cycloid–pin direction rotates with the crank (the paper writes a fixed direction).
* Excitations: involute mesh stiffness (rectangular wave of the contact ratio, Fourier series,
  eq 11), cycloid–pin stiffness from the loaded contact
  (:mod:`gearte.models.cycloid_loaded_contact`,
  Fourier series, eq 13), the eccentricity/assembly errors of Table 3 on explicitly chosen
  cranks/discs, bearing clearances, constant load torque on the output, speed-controlled motor
  behind the input torsional stiffness.
* Damping: stiffness-proportional per element, c_e(t) = β_R k_e(t), with β_R = 2ζ/ω_1 so the lowest
  elastic mode has damping ratio ζ (paper 004 gives no damping).

Internal units: mm, N, s, hence mass in tonne (t = 1e3 kg) and inertia in t·mm²; inputs carry
paper units (kg, kg·m², N/m, N·m/rad, N·m, rpm) in their names and are converted once here.

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from numba import njit

from gearte.errors import ConvergenceError, ParameterError
from gearte.models.cycloid_loaded_contact import (
    CycloidPinPair,
    fourier_eval,
    fourier_fit,
    mesh_period_contact,
)

__all__ = [
    "KG_TO_T",
    "KGM2_TO_TMM2",
    "N_PER_M_TO_N_PER_MM",
    "NM_PER_RAD_TO_NMM_PER_RAD",
    "RVDynamicsParameters",
    "RVErrors",
    "RVDynamicModel",
    "ModalResult",
    "involute_contact_ratio",
    "rectangular_mesh_stiffness_fourier",
    "rv_rhs",
    "rv_dte",
    "RHS_SOURCE_KEY",
    "RHS_WORK_SIZE",
    "ode_system",
    "parameters_from_reducer",
    "errors_from_reducer",
]

# --- unit conversions of the dynamic model (paper units → mm, N, s, t) -----------------------
KG_TO_T = 1e-3
"""Mass [kg] → [t] (1 t·mm/s² = 1 N)."""
KGM2_TO_TMM2 = 1e3
"""Inertia [kg·m²] → [t·mm²]."""
N_PER_M_TO_N_PER_MM = 1e-3
"""Stiffness [N/m] → [N/mm]."""
NM_PER_RAD_TO_NMM_PER_RAD = 1e3
"""Torsional stiffness [N·m/rad] → [N·mm/rad]."""

_SLOT = 16  # t, 6 trigonometric values, 6 involute and 3 cycloid mesh stiffnesses
RHS_WORK_SIZE = 2 * _SLOT + 1
"""Scratch floats :func:`rv_rhs` uses to memoise time-only quantities (≤ 6 cranks, ≤ 3 discs)."""

RHS_SOURCE_KEY = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]
"""Hash of this file: part of the numba cache key of the integrators built on :func:`rv_rhs`."""


@dataclass(frozen=True)
class RVDynamicsParameters:
    """Parameters of the lumped RV model (paper 004 Tables 1–2 and stated assumptions).

    Geometry (Table 1): ``sun_teeth`` z_s, ``planet_teeth`` z_pl, ``module_mm`` m [mm],
    ``pressure_angle_deg`` α [deg], ``crank_count`` M, ``disc_count`` N, ``pair`` the cycloid–pin
    pair (pins, radii, eccentricity, modification).
    Masses [kg] and inertias [kg·m²] (Table 2, exponent signs restored: J_s = 4.44e-4,
    J_p = 1.01e-3, J_H = 7.56e-5, J_c = 0.0209 per disc as printed, J_o = 0.106).
    Stiffnesses [N/m] and torsional stiffnesses [N·m/rad] (Table 2). Not in the paper, assumed:
    ``involute_single_pair_stiffness_N_per_m`` (ISO 6336 c' ≈ 14 N/(mm·µm) × 10 mm face width),
    ``damping_ratio`` ζ of the lowest elastic mode.
    ``cycloid_stiffness``: "fourier" (time-varying k_cr from the loaded contact, eq 13) or "mean"
    (its mean only, as paper 004 §4.1 does). ``cycloid_mesh_stiffness_N_per_m`` and
    ``cycloid_pressure_angle_deg`` override the contact analysis' mean k_cr (the ripple is scaled
    with it) and β, e.g. to feed the paper's printed 2.62e8 N/m and 3.8°.
    Operating point: ``input_speed_rpm``, ``output_torque_Nm`` (450 N·m, split equally over the
    discs for the contact analysis).
    """

    sun_teeth: int = 12
    planet_teeth: int = 36
    module_mm: float = 1.5
    pressure_angle_deg: float = 20.0
    crank_count: int = 3
    disc_count: int = 2
    pair: CycloidPinPair = field(default_factory=CycloidPinPair)
    sun_mass_kg: float = 1.3
    planet_mass_kg: float = 0.88
    crank_mass_kg: float = 0.4
    disc_mass_kg: float = 2.76
    output_mass_kg: float = 15.33
    sun_inertia_kgm2: float = 4.44e-4
    planet_inertia_kgm2: float = 1.01e-3
    crank_inertia_kgm2: float = 7.56e-5
    disc_inertia_kgm2: float = 0.0209
    output_inertia_kgm2: float = 0.106
    input_torsional_stiffness_Nm_per_rad: float = 1.16e4  # noqa: N815
    sun_support_stiffness_N_per_m: float = 4.68e7  # noqa: N815
    crank_torsional_stiffness_Nm_per_rad: float = 6.99e4  # noqa: N815
    crank_bending_stiffness_N_per_m: float = 5.55e8  # noqa: N815
    crank_bearing_stiffness_N_per_m: float = 5.76e8  # noqa: N815
    turning_arm_bearing_stiffness_N_per_m: float = 2.84e8  # noqa: N815
    output_support_stiffness_N_per_m: float = 3.15e8  # noqa: N815
    involute_single_pair_stiffness_N_per_m: float = 1.4e8  # noqa: N815
    involute_harmonics: int = 10
    cycloid_harmonics: int = 8
    contact_positions: int = 48
    damping_ratio: float = 0.03
    cycloid_stiffness: str = "fourier"
    cycloid_mesh_stiffness_N_per_m: float | None = None  # noqa: N815
    cycloid_pressure_angle_deg: float | None = None
    input_speed_rpm: float = 1500.0
    output_torque_Nm: float = 450.0  # noqa: N815
    crank_phase_deg: float = 0.0

    def __post_init__(self) -> None:
        ints = {
            "sun_teeth": 6,
            "planet_teeth": 6,
            "crank_count": 2,
            "disc_count": 1,
            "involute_harmonics": 1,
            "cycloid_harmonics": 1,
            "contact_positions": 8,
        }
        for name, lo in ints.items():
            if int(getattr(self, name)) < lo:
                raise ParameterError(name, getattr(self, name), f"must be an integer ≥ {lo}")
        if self.crank_count > 6 or self.disc_count > 3:
            raise ParameterError(
                "crank_count/disc_count",
                (self.crank_count, self.disc_count),
                "at most 6 cranks and 3 discs (size of the right-hand side's memo)",
            )
        for name, val in self.__dict__.items():
            if name in ints or name in ("pair", "crank_phase_deg", "cycloid_stiffness"):
                continue
            if val is None and name.startswith("cycloid_"):
                continue
            if not (np.isfinite(val) and val > 0):
                raise ParameterError(name, val, "must be finite and > 0")
        if self.cycloid_stiffness not in ("fourier", "mean"):
            raise ParameterError(
                "cycloid_stiffness", self.cycloid_stiffness, "must be 'fourier' or 'mean'"
            )
        if not self.damping_ratio < 1.0:
            raise ParameterError("damping_ratio", self.damping_ratio, "must be in (0, 1)")
        if self.cycloid_harmonics >= self.contact_positions // 2:
            raise ParameterError(
                "cycloid_harmonics",
                self.cycloid_harmonics,
                f"must be < contact_positions/2 = {self.contact_positions // 2}",
            )

    # --- derived kinematics ------------------------------------------------------------------
    @property
    def ratio(self) -> float:
        """i = 1 + z_p z_pl / z_s, input/output speed ratio with fixed pins (121 for Table 1)."""
        return 1.0 + self.pair.pin_count * self.planet_teeth / self.sun_teeth

    @property
    def output_speed(self) -> float:
        """ω_o, nominal output speed [rad/s]."""
        return self.input_speed_rpm * 2.0 * np.pi / 60.0 / self.ratio

    @property
    def centre_distance_mm(self) -> float:
        """a_H = m (z_s + z_pl)/2, crank circle radius [mm]."""
        return self.module_mm * (self.sun_teeth + self.planet_teeth) / 2.0

    def frequencies(self) -> dict[str, float]:
        """Characteristic frequencies at the operating speed [Hz]."""
        fo = self.output_speed / (2 * np.pi)
        zp, zc = self.pair.pin_count, self.pair.tooth_count
        return {
            "output rotation": fo,
            "input rotation": self.ratio * fo,
            "crank rotation": zp * fo,  # relative to the carrier
            "involute mesh": self.sun_teeth * (self.ratio - 1.0) * fo,
            "cycloid mesh": zp * zc * fo,
        }


@dataclass(frozen=True)
class RVErrors:
    """Errors of paper 004 Table 3 placed on explicit cranks/discs, and bearing clearances.

    Each error is an (amplitude [mm], phase [rad]) pair; arrays give one per crank i (shape (M,)),
    or per crank and disc (shape (M, N)); an amplitude of 0 means "not on this one".

    sun_eccentricity (E_s, β_s): tooth geometry offset rotating with the sun.
    planet_eccentricity (E_p,i, β_p,i): rotating with planet i.
    sun_assembly (E_sa, β_sa): fixed offset of the sun's support seat in the housing.
    disc_hole (E^H_cji, β^H_cji): offset of the crank hole i in disc j, rotating with the disc.
    cam (E_dji, β_dji): offset of cam j of crank i, rotating with the crank.
    carrier_hole (E^H_oi, β^H_oi): offset of crank hole i in the output disc, rotating with it.
    output_assembly (E_o, β_o): fixed offset of the output's support seat.
    pin_composite (E_cr,j, phase): composite error of disc j along its line of action,
      E sin(θ_o + phase) (paper eq 21; no value given).
    Clearances [mm]: turning-arm (crank–disc) bearings ε_c, crank support bearings in the output
    disc ε_oH, output main bearing ε_h; radial dead zone of the bearing spring.
    """

    crank_count: int = 3
    disc_count: int = 2
    sun_eccentricity: tuple[float, float] = (0.0, 0.0)
    sun_assembly: tuple[float, float] = (0.0, 0.0)
    output_assembly: tuple[float, float] = (0.0, 0.0)
    planet_eccentricity: np.ndarray | None = None  # (M, 2)
    carrier_hole: np.ndarray | None = None  # (M, 2)
    disc_hole: np.ndarray | None = None  # (M, N, 2)
    cam: np.ndarray | None = None  # (M, N, 2)
    pin_composite: np.ndarray | None = None  # (N, 2)
    turning_arm_clearance_mm: float = 0.0
    crank_bearing_clearance_mm: float = 0.0
    output_bearing_clearance_mm: float = 0.0

    def __post_init__(self) -> None:
        m, n = self.crank_count, self.disc_count
        shapes = {
            "planet_eccentricity": (m, 2),
            "carrier_hole": (m, 2),
            "disc_hole": (m, n, 2),
            "cam": (m, n, 2),
            "pin_composite": (n, 2),
        }
        for name, shape in shapes.items():
            v = getattr(self, name)
            arr = np.zeros(shape) if v is None else np.asarray(v, dtype=float)
            if arr.shape != shape:
                raise ParameterError(name, arr.shape, f"must have shape {shape}")
            if not np.all(np.isfinite(arr)) or np.any(arr[..., 0] < 0):
                raise ParameterError(name, arr.tolist(), "amplitudes must be finite and ≥ 0")
            object.__setattr__(self, name, arr)
        for name in ("sun_eccentricity", "sun_assembly", "output_assembly"):
            v = tuple(float(x) for x in getattr(self, name))
            if len(v) != 2 or v[0] < 0 or not np.all(np.isfinite(v)):
                raise ParameterError(name, v, "must be (amplitude ≥ 0 [mm], phase [rad])")
            object.__setattr__(self, name, v)
        for name in (
            "turning_arm_clearance_mm",
            "crank_bearing_clearance_mm",
            "output_bearing_clearance_mm",
        ):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ParameterError(name, v, "must be finite and ≥ 0")

    @classmethod
    def table3(
        cls,
        crank_count: int = 3,
        disc_count: int = 2,
        placement: str = "first",
        **clearances: float,
    ) -> RVErrors:
        """Paper 004 Table 3 with an explicit placement of the per-crank/per-disc errors.

        placement = "first": each per-crank error sits on crank 1 and each per-disc error on
        disc 1 (a single faulty part, the other parts nominal); "all": identical on every crank
        and disc (the patterns then largely cancel, see docs). Angles of Table 3 in degrees.
        """
        if placement not in ("first", "all"):
            raise ParameterError("placement", placement, "must be 'first' or 'all'")
        d = np.deg2rad
        m, n = crank_count, disc_count
        mask_m = np.zeros(m)
        mask_mn = np.zeros((m, n))
        if placement == "first":
            mask_m[0] = 1.0
            mask_mn[0, 0] = 1.0
        else:
            mask_m[:] = 1.0
            mask_mn[:] = 1.0

        def per_m(e: float, b: float) -> np.ndarray:
            return np.stack([e * mask_m, np.full(m, d(b))], axis=-1)

        def per_mn(e: float, b: float) -> np.ndarray:
            return np.stack([e * mask_mn, np.full((m, n), d(b))], axis=-1)

        return cls(
            crank_count=m,
            disc_count=n,
            sun_eccentricity=(0.005, d(45.0)),
            planet_eccentricity=per_m(0.006, 30.0),
            sun_assembly=(0.005, d(100.0)),
            disc_hole=per_mn(0.008, 140.0),
            cam=per_mn(0.008, 90.0),
            carrier_hole=per_m(0.035, 270.0),
            output_assembly=(0.038, d(90.0)),
            **clearances,
        )


def involute_contact_ratio(z1: int, z2: int, module_mm: float, alpha_rad: float) -> float:
    """Transverse contact ratio ε_α of a standard external spur pair (addendum = m) [-]."""
    r1, r2 = module_mm * z1 / 2, module_mm * z2 / 2
    rb1, rb2 = r1 * np.cos(alpha_rad), r2 * np.cos(alpha_rad)
    ra1, ra2 = r1 + module_mm, r2 + module_mm
    a = r1 + r2
    path = np.sqrt(ra1**2 - rb1**2) + np.sqrt(ra2**2 - rb2**2) - a * np.sin(alpha_rad)
    return float(path / (np.pi * module_mm * np.cos(alpha_rad)))


def rectangular_mesh_stiffness_fourier(
    single_pair_stiffness: float, contact_ratio: float, n_harmonics: int, n_samples: int = 4096
) -> tuple[float, np.ndarray, np.ndarray]:
    """Fourier series (eq 11) of the rectangular-wave involute mesh stiffness.

    Two pairs in mesh (2 k_1) over the fraction ε_α − 1 of a mesh period, one pair (k_1) over the
    rest: mean k_1 ε_α. Returns (mean, a_l, b_l) in the units of ``single_pair_stiffness``.
    """
    if not 1.0 < contact_ratio < 2.0:
        raise ParameterError("contact_ratio", contact_ratio, "must be in (1, 2)")
    s = 2 * np.pi * np.arange(n_samples) / n_samples
    k = np.where(s < 2 * np.pi * (contact_ratio - 1.0), 2.0, 1.0) * single_pair_stiffness
    return fourier_fit(k, n_harmonics)


# --- compiled right-hand side ------------------------------------------------------------------
# layout of the scalar parameter vector ``pf``
_P = {
    name: i
    for i, name in enumerate(
        [
            "w_o",  # nominal output speed [rad/s]
            "ratio",  # i
            "crank_rate",  # crank absolute speed / ω_o = 1 − z_p
            "phi_h0",  # crank phase at t = 0 [rad]
            "a_h",  # crank circle radius [mm]
            "ecc",  # eccentricity [mm]
            "r_bs",  # base radius of the sun [mm]
            "alpha",  # working pressure angle of the involute pair [rad]
            "z_s",
            "z_p",
            "k_s",
            "k_st",
            "k_sp",  # mean involute mesh stiffness [N/mm]
            "k_h",
            "k_ht",
            "k_hb",
            "k_cb",
            "k_cr",  # mean cycloid–pin stiffness [N/mm]
            "k_o",
            "beta_cr",  # equivalent pressure angle [rad]
            "sgn_r",  # sign of the radial component of the pin resultant (+1 outward)
            "beta_r",  # stiffness-proportional damping coefficient [s]
            "t_o",  # load torque on the output [N·mm]
            "m_p",
            "m_h",
            "m_c",
            "cl_oh",
            "cl_c",
            "cl_h",
            "r_bp",
            "n_m",
            "n_n",
            "cos_alpha",
            "sin_alpha",
            "cos_beta_cr",
            "sin_beta_cr",
        ]
    )
}
NPF = len(_P)


@njit(cache=True, nogil=True)
def _bearing(dx, dy, vx, vy, k, c, cl):
    """Force (on body a) of an isotropic bearing with radial clearance cl; returns fx, fy."""
    if cl <= 0.0:
        return -k * dx - c * vx, -k * dy - c * vy
    r = np.sqrt(dx * dx + dy * dy)
    if r <= cl:
        return 0.0, 0.0
    s = k * (r - cl) / r
    return -s * dx - c * vx, -s * dy - c * vy


@njit(cache=True, nogil=True)
def _fourier2(mean, coef, c1, s1):
    """mean + Σ_l a_l cos(l s) + b_l sin(l s) given cos s and sin s (angle-addition recurrence)."""
    c = c1
    s = s1
    val = mean
    for ll in range(coef.shape[1]):
        val += coef[0, ll] * c + coef[1, ll] * s
        c, s = c * c1 - s * s1, s * c1 + c * s1
    return val


@njit(cache=True, nogil=True)
def rv_rhs(t, y, args, dydt, work):
    """dy/dt of the lumped RV model (compiled; plain twin: ``RVDynamicModel.rhs_numpy``).

    y = [q (6M+3N+6), q̇]; q per body (x [mm], y [mm], θ [rad]) in the order sun, planets 1..M,
    cranks 1..M, discs 1..N, output. ``args`` = (pf, inv_mass, fsp, fcr, err_g, err_m, err_mn,
    err_n, geo_m, geo_n) from :meth:`RVDynamicModel.kernel_args`; errors are given there as
    body-fixed Cartesian offsets (E cos β, E sin β) and rotated here with the body, so the only
    trigonometric calls per evaluation are the five nominal angles. ``work`` (``RHS_WORK_SIZE``
    floats, NaN-filled, one per integration) memoises them and the mesh stiffnesses for the last
    two times, so RK4 computes them twice per step instead of four times; pass
    ``np.full(RHS_WORK_SIZE, np.nan)`` (a shorter array makes the call allocate its own).
    """
    pf, inv_m, fsp, fcr, err_g, err_m, err_mn, err_n, geo_m, geo_n = args
    nm = int(pf[30])
    nn = int(pf[31])
    nd = 3 * (2 * nm + nn + 2)
    q = y[:nd]
    v = y[nd:]
    f = dydt[nd:]
    for i in range(nd):
        dydt[i] = v[i]
        f[i] = 0.0
    w_o = pf[0]
    th_o = w_o * t
    th_s = pf[1] * th_o
    th_h = pf[3] + pf[2] * th_o
    # Memo of everything that depends on t only (nominal angles, mesh stiffnesses): two slots
    # [t, cos/sin of θ_o, θ_s, θ_H, k_sp,i (≤ 6), k_cr,j (≤ 3)] and a flag naming the older slot.
    if work.size < RHS_WORK_SIZE:
        work = np.full(RHS_WORK_SIZE, np.nan)
    if work[0] == t:
        o = 0
    elif work[_SLOT] == t:
        o = _SLOT
    else:
        o = _SLOT if work[2 * _SLOT] != 1.0 else 0
        work[2 * _SLOT] = 1.0 if o == _SLOT else 0.0
        work[o] = t
        work[o + 1] = np.cos(th_o)
        work[o + 2] = np.sin(th_o)
        work[o + 3] = np.cos(th_s)
        work[o + 4] = np.sin(th_s)
        work[o + 5] = np.cos(th_h)
        work[o + 6] = np.sin(th_h)
        ph_s = pf[8] * (th_s - th_o)
        cps0 = np.cos(ph_s)
        sps0 = np.sin(ph_s)
        for i in range(nm):  # involute mesh stiffness (eq 11), phase z_s(θ_s − θ_o) + z_s ψ_i
            work[o + 7 + i] = _fourier2(
                pf[12],
                fsp,
                cps0 * geo_m[i, 2] - sps0 * geo_m[i, 3],
                sps0 * geo_m[i, 2] + cps0 * geo_m[i, 3],
            )
        ph_c = pf[9] * th_h
        cpc0 = np.cos(ph_c)
        spc0 = np.sin(ph_c)
        for j in range(nn):  # cycloid–pin stiffness (eq 13), phase z_p χ_j
            work[o + 13 + j] = _fourier2(
                pf[17],
                fcr,
                cpc0 * geo_n[j, 2] - spc0 * geo_n[j, 3],
                spc0 * geo_n[j, 2] + cpc0 * geo_n[j, 3],
            )
    co = work[o + 1]
    so = work[o + 2]
    cs = work[o + 3]
    ss = work[o + 4]
    chh = work[o + 5]
    shh = work[o + 6]
    a_h = pf[4]
    ecc = pf[5]
    r_bs = pf[6]
    ca = pf[32]
    sa = pf[33]
    br = pf[21]
    i_out = nd - 3
    # sun support (ground seat offset = sun assembly error) and input shaft torsion
    k = pf[10]
    fx, fy = _bearing(q[0] - err_g[1, 0], q[1] - err_g[1, 1], v[0], v[1], k, br * k, 0.0)
    f[0] += fx
    f[1] += fy
    k = pf[11]
    f[2] += -k * q[2] - br * k * v[2]
    # output support
    k = pf[18]
    fx, fy = _bearing(
        q[i_out] - err_g[2, 0],
        q[i_out + 1] - err_g[2, 1],
        v[i_out],
        v[i_out + 1],
        k,
        br * k,
        pf[28],
    )
    f[i_out] += fx
    f[i_out + 1] += fy
    # sun eccentricity offset (rotates with the sun)
    sex = err_g[0, 0] * cs - err_g[0, 1] * ss
    sey = err_g[0, 0] * ss + err_g[0, 1] * cs
    w2 = w_o * w_o * a_h
    for i in range(nm):
        ip = 3 * (1 + i)
        ih = 3 * (1 + nm + i)
        cps = co * geo_m[i, 0] - so * geo_m[i, 1]  # psi_i = th_o + 2π i / M
        sps = so * geo_m[i, 0] + co * geo_m[i, 1]
        chx = a_h * cps
        chy = a_h * sps
        # sun–planet mesh i: line of action tangent to the sun base circle at angle psi − alpha
        tx = cps * ca + sps * sa
        ty = sps * ca - cps * sa
        nx = -ty
        ny = tx
        px = r_bs * tx
        py = r_bs * ty
        ksp = work[o + 7 + i]
        pex = err_m[i, 0, 0] * chh - err_m[i, 0, 1] * shh
        pey = err_m[i, 0, 0] * shh + err_m[i, 0, 1] * chh
        ga_t = px * ny - py * nx  # arm of the sun
        gb_t = (px - chx) * ny - (py - chy) * nx  # arm of the planet
        d = (
            nx * (q[0] - q[ip])
            + ny * (q[1] - q[ip + 1])
            + ga_t * q[2]
            - gb_t * q[ip + 2]
            + nx * (sex - pex)
            + ny * (sey - pey)
        )
        dv = nx * (v[0] - v[ip]) + ny * (v[1] - v[ip + 1]) + ga_t * v[2] - gb_t * v[ip + 2]
        fn = -ksp * d - br * ksp * dv
        f[0] += fn * nx
        f[1] += fn * ny
        f[2] += fn * ga_t
        f[ip] -= fn * nx
        f[ip + 1] -= fn * ny
        f[ip + 2] -= fn * gb_t
        # planet–crank shaft: bending (translation) and torsion
        k = pf[13]
        fx, fy = _bearing(
            q[ip] - q[ih],
            q[ip + 1] - q[ih + 1],
            v[ip] - v[ih],
            v[ip + 1] - v[ih + 1],
            k,
            br * k,
            0.0,
        )
        f[ip] += fx
        f[ip + 1] += fy
        f[ih] -= fx
        f[ih + 1] -= fy
        k = pf[14]
        tq = -k * (q[ip + 2] - q[ih + 2]) - br * k * (v[ip + 2] - v[ih + 2])
        f[ip + 2] += tq
        f[ih + 2] -= tq
        # crank support bearing in the output disc (hole offset rotates with the output)
        k = pf[15]
        ox = err_m[i, 1, 0] * cps - err_m[i, 1, 1] * sps
        oy = err_m[i, 1, 0] * sps + err_m[i, 1, 1] * cps
        # output material point at c_H: u_o + θ_o ẑ×c_H
        dx = q[ih] - (q[i_out] - q[i_out + 2] * chy) - ox
        dy = q[ih + 1] - (q[i_out + 1] + q[i_out + 2] * chx) - oy
        vx = v[ih] - (v[i_out] - v[i_out + 2] * chy)
        vy = v[ih + 1] - (v[i_out + 1] + v[i_out + 2] * chx)
        fx, fy = _bearing(dx, dy, vx, vy, k, br * k, pf[26])
        f[ih] += fx
        f[ih + 1] += fy
        f[i_out] -= fx
        f[i_out + 1] -= fy
        f[i_out + 2] -= chx * fy - chy * fx
        # centripetal load of the carried planet and crank (nominal circular motion)
        f[ip] += pf[23] * w2 * cps
        f[ip + 1] += pf[23] * w2 * sps
        f[ih] += pf[24] * w2 * cps
        f[ih + 1] += pf[24] * w2 * sps
    # discs
    w_h = pf[2] * w_o
    sb = pf[35]
    cb = pf[34]
    for j in range(nn):
        ic = 3 * (1 + 2 * nm + j)
        ex = chh * geo_n[j, 0] - shh * geo_n[j, 1]  # chi_j = th_h + π j
        ey = shh * geo_n[j, 0] + chh * geo_n[j, 1]
        ccx = ecc * ex
        ccy = ecc * ey
        for i in range(nm):
            ih = 3 * (1 + nm + i)
            cps = co * geo_m[i, 0] - so * geo_m[i, 1]
            sps = so * geo_m[i, 0] + co * geo_m[i, 1]
            chx = a_h * cps
            chy = a_h * sps
            # turning-arm bearing at the cam centre C = c_H + e ê_χ
            k = pf[16]
            amx = err_mn[i, j, 1, 0] * ex - err_mn[i, j, 1, 1] * ey  # cam (with crank)
            amy = err_mn[i, j, 1, 0] * ey + err_mn[i, j, 1, 1] * ex
            hox = err_mn[i, j, 0, 0] * cps - err_mn[i, j, 0, 1] * sps  # hole (with disc)
            hoy = err_mn[i, j, 0, 0] * sps + err_mn[i, j, 0, 1] * cps
            # arms: C − c_H = e ê_χ (crank), C − c_c = c_H (disc)
            dx = (q[ih] - q[ih + 2] * ccy) - (q[ic] - q[ic + 2] * chy) + amx - hox
            dy = (q[ih + 1] + q[ih + 2] * ccx) - (q[ic + 1] + q[ic + 2] * chx) + amy - hoy
            vx = (v[ih] - v[ih + 2] * ccy) - (v[ic] - v[ic + 2] * chy)
            vy = (v[ih + 1] + v[ih + 2] * ccx) - (v[ic + 1] + v[ic + 2] * chx)
            fx, fy = _bearing(dx, dy, vx, vy, k, br * k, pf[27])
            f[ih] += fx
            f[ih + 1] += fy
            f[ih + 2] += ccx * fy - ccy * fx
            f[ic] -= fx
            f[ic + 1] -= fy
            f[ic + 2] -= chx * fy - chy * fx
        # equivalent cycloid–pin contact at the pitch point P = z_p e ê_χ (eq 27, rotating)
        kcr = work[o + 13 + j]
        # force on the disc along d = sgn sinβ ê + cosβ ẑ×ê ; approach direction n = −d
        nx = -(pf[20] * sb * ex - cb * ey)
        ny = -(pf[20] * sb * ey + cb * ex)
        rx = (pf[9] - 1.0) * ccx
        ry = (pf[9] - 1.0) * ccy
        g_t = rx * ny - ry * nx
        ecr = (
            err_n[j, 0] * so + err_n[j, 1] * co
        )  # E sin(th_o + φ) = E cosφ sin th_o + E sinφ cos th_o
        d = nx * q[ic] + ny * q[ic + 1] + g_t * q[ic + 2] + ecr
        dv = nx * v[ic] + ny * v[ic + 1] + g_t * v[ic + 2]
        fn = -kcr * d - br * kcr * dv
        f[ic] += fn * nx
        f[ic + 1] += fn * ny
        f[ic + 2] += fn * g_t
        # centripetal load of the disc on its eccentric circle
        f[ic] += pf[25] * w_h * w_h * ccx
        f[ic + 1] += pf[25] * w_h * w_h * ccy
    f[i_out + 2] -= pf[22]
    for i in range(nd):
        f[i] *= inv_m[i]


@njit(cache=True, nogil=True)
def rv_dte(t, y, args):
    """Dynamic transmission error θ_o − θ_s / i [rad] of state y."""
    pf = args[0]
    nd = 3 * (2 * int(pf[30]) + int(pf[31]) + 2)
    return y[nd - 1] - y[2] / pf[1]


# --- model object ----------------------------------------------------------------------------
@dataclass(frozen=True)
class ModalResult:
    """Natural frequencies [Hz] (ascending) and mass-normalised mode shapes (columns)."""

    frequencies: np.ndarray
    shapes: np.ndarray
    dof_names: list[str]


class RVDynamicModel:
    """The lumped model built from an RV description (parameters + errors).

    Parameters
    ----------
    params : RVDynamicsParameters
    errors : RVErrors, optional
        Defaults to no errors and no clearances.
    contact : MeshPeriodContact, optional
        Loaded contact over one mesh period at the per-disc torque; computed when omitted.
    """

    def __init__(
        self,
        params: RVDynamicsParameters,
        errors: RVErrors | None = None,
        contact=None,
    ) -> None:
        self.params = p = params
        m, n = p.crank_count, p.disc_count
        self.errors = errors if errors is not None else RVErrors(crank_count=m, disc_count=n)
        if (self.errors.crank_count, self.errors.disc_count) != (m, n):
            raise ParameterError(
                "errors",
                (self.errors.crank_count, self.errors.disc_count),
                f"must be for ({m}, {n})",
            )
        self.n_bodies = 2 * m + n + 2
        self.n_dof = 3 * self.n_bodies
        t_disc = p.output_torque_Nm * 1e3 / n
        self.contact = contact or mesh_period_contact(p.pair, t_disc, p.contact_positions)
        k_cr_mean, a_cr, b_cr = fourier_fit(self.contact.mesh_stiffness, p.cycloid_harmonics)
        if p.cycloid_stiffness == "mean":  # paper 004 §4.1 feeds the mean into the model
            a_cr, b_cr = np.zeros_like(a_cr), np.zeros_like(b_cr)
        if p.cycloid_mesh_stiffness_N_per_m is not None:
            scale = p.cycloid_mesh_stiffness_N_per_m * N_PER_M_TO_N_PER_MM / k_cr_mean
            k_cr_mean, a_cr, b_cr = k_cr_mean * scale, a_cr * scale, b_cr * scale
        self.cycloid_fourier = (k_cr_mean, a_cr, b_cr)  # N/mm
        self.beta_cr = self.contact.pressure_angle_mean
        if p.cycloid_pressure_angle_deg is not None:
            self.beta_cr = float(np.deg2rad(p.cycloid_pressure_angle_deg))
        sr = float(np.sum(self.contact.contact.radial_force_signed))
        self.sgn_radial = 1.0 if sr >= 0 else -1.0
        alpha = np.deg2rad(p.pressure_angle_deg)
        self.contact_ratio = involute_contact_ratio(p.sun_teeth, p.planet_teeth, p.module_mm, alpha)
        k1 = p.involute_single_pair_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        self.involute_fourier = rectangular_mesh_stiffness_fourier(
            k1, self.contact_ratio, p.involute_harmonics
        )
        self.alpha = alpha
        self.r_bs = p.module_mm * p.sun_teeth / 2 * np.cos(alpha)
        self.r_bp = p.module_mm * p.planet_teeth / 2 * np.cos(alpha)
        mass = []
        for mk, jk, cnt in (
            (p.sun_mass_kg, p.sun_inertia_kgm2, 1),
            (p.planet_mass_kg, p.planet_inertia_kgm2, m),
            (p.crank_mass_kg, p.crank_inertia_kgm2, m),
            (p.disc_mass_kg, p.disc_inertia_kgm2, n),
            (p.output_mass_kg, p.output_inertia_kgm2, 1),
        ):
            mass += [mk * KG_TO_T, mk * KG_TO_T, jk * KGM2_TO_TMM2] * cnt
        self.mass = np.array(mass)
        names = ["sun"] + [f"planet{i + 1}" for i in range(m)] + [f"crank{i + 1}" for i in range(m)]
        names += [f"disc{j + 1}" for j in range(n)] + ["output"]
        self.body_names = names
        self.dof_names = [f"{b}.{c}" for b in names for c in ("x", "y", "theta")]
        self._lu_cache: dict = {}
        self._beta_r = 0.0
        self._beta_r = self._calibrate_damping()

    # --- indices -------------------------------------------------------------------------
    def body(self, name: str) -> int:
        """First DOF index of a body (``"sun"``, ``"planet1"``, ``"disc2"``, ``"output"``...)."""
        return 3 * self.body_names.index(name)

    # --- packed arguments of the compiled RHS ----------------------------------------------
    def kernel_args(self, errors: RVErrors | None = None, *, damping: bool = True) -> tuple:
        """Arrays passed to :func:`rv_rhs` (errors may be swapped for a batch realisation)."""
        p = self.params
        e = errors if errors is not None else self.errors
        pf = np.zeros(NPF)
        k_sp_mean, a_sp, b_sp = self.involute_fourier
        k_cr_mean, a_cr, b_cr = self.cycloid_fourier
        vals = {
            "w_o": p.output_speed,
            "ratio": p.ratio,
            "crank_rate": 1.0 - p.pair.pin_count,
            "phi_h0": np.deg2rad(p.crank_phase_deg),
            "a_h": p.centre_distance_mm,
            "ecc": p.pair.eccentricity_mm,
            "r_bs": self.r_bs,
            "alpha": self.alpha,
            "z_s": p.sun_teeth,
            "z_p": p.pair.pin_count,
            "k_s": p.sun_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_st": p.input_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
            "k_sp": k_sp_mean,
            "k_h": p.crank_bending_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_ht": p.crank_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
            "k_hb": p.crank_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_cb": p.turning_arm_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "k_cr": k_cr_mean,
            "k_o": p.output_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
            "beta_cr": self.beta_cr,
            "sgn_r": self.sgn_radial,
            "beta_r": self._beta_r if damping else 0.0,
            "t_o": p.output_torque_Nm * 1e3,
            "m_p": p.planet_mass_kg * KG_TO_T,
            "m_h": p.crank_mass_kg * KG_TO_T,
            "m_c": p.disc_mass_kg * KG_TO_T,
            "cl_oh": e.crank_bearing_clearance_mm,
            "cl_c": e.turning_arm_clearance_mm,
            "cl_h": e.output_bearing_clearance_mm,
            "r_bp": self.r_bp,
            "n_m": p.crank_count,
            "n_n": p.disc_count,
            "cos_alpha": np.cos(self.alpha),
            "sin_alpha": np.sin(self.alpha),
            "cos_beta_cr": np.cos(self.beta_cr),
            "sin_beta_cr": np.sin(self.beta_cr),
        }
        for key, val in vals.items():
            pf[_P[key]] = val

        def cart(a):
            a = np.asarray(a, dtype=float)
            return np.stack([a[..., 0] * np.cos(a[..., 1]), a[..., 0] * np.sin(a[..., 1])], -1)

        err_g = cart([e.sun_eccentricity, e.sun_assembly, e.output_assembly])
        err_m = cart(np.stack([e.planet_eccentricity, e.carrier_hole], axis=1))
        err_mn = cart(np.stack([e.disc_hole, e.cam], axis=2))
        pin = np.asarray(e.pin_composite, dtype=float)
        m, n = p.crank_count, p.disc_count
        om = 2 * np.pi * np.arange(m) / m
        on = np.pi * np.arange(n)
        geo_m = np.stack(
            [np.cos(om), np.sin(om), np.cos(p.sun_teeth * om), np.sin(p.sun_teeth * om)], 1
        )
        zp = p.pair.pin_count
        geo_n = np.stack([np.cos(on), np.sin(on), np.cos(zp * on), np.sin(zp * on)], 1)
        return (
            pf,
            1.0 / self.mass,
            np.ascontiguousarray(np.stack([a_sp, b_sp])),
            np.ascontiguousarray(np.stack([a_cr, b_cr])),
            np.ascontiguousarray(err_g),
            np.ascontiguousarray(err_m),
            np.ascontiguousarray(err_mn),
            np.ascontiguousarray(cart(pin)),
            np.ascontiguousarray(geo_m),
            np.ascontiguousarray(geo_n),
        )

    # --- plain element model (readable twin) ------------------------------------------------
    def elements(self, t: float, *, mesh: str = "time") -> list[dict]:
        """Element list at time t: each with kind, stiffness, rows g (deflection = g·q + e).

        ``mesh="time"`` evaluates the mesh stiffnesses at t, ``"mean"`` uses their means,
        ``"max"`` their maxima over a period (for the stability limit).
        """
        p, e = self.params, self.errors
        nd = self.n_dof
        m, n = p.crank_count, p.disc_count
        w_o = p.output_speed
        th_o = w_o * t
        th_s = p.ratio * th_o
        th_h = np.deg2rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
        a_h = p.centre_distance_mm
        ecc = p.pair.eccentricity_mm
        out = []

        def row(entries):
            g = np.zeros(nd)
            for body_idx, (gx, gy, gt) in entries:
                if body_idx is None:
                    continue
                g[3 * body_idx : 3 * body_idx + 3] += (gx, gy, gt)
            return g

        def point_rows(a, ca, b, cb, c):
            """x and y rows of the relative displacement of material points at c."""
            ra = (c[0] - ca[0], c[1] - ca[1])
            rx = [(a, (1.0, 0.0, -ra[1]))]
            ry = [(a, (0.0, 1.0, ra[0]))]
            if b is not None:
                rb = (c[0] - cb[0], c[1] - cb[1])
                rx.append((b, (-1.0, 0.0, rb[1])))
                ry.append((b, (0.0, -1.0, -rb[0])))
            return row(rx), row(ry)

        def polar(amp, ang):
            return np.array([amp * np.cos(ang), amp * np.sin(ang)])

        def series(coef, phase):
            mean, a, b = coef
            if mesh == "mean":
                return mean
            if mesh == "max":
                s = np.linspace(0, 2 * np.pi, 721)
                return float(np.max(fourier_eval(mean, a, b, s)))
            return float(fourier_eval(mean, a, b, phase))

        i_s, i_o = 0, self.n_bodies - 1
        k = p.sun_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        gx, gy = point_rows(i_s, (0, 0), None, None, (0, 0))
        out.append(
            dict(
                name="sun support",
                kind="bearing",
                k=k,
                g=(gx, gy),
                cl=0.0,
                e=-polar(*e.sun_assembly),
            )
        )
        g = np.zeros(nd)
        g[2] = 1.0
        out.append(
            dict(
                name="input shaft",
                kind="line",
                k=p.input_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
                g=g,
                e=0.0,
            )
        )
        k = p.output_support_stiffness_N_per_m * N_PER_M_TO_N_PER_MM
        gx, gy = point_rows(i_o, (0, 0), None, None, (0, 0))
        out.append(
            dict(
                name="output support",
                kind="bearing",
                k=k,
                g=(gx, gy),
                cl=e.output_bearing_clearance_mm,
                e=-polar(*e.output_assembly),
            )
        )
        sun_off = polar(e.sun_eccentricity[0], th_s + e.sun_eccentricity[1])
        for i in range(m):
            ip, ih = 1 + i, 1 + m + i
            psi = th_o + 2 * np.pi * i / m
            ch = a_h * np.array([np.cos(psi), np.sin(psi)])
            tdir = np.array([np.cos(psi - self.alpha), np.sin(psi - self.alpha)])
            nvec = np.array([-tdir[1], tdir[0]])
            pp = self.r_bs * tdir
            arm_a = pp[0] * nvec[1] - pp[1] * nvec[0]
            rb = pp - ch
            arm_b = rb[0] * nvec[1] - rb[1] * nvec[0]
            g = row([(0, (nvec[0], nvec[1], arm_a)), (ip, (-nvec[0], -nvec[1], -arm_b))])
            phase = p.sun_teeth * (th_s - th_o) + p.sun_teeth * 2 * np.pi * i / m
            pl_off = polar(e.planet_eccentricity[i, 0], th_h + e.planet_eccentricity[i, 1])
            out.append(
                dict(
                    name=f"sun-planet{i + 1} mesh",
                    kind="line",
                    k=series(self.involute_fourier, phase),
                    g=g,
                    e=float(nvec @ (sun_off - pl_off)),
                )
            )
            gx, gy = point_rows(ip, ch, ih, ch, ch)
            out.append(
                dict(
                    name=f"crank{i + 1} bending",
                    kind="bearing",
                    k=p.crank_bending_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                    g=(gx, gy),
                    cl=0.0,
                    e=np.zeros(2),
                )
            )
            g = np.zeros(nd)
            g[3 * ip + 2], g[3 * ih + 2] = 1.0, -1.0
            out.append(
                dict(
                    name=f"crank{i + 1} torsion",
                    kind="line",
                    k=p.crank_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD,
                    g=g,
                    e=0.0,
                )
            )
            gx, gy = point_rows(ih, ch, i_o, (0, 0), ch)
            out.append(
                dict(
                    name=f"crank{i + 1} support",
                    kind="bearing",
                    k=p.crank_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                    g=(gx, gy),
                    cl=e.crank_bearing_clearance_mm,
                    e=-polar(e.carrier_hole[i, 0], psi + e.carrier_hole[i, 1]),
                )
            )
        for j in range(n):
            ic = 1 + 2 * m + j
            chi = th_h + np.pi * j
            ehat = np.array([np.cos(chi), np.sin(chi)])
            eperp = np.array([-ehat[1], ehat[0]])
            cc = ecc * ehat
            for i in range(m):
                ih = 1 + m + i
                psi = th_o + 2 * np.pi * i / m
                ch = a_h * np.array([np.cos(psi), np.sin(psi)])
                c = ch + cc
                gx, gy = point_rows(ih, ch, ic, cc, c)
                cam = polar(e.cam[i, j, 0], chi + e.cam[i, j, 1])
                hole = polar(e.disc_hole[i, j, 0], psi + e.disc_hole[i, j, 1])
                out.append(
                    dict(
                        name=f"crank{i + 1}-disc{j + 1} bearing",
                        kind="bearing",
                        k=p.turning_arm_bearing_stiffness_N_per_m * N_PER_M_TO_N_PER_MM,
                        g=(gx, gy),
                        cl=e.turning_arm_clearance_mm,
                        e=cam - hole,
                    )
                )
            b = self.beta_cr
            dvec = self.sgn_radial * np.sin(b) * ehat + np.cos(b) * eperp
            nvec = -dvec
            pp = p.pair.pin_count * cc
            r = pp - cc
            g = row([(ic, (nvec[0], nvec[1], r[0] * nvec[1] - r[1] * nvec[0]))])
            out.append(
                dict(
                    name=f"disc{j + 1}-pins",
                    kind="line",
                    k=series(self.cycloid_fourier, p.pair.pin_count * chi),
                    g=g,
                    e=float(e.pin_composite[j, 0] * np.sin(th_o + e.pin_composite[j, 1])),
                )
            )
        return out

    def stiffness_matrix(
        self, t: float = 0.0, *, mesh: str = "mean", input_shaft: bool = True
    ) -> np.ndarray:
        """K [N/mm, N, N·mm/rad mixed by DOF] assembled from the elements (clearances closed)."""
        K = np.zeros((self.n_dof, self.n_dof))
        for el in self.elements(t, mesh=mesh):
            if el["name"] == "input shaft" and not input_shaft:
                continue
            gs = el["g"] if el["kind"] == "bearing" else (el["g"],)
            for g in gs:
                K += el["k"] * np.outer(g, g)
        return K

    def external_force(self, t: float) -> np.ndarray:
        """Load torque on the output and centripetal loads of the carried bodies [N, N·mm]."""
        p = self.params
        m, n = p.crank_count, p.disc_count
        f = np.zeros(self.n_dof)
        f[-1] = -p.output_torque_Nm * 1e3
        w_o = p.output_speed
        th_o = w_o * t
        th_h = np.deg2rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
        for i in range(m):
            psi = th_o + 2 * np.pi * i / m
            c = p.centre_distance_mm * np.array([np.cos(psi), np.sin(psi)]) * w_o**2
            f[3 * (1 + i) : 3 * (1 + i) + 2] += p.planet_mass_kg * KG_TO_T * c
            f[3 * (1 + m + i) : 3 * (1 + m + i) + 2] += p.crank_mass_kg * KG_TO_T * c
        w_h = (1.0 - p.pair.pin_count) * w_o
        for j in range(n):
            chi = th_h + np.pi * j
            c = p.pair.eccentricity_mm * np.array([np.cos(chi), np.sin(chi)]) * w_h**2
            ic = 3 * (1 + 2 * m + j)
            f[ic : ic + 2] += p.disc_mass_kg * KG_TO_T * c
        return f

    def elastic_force(self, t: float, q: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """Element forces on the DOFs (springs with clearances, dampers) [N, N·mm]."""
        f = np.zeros(self.n_dof)
        br = self._beta_r
        v = np.zeros(self.n_dof) if v is None else v
        for el in self.elements(t):
            k = el["k"]
            if el["kind"] == "line":
                g = el["g"]
                d = g @ q + el["e"]
                f -= (k * d + br * k * (g @ v)) * g
            else:
                gx, gy = el["g"]
                d = np.array([gx @ q, gy @ q]) + el["e"]
                r = np.hypot(*d)
                cl = el["cl"]
                if cl > 0 and r <= cl:
                    continue
                s = k * (r - cl) / r if cl > 0 else k
                fx, fy = s * d + br * k * np.array([gx @ v, gy @ v])
                f -= fx * gx + fy * gy
        return f

    def rhs_numpy(self, t: float, y: np.ndarray) -> np.ndarray:
        """Plain-Python twin of :func:`rv_rhs` (element loop), for solve_ivp and tests."""
        nd = self.n_dof
        q, v = y[:nd], y[nd:]
        acc = (self.elastic_force(t, q, v) + self.external_force(t)) / self.mass
        return np.concatenate([v, acc])

    # --- statics and modes ---------------------------------------------------------------------
    def static_equilibrium(
        self, t: float = 0.0, *, tol: float = 1e-10, compiled: bool = True
    ) -> np.ndarray:
        """Deviation q of static equilibrium at time t (modified Newton with the linear K).

        The residual (all element forces + loads at zero velocity) comes from the compiled
        :func:`rv_rhs` (``compiled=True``) or the plain element model. Raises ConvergenceError
        when the clearances prevent convergence in 100 iterations.
        """
        from scipy.linalg import lu_factor, lu_solve

        # K does not depend on the errors: its factorisation is shared by with_errors() copies
        lu = self._lu_cache.get(t)
        if lu is None:
            lu = lu_factor(self.stiffness_matrix(t, mesh="time"))
            self._lu_cache[t] = lu
        nd = self.n_dof
        q = np.zeros(nd)
        f_ext = self.external_force(t)
        scale = np.max(np.abs(f_ext))
        args = self.kernel_args() if compiled else None
        y = np.zeros(2 * nd)
        dydt = np.empty(2 * nd)
        for it in range(100):  # noqa: B007 - reported on failure
            if compiled:
                y[:nd] = q
                rv_rhs(t, y, args, dydt, np.full(RHS_WORK_SIZE, np.nan))
                r = dydt[nd:] * self.mass
            else:
                r = self.elastic_force(t, q) + f_ext
            if np.max(np.abs(r)) <= tol * scale:
                return q
            q = q + lu_solve(lu, r)
        raise ConvergenceError(
            f"static_equilibrium: modified Newton did not converge in {it + 1} iterations "
            f"(residual {np.max(np.abs(r)):.3g} N, tolerance {tol * scale:.3g} N)"
        )

    def element_deflections(self, t: float, q: np.ndarray) -> dict[str, float]:
        """Deflection of each line element (or radial deflection of a bearing) [mm or rad]."""
        out = {}
        for el in self.elements(t):
            if el["kind"] == "line":
                out[el["name"]] = float(el["g"] @ q + el["e"])
            else:
                gx, gy = el["g"]
                out[el["name"]] = float(np.hypot(gx @ q + el["e"][0], gy @ q + el["e"][1]))
        return out

    def modal(self, t: float = 0.0, *, input_shaft: bool = True, mesh: str = "mean") -> ModalResult:
        """Undamped natural frequencies [Hz] and mode shapes at mean mesh stiffness."""
        K = self.stiffness_matrix(t, mesh=mesh, input_shaft=input_shaft)
        s = 1.0 / np.sqrt(self.mass)
        lam, vec = np.linalg.eigh(s[:, None] * K * s[None, :])
        lam = np.where(np.abs(lam) < 1e-9 * np.max(lam), 0.0, lam)
        freq = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
        return ModalResult(frequencies=freq, shapes=s[:, None] * vec, dof_names=self.dof_names)

    def rigid_mode(self, t: float = 0.0) -> np.ndarray:
        """Analytic rigid-body vector for θ_o = 1: θ_s = i, θ_p = θ_H = 1 − z_p, θ_c = 1."""
        p = self.params
        m, n = p.crank_count, p.disc_count
        q = np.zeros(self.n_dof)
        th_o = p.output_speed * t
        th_h = np.deg2rad(p.crank_phase_deg) + (1.0 - p.pair.pin_count) * th_o
        rate = 1.0 - p.pair.pin_count
        q[2] = p.ratio
        for i in range(m):
            psi = th_o + 2 * np.pi * i / m
            tang = p.centre_distance_mm * np.array([-np.sin(psi), np.cos(psi)])
            for b in (1 + i, 1 + m + i):
                q[3 * b : 3 * b + 2] = tang
                q[3 * b + 2] = rate
        for j in range(n):
            chi = th_h + np.pi * j
            ic = 3 * (1 + 2 * m + j)
            q[ic : ic + 2] = rate * p.pair.eccentricity_mm * np.array([-np.sin(chi), np.cos(chi)])
            q[ic + 2] = 1.0
        q[-1] = 1.0
        return q

    def _calibrate_damping(self) -> float:
        """β_R = 2ζ/ω_1 with ω_1 the lowest elastic mode (with the input shaft)."""
        f = self.modal().frequencies
        w1 = 2 * np.pi * f[f > 0][0]
        return 2.0 * self.params.damping_ratio / w1

    @property
    def damping_coefficient(self) -> float:
        """β_R of the stiffness-proportional element damping [s]."""
        return self._beta_r

    def damped_eigenvalues(self, t: float = 0.0, *, mesh: str = "max") -> np.ndarray:
        """Eigenvalues of the first-order state matrix [1/s] (for the stability limit)."""
        K = self.stiffness_matrix(t, mesh=mesh)
        minv = 1.0 / self.mass
        nd = self.n_dof
        A = np.zeros((2 * nd, 2 * nd))
        A[:nd, nd:] = np.eye(nd)
        A[nd:, :nd] = -minv[:, None] * K
        A[nd:, nd:] = -minv[:, None] * (self._beta_r * K)
        return np.linalg.eigvals(A)

    def resonance_warnings(
        self, margin: float = 0.1, harmonics: tuple[int, ...] = (1,)
    ) -> list[str]:
        """Warnings when a mesh frequency × ``harmonics`` lies within ±margin of a mode."""
        freqs = self.modal().frequencies
        freqs = freqs[freqs > 0]
        msgs = []
        for name, fm in self.params.frequencies().items():
            if "mesh" not in name:
                continue
            for h in harmonics:
                near = freqs[np.abs(freqs - h * fm) <= margin * h * fm]
                for fn in near:
                    msgs.append(
                        f"{name} frequency {'×2 ' if h == 2 else ''}{h * fm:.1f} Hz is within "
                        f"{100 * abs(fn - h * fm) / (h * fm):.1f}% of the natural frequency "
                        f"{fn:.1f} Hz: the response is resonant and hypersensitive to damping"
                    )
        return msgs

    def with_errors(self, errors: RVErrors) -> RVDynamicModel:
        """Same model (same contact analysis, same damping) with other errors."""
        new = object.__new__(RVDynamicModel)
        new.__dict__.update(self.__dict__)
        if (errors.crank_count, errors.disc_count) != (
            self.params.crank_count,
            self.params.disc_count,
        ):
            raise ParameterError("errors", (errors.crank_count, errors.disc_count), "wrong counts")
        new.errors = errors
        return new

    def with_params(self, **changes) -> RVDynamicModel:
        """Model with some parameters changed (contact recomputed when the pair/load changes)."""
        new = replace(self.params, **changes)
        same = new.pair == self.params.pair and new.output_torque_Nm == self.params.output_torque_Nm
        return RVDynamicModel(new, self.errors, contact=self.contact if same else None)


def _dte_python(t: float, y: np.ndarray, n_dof: int, ratio: float) -> float:
    """Plain twin of :func:`rv_dte` (a module-level function, so the system pickles)."""
    return float(y[n_dof - 1] - y[2] / ratio)


def ode_system(model: RVDynamicModel, errors: RVErrors | None = None):
    """The model as a :class:`gearte.solvers.ode.ODESystem` with DTE [rad] as output.

    Everything in it pickles (no local closures), so it crosses process boundaries
    (``--scheduler processes``, Dask workers).
    """
    from functools import partial

    from gearte.solvers.ode import ODESystem

    args = model.kernel_args(errors)
    m = model if errors is None else model.with_errors(errors)
    return ODESystem(
        rhs=rv_rhs,
        output=rv_dte,
        args=args,
        key=RHS_SOURCE_KEY,
        rhs_python=m.rhs_numpy,
        output_python=partial(_dte_python, n_dof=m.n_dof, ratio=m.params.ratio),
        stability_eigenvalues=model.damped_eigenvalues(mesh="max"),
        work_size=RHS_WORK_SIZE,
    )


# --- building the dynamic model from the shared RV description (gearte.geometry.rv) ----------
def parameters_from_reducer(reducer, **dynamic) -> RVDynamicsParameters:
    """RVDynamicsParameters from an :class:`gearte.geometry.rv.RVReducer` description.

    The description supplies geometry, modification, material, mesh/bearing/support stiffnesses
    (its N/mm → N/m here); ``dynamic`` supplies what only the dynamics needs (masses, inertias,
    torsional and bending stiffnesses, damping, operating point), defaulting to paper 004 Table 2.
    The description's mean involute mesh stiffness k̄ becomes the single-pair stiffness k̄/ε_α of
    the rectangular wave.

    Raises
    ------
    ParameterError
        When the crank circle radius differs from the first-stage centre distance (the dynamic
        model derives it from the gears) or a per-pin error is given (the equivalent single-spring
        cycloid–pin contact cannot represent it).
    """
    fs, cr, di, pins = reducer.first_stage, reducer.cranks, reducer.discs, reducer.pins
    a_h = fs.module * (fs.sun_teeth + fs.planet_teeth) / 2.0
    if abs(cr.circle_radius - a_h) > 1e-6 * a_h:
        raise ParameterError(
            "cranks.circle_radius",
            cr.circle_radius,
            f"must equal the first-stage centre distance m (z_1 + z_2)/2 = {a_h:g} mm",
        )
    for name in ("radius_errors", "radial_position_errors", "tangential_position_errors"):
        if np.any(getattr(pins, name) != 0):
            raise ParameterError(
                f"pins.{name}",
                "non-zero",
                "per-pin errors are not representable by the equivalent cycloid–pin spring of "
                "the dynamic model; use the composite error RVErrors.pin_composite",
            )
    pair = CycloidPinPair(
        pin_count=pins.count,
        pin_radius_mm=pins.pin_radius,
        pin_circle_radius_mm=pins.circle_radius,
        eccentricity_mm=cr.eccentricity,
        face_width_mm=di.face_width,
        youngs_modulus_MPa=di.youngs_modulus,
        poisson_ratio=di.poisson_ratio,
        pin_radius_modification_mm=di.equidistant_modification,
        pin_position_modification_mm=di.shift_modification,
    )
    eps = involute_contact_ratio(fs.sun_teeth, fs.planet_teeth, fs.module, fs.pressure_angle)
    kw = dict(
        sun_teeth=fs.sun_teeth,
        planet_teeth=fs.planet_teeth,
        module_mm=fs.module,
        pressure_angle_deg=float(np.degrees(fs.pressure_angle)),
        crank_count=cr.count,
        disc_count=di.count,
        pair=pair,
        sun_support_stiffness_N_per_m=fs.sun_support_stiffness / N_PER_M_TO_N_PER_MM,
        involute_single_pair_stiffness_N_per_m=fs.mesh_stiffness / eps / N_PER_M_TO_N_PER_MM,
        turning_arm_bearing_stiffness_N_per_m=cr.cam_bearing_stiffness / N_PER_M_TO_N_PER_MM,
        crank_bearing_stiffness_N_per_m=cr.carrier_bearing_stiffness / N_PER_M_TO_N_PER_MM,
        output_support_stiffness_N_per_m=reducer.supports.carrier_radial_stiffness
        / N_PER_M_TO_N_PER_MM,
    )
    kw.update(dynamic)
    return RVDynamicsParameters(**kw)


def errors_from_reducer(reducer, **paper004) -> RVErrors:
    """RVErrors from the description's measured errors and clearances.

    The description's error vectors (x, y) in the part frames use the same frames as this model
    (planet: from disc 1's eccentric direction; disc bore and carrier bore: from the radial
    direction; cam: from its eccentric direction), so they map 1:1 to (amplitude, phase). Its
    disc-bore array is indexed (disc, crank) and is transposed. ``paper004`` adds the errors the
    description does not hold (sun_eccentricity, sun_assembly, output_assembly, pin_composite,
    output_bearing_clearance_mm).
    """
    e = reducer.errors
    m, n = reducer.cranks.count, reducer.discs.count

    def polar(v):
        v = np.asarray(v, dtype=float)
        return np.stack([np.hypot(v[..., 0], v[..., 1]), np.arctan2(v[..., 1], v[..., 0])], -1)

    return RVErrors(
        crank_count=m,
        disc_count=n,
        planet_eccentricity=polar(e.planet),
        carrier_hole=polar(e.carrier_bore),
        disc_hole=polar(np.swapaxes(e.disc_bore, 0, 1)),
        cam=polar(e.cam),
        turning_arm_clearance_mm=reducer.cranks.cam_bearing_clearance,
        crank_bearing_clearance_mm=reducer.cranks.carrier_bearing_clearance,
        **paper004,
    )
