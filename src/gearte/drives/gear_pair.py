"""Spur and bevel pairs as drives (Jiang et al. 2024 backlash stack, eqs. 2–14 and 29).

The pair's own model gives its normal backlash as a linear tolerance stack
(:meth:`~gearte.models.backlash.SpurPair.backlash_stack`); eq. (14)/(29) turns it into the return
error at the driven gear, ``Δφ = 2 jn / (d cos α)``. Torsional stiffness, when a face width is
known, is the ISO 6336-1 mean mesh stiffness ``c_γ b`` on the driven gear's base radius:
``K = c_γ b r_b2²`` (bevel: at the mean diameter ``dm``, ``r_b2 = dm cos α / 2``). Jiang 2024 has
no transmission-error model of a pair, so :meth:`GearPairDrive.transmission_error` is ``None``.

References
----------
Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024) Gear backlash modeling and tolerance simulation
of fully gear-coupled robot. J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
doi:10.3785/j.issn.1008-973X.2024.08.001
ISO 6336-1:2019, 9.3 (mesh stiffness c_γ ≈ 20 N/(mm·µm) for solid steel spur gears).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import LostMotionSpread
from gearte.errors import ParameterError
from gearte.models.backlash import BevelPair, SpurPair, summarise_backlash
from gearte.models.lost_motion import return_error
from gearte.models.rv_stiffness import iso6336_mesh_stiffness

__all__ = ["GearPairDrive"]


@dataclass(frozen=True)
class GearPairDrive:
    """A spur or bevel pair answering the :class:`~gearte.drives.Drive` questions.

    Parameters
    ----------
    pair : SpurPair or BevelPair
        The pair with its tolerances (gearte.models.backlash).
    name : str
        Label.
    face_width : float, optional
        Face width b [mm] of a spur pair for its mesh stiffness (a bevel pair uses its own
        ``face_width``); without it a spur pair's stiffness is not modelled (``None``).
    c_gamma : float
        Mesh stiffness per face width c_γ [N/(mm·µm)] (ISO 6336-1: 20 for solid steel gears).
    """

    pair: SpurPair | BevelPair
    name: str = "gear pair"
    face_width: float | None = None
    c_gamma: float = 20.0

    def __post_init__(self) -> None:
        if self.face_width is not None and not self.face_width > 0:
            raise ParameterError("face_width", self.face_width, "must be > 0 mm")
        if not self.c_gamma > 0:
            raise ParameterError("c_gamma", self.c_gamma, "must be > 0 N/(mm·µm)")

    @property
    def kind(self) -> str:
        return "bevel_pair" if isinstance(self.pair, BevelPair) else "spur_pair"

    @property
    def ratio(self) -> float:
        return self.pair.ratio

    def _return_error(self, jn: float) -> float:
        """Return error [rad] of a normal backlash [mm]; a negative one (interference) is 0."""
        return float(
            return_error(max(jn, 0.0), self.pair.output_diameter, self.pair.pressure_angle)
        )

    def lost_motion(self, torque: float | None = None) -> float | None:
        """Return error of the mean backlash [rad], eq. (14)/(29); plus ``2|T|/K`` at a torque.

        Parameters
        ----------
        torque : float, optional
            Output torque [N·mm]. ``None`` or 0: the backlash alone (Jiang's definition). A
            non-zero torque adds the elastic wind-up ``2|T|/K`` in both directions and needs the
            stiffness (a face width); without it the pair is rigid and the torque changes nothing.
        """
        lm = self._return_error(summarise_backlash(self.pair.backlash_stack()).mean)
        k = self.torsional_stiffness()
        if torque is not None and torque != 0.0 and k is not None:
            lm += 2.0 * abs(float(torque)) / k
        return lm

    def torsional_stiffness(self) -> float | None:
        """``c_γ b r_b2²`` [N·mm/rad] at the driven gear (ISO 6336-1 mean mesh stiffness)."""
        b = self.pair.face_width if isinstance(self.pair, BevelPair) else self.face_width
        if b is None:
            return None
        r_b = 0.5 * self.pair.output_diameter * math.cos(self.pair.pressure_angle)
        return float(iso6336_mesh_stiffness(b, self.c_gamma)) * r_b * r_b

    def transmission_error(self, output_angle: ArrayLike) -> np.ndarray | None:
        """Not modelled for a pair (Jiang 2024 gives backlash only): ``None``."""
        return None

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread:
        """The backlash stack's mean, σ and range at ``confidence`` as return error [rad]."""
        s = summarise_backlash(self.pair.backlash_stack(), confidence=confidence)
        d, a = self.pair.output_diameter, self.pair.pressure_angle
        return LostMotionSpread(
            mean=self._return_error(s.mean),
            sd=float(return_error(s.sd, d, a)),
            min=self._return_error(s.min),
            max=self._return_error(s.max),
            confidence=confidence,
        )
