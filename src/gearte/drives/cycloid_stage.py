"""A cycloid–pin stage as a drive: its lost motion from Hu et al. 2020's geometric TE model.

Hu 2020's "geometric transmission error" of a cycloid stage (eq 5–17) is the lost motion of the
stage referred to the disc (output) rotation: the modifications and the nine component errors open
or close the clearance between disc and pins. :func:`gearte.models.cycloid_te.geometric_te` gives
its mean (eq 16) and the RSS tolerance T (eq 17, the TE lies in mean ± T/2). Read as a ±3σ band,
σ = T/6 — the spread this adapter reports.

The stage alone turns the disc once per ``z_c`` eccentric turns with the pins fixed: the ratio is
``z_c = z_p − 1``. The geometric model is rigid (no stiffness) and has no angle-dependent TE, so
those answers are ``None``; the loaded stiffness of a cycloid stage inside a reducer is the RV
drive's.

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020) Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import LostMotionSpread
from gearte.geometry.cycloid import CycloidStage
from gearte.tolerance.stackup import z_for_confidence

__all__ = ["CycloidStageDrive"]


@dataclass(frozen=True)
class CycloidStageDrive:
    """A cycloid–pin stage answering the :class:`~gearte.drives.Drive` questions.

    Parameters
    ----------
    stage : CycloidStage
        The stage and its modifications (gearte.geometry.cycloid).
    means : mapping, optional
        Error factor → mean error [mm] (keys of ``gearte.models.cycloid_te.ERROR_FACTORS``).
    tolerances : mapping, optional
        Error factor → tolerance band width [mm].
    name : str
        Label.
    """

    stage: CycloidStage
    means: Mapping[str, float] | None = None
    tolerances: Mapping[str, float] | None = None
    name: str = "cycloid stage"
    _te: list = field(default_factory=list, init=False, repr=False, compare=False)

    kind = "cycloid_stage"

    @property
    def ratio(self) -> float:
        """``z_c`` eccentric turns per disc turn [-] (pins fixed)."""
        return float(self.stage.z_p - 1)

    def geometric_te(self):
        """Hu 2020's :class:`~gearte.models.cycloid_te.GeometricTE` of the stage (computed once)."""
        from gearte.models.cycloid_te import geometric_te

        if not self._te:
            self._te.append(geometric_te(self.stage, self.means, self.tolerances))
        return self._te[0]

    def lost_motion(self, torque: float | None = None) -> float:
        """Mean geometric TE Δθ̄ [rad] (eq 16); a negative one (preload) loses no motion: 0.

        The model is rigid: the torque does not change it.
        """
        return max(self.geometric_te().mean, 0.0)

    def torsional_stiffness(self) -> float | None:
        """Not in the geometric model: ``None``."""
        return None

    def transmission_error(self, output_angle: ArrayLike) -> np.ndarray | None:
        """Not in the geometric model (its TE is one number, the lost motion): ``None``."""
        return None

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread:
        """Mean Δθ̄ and σ = T/6 (eq 17's RSS tolerance read as ±3σ) [rad], range at confidence."""
        te = self.geometric_te()
        sd = te.tolerance / 6.0
        z = z_for_confidence(confidence)
        return LostMotionSpread(
            mean=te.mean,
            sd=sd,
            min=max(te.mean - z * sd, 0.0),
            max=max(te.mean + z * sd, 0.0),
            confidence=confidence,
        )
