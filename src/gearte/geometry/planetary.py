"""2K-H planetary gear set: geometry, assembly conditions and Willis kinematics.

A 2K-H set has a sun ``s`` (external), ``N`` identical planets ``p`` (external) on a carrier ``c``
and a ring ``r`` (internal). One of sun, ring, carrier is fixed, one is the input, the third the
output. Units: mm, rad, rad/s (angles of planets in rad, measured counter-clockwise from the
first planet, which sits on the x axis at t = 0).

References
----------
Wang C., Chen X., Li Y., Chen H. (2013). Coupling compensation of transmission error for planetary
gear. Trans. CSAM 44(8), 287-292. doi:10.6041/j.issn.1000-1298.2013.08.049 (Table 1).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Literal

import numpy as np

from gearte.errors import ParameterError

__all__ = [
    "MEMBERS",
    "EccentricityError",
    "PlanetarySet",
    "SunPlanetErrors",
    "SunPlanets",
    "willis_speeds",
]

Member = Literal["sun", "ring", "carrier"]
MEMBERS: tuple[str, ...] = ("sun", "ring", "carrier")


def willis_speeds(
    z_sun: int, z_ring: int, fixed: str, input_member: str, input_speed: float = 1.0
) -> dict[str, float]:
    """Absolute angular speeds of sun, ring, carrier and planet from the Willis equation.

    Parameters
    ----------
    z_sun, z_ring : int
        Tooth numbers of sun and ring [-].
    fixed, input_member : {"sun", "ring", "carrier"}
        The fixed member (speed 0) and the driven-from-outside member.
    input_speed : float
        Angular speed of the input member [rad/s].

    Returns
    -------
    dict
        ``{"sun", "ring", "carrier"}`` absolute speeds [rad/s] (planet speeds need ``z_planet``:
        see :meth:`PlanetarySet.speeds`).

    Notes
    -----
    Willis: ``(w_s - w_c) / (w_r - w_c) = -z_r / z_s``, i.e.
    ``z_s w_s + z_r w_r = (z_s + z_r) w_c``.
    With the ring fixed and the sun as input, ``w_c = w_s z_s / (z_s + z_r)`` (1/8 for 12/84).
    """
    for name, m in (("fixed", fixed), ("input", input_member)):
        if m not in MEMBERS:
            raise ParameterError(name, m, f"must be one of {MEMBERS}")
    if fixed == input_member:
        raise ParameterError("input", input_member, "input and fixed member must differ")
    zs, zr = Fraction(z_sun), Fraction(z_ring)
    # speeds as exact fractions of the input speed
    w: dict[str, Fraction] = {fixed: Fraction(0), input_member: Fraction(1)}
    (other,) = [m for m in MEMBERS if m not in (fixed, input_member)]
    # z_s w_s + z_r w_r - (z_s + z_r) w_c = 0, solve for the unknown member
    coef = {"sun": zs, "ring": zr, "carrier": -(zs + zr)}
    w[other] = -(coef[fixed] * w[fixed] + coef[input_member] * w[input_member]) / coef[other]
    return {k: float(v) * input_speed for k, v in w.items()}


@dataclass(frozen=True)
class SunPlanets:
    """Sun and ``N`` identical planets of an involute planetary stage; a ring is optional.

    The gear set of the ``planetary`` kind (:class:`PlanetarySet`, with its ring) and of the
    first stage of an RV reducer (:class:`gearte.geometry.rv.FirstStage`, no ring: the planets
    sit on the cranks) — one class, one validation.

    Parameters
    ----------
    z_sun, z_planet : int
        Tooth numbers [-].
    module : float
        Normal module m [mm].
    pressure_angle : float
        Pressure angle of the sun–planet mesh alpha [rad].
    n_planets : int
        Number of planets N [-].
    planet_angles : tuple of float, optional
        Position angles eta_i of the planets on the carrier [rad], the first 0; default equal
        spacing 2 pi i / N.
    z_ring : int, optional
        Ring tooth number [-]; None for a stage without ring (RV first stage).
    standard : bool
        With a ring: standard (unshifted) gears, ``z_r = z_s + 2 z_p`` must hold.

    Raises
    ------
    ParameterError
        Teeth < 3, module or pressure angle out of range, wrong number of planet angles,
        ``z_r != z_s + 2 z_p`` for standard gears or ``z_r <= z_s + z_p``, planets that cannot be
        assembled with the ring (``(z_s + z_r) eta_i / 2 pi`` not an integer), neighbouring
        planets whose tip circles overlap.

    References
    ----------
    Wang C. et al. (2013), Trans. CSAM 44(8), 287-292, Table 1.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """

    z_sun: int
    z_planet: int
    module: float
    pressure_angle: float
    n_planets: int = 3
    planet_angles: tuple[float, ...] | None = None
    z_ring: int | None = None
    standard: bool = True
    _eta: tuple[float, ...] = field(init=False, repr=False, compare=False, default=())

    def __post_init__(self) -> None:
        for name in ("z_sun", "z_planet") + (("z_ring",) if self.z_ring is not None else ()):
            z = getattr(self, name)
            if int(z) != z or z < 3:
                raise ParameterError(name, z, "must be an integer >= 3")
        if not (np.isfinite(self.module) and self.module > 0):
            raise ParameterError("module", self.module, "must be > 0 [mm]")
        if not (0.0 < self.pressure_angle < np.pi / 4):
            raise ParameterError(
                "pressure_angle", self.pressure_angle, "must be in (0, pi/4) [rad]"
            )
        if int(self.n_planets) != self.n_planets or self.n_planets < 1:
            raise ParameterError("n_planets", self.n_planets, "must be an integer >= 1")
        if self.z_ring is not None:
            if self.standard and self.z_ring != self.z_sun + 2 * self.z_planet:
                raise ParameterError(
                    "z_ring",
                    self.z_ring,
                    f"standard gears need z_r = z_s + 2 z_p = {self.z_sun + 2 * self.z_planet}",
                )
            if self.z_ring <= self.z_sun + self.z_planet:
                raise ParameterError("z_ring", self.z_ring, "must exceed z_s + z_p")
        n = int(self.n_planets)
        if self.planet_angles is None:
            eta = tuple(2.0 * np.pi * i / n for i in range(n))
        else:
            eta = tuple(float(x) for x in self.planet_angles)
            if len(eta) != n:
                raise ParameterError(
                    "planet_angles", self.planet_angles, f"needs n_planets = {n} angles"
                )
            if eta[0] != 0.0:
                raise ParameterError("planet_angles", self.planet_angles, "first angle must be 0")
        if self.z_ring is not None:
            zsum = self.z_sun + self.z_ring
            for i, e in enumerate(eta):
                k = zsum * e / (2.0 * np.pi)
                if abs(k - round(k)) > 1e-6:
                    raise ParameterError(
                        f"planet_angles[{i}]" if self.planet_angles is not None else "n_planets",
                        e if self.planet_angles is not None else n,
                        f"planet cannot be assembled: (z_s + z_r) * eta / 2pi = {k:.4g} is not "
                        f"an integer (z_s + z_r = {zsum})",
                    )
        # neighbouring planets must not overlap (tip circle m (z_p + 2) for standard addendum)
        if n > 1:
            srt = np.sort(np.mod(np.asarray(eta), 2 * np.pi))
            gaps = np.diff(np.concatenate([srt, [srt[0] + 2 * np.pi]]))
            chord = 2.0 * self.centre_distance * np.sin(gaps.min() / 2.0)
            tip = self.module * (self.z_planet + 2)
            if chord <= tip:
                raise ParameterError(
                    "n_planets",
                    n,
                    f"neighbouring planets overlap: centre chord {chord:.4g} mm <= planet tip "
                    f"diameter {tip:.4g} mm",
                )
        object.__setattr__(self, "_eta", eta)

    @property
    def eta(self) -> np.ndarray:
        """Planet position angles eta_i [rad]."""
        return np.asarray(self._eta)

    def base_radius(self, member: str) -> float:
        """Base-circle radius r_b = m z cos(alpha) / 2 of ``sun``, ``planet`` or ``ring`` [mm]."""
        z = {"sun": self.z_sun, "planet": self.z_planet, "ring": self.z_ring}[member]
        if z is None:
            raise ParameterError("member", member, "this gear set has no ring")
        return 0.5 * self.module * z * np.cos(self.pressure_angle)

    @property
    def centre_distance(self) -> float:
        """Sun–planet centre distance a = m (z_s + z_p) / 2 [mm]."""
        return 0.5 * self.module * (self.z_sun + self.z_planet)


@dataclass(frozen=True)
class EccentricityError:
    """One eccentricity (position) error: a vector of length ``amplitude`` at angle ``phase``.

    The one eccentricity value of the ``planetary`` kind (Wang 2013's ``E, beta`` and
    ``A, gamma``) and of the RV first stage (``[[reducer.errors]]`` ``value_um, angle_deg``).
    Turning with its part, the offset at part angle ``theta`` is
    ``amplitude (cos(theta + phase), sin(theta + phase))``.

    Parameters
    ----------
    amplitude : float
        Magnitude E [mm], finite and >= 0.
    phase : float
        Angle of the error in the part's frame [rad], finite.
    name : str
        Key named in the error message (not compared).

    Raises
    ------
    ParameterError
        Naming ``name``: negative or non-finite amplitude, non-finite phase.

    References
    ----------
    Wang C. et al. (2013), Trans. CSAM 44(8), 287-292, Table 1.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """

    amplitude: float = 0.0
    phase: float = 0.0
    name: str = field(default="eccentricity", compare=False, repr=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.amplitude) and self.amplitude >= 0.0):
            raise ParameterError(
                self.name, self.amplitude, "amplitude must be finite and >= 0 [mm]"
            )
        if not np.isfinite(self.phase):
            raise ParameterError(self.name, self.phase, "phase must be finite [rad]")
        object.__setattr__(self, "amplitude", float(self.amplitude))
        object.__setattr__(self, "phase", float(self.phase))

    @classmethod
    def from_vector(cls, vector: np.ndarray, name: str = "eccentricity") -> EccentricityError:
        """The error of a vector ``(x, y)`` [mm] (amplitude = its length, phase = its angle)."""
        v = np.asarray(vector, dtype=float)
        return cls(float(np.hypot(v[0], v[1])), float(np.arctan2(v[1], v[0])), name)

    @property
    def vector(self) -> np.ndarray:
        """``amplitude (cos phase, sin phase)`` [mm], shape ``(2,)``."""
        return self.amplitude * np.array([np.cos(self.phase), np.sin(self.phase)])

    def offset(self, angle: np.ndarray | float) -> np.ndarray:
        """Offset [mm], shape ``(..., 2)``, when its part has turned by ``angle`` [rad]."""
        a = np.asarray(angle, dtype=float) + self.phase
        return self.amplitude * np.stack([np.cos(a), np.sin(a)], axis=-1)


@dataclass(frozen=True)
class SunPlanetErrors:
    """The eccentricity errors of a sun and its planets, shared by the ``planetary`` kind and
    the RV first stage (:attr:`gearte.geometry.rv.ManufacturingErrors.first_stage`).

    Parameters
    ----------
    planets : tuple of EccentricityError
        Manufacturing eccentricity of each planet (Wang ``E_p<i>, beta_p<i>``; RV
        ``planet_eccentricity``) [mm, rad], turning with the planet, in the planet frame.
    sun : EccentricityError
        Manufacturing eccentricity of the sun (Wang ``E_s, beta_s``) [mm, rad], turning with it.
    sun_assembly : EccentricityError
        Assembly error of the sun (Wang ``A_s, gamma_s``; Li ``E_sa``) [mm, rad], fixed in
        the housing.

    Raises
    ------
    ParameterError
        An entry that is not an :class:`EccentricityError`; :meth:`check_planets` names the
        planet count that does not match.

    References
    ----------
    Wang C. et al. (2013), Trans. CSAM 44(8), 287-292, Table 1.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """

    planets: tuple[EccentricityError, ...]
    sun: EccentricityError = EccentricityError(name="sun_eccentricity")
    sun_assembly: EccentricityError = EccentricityError(name="sun_assembly")

    def __post_init__(self) -> None:
        object.__setattr__(self, "planets", tuple(self.planets))
        for name, v in (("sun_eccentricity", self.sun), ("sun_assembly", self.sun_assembly)):
            if not isinstance(v, EccentricityError):
                raise ParameterError(name, v, "must be an EccentricityError")
        for i, v in enumerate(self.planets):
            if not isinstance(v, EccentricityError):
                raise ParameterError(
                    f"planet_eccentricity[{i + 1}]", v, "must be an EccentricityError"
                )

    @classmethod
    def none(cls, n_planets: int) -> SunPlanetErrors:
        """No errors on a sun and ``n_planets`` planets."""
        return cls(
            tuple(EccentricityError(name=f"planet_eccentricity[{i + 1}]") for i in range(n_planets))
        )

    @classmethod
    def from_vectors(
        cls, sun: np.ndarray, sun_assembly: np.ndarray, planets: np.ndarray
    ) -> SunPlanetErrors:
        """From error vectors [mm]: sun ``(2,)``, sun assembly ``(2,)``, planets ``(N, 2)``."""
        pl = np.asarray(planets, dtype=float).reshape(-1, 2)
        return cls(
            tuple(
                EccentricityError.from_vector(v, f"planet_eccentricity[{i + 1}]")
                for i, v in enumerate(pl)
            ),
            EccentricityError.from_vector(sun, "sun_eccentricity"),
            EccentricityError.from_vector(sun_assembly, "sun_assembly"),
        )

    def check_planets(self, n_planets: int, field_name: str = "planet_eccentricity") -> None:
        """Raise :class:`ParameterError` naming ``field_name`` unless there are ``n_planets``."""
        if len(self.planets) != n_planets:
            raise ParameterError(
                field_name,
                len(self.planets),
                f"needs one eccentricity per planet: {n_planets} planets",
            )

    def vectors(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Error vectors [mm]: sun ``(2,)``, sun assembly ``(2,)``, planets ``(N, 2)``."""
        pl = np.array([p.vector for p in self.planets]).reshape(-1, 2)
        return self.sun.vector, self.sun_assembly.vector, pl

    def sun_offset(self, sun_angle: np.ndarray | float) -> np.ndarray:
        """Displacement of the sun's tooth centre [mm], ``(..., 2)``, at sun angle [rad]:
        its eccentricity turned by ``sun_angle`` plus the fixed assembly error."""
        return self.sun.offset(sun_angle) + self.sun_assembly.vector

    def planet_offsets(self, planet_angle: np.ndarray | float) -> np.ndarray:
        """Displacement of each planet's tooth centre from its pin [mm], ``(..., N, 2)``, in the
        planet frame after the planet turned by ``planet_angle`` [rad] relative to it."""
        return np.stack([p.offset(planet_angle) for p in self.planets], axis=-2)


