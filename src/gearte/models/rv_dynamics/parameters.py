"""Parameters and errors of the lumped RV dynamic model (Li et al. 2023, Tables 1–3).

:class:`RVDynamicsParameters` holds geometry, masses, inertias, stiffnesses, damping and the
operating point in paper units named in the fields (kg, kg·m², N/m, N·m/rad, N·m, rpm);
:class:`RVErrors` the eccentricity/assembly errors [mm, rad] and bearing clearances [mm].
:func:`parameters_from_reducer` and :func:`errors_from_reducer` build both from the shared RV
description (:class:`gearte.geometry.rv.RVReducer`).

References
----------
Li X., Huang J., Ding C., Guo R., Niu W. (2023). Dynamic Modeling and Analysis of an RV Reducer
Considering Tooth Profile Modifications and Errors. Machines 11(6), 626.
doi:10.3390/machines11060626
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.models.cycloid_loaded_contact import CycloidPinPair
from gearte.models.rv_dynamics.mesh_stiffness import involute_contact_ratio
from gearte.units import N_PER_M_TO_N_PER_MM, rad_to_deg, rpm_to_rad_per_s

__all__ = [
    "RVDynamicsParameters",
    "RVErrors",
    "parameters_from_reducer",
    "errors_from_reducer",
    "DYNAMIC_ONLY",
]


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
    Operating point: ``input_speed_rpm``, ``output_torque_Nm`` (split equally over the discs for
    the contact analysis).
    No field that is data has a default: Li 2023's values live in the example cases
    ``examples/li2023_rv*.toml``; build from a case with
    :func:`gearte.studies._rv_dynamics.build_dynamic_model` or from an
    :class:`~gearte.geometry.rv.RVReducer` with :func:`parameters_from_reducer`.
    """

    sun_teeth: int
    planet_teeth: int
    module_mm: float
    pressure_angle_deg: float
    crank_count: int
    disc_count: int
    pair: CycloidPinPair
    sun_mass_kg: float
    planet_mass_kg: float
    crank_mass_kg: float
    disc_mass_kg: float
    output_mass_kg: float
    sun_inertia_kgm2: float
    planet_inertia_kgm2: float
    crank_inertia_kgm2: float
    disc_inertia_kgm2: float
    output_inertia_kgm2: float
    input_torsional_stiffness_Nm_per_rad: float  # noqa: N815
    sun_support_stiffness_N_per_m: float  # noqa: N815
    crank_torsional_stiffness_Nm_per_rad: float  # noqa: N815
    crank_bending_stiffness_N_per_m: float  # noqa: N815
    crank_bearing_stiffness_N_per_m: float  # noqa: N815
    turning_arm_bearing_stiffness_N_per_m: float  # noqa: N815
    output_support_stiffness_N_per_m: float  # noqa: N815
    involute_single_pair_stiffness_N_per_m: float  # noqa: N815
    damping_ratio: float
    input_speed_rpm: float
    output_torque_Nm: float  # noqa: N815
    # modelling options (not data)
    involute_harmonics: int = 10
    cycloid_harmonics: int = 8
    contact_positions: int = 48
    cycloid_stiffness: str = "fourier"
    cycloid_mesh_stiffness_N_per_m: float | None = None  # noqa: N815
    cycloid_pressure_angle_deg: float | None = None
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
        return rpm_to_rad_per_s(self.input_speed_rpm) / self.ratio

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
    """Eccentricity errors (the kinds of paper 004 Table 3) on explicit cranks/discs, clearances.

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
    disc_rotation (Δθ_j): shape (N, K), the loaded rotation shift [rad] of disc j caused by the
      per-pin and disc-profile errors at K equally spaced output angles over one revolution
      (:func:`gearte.models.rv_dynamics.excitation.disc_rotation_error`); the disc's cycloid–pin
      spring reads θ_j − Δθ_j(θ_o), linearly interpolated. None → no such errors.
    Clearances [mm]: turning-arm (crank–disc) bearings ε_c, crank support bearings in the output
    disc ε_oH, output main bearing ε_h; radial dead zone of the bearing spring.
    cam_clearances_mm, carrier_clearances_mm: measured clearance of each turning-arm bearing
      (shape (M, N), crank i in disc j) and of each crank's support bearing (shape (M,)) [mm];
      None → the scalar ε_c / ε_oH for every bearing.
    """

    crank_count: int
    disc_count: int
    sun_eccentricity: tuple[float, float] = (0.0, 0.0)
    sun_assembly: tuple[float, float] = (0.0, 0.0)
    output_assembly: tuple[float, float] = (0.0, 0.0)
    planet_eccentricity: np.ndarray = None  # type: ignore[assignment]  # (M, 2); None → zeros
    carrier_hole: np.ndarray = None  # type: ignore[assignment]  # (M, 2); None → zeros
    disc_hole: np.ndarray = None  # type: ignore[assignment]  # (M, N, 2); None → zeros
    cam: np.ndarray = None  # type: ignore[assignment]  # (M, N, 2); None → zeros
    pin_composite: np.ndarray = None  # type: ignore[assignment]  # (N, 2); None → zeros
    disc_rotation: np.ndarray = None  # type: ignore[assignment]  # (N, K); None → zeros (N, 1)
    turning_arm_clearance_mm: float = 0.0
    crank_bearing_clearance_mm: float = 0.0
    output_bearing_clearance_mm: float = 0.0
    cam_clearances_mm: np.ndarray | None = None
    carrier_clearances_mm: np.ndarray | None = None

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
        rot = (
            np.zeros((n, 1))
            if self.disc_rotation is None
            else np.array(self.disc_rotation, dtype=float, ndmin=2)
        )
        if rot.ndim != 2 or rot.shape[0] != n or rot.shape[1] < 1:
            raise ParameterError("disc_rotation", rot.shape, f"must have shape ({n}, K ≥ 1)")
        if not np.all(np.isfinite(rot)):
            raise ParameterError("disc_rotation", "non-finite", "must be finite [rad]")
        object.__setattr__(self, "disc_rotation", np.ascontiguousarray(rot))
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
        for name, shape in (("cam_clearances_mm", (m, n)), ("carrier_clearances_mm", (m,))):
            v = getattr(self, name)
            if v is None:
                continue
            arr = np.asarray(v, dtype=float)
            if arr.shape != shape or not np.all(np.isfinite(arr)) or np.any(arr < 0):
                raise ParameterError(
                    name, arr.tolist(), f"must have shape {shape}, finite and ≥ 0 [mm]"
                )
            object.__setattr__(self, name, arr)

    def bearing_clearances(self) -> np.ndarray:
        """Clearance of every crank's bearings [mm], shape (M, N + 1).

        Column j < N: turning-arm bearing of crank i in disc j; column N: crank i's support
        bearing in the output disc. Measured values where given, else the scalar ones.
        """
        m, n = self.crank_count, self.disc_count
        out = np.empty((m, n + 1))
        out[:, :n] = (
            self.turning_arm_clearance_mm
            if self.cam_clearances_mm is None
            else self.cam_clearances_mm
        )
        out[:, n] = (
            self.crank_bearing_clearance_mm
            if self.carrier_clearances_mm is None
            else self.carrier_clearances_mm
        )
        return out


