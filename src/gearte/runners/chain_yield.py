"""A gear chain as a yield model: each stage's lost motion from its own drawn errors → joint.

Each stage of a ``gear_chain`` is one of

* a **backlash stage** (a spur or bevel pair, given as ``[pair]`` or as a ``gear_pair`` drive):
  its normal backlash is the pair's linear stack (Jiang et al. 2024 eqs. 2–13 / 15–28,
  :meth:`gearte.models.backlash.SpurPair.backlash_stack`), evaluated on the drawn contributors
  (tooth thicknesses, centre distance, bearing clearance [µm]; eccentricities and run-outs as a
  magnitude [µm] with a uniform direction, entering as ``r sin φ``), then turned into the return
  error at the driven gear by eq. (14)/(29), ``Δφ = 2 max(jn, 0) / (d cos α)``;
* a **drive stage** of any other family with tolerances of its own (a cycloid stage's nine
  component errors, a strain-wave gear's errors): its family's model of its lost motion from its
  own drawn errors (:class:`gearte.families.StageYield`), keys ``<stage slug>.<error>``;
* a **lost-motion stage** (a drive without tolerances of its own, a stage given by its lost
  motion or backlash values, or a stage whose whole law the user gives): its lost motion
  [arcmin at the stage output, key: the stage name] is itself the drawn error.

The joint's lost motion is Jiang et al. (2024) eq. (30), ``Δφ_joint = Σₖ Δφₖ / Πⱼ₍ⱼ>ₖ₎ iⱼ``,
sample by sample (the distribution, not only the sum of maxima), and the end-effector error
eq. (31), ``Δφ_joint · L``.

References
----------
Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024) Gear backlash modeling and tolerance simulation
of fully gear-coupled robot. J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
doi:10.3785/j.issn.1008-973X.2024.08.001
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.units import arcmin_to_rad, rad_to_arcmin, um_to_mm

__all__ = ["StageTerm", "ChainStage", "PairLostMotion", "GearChainYield", "stack_terms"]


@dataclass(frozen=True)
class StageTerm:
    """One drawn error of a backlash stage.

    Attributes
    ----------
    key : str
        Tolerance key (``<stage slug>.<contributor slug>``) [µm].
    sensitivity : float
        ``∂jn/∂x`` of the pair's stack [-].
    radial : bool
        A magnitude with a uniform direction ``<key>_phase_rad``: enters as ``r sin φ`` (drawn
        without a direction, the value is taken as the projection itself).
    """

    key: str
    sensitivity: float
    radial: bool = False


class PairLostMotion:
    """A pair's return error from its drawn backlash-stack contributors (picklable).

    Parameters
    ----------
    terms : tuple of StageTerm
        The stack's contributors (keys [µm]).
    diameter : float
        Driven-gear pitch (bevel: mean) diameter d [mm] of eq. (14)/(29).
    pressure_angle : float
        Pressure angle α [rad].

    Notes
    -----
    ``jn = Σ ∂jn/∂x · x`` (a radial term as ``r sin φ`` when its direction is drawn), then
    ``Δφ = 2 max(jn, 0) / (d cos α)`` (Jiang et al. 2024 eq. 14/29) [rad].
    """

    def __init__(self, terms: Sequence[StageTerm], diameter: float, pressure_angle: float) -> None:
        self.terms = tuple(terms)
        self.diameter = float(diameter)
        self.pressure_angle = float(pressure_angle)

    def __call__(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        jn = np.zeros(n)
        for t in self.terms:
            x = um_to_mm(np.asarray(errors[t.key], dtype=float))
            if t.radial and f"{t.key}_phase_rad" in errors:
                x = x * np.sin(np.asarray(errors[f"{t.key}_phase_rad"], dtype=float))
            jn += t.sensitivity * x
        return 2.0 * np.maximum(jn, 0.0) / (self.diameter * np.cos(self.pressure_angle))


@dataclass(frozen=True)
class ChainStage:
    """One stage of the chain as the yield model sees it.

    Attributes
    ----------
    name : str
        Stage name (its output quantity is ``"<slug>.lost_motion [arcmin]"``).
    slug : str
        Key prefix of its errors.
    ratio : float
        Reduction ratio [-], > 0.
    model : callable, optional
        The drive's own lost motion from its drawn errors, ``model(errors, n)`` → [rad] at the
        stage output (:class:`gearte.families.StageYield`; a pair: :class:`PairLostMotion`).
        ``None``: a lost-motion stage whose error key is its name [arcmin at its output].
    """

    name: str
    slug: str
    ratio: float
    model: Any = None


class _Drawn(Mapping):
    """The drawn errors, with the nominal value of a key the batch does not draw (``in`` still
    says whether it was drawn: a direction ``<key>_phase_rad`` counts only when drawn)."""

    def __init__(self, errors: Mapping[str, np.ndarray], nominal: Mapping[str, float], n: int):
        self.errors, self.nominal, self.n = errors, nominal, n

    def __getitem__(self, key: str) -> np.ndarray:
        if key in self.errors:
            return np.asarray(self.errors[key], dtype=float)
        return np.full(self.n, self.nominal.get(key, 0.0))

    def __contains__(self, key: object) -> bool:
        return key in self.errors

    def __iter__(self):
        return iter(self.errors)

    def __len__(self) -> int:
        return len(self.errors)


def stack_terms(slug: str, stack) -> tuple[tuple[StageTerm, ...], dict[str, tuple]]:
    """The terms of a pair's backlash stack and each one's law.

    Parameters
    ----------
    slug : str
        Stage key prefix.
    stack : LinearStack
        The pair's normal-backlash stack [mm] (Normal and RadialPhase-of-Rayleigh contributors).

    Returns
    -------
    (terms, laws)
        ``laws[key] = ("normal", 3σ [µm], μ [µm])`` or ``("rayleigh", 6σx [µm], 0)`` — the
        Rayleigh tolerance ``t`` with ``sigmas = 6``: scale ``σx = t/6`` as Jiang 2024 ties it
        to the radial composite tolerance.
    """
    from gearte.tolerance.distributions import Normal, RadialPhase, Rayleigh

    terms, laws = [], {}
    for c in stack.contributors:
        key = f"{slug}.{'_'.join(c.name.lower().split())}"
        dist = c.distribution
        if isinstance(dist, Normal):  # (its lower/upper are stated limits, not a truncation)
            terms.append(StageTerm(key, float(c.sensitivity)))
            laws[key] = ("normal", 3.0e3 * dist.sigma, 1.0e3 * dist.mu)
        elif isinstance(dist, RadialPhase) and isinstance(dist.magnitude, Rayleigh):
            terms.append(StageTerm(key, float(c.sensitivity), radial=True))
            laws[key] = ("rayleigh", 6.0e3 * dist.magnitude.scale, 0.0)
        else:
            raise ParameterError(
                f"{slug}.{c.name}", type(dist).__name__, "no yield law for this contributor"
            )
    return tuple(terms), laws


class GearChainYield:
    """Joint lost motion of a gear chain from each stage's drawn errors.

    Parameters
    ----------
    stages : sequence of ChainStage
        Motor to joint.
    nominal : mapping
        Error key → value used where a batch does not draw it ([µm]; a stage's lost motion
        [arcmin]).
    lever_length : float
        Joint axis to end effector L [mm] (eq. 31).

    Notes
    -----
    Outputs ``"<slug>.lost_motion [arcmin]"`` per stage (at its output),
    ``"joint_lost_motion [arcmin]"`` and ``"end_effector_error [mm]"``. A stage whose drawn parts
    interfere (``jn < 0``) has zero lost motion, never a negative one.

    References
    ----------
    Jiang et al. (2024) eqs. (14), (29)–(31), doi:10.3785/j.issn.1008-973X.2024.08.001
    """

    def __init__(
        self, stages: Sequence[ChainStage], nominal: Mapping[str, float], lever_length: float
    ) -> None:
        from gearte.models.lost_motion import stage_transfer_factors

        self.stages = tuple(stages)
        self.nominal = {k: float(v) for k, v in nominal.items()}
        self.factors = stage_transfer_factors([s.ratio for s in self.stages])
        if not lever_length > 0:
            raise ParameterError("lever_length", lever_length, "must be > 0 mm")
        self.lever_length = float(lever_length)
        #: The names of the outputs (a spec may bound them; checked before any sample).
        self.quantities: tuple[str, ...] = (
            *(f"{st.slug}.lost_motion [arcmin]" for st in self.stages),
            "joint_lost_motion [arcmin]",
            "end_effector_error [mm]",
        )

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = next((int(np.shape(v)[0]) for v in errors.values()), 1)
        drawn = _Drawn(errors, self.nominal, n)
        out: dict[str, np.ndarray] = {}
        joint = np.zeros(n)
        for st, f in zip(self.stages, self.factors, strict=True):
            if st.model is not None:
                lm = np.maximum(np.asarray(st.model(drawn, n), dtype=float), 0.0)
            else:
                lm = np.maximum(arcmin_to_rad(drawn[st.name]), 0.0)
            out[f"{st.slug}.lost_motion [arcmin]"] = np.asarray(rad_to_arcmin(lm), dtype=float)
            joint += lm * f
        out["joint_lost_motion [arcmin]"] = np.asarray(rad_to_arcmin(joint), dtype=float)
        out["end_effector_error [mm]"] = joint * self.lever_length
        return out
