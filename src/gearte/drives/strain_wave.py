"""A strain-wave (harmonic) gear as a drive: catalogue stiffness, hysteresis, lost motion and
transmission error (:mod:`gearte.models.strain_wave`).

* ``ratio``: i = z_f / (z_c − z_f) (CS fixed, WG input, FS output);
* ``lost_motion(torque)``: H + 2 φ(T), at the catalogue's test torque T_L when ``torque`` is
  ``None``;
* ``torsional_stiffness()``: K3, the catalogue's stiffness above T2 (the linear high-torque
  region, as the RV drive's catalogue rigidity is taken between T_r/2 and T_r);
* ``transmission_error(θ_out)``: eq. (te) at the WG angle ``θ_WG = −i θ_out``;
* ``lost_motion_spread``: the tolerances of H and of θ1 = T1/K1 (normal, 3σ) through the lost
  motion, linearised: ``σ² = σ_H² + (2 ∂φ(T_L)/∂θ1 σ_θ1)²`` with ``∂φ/∂θ1 = T_L/T1`` below T1
  and 1 above (exact: LM is linear in H and θ1). ``None`` without those tolerances.

References
----------
Harmonic Drive AG (2015) CHA manual 1018854, eq. 68.1–68.4; Harmonic Drive LLC, CSF & CSG
engineering data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import LostMotionSpread
from gearte.models.strain_wave import StrainWaveGear, lost_motion
from gearte.tolerance.stackup import z_for_confidence

__all__ = ["StrainWaveDrive"]


@dataclass(frozen=True)
class StrainWaveDrive:
    """A strain-wave gear answering the :class:`~gearte.drives.Drive` questions.

    Parameters
    ----------
    gear : StrainWaveGear
        The gear set with its catalogue data, errors and tolerances.
    name : str
        Label.
    """

    gear: StrainWaveGear
    name: str = "strain-wave gear"

    kind = "strain_wave"

    @property
    def ratio(self) -> float:
        """i = z_f / (z_c − z_f) [-]."""
        return self.gear.ratio

    def lost_motion(self, torque: float | None = None) -> float:
        """H + 2 φ(T) [rad]; ``None``: at the catalogue's test torque T_L [N·mm]."""
        g = self.gear
        if torque is None:
            return g.lost_motion()
        return float(lost_motion(g.hysteresis_loss, abs(torque), g.T1, g.T2, g.K1, g.K2, g.K3))

    def torsional_stiffness(self) -> float:
        """K3 [N·mm/rad] (the catalogue's stiffness above T2)."""
        return float(self.gear.K3)

    def transmission_error(self, output_angle: ArrayLike) -> np.ndarray:
        """Output angle error [rad] at output angles [rad] (WG at −i θ_out)."""
        th = np.asarray(output_angle, dtype=float)
        return self.gear.transmission_error(-self.gear.ratio * th)

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread | None:
        """Mean, σ and range [rad] of the lost motion over the tolerances of H and θ1."""
        g = self.gear
        t = g.tolerances
        if t.hysteresis_loss <= 0 and t.torsion_at_T1 <= 0:
            return None
        slope = g.lost_motion_torque / g.T1 if g.lost_motion_torque <= g.T1 else 1.0
        sd = math.hypot(t.hysteresis_loss / 3.0, 2.0 * slope * t.torsion_at_T1 / 3.0)
        mean = g.lost_motion()
        z = z_for_confidence(confidence)
        return LostMotionSpread(
            mean=mean,
            sd=sd,
            min=max(mean - z * sd, 0.0),
            max=max(mean + z * sd, 0.0),
            confidence=confidence,
        )
