"""A 2K-H planetary set as a drive: its transmission error from Wang et al. 2013's coupled model.

The eccentricity and assembly errors of sun, planets and ring become mesh errors along the lines of
action; their sum, scaled to the output, is the coupled output TE
(:func:`gearte.models.planetary_errors.coupled_te`), a trig polynomial in the input angle. This
adapter evaluates it at output angles θ: the input angle is ``i θ`` and the polynomial's phase
``u = q0 i θ`` (``q0``: fundamental frequency as a multiple of the input speed).

Wang 2013's model has no backlash and no stiffness: lost motion, stiffness and lost-motion spread
are ``None`` (a chain stage then gives its lost motion as a catalogue value).

References
----------
Wang C., Chen X., Li Y., Chen H. (2013) Coupling compensation of transmission error for planetary
gear. Transactions of the Chinese Society for Agricultural Machinery 44(8).
doi:10.6041/j.issn.1000-1298.2013.08.049
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import LostMotionSpread
from gearte.geometry.planetary import PlanetarySet
from gearte.models.planetary_errors import TermSet

__all__ = ["PlanetaryDrive"]


@dataclass(frozen=True)
class PlanetaryDrive:
    """A 2K-H planetary set answering the :class:`~gearte.drives.Drive` questions.

    Parameters
    ----------
    gearset : PlanetarySet
        Teeth, module, fixed/input/output members (gearte.geometry.planetary).
    terms : TermSet
        The error terms (derived or as printed; gearte.models.planetary_errors).
    magnitudes : mapping
        Error magnitude per key [mm].
    angles : mapping
        Error and assembly angle per key [rad].
    name : str
        Label.
    """

    gearset: PlanetarySet
    terms: TermSet
    magnitudes: Mapping[str, float]
    angles: Mapping[str, float]
    name: str = "planetary set"

    kind = "planetary"

    @property
    def ratio(self) -> float:
        return float(self.gearset.ratio)

    def lost_motion(self, torque: float | None = None) -> float | None:
        """Not in Wang 2013's model (no backlash): ``None``."""
        return None

    def torsional_stiffness(self) -> float | None:
        """Not in Wang 2013's model: ``None``."""
        return None

    def transmission_error(self, output_angle: ArrayLike) -> np.ndarray:
        """Coupled output TE [rad] at output angles θ [rad] (rigid model: no torque)."""
        from gearte.models.planetary_errors import coupled_te

        te = coupled_te(self.terms, self.magnitudes, self.angles)
        th = np.asarray(output_angle, dtype=float)
        return te.signal(float(te.q0) * self.ratio * th) * te.scale

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread | None:
        """Not in Wang 2013's model: ``None``."""
        return None
