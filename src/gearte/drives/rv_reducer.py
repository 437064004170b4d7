"""The RV reducer as a drive: its lost motion and stiffness from the catalogue virtual test.

The whole-reducer load-sharing model (:mod:`gearte.models.rv_load_sharing`, Han et al. 2023 with
the Hu 2020 pin contact) is loaded on the output with the input locked, as the manufacturers'
test bench does (:func:`gearte.models.rv_catalogue.catalogue_values`):

* lost motion = θ(+T) − θ(−T) at T = 3 % rated torque (the catalogue definition), or at the
  torque asked for;
* torsional stiffness = the catalogue rigidity ``(T_r/2)/(θ(T_r) − θ(T_r/2))``, both directions;
* transmission error: the model's output angle error over output angles (unloaded: solved at
  ``zero_load_fraction`` × rated torque; loaded at a given torque).

An RV reducer described with its measured errors has no tolerance stack: its lost-motion spread
is ``None`` (the production yield samples the errors through this model instead).

References
----------
Han L., Xu W., Wang Y., Zhang Y. (2023) Impact of manufacturing errors on tooth surface forces in
RV reducer cycloid pinwheels. Journal of Engineering Research and Reports 25(8).
doi:10.9734/JERR/2023/v25i8970
Hu Y., Li G., Zhu W., Cui J. (2020) Applied Sciences 10(2), 481. doi:10.3390/app10020481
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from gearte.drives import LostMotionSpread
from gearte.errors import ParameterError
from gearte.geometry.rv import RVReducer

__all__ = ["RVDrive"]


@dataclass
class RVDrive:
    """An RV reducer answering the :class:`~gearte.drives.Drive` questions.

    Parameters
    ----------
    reducer : RVReducer
        The reducer (gearte.geometry.rv), with its errors.
    name : str
        Label.
    position : float
        Output angle of the virtual torsion test [rad].
    turning_points : tuple of float
        Torque sweep of the test, fractions of rated torque [-].
    steps_per_segment : int
        Steps between turning points [-].
    lost_motion_fraction : float
        Torque of the catalogue lost motion, fraction of rated torque [-] (catalogue: 0.03).
    zero_load_fraction : float
        The unloaded TE is solved at this fraction of rated torque [-].
    law : ContactLaw, optional
        Pin-contact law; default: the load-sharing model's own.
    first_stage_free_angle : float
        Output free angle of the first stage's backlash [rad], added as a dead zone of the
        catalogue test (:mod:`gearte.models.rv_first_stage`; 0: none).
    """

    reducer: RVReducer
    name: str = "RV reducer"
    position: float = 0.0
    turning_points: tuple[float, ...] = (0.0, 1.0, 0.0, -1.0, 0.0, 1.0)
    steps_per_segment: int = 20
    lost_motion_fraction: float = 0.03
    zero_load_fraction: float = 1e-3
    law: Any = None
    first_stage_free_angle: float = 0.0
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    kind = "rv_reducer"

    @property
    def ratio(self) -> float:
        return float(self.reducer.ratio)

    def catalogue(self, lost_motion_fraction: float | None = None):
        """The catalogue virtual test (:func:`~gearte.models.rv_catalogue.catalogue_values`)."""
        from gearte.models.rv_catalogue import catalogue_values

        frac = self.lost_motion_fraction if lost_motion_fraction is None else lost_motion_fraction
        if frac not in self._cache:
            self._cache[frac] = catalogue_values(
                self.reducer,
                theta=self.position,
                turning_points=self.turning_points,
                steps_per_segment=self.steps_per_segment,
                lost_motion_fraction=frac,
                law=self.law,
            )
            if self.first_stage_free_angle > 0.0:
                from gearte.models.rv_first_stage import catalogue_with_free_angle

                self._cache[frac] = catalogue_with_free_angle(
                    self._cache[frac], self.first_stage_free_angle, self._rated(), frac
                )
        return self._cache[frac]

    def lost_motion(self, torque: float | None = None) -> float:
        """θ(+T) − θ(−T) [rad] at the output, input locked (catalogue: T = 3 % rated).

        Parameters
        ----------
        torque : float, optional
            Test torque [N·mm], ``0 < |T| < 0.5`` rated torque; default: the catalogue's.
        """
        if torque is None:
            return self.catalogue().lost_motion
        frac = abs(float(torque)) / self._rated()
        if not 0.0 < frac < 0.5:
            raise ParameterError(
                "torque", torque, "lost-motion torque must be within (0, 0.5) x rated torque"
            )
        return self.catalogue(frac).lost_motion

    def _rated(self) -> float:
        """Rated torque [N·mm]; a case may leave it out, the catalogue definitions need it."""
        if self.reducer.rated_torque is None:
            raise ParameterError(
                "reducer.rated_torque_Nm", None, "the RV drive's catalogue quantities need it"
            )
        return float(self.reducer.rated_torque)

    def torsional_stiffness(self) -> float:
        """Catalogue torsional rigidity [N·mm/rad] (between 50 % and 100 % rated torque)."""
        return self.catalogue().torsional_rigidity

    def transmission_error(
        self, output_angle: ArrayLike, torque: float | None = None
    ) -> np.ndarray:
        """Output angle error [rad] at output angles [rad]; unloaded unless ``torque`` [N·mm]."""
        from gearte.models.rv_load_sharing import transmission_error

        th = np.atleast_1d(np.asarray(output_angle, dtype=float))
        t_ref = self._rated() if torque is None else float(torque)
        te = transmission_error(
            self.reducer,
            t_ref,
            th,
            zero_load_fraction=self.zero_load_fraction,
            mesh_samples=0,
            law=self.law,
        )
        return te.geometric if torque is None else te.total

    def lost_motion_spread(self, confidence: float = 0.9973) -> LostMotionSpread | None:
        """``None``: a reducer with given (measured) errors has no tolerance stack."""
        return None
