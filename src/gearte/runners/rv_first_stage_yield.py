"""An RV yield model with the first stage's backlash added at the output.

Wraps :class:`gearte.runners.yield_models.RVReducerYield` (its solver untouched): the
first-stage error keys are taken out of each sample, the rest goes to the reducer model, and
the output free angle of the sun–planet meshes (:mod:`gearte.models.rv_first_stage`) is added
to the lost motion, backlash and hysteresis loss (``first_stage_backlash = "additive"``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from gearte.units import mm_to_um, rad_to_arcmin, um_to_mm

__all__ = ["FIRST_STAGE_QUANTITIES", "first_stage_error_keys", "FirstStageBacklashYield"]

#: The quantities that take the first stage's free angle (a dead zone of the torsion curve).
FIRST_STAGE_QUANTITIES = ("lost_motion [arcmin]", "backlash [arcmin]", "hysteresis_loss [arcmin]")


def first_stage_error_keys(planets: int) -> dict[str, list[str]]:
    """Family → instance keys of the first stage's backlash errors [µm].

    ``first_stage.sun_thickness`` (the sun's tooth-thickness deviation),
    ``first_stage.planet_thickness.c<i>`` and ``first_stage.centre_distance.c<i>`` (each
    planet's tooth-thickness deviation and its sun–planet centre-distance deviation; crank
    ``i`` 1-based as in the case file).

    Parameters
    ----------
    planets : int
        Number of planets (= cranks) [-].
    """
    cr = range(1, int(planets) + 1)
    return {
        "first_stage.sun_thickness": ["first_stage.sun_thickness"],
        "first_stage.planet_thickness": [f"first_stage.planet_thickness.c{i}" for i in cr],
        "first_stage.centre_distance": [f"first_stage.centre_distance.c{i}" for i in cr],
    }


class FirstStageBacklashYield:
    """A reducer yield model plus the first stage's backlash at the output.

    Parameters
    ----------
    inner : callable
        The reducer's yield model (``errors → quantities``), e.g.
        :class:`~gearte.runners.yield_models.RVReducerYield`.
    given_um : sequence of float
        Backlash ``j_k`` of each sun–planet mesh given directly [µm] (zeros with classes).
    sun_pitch_radius : float
        ``r_sun`` [mm].
    ratio : float
        Reduction ratio ``i`` [-].
    working_pressure_angle : float
        ``α_w`` [rad].
    nominal_um : mapping, optional
        Value of a first-stage key that a sample does not draw [µm] (default 0).

    Notes
    -----
    Output ``"first_stage_backlash_at_output [arcmin]"`` besides the inner model's, whose
    lost motion, backlash and hysteresis loss grow by it (:mod:`gearte.models.rv_first_stage`).
    """

    def __init__(
        self,
        inner,
        given_um: Sequence[float],
        sun_pitch_radius: float,
        ratio: float,
        working_pressure_angle: float,
        nominal_um: Mapping[str, float] | None = None,
    ) -> None:
        self.inner = inner
        self.given = np.asarray(um_to_mm(np.asarray(given_um, dtype=float)), dtype=float)
        self.r_sun = float(sun_pitch_radius)
        self.ratio = float(ratio)
        self.alpha = float(working_pressure_angle)
        self.keys = first_stage_error_keys(self.given.size)
        self.nominal = dict(nominal_um or {})
        #: The names of the outputs: the inner model's and the first stage's backlash.
        self.quantities: tuple[str, ...] = (
            *getattr(inner, "quantities", ()),
            "first_stage_backlash_at_output [arcmin]",
        )

    def _backlash(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        """``(n, N)`` backlash of each mesh [mm]."""
        from gearte.models.rv_first_stage import mesh_backlash

        def col(key: str) -> np.ndarray:
            v = errors.get(key)
            if v is None:
                return np.full(n, float(self.nominal.get(key, 0.0)))
            return np.asarray(v, dtype=float).reshape(n)

        sun = um_to_mm(col("first_stage.sun_thickness"))
        planet = um_to_mm(
            np.column_stack([col(k) for k in self.keys["first_stage.planet_thickness"]])
        )
        centre = um_to_mm(
            np.column_stack([col(k) for k in self.keys["first_stage.centre_distance"]])
        )
        return mesh_backlash(self.given, sun, planet, centre, self.alpha)

    def free_angle_arcmin(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        """The output free angle of each sample [arcmin]."""
        from gearte.models.rv_first_stage import output_free_angle

        j = self._backlash(errors, n)
        return np.asarray(rad_to_arcmin(output_free_angle(j, self.r_sun, self.ratio)))

    def mesh_backlash_um(self, errors: Mapping[str, float]) -> list[float]:
        """``j_t,k`` of each mesh of one sample [µm] (a worst sample's case file)."""
        one = {k: np.array([float(v)]) for k, v in errors.items()}
        return [float(x) for x in mm_to_um(self._backlash(one, 1)[0])]

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        ours = {k for v in self.keys.values() for k in v}
        n = next((int(np.shape(v)[0]) for v in errors.values()), 1)
        rest = {k: v for k, v in errors.items() if k not in ours}
        out = {k: np.asarray(v, dtype=float) for k, v in self.inner(rest).items()}
        if not rest:  # nothing of the reducer drawn: one evaluation stands for every sample
            out = {k: np.broadcast_to(v.reshape(-1)[:1], (n,)).copy() for k, v in out.items()}
        extra = self.free_angle_arcmin(errors, n)
        for q in FIRST_STAGE_QUANTITIES:
            if q in out:
                out[q] = out[q] + extra
        out["first_stage_backlash_at_output [arcmin]"] = extra
        return out
