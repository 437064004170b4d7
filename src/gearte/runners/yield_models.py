"""Drives as yield models: vectorised functions of drawn errors for :func:`run_yield`.

Each class holds one drive's nominal description and maps a batch of drawn errors (keyed as
the drive's case file keys them, in the unit the key names) to the quantities a spec can
bound. They are picklable (module-level classes), so processes and Dask can run them.

* :class:`CycloidGeometricTE` — cycloid–pin stage, the nine component errors of Hu et al.
  (2020) Table 2 [µm] → geometric TE (lost motion of the stage) [arcmin]: the eight linear
  factors through their gains, the eccentricity error through its exact second-order effect
  (:func:`gearte.models.cycloid_te.eccentricity_te`), the design modifications as constants.
  Replaces the RSS-only band of eq. 17 by the distribution.
* :class:`PlanetaryCoupledTE` — 2K-H planetary, eccentricity magnitudes [µm] and directions
  [deg] (Wang et al. 2013) → exact coupled TE amplitude and peak-to-peak [arcsec]
  (:func:`gearte.models.planetary_errors.sample_extremes`).
* :class:`RVReducerYield` — a whole RV reducer, each sample one assembled reducer: its
  eccentricity errors (magnitude [µm] and direction) and pin errors [µm] → the catalogue virtual
  test (lost motion at ±3 % rated torque, rigidity, backlash, hysteresis), angular TE over one
  output revolution (unloaded: geometric; at the TE torque: total) and the peak pin load
  (Han et al. 2023 load sharing, :mod:`gearte.models.rv_load_sharing`).
* :class:`GearChainLostMotion` — a chain of drives: each stage's lost motion [arcmin, at its
  output] drawn from its own distribution (:func:`chain_tolerances` builds them from each drive's
  ``lost_motion_spread``), combined at the joint by Jiang et al. (2024) eq. (30) → the
  distribution of the joint's lost motion, not only its maximum.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from gearte.units import (
    Nmm_to_Nm,
    arcmin_to_rad,
    deg_to_rad,
    rad_to_arcmin,
    rad_to_arcsec,
    um_to_mm,
)

__all__ = [
    "CycloidGeometricTE",
    "PlanetaryCoupledTE",
    "RVReducerYield",
    "RV_VECTOR_PARTS",
    "RV_PIN_FAMILIES",
    "MODIFICATION_FAMILIES",
    "rv_error_keys",
    "GearChainLostMotion",
    "chain_tolerances",
]


def _n(errors: Mapping[str, np.ndarray]) -> int:
    for v in errors.values():
        return int(np.shape(v)[0])
    return 1


class CycloidGeometricTE:
    """Geometric TE of a cycloid stage as a function of its nine component errors.

    Parameters
    ----------
    stage : CycloidStage
        The nominal stage (with its modifications).
    nominal_um : mapping
        Error factor → value [µm] used where a batch does not draw the factor (its mean).

    Notes
    -----
    ``TE = Σ_mod Δθ + Σ_j g_j e_j + Δθ_ecc(δa)`` [rad] (Hu et al. 2020 eq 5–16; the
    eccentricity term is gearte's second-order reading, see :mod:`gearte.models.cycloid_te`).
    Output ``"geometric_te [arcmin]"``.

    References
    ----------
    Hu Y. et al. (2020) Applied Sciences 10(2), 481. doi:10.3390/app10020481
    """

    #: The names of the outputs (a spec may bound them; checked before any sample).
    quantities: tuple[str, ...] = ("geometric_te [arcmin]",)

    def __init__(self, stage, nominal_um: Mapping[str, float] | None = None) -> None:
        from gearte.models.cycloid_te import ERROR_FACTORS, factor_contributions, te_gradients

        self.stage = stage
        self.factors = ERROR_FACTORS
        self.nominal_um = {k: float((nominal_um or {}).get(k, 0.0)) for k in ERROR_FACTORS}
        contrib = factor_contributions(stage, {})
        self.modifications = float(
            contrib["equidistant_modification"]
            + contrib["shifted_modification"]
            + contrib["rotation_modification"]
        )
        self.gradients = te_gradients(stage)

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        from gearte.models.cycloid_te import eccentricity_te

        n = _n(errors)
        te = np.full(n, self.modifications)
        for k in self.factors:
            e = np.asarray(
                um_to_mm(errors[k] if k in errors else np.full(n, self.nominal_um[k])),
                dtype=float,
            )
            if k == "eccentricity_error":
                nz = e != 0.0
                if np.any(nz):
                    te[nz] += eccentricity_te(self.stage, e[nz])
            else:
                te += self.gradients[k] * e
        return {self.quantities[0]: np.asarray(rad_to_arcmin(te), dtype=float)}


class PlanetaryCoupledTE:
    """Exact coupled TE of a 2K-H planetary as a function of its errors.

    Parameters
    ----------
    terms : TermSet
        The equivalent mesh-error terms (derived or as given).
    nominal_magnitudes_um : mapping
        Magnitude key → value [µm] where a batch does not draw it.
    nominal_angles_deg : mapping
        Angle key → value [deg] where a batch does not draw it (missing: 0).

    Notes
    -----
    ``amplitude = max_t |Σ e(t)|·|scale|``, ``peak_to_peak = (max − min)·|scale|`` (Wang et al.
    2013 eqs 7–9, exact extremes). Outputs ``"coupled_te_amplitude [arcsec]"`` and
    ``"coupled_te_peak_to_peak [arcsec]"``.

    References
    ----------
    Wang C. et al. (2013) Trans. CSAM 44(8), 287–292. doi:10.6041/j.issn.1000-1298.2013.08.049
    """

    #: The names of the outputs (a spec may bound them; checked before any sample).
    quantities: tuple[str, ...] = (
        "coupled_te_amplitude [arcsec]",
        "coupled_te_peak_to_peak [arcsec]",
    )

    def __init__(
        self,
        terms,
        nominal_magnitudes_um: Mapping[str, float],
        nominal_angles_deg: Mapping[str, float] | None = None,
    ) -> None:
        self.terms = terms
        self.mag_nom = {k: float(nominal_magnitudes_um.get(k, 0.0)) for k in terms.magnitudes}
        self.ang_nom = {k: float((nominal_angles_deg or {}).get(k, 0.0)) for k in terms.angles}

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        from gearte.models.planetary_errors import sample_extremes

        n = _n(errors)
        mags = np.column_stack(
            [
                um_to_mm(np.asarray(errors[k], dtype=float))
                if k in errors
                else np.full(n, float(um_to_mm(self.mag_nom[k])))
                for k in self.terms.magnitudes
            ]
        )
        if self.terms.angles:
            angs = np.column_stack(
                [
                    deg_to_rad(np.asarray(errors[k], dtype=float))
                    if k in errors
                    else np.full(n, float(deg_to_rad(self.ang_nom[k])))
                    for k in self.terms.angles
                ]
            )
        else:
            angs = np.zeros((n, 0))
        fmax, fmin = sample_extremes(self.terms, mags, angs)
        s = abs(self.terms.scale)
        amplitude, peak_to_peak = self.quantities
        return {
            amplitude: np.asarray(rad_to_arcsec(np.maximum(fmax, -fmin) * s), dtype=float),
            peak_to_peak: np.asarray(rad_to_arcsec((fmax - fmin) * s), dtype=float),
        }


#: Eccentricity error families of an RV reducer (``[[reducer.errors]]`` parts); each instance
#: is a vector: a magnitude [µm] and a direction ``<key>_phase_rad`` in the part's frame.
RV_VECTOR_PARTS: tuple[str, ...] = (
    "planet_base_circle",
    "disc_crank_bore",
    "cam",
    "carrier_crank_bore",
    "disc_radial_runout",
    "disc_cumulative_pitch",
    "sun_eccentricity",
    "sun_assembly",
    "output_assembly",
)
#: Pin error families (``[reducer.pins]`` ``*_errors_um``), one value per pin [µm].
RV_PIN_FAMILIES: tuple[str, ...] = (
    "radius_errors",
    "radial_position_errors",
    "tangential_position_errors",
)
#: Per-disc modification error families (``[reducer.discs]`` ``*_modification_errors_um``), one
#: value per disc [µm]: ``discs.equidistant_modification_errors.d<j>`` …
MODIFICATION_FAMILIES: tuple[str, ...] = (
    "discs.equidistant_modification_errors",
    "discs.shift_modification_errors",
)


def rv_error_keys(reducer) -> dict[str, list[str]]:
    """Error family → the keys of its instances for this reducer.

    ``planet_base_circle.c<i>``, ``disc_crank_bore.c<i>.d<j>``, ``cam.c<i>.d<j>``,
    ``carrier_crank_bore.c<i>``, ``disc_radial_runout.d<j>``, ``disc_cumulative_pitch.d<j>``
    (crank ``i``, disc ``j``, 1-based as in the case file), ``sun_eccentricity``,
    ``sun_assembly``, ``output_assembly`` (one instance: the family key itself; the part names
    of ``[[reducer.errors]]``), ``pins.radius_errors.p<k>`` … for every pin ``k`` (families
    ``pins.radius_errors`` …) and ``discs.equidistant_modification_errors.d<j>``,
    ``discs.shift_modification_errors.d<j>`` (the per-disc modification errors of
    ``[reducer.discs]``).
    """
    m, n, zp = reducer.cranks.count, reducer.discs.count, reducer.pins.count
    cr, dr = range(1, m + 1), range(1, n + 1)
    return {
        "planet_base_circle": [f"planet_base_circle.c{i}" for i in cr],
        "disc_crank_bore": [f"disc_crank_bore.c{i}.d{j}" for i in cr for j in dr],
        "cam": [f"cam.c{i}.d{j}" for i in cr for j in dr],
        "carrier_crank_bore": [f"carrier_crank_bore.c{i}" for i in cr],
        "disc_radial_runout": [f"disc_radial_runout.d{j}" for j in dr],
        "disc_cumulative_pitch": [f"disc_cumulative_pitch.d{j}" for j in dr],
        **{k: [k] for k in ("sun_eccentricity", "sun_assembly", "output_assembly")},
        **{f"pins.{f}": [f"pins.{f}.p{k}" for k in range(1, zp + 1)] for f in RV_PIN_FAMILIES},
        **{f: [f"{f}.d{j}" for j in dr] for f in MODIFICATION_FAMILIES},
    }


class RVReducerYield:
    """A whole RV reducer as a yield model: drawn errors → catalogue test, TE, pin load.

    Parameters
    ----------
    reducer : RVReducer
        The nominal reducer (its measured errors are the nominal of errors not drawn).
    positions : int
        Output positions over one revolution for the TE and the pin loads (≥ 36 for a
        catalogue TE).
    te_torque : float, optional
        Torque of the loaded TE and the pin loads [N·mm]; default the rated torque.
    zero_load_fraction : float
        The unloaded (geometric) TE is solved at this fraction of ``te_torque``.
    lost_motion_fraction : float
        Lost motion read at ± this fraction of the rated torque (catalogue: 0.03).
    batched : bool
        Solve a batch of samples in one compiled call (:mod:`gearte.runners.rv_yield_batch`,
        :mod:`gearte.solvers.rv_batch`; the same physics and algorithm, equal to round-off);
        ``False``: each sample on its own through :meth:`one`.

    Notes
    -----
    A drawn error replaces the reducer's value of that instance; an error not drawn keeps it.
    Per sample: the 16 torque levels of the catalogue's virtual loop and ``2 × positions``
    positions for the TE (the quasi-static load-sharing equilibrium of
    :mod:`gearte.models.rv_load_sharing`).

    Outputs: ``"lost_motion [arcmin]"``, ``"torsional_rigidity [Nm/arcmin]"``,
    ``"backlash [arcmin]"``, ``"hysteresis_loss [arcmin]"``, ``"angular_te [arcmin]"``
    (unloaded, peak-to-peak over one output revolution), ``"loaded_te [arcmin]"``,
    ``"peak_pin_load [N]"``, ``"max_contact_pressure [MPa]"`` (Hertz, each pin with its own flank
    curvature, at the TE torque).

    References
    ----------
    Han et al. (2023), Hu et al. (2020); see :mod:`gearte.models.rv_load_sharing` and
    :mod:`gearte.models.rv_catalogue`.
    """

    #: The names of the outputs, those of :meth:`one` and of the batched solver (a spec may bound
    #: them; checked before any sample, and against the outputs when a yield runs).
    quantities: tuple[str, ...] = (
        "lost_motion [arcmin]",
        "torsional_rigidity [Nm/arcmin]",
        "backlash [arcmin]",
        "hysteresis_loss [arcmin]",
        "angular_te [arcmin]",
        "loaded_te [arcmin]",
        "peak_pin_load [N]",
        "max_contact_pressure [MPa]",
    )

    #: The outputs read on the grid of output positions (their grid error can be estimated by
    #: the same model at more positions).
    grid_quantities: tuple[str, ...] = (
        "angular_te [arcmin]",
        "loaded_te [arcmin]",
        "peak_pin_load [N]",
        "max_contact_pressure [MPa]",
    )

    def __init__(
        self,
        reducer,
        *,
        positions: int = 36,
        te_torque: float | None = None,
        zero_load_fraction: float = 1e-3,
        lost_motion_fraction: float = 0.03,
        batched: bool = True,
    ) -> None:
        from gearte.errors import ParameterError
        from gearte.models.rv_load_sharing import output_positions

        if int(positions) != positions or positions < 2:
            raise ParameterError("positions", positions, "must be an integer >= 2")
        if reducer.rated_torque is None:
            raise ParameterError(
                "reducer.rated_torque",
                None,
                "every sample's catalogue virtual test (lost motion at ±3 % of it, rigidity, "
                "hysteresis) needs the rated torque [N·mm]",
            )
        self.reducer = reducer
        self.theta = output_positions(int(positions))
        self.te_torque = float(reducer.rated_torque if te_torque is None else te_torque)
        self.zero_load_fraction = float(zero_load_fraction)
        self.lost_motion_fraction = float(lost_motion_fraction)
        self.keys = rv_error_keys(reducer)
        self.batched = bool(batched)
        self.vector_parts = RV_VECTOR_PARTS
        self.modification_families = MODIFICATION_FAMILIES

    def reducer_for(self, errors: Mapping[str, float]):
        """The assembled reducer of one sample (errors [µm], phases [rad])."""
        import dataclasses

        red = self.reducer
        e0 = red.errors
        names = ("planet", "disc_bore", "cam", "carrier_bore", "sun", "sun_seat", "output_seat",
                 "disc_runout", "disc_pitch", "disc_modification")  # fmt: skip
        arr = {n: np.array(getattr(e0, n), dtype=float, copy=True) for n in names}

        def vec(key: str) -> np.ndarray | None:
            if key not in errors:
                return None
            r = float(um_to_mm(errors[key]))
            ph = float(errors.get(f"{key}_phase_rad", 0.0))
            return r * np.array([np.cos(ph), np.sin(ph)])

        for name, key in (
            ("sun", "sun_eccentricity"),
            ("sun_seat", "sun_assembly"),
            ("output_seat", "output_assembly"),
        ):
            if (v := vec(key)) is not None:
                arr[name][:] = v
        for i in range(red.cranks.count):
            if (v := vec(f"planet_base_circle.c{i + 1}")) is not None:
                arr["planet"][i] = v
            if (v := vec(f"carrier_crank_bore.c{i + 1}")) is not None:
                arr["carrier_bore"][i] = v
            for j in range(red.discs.count):
                if (v := vec(f"disc_crank_bore.c{i + 1}.d{j + 1}")) is not None:
                    arr["disc_bore"][j, i] = v
                if (v := vec(f"cam.c{i + 1}.d{j + 1}")) is not None:
                    arr["cam"][i, j] = v
        for j in range(red.discs.count):
            if (v := vec(f"disc_radial_runout.d{j + 1}")) is not None:
                arr["disc_runout"][j] = v
            if (v := vec(f"disc_cumulative_pitch.d{j + 1}")) is not None:
                arr["disc_pitch"][j] = v
            for col, fam in enumerate(MODIFICATION_FAMILIES):
                if (key := f"{fam}.d{j + 1}") in errors:
                    arr["disc_modification"][j, col] = float(um_to_mm(errors[key]))
        red = red.with_errors(dataclasses.replace(e0, **arr))
        pins = red.pins
        changed = {}
        for f in RV_PIN_FAMILIES:
            keys = self.keys[f"pins.{f}"]
            if any(k in errors for k in keys):
                a = np.asarray(getattr(pins, f), dtype=float).copy()
                for k, key in enumerate(keys):
                    if key in errors:
                        a[k] = float(um_to_mm(errors[key]))
                changed[f] = a
        if changed:
            from dataclasses import replace

            red = red.replace(pins=replace(pins, **changed))
        return red

    def one(self, red) -> dict[str, float]:
        """The quantities of one assembled reducer."""
        from gearte.models.rv_catalogue import catalogue_values
        from gearte.models.rv_load_sharing import assemble, contact_law, load_sharing

        law = contact_law(red)
        # the catalogue quantities only (a two-point curve: the hysteresis plot is not needed)
        cv = catalogue_values(
            red,
            turning_points=(1.0, -1.0),
            steps_per_segment=2,
            lost_motion_fraction=self.lost_motion_fraction,
            law=law,
        )
        system = assemble(red, self.theta)
        loaded = load_sharing(red, self.te_torque, law=law, system=system)
        unloaded = load_sharing(
            red, self.zero_load_fraction * self.te_torque, law=law, system=system
        )

        def arcmin(x: float) -> float:
            return float(rad_to_arcmin(x))

        return {
            "lost_motion [arcmin]": arcmin(cv.lost_motion),
            "torsional_rigidity [Nm/arcmin]": float(Nmm_to_Nm(cv.torsional_rigidity))
            * float(arcmin_to_rad(1.0)),
            "backlash [arcmin]": arcmin(cv.backlash),
            "hysteresis_loss [arcmin]": arcmin(cv.hysteresis_loss),
            "angular_te [arcmin]": arcmin(float(np.ptp(unloaded.output_error))),
            "loaded_te [arcmin]": arcmin(float(np.ptp(loaded.output_error))),
            "peak_pin_load [N]": loaded.peak_pin_load,
            "max_contact_pressure [MPa]": loaded.max_contact_pressure,
        }

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = _n(errors)
        if self.batched and errors and n > 0:
            from gearte.runners.rv_yield_batch import batch_quantities

            return batch_quantities(self, errors, n)
        rows = []
        for s in range(n):
            e = {k: float(v[s]) for k, v in errors.items()}
            rows.append(self.one(self.reducer_for(e)))
        if not rows:
            rows.append(self.one(self.reducer))
        return {k: np.array([r[k] for r in rows]) for k in rows[0]}


class GearChainLostMotion:
    """Lost motion at the joint of a chain from the stages' drawn lost motions.

    Parameters
    ----------
    names : sequence of str
        Stage keys (motor to joint), the tolerance keys [arcmin at the stage output].
    ratios : sequence of float
        Stage reduction ratios (``> 0``), motor to joint.

    Notes
    -----
    ``Δφ_joint = Σₖ max(Δφₖ, 0) / Πⱼ₍ⱼ>ₖ₎ iⱼ`` (Jiang et al. 2024 eq. 30; a stage whose parts
    interfere has no lost motion, never a negative one). Output ``"joint_lost_motion [arcmin]"``.

    References
    ----------
    Jiang et al. (2024), see :mod:`gearte.models.lost_motion`.
    """

    #: The names of the outputs (a spec may bound them; checked before any sample).
    quantities: tuple[str, ...] = ("joint_lost_motion [arcmin]",)

    def __init__(self, names, ratios) -> None:
        from gearte.models.lost_motion import stage_transfer_factors

        self.names = tuple(names)
        self.factors = stage_transfer_factors(ratios)
        if len(self.names) != self.factors.size:
            from gearte.errors import ParameterError

            raise ParameterError("names", self.names, "one name per stage ratio")

    def __call__(self, errors: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = _n(errors)
        e = np.column_stack(
            [np.maximum(np.asarray(errors[k], dtype=float), 0.0) for k in self.names]
        )
        return {self.quantities[0]: (e @ self.factors).reshape(n)}


def chain_tolerances(drives, confidence: float = 0.9973):
    """One normal tolerance per drive from its ``lost_motion_spread`` [arcmin]: nominal = the
    stack's mean, σ = its σ (``sigmas = 3`` with ``tolerance = 3σ``). Drives without a tolerance
    stack (``None``) are an error naming the drive.

    Parameters
    ----------
    drives : sequence of Drive
        The chain's drives, motor to joint.
    confidence : float
        Confidence passed to ``lost_motion_spread`` [-].
    """
    from gearte.errors import ParameterError
    from gearte.tolerance.yield_mc import Tolerance, ToleranceSet

    tols = []
    for d in drives:
        s = d.lost_motion_spread(confidence)
        if s is None:
            raise ParameterError(f"{d.name}.lost_motion_spread", None, "this drive has no stack")
        tols.append(
            Tolerance(
                d.name,
                "normal",
                3.0 * float(rad_to_arcmin(s.sd)),
                nominal=float(rad_to_arcmin(s.mean)),
            )
        )
    return ToleranceSet(tuple(tols))