@dataclass(frozen=True)
class PlanetarySet:
    """A 2K-H planetary gear set with involute gears.

    Parameters
    ----------
    z_sun, z_planet, z_ring : int
        Tooth numbers [-] (Wang 2013 Table 1: 12, 36, 84).
    module : float
        Normal module m [mm].
    pressure_angle : float
        Working pressure angle of both meshes alpha [rad] (standard gears: alpha_w = alpha = 20°).
    n_planets : int
        Number of planets N [-].
    planet_angles : tuple of float, optional
        Position angles eta_i of the planets [rad], the first 0; default equal spacing 2 pi i / N.
    fixed, input, output : {"sun", "ring", "carrier"}
        Which member is held, driven and taken off (Wang 2013: ring, sun, carrier).
    standard : bool
        Standard (unshifted) gears: then ``z_r = z_s + 2 z_p`` must hold (concentricity).

    Raises
    ------
    ParameterError
        Teeth < 3, module or pressure angle out of range, ``z_r != z_s + 2 z_p`` for standard
        gears, planets that cannot be assembled (``(z_s + z_r) eta_i / 2 pi`` not an integer),
        neighbouring planets whose tip circles overlap (the checks of :class:`SunPlanets`, which
        holds the sun, planets and ring as ``gears``), or members not a permutation.
    """

    z_sun: int
    z_planet: int
    z_ring: int
    module: float
    pressure_angle: float
    n_planets: int = 3
    planet_angles: tuple[float, ...] | None = None
    fixed: str = "ring"
    input: str = "sun"
    output: str = "carrier"
    standard: bool = True
    _eta: tuple[float, ...] = field(init=False, repr=False, compare=False, default=())
    gears: SunPlanets = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        gears = SunPlanets(  # the sun, planets and ring: validated there (one set of rules)
            self.z_sun,
            self.z_planet,
            self.module,
            self.pressure_angle,
            self.n_planets,
            self.planet_angles,
            z_ring=self.z_ring,
            standard=self.standard,
        )
        if sorted((self.fixed, self.input, self.output)) != sorted(MEMBERS):
            raise ParameterError(
                "fixed/input/output",
                (self.fixed, self.input, self.output),
                f"must be a permutation of {MEMBERS}",
            )
        object.__setattr__(self, "gears", gears)
        object.__setattr__(self, "_eta", gears._eta)

    # ------------------------------------------------------------------ geometry
    @property
    def eta(self) -> np.ndarray:
        """Planet position angles eta_i [rad]."""
        return np.asarray(self._eta)

    def base_radius(self, member: str) -> float:
        """Base-circle radius r_b = m z cos(alpha) / 2 of ``sun``, ``planet`` or ``ring`` [mm]."""
        return self.gears.base_radius(member)

    @property
    def centre_distance(self) -> float:
        """Sun–planet centre distance a = m (z_s + z_p) / 2 [mm]."""
        return self.gears.centre_distance

    # ---------------------------------------------------------------- kinematics
    def speed_ratios(self) -> dict[str, Fraction]:
        """Exact speeds as fractions of the input speed: sun, ring, carrier, planet (absolute)
        and ``planet_rel`` (planet relative to the carrier), by the Willis equation."""
        zs, zp, zr = Fraction(self.z_sun), Fraction(self.z_planet), Fraction(self.z_ring)
        w: dict[str, Fraction] = {self.fixed: Fraction(0), self.input: Fraction(1)}
        coef = {"sun": zs, "ring": zr, "carrier": -(zs + zr)}
        o = self.output
        w[o] = -(coef[self.fixed] * w[self.fixed] + coef[self.input] * w[self.input]) / coef[o]
        # planet relative to carrier: sun-planet external mesh (w_p - w_c) = -(z_s/z_p)(w_s - w_c)
        w["planet_rel"] = -(zs / zp) * (w["sun"] - w["carrier"])
        w["planet"] = w["planet_rel"] + w["carrier"]
        return w

    def speeds(self, input_speed: float = 1.0) -> dict[str, float]:
        """Absolute speeds [rad/s] (and ``planet_rel``) for an input speed [rad/s]."""
        return {k: float(v) * input_speed for k, v in self.speed_ratios().items()}

    @property
    def ratio(self) -> float:
        """Transmission ratio i = w_input / w_output [-] (8 for Wang 2013)."""
        r = self.speed_ratios()
        return float(Fraction(1) / r[self.output])

    def output_scale(self) -> float:
        """Output rotation error per unit of (e_w + e_n) [rad/mm].

        From the linearised contact conditions along the two lines of action,
        ``r_bs dθ_s + r_br dθ_r + e_w + e_n = (r_bs + r_br) dθ_c``; the input and the fixed member
        have dθ = 0, so the output error is ``(e_w + e_n)`` times ``1/(r_bs + r_br)`` (carrier),
        ``-1/r_br`` (ring) or ``-1/r_bs`` (sun). For the carrier output this is Wang 2013's
        ``1/(r_bs i_sc)`` (eq. 9).
        """
        rbs, rbr = self.base_radius("sun"), self.base_radius("ring")
        return {"carrier": 1.0 / (rbs + rbr), "ring": -1.0 / rbr, "sun": -1.0 / rbs}[self.output]
