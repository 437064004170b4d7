"""The data of a 2K-H planetary's coupled transmission error: its equivalent mesh-error terms
(:class:`ErrorTerm`, :class:`TermSet`) and the coupled TE of one assembly (:class:`CoupledTE`).

Plain records (numpy and the standard library, no numba): a study's result holds them, and the
report process unpickles them without importing numba (docs/report.md). The models that make
them are in :mod:`gearte.models.planetary_errors`, which re-exports them.

References
----------
Wang C., Chen X., Li Y., Chen H. (2013). Coupling compensation of transmission error for planetary
gear. Trans. CSAM 44(8), 287-292. doi:10.6041/j.issn.1000-1298.2013.08.049 (Table 2, eqs 7-9).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from gearte.errors import ParameterError

__all__ = ["ErrorTerm", "TermSet", "CoupledTE"]


@dataclass(frozen=True)
class ErrorTerm:
    """One equivalent mesh error term ``e(t) = gain * M * sin(q w_in t + phase + k * theta)``.

    Attributes
    ----------
    name : str
        Label, e.g. ``"E_s/external"``.
    magnitude : str
        Key of the error magnitude M [mm] (``"E_s"``, ``"A_c"``, ``"E_p1"``...).
    gain : float
        Dimensionless factor on M (1 for a plain projection; 1/N in the planet-mean model).
    frequency : Fraction
        Angular frequency as a signed multiple q of the input speed [-].
    phase : float
        Constant phase phi0 [rad].
    angle : str or None
        Key of the error angle theta [rad] (``"beta_s"``, ``"gamma_c"``...), None for none.
    angle_coeff : int
        k, the multiple of theta in the phase (+1 or -1; 0 when ``angle`` is None).
    line : str
        ``"external"``, ``"internal"`` or ``"given"``.
    """

    name: str
    magnitude: str
    gain: float
    frequency: Fraction
    phase: float
    angle: str | None
    angle_coeff: int
    line: str = "given"


@dataclass(frozen=True)
class TermSet:
    """The terms of a set and the output scale that turns Σe [mm] into output rotation [rad]."""

    terms: tuple[ErrorTerm, ...]
    scale: float  # [rad/mm]
    reference_angle: str | None = None  # an angle held at 0: the assembly datum
    magnitudes: tuple[str, ...] = field(init=False)
    angles: tuple[str, ...] = field(init=False)
    _arrays: dict[str, np.ndarray] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _basis: tuple[Fraction, tuple[int, ...], np.ndarray] | None = field(
        default=None, init=False, repr=False, compare=False
    )  # frequency_basis's answer, kept (its fraction arithmetic is slow)

    def __post_init__(self) -> None:
        if not self.terms:
            raise ParameterError("terms", [], "at least one term is needed")
        mags: list[str] = []
        angs: list[str] = []
        for t in self.terms:
            if (t.angle is None and t.angle_coeff != 0) or (
                t.angle is not None and t.angle_coeff not in (-1, 1)
            ):
                raise ParameterError(
                    f"terms.{t.name}.angle_coeff", t.angle_coeff, "must be ±1 (0 without angle)"
                )
            if t.magnitude not in mags:
                mags.append(t.magnitude)
            if t.angle is not None and t.angle not in angs:
                angs.append(t.angle)
        object.__setattr__(self, "magnitudes", tuple(mags))
        object.__setattr__(self, "angles", tuple(angs))
        if self.reference_angle is not None and self.reference_angle not in angs:
            raise ParameterError(
                "reference_angle", self.reference_angle, f"must be one of the angles {angs}"
            )

    @property
    def free_angles(self) -> tuple[str, ...]:
        """Angles the assembler can choose (all but the reference)."""
        return tuple(a for a in self.angles if a != self.reference_angle)


@dataclass(frozen=True)
class CoupledTE:
    """Coupled transmission error of one assembly.

    Attributes
    ----------
    constant : float
        Zero-frequency part of Σe [mm].
    harmonics : tuple of int
        Harmonic numbers n_g of the groups (u = q0 w_in t).
    frequencies : tuple of Fraction
        Group frequencies as multiples of the input speed.
    phasors : ndarray of complex
        Group phasors Z_g [mm] (amplitude |Z_g|, initial phase arg Z_g).
    fmax, fmin : float
        Exact max and min of Σe over the common period [mm].
    scale : float
        Output rotation per mm [rad/mm].
    q0 : Fraction
        Fundamental frequency (common period = 1/q0 input revolutions).
    """

    constant: float
    harmonics: tuple[int, ...]
    frequencies: tuple[Fraction, ...]
    phasors: np.ndarray
    fmax: float
    fmin: float
    scale: float
    q0: Fraction

    @property
    def amplitude(self) -> float:
        """max over the common period of |Σe(t)| times |scale| [rad]."""
        return max(self.fmax, -self.fmin) * abs(self.scale)

    @property
    def peak_to_peak(self) -> float:
        """(max - min) of Σe(t) over the common period times |scale| [rad]."""
        return (self.fmax - self.fmin) * abs(self.scale)

    @property
    def amplitude_sum(self) -> float:
        """Wang 2013 §1(3) approximation (lambda_i = 1 across frequencies):
        ``|c| + Σ_g |Z_g|`` times |scale| [rad]; an upper bound of :attr:`amplitude`."""
        return (abs(self.constant) + float(np.abs(self.phasors).sum())) * abs(self.scale)

    def signal(self, u: np.ndarray) -> np.ndarray:
        """Σe(u) [mm] at the phase u = q0 w_in t [rad] of the common period."""
        u = np.asarray(u, dtype=float)
        nh = np.asarray(self.harmonics)
        return self.constant + (self.phasors * np.exp(1j * nh * u[..., None])).imag.sum(-1)