# --- building the dynamic model from the shared RV description (gearte.geometry.rv) ----------
def parameters_from_reducer(reducer, **dynamic) -> RVDynamicsParameters:
    """RVDynamicsParameters from an :class:`gearte.geometry.rv.RVReducer` description.

    The description supplies geometry, modification, material, mesh/bearing/support stiffnesses
    (its N/mm → N/m here); ``dynamic`` supplies what only the dynamics needs (:data:`DYNAMIC_ONLY`:
    masses, inertias, torsional and bending stiffnesses, damping, operating point); nothing
    defaults (a missing one raises :class:`~gearte.errors.ParameterError` naming it).
    The description's mean involute mesh stiffness k̄ becomes the single-pair stiffness k̄/ε_α of
    the rectangular wave.

    Per-pin and disc-profile errors are not parameters: :func:`errors_from_reducer` turns them
    into the discs' rotation excitation.

    Parameters
    ----------
    reducer : RVReducer
        The reducer description (geometry [mm], stiffnesses [N/mm], material [MPa]).

    Returns
    -------
    RVDynamicsParameters
        The parameters of the lumped model.

    Raises
    ------
    ParameterError
        When the crank circle radius differs from the first-stage centre distance (the dynamic
        model derives it from the gears).
    """
    fs, cr, di, pins = reducer.first_stage, reducer.cranks, reducer.discs, reducer.pins
    a_h = fs.module * (fs.sun_teeth + fs.planet_teeth) / 2.0
    if abs(cr.circle_radius - a_h) > 1e-6 * a_h:
        raise ParameterError(
            "cranks.circle_radius",
            cr.circle_radius,
            f"must equal the first-stage centre distance m (z_1 + z_2)/2 = {a_h:g} mm",
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
        contact_law=di.contact_law,  # the reducer's one pin-contact law
    )
    eps = involute_contact_ratio(fs.sun_teeth, fs.planet_teeth, fs.module, fs.pressure_angle)
    kw = dict(
        sun_teeth=fs.sun_teeth,
        planet_teeth=fs.planet_teeth,
        module_mm=fs.module,
        pressure_angle_deg=rad_to_deg(float(fs.pressure_angle)),
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
    missing = [
        f.name
        for f in dataclasses.fields(RVDynamicsParameters)
        if f.default is dataclasses.MISSING and f.name not in kw
    ]
    if missing:
        raise ParameterError(
            "dynamic",
            missing,
            "the dynamics need these beyond the reducer description (masses [kg], inertias "
            "[kg·m²], torsional/bending stiffnesses, damping ratio, operating point)",
        )
    return RVDynamicsParameters(**kw)


#: What :func:`parameters_from_reducer` needs beyond the reducer description.
DYNAMIC_ONLY = (
    "sun_mass_kg",
    "planet_mass_kg",
    "crank_mass_kg",
    "disc_mass_kg",
    "output_mass_kg",
    "sun_inertia_kgm2",
    "planet_inertia_kgm2",
    "crank_inertia_kgm2",
    "disc_inertia_kgm2",
    "output_inertia_kgm2",
    "input_torsional_stiffness_Nm_per_rad",
    "crank_torsional_stiffness_Nm_per_rad",
    "crank_bending_stiffness_N_per_m",
    "damping_ratio",
    "input_speed_rpm",
    "output_torque_Nm",
)


def _check_output_torque(reducer, output_torque_Nm: float) -> None:  # noqa: N803
    """A :class:`ParameterError` naming ``output_torque_Nm`` [N·m] unless it is finite, > 0 and
    within what the pins carry (the case files' pin-pressure ceiling, ideal share over the
    discs: :func:`gearte.models.rv_load_sharing.implausible_reducer_torque`)."""
    from gearte.models.rv_load_sharing import implausible_reducer_torque
    from gearte.units import Nm_to_Nmm

    if not (np.isfinite(output_torque_Nm) and output_torque_Nm > 0):
        raise ParameterError("output_torque_Nm", output_torque_Nm, "must be finite and > 0 [N·m]")
    reason = implausible_reducer_torque(reducer, float(Nm_to_Nmm(output_torque_Nm)))
    if reason is not None:
        raise ParameterError("output_torque_Nm", output_torque_Nm, reason)


def errors_from_reducer(
    reducer,
    *,
    output_torque_Nm: float | None = None,  # noqa: N803
    samples_per_mesh: int = 4,
    **paper004,
) -> RVErrors:
    """RVErrors from the description's measured errors and clearances.

    The description's error vectors (x, y) in the part frames use the same frames as this model
    (planet: from disc 1's eccentric direction; disc bore and carrier bore: from the radial
    direction; cam: from its eccentric direction), so they map 1:1 to (amplitude, phase). Its
    disc-bore array is indexed (disc, crank) and is transposed. The errors that act on single pin
    contacts (per-pin radius and position, disc radial run-out and cumulative pitch, per-disc
    modification errors) become each disc's rotation excitation ``disc_rotation``
    (:func:`gearte.models.rv_dynamics.excitation.disc_rotation_error`, at the per-disc share of
    ``output_torque_Nm`` [N·m], ``samples_per_mesh`` output angles per mesh period).
    ``paper004`` adds the errors the description does not hold (sun_eccentricity, sun_assembly,
    output_assembly, pin_composite, output_bearing_clearance_mm).

    Parameters
    ----------
    reducer : RVReducer
        The reducer description with its measured errors and clearances.
    output_torque_Nm : float, optional
        Output torque [N·m] at which the pin-error excitation is computed.
    samples_per_mesh : int
        Output angles per mesh period of the excitation table [-].

    Returns
    -------
    RVErrors
        The errors of the dynamic model (amplitudes [mm], phases [rad], disc rotations [rad]).

    Raises
    ------
    ParameterError
        Naming ``output_torque_Nm`` when the reducer has pin or disc-profile errors and no torque
        is given (their effect on the loaded contact depends on the load), or a torque that is
        not finite and > 0 or more than the pins carry (the case files' pin-pressure ceiling).
    """
    from gearte.models.rv_dynamics.excitation import disc_rotation_error, has_pin_errors
    from gearte.units import Nm_to_Nmm

    e = reducer.error_set
    m, n = reducer.cranks.count, reducer.discs.count

    def polar(v):
        v = np.asarray(v, dtype=float)
        return np.stack([np.hypot(v[..., 0], v[..., 1]), np.arctan2(v[..., 1], v[..., 0])], -1)

    if has_pin_errors(reducer) and "disc_rotation" not in paper004:
        if output_torque_Nm is None:
            raise ParameterError(
                "output_torque_Nm",
                None,
                "needed to turn the pin and disc-profile errors into the discs' loaded "
                "rotation excitation",
            )
        _check_output_torque(reducer, output_torque_Nm)
        paper004["disc_rotation"] = disc_rotation_error(
            reducer, Nm_to_Nmm(output_torque_Nm) / n, samples_per_mesh
        )
    return RVErrors(
        crank_count=m,
        disc_count=n,
        planet_eccentricity=np.array(
            [(p.amplitude, p.phase) for p in e.first_stage.planets], dtype=float
        ).reshape(m, 2),
        carrier_hole=polar(e.carrier_bore),
        disc_hole=polar(np.swapaxes(e.disc_bore, 0, 1)),
        cam=polar(e.cam),
        turning_arm_clearance_mm=reducer.cranks.cam_bearing_clearance,
        crank_bearing_clearance_mm=reducer.cranks.carrier_bearing_clearance,
        cam_clearances_mm=None if e.cam_clearance is None else np.asarray(e.cam_clearance),
        carrier_clearances_mm=None
        if e.carrier_clearance is None
        else np.asarray(e.carrier_clearance),
        **paper004,
    )
