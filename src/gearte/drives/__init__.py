"""Drives that compose: one small interface that every drive gearte models answers.

A *drive* is one reduction stage with an input and an output shaft: a spur pair, a bevel pair, a
2K-H planetary set, a cycloid–pin stage, a whole RV reducer — any registered drive family
(:mod:`gearte.families`). Whatever its inner model, it answers
the same few questions, so that a chain, a sweep or a Monte-Carlo study can use any drive without
knowing which one it is (docs/drives.md)::

    drive.name, drive.kind            what it is
    drive.ratio                       reduction i = ω_in / ω_out [-] (> 0)
    drive.lost_motion(torque=None)    θ(+T) − θ(−T) at its output [rad]
    drive.torsional_stiffness()       at its output, input locked [N·mm/rad]
    drive.transmission_error(theta)   output angle error over output angles [rad]
    drive.lost_motion_spread(conf)    mean, σ, min, max of its lost motion [rad] from its
                                      tolerance stack

A question the drive's own model does not answer returns ``None`` (never a guessed number): Jiang
2024's pairs have no transmission-error model, Wang 2013's planetary model has no backlash, an RV
reducer described with its measured errors has no tolerance stack. Each adapter calls that drive's
own model; nothing is re-implemented here.

Units: angles [rad], torques [N·mm], stiffness [N·mm/rad], all at the drive's *output* shaft.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["Drive", "LostMotionSpread"]


@dataclass(frozen=True)
class LostMotionSpread:
    """Distribution of a drive's lost motion over its tolerances [rad, at its output].

    Attributes
    ----------
    mean, sd : float
        Mean and standard deviation [rad].
    min, max : float
        The range at ``confidence`` (mean ∓ z·σ, clipped at 0 where the parts interfere) [rad].
    confidence : float
        Two-sided confidence of ``[min, max]`` [-].
    """

    mean: float
    sd: float
    min: float
    max: float
    confidence: float


@runtime_checkable
class Drive(Protocol):
    """What every drive answers (see the module docstring and docs/drives.md)."""

    @property
    def name(self) -> str:
        """Label of this drive (the chain stage name, the case name)."""
        ...

    @property
    def kind(self) -> str:
        """What it is (``"spur_pair"``, ``"rv_reducer"``, ...: its family's ``drive_kinds``,
        :mod:`gearte.families`)."""
        ...

    @property
    def ratio(self) -> float:
        """Reduction ratio i = ω_in / ω_out [-], > 0."""
        ...

    def lost_motion(self, torque: float | None = None) -> float | None:
        """Lost motion θ(+T) − θ(−T) at the output [rad].

        Parameters
        ----------
        torque : float, optional
            Output torque T [N·mm] of the test; ``None``: the drive's reference definition
            (rigid-flank models: the backlash; RV reducer: the catalogue's ±3 % rated torque).
        """
        ...

    def torsional_stiffness(self) -> float | None:
        """Torsional stiffness at the output with the input locked [N·mm/rad]."""
        ...

    def transmission_error(self, output_angle: ArrayLike) -> np.ndarray | None:
        """Output angle error (actual − nominal) at the output angles [rad] (array of them)."""
        ...

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread | None:
        """Mean, σ and range of the lost motion over the drive's tolerances [rad]."""
        ...
