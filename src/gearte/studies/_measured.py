"""Shared base of the case kinds built from measurement files (``rv_serial``, ``rv_lot``)."""

from __future__ import annotations

from typing import Any

from pydantic import PrivateAttr, model_validator

from gearte.io.schema import CaseBase
from gearte.studies.rv_bench import ReducerRef


class MeasuredPartsCase(CaseBase):
    """A case that refers to an ``rv_reducer`` design and reads measured parts.

    The measurement files are read when the case is validated (:meth:`_build` of the kind), so
    ``gearte validate`` refuses a malformed file (one line naming file, line and column) as
    ``run`` would; what they give is kept for ``run`` in ``_built``.
    """

    _built: Any = PrivateAttr(default=None)
    reducer: ReducerRef

    def _build(self) -> Any:  # pragma: no cover - every kind overrides it
        raise NotImplementedError

    def design(self) -> tuple[Any, Any]:
        """``(design case, RVReducer)`` of ``reducer.case``, which must be an ``rv_reducer``
        case (a :class:`~gearte.errors.ParameterError` naming ``reducer.case`` otherwise)."""
        from gearte.errors import ParameterError
        from gearte.io.case_file import load_case
        from gearte.studies import rv_reducer as rv

        try:
            design: Any = load_case(self.reducer.case)  # an rv_reducer Case, checked below
        except (FileNotFoundError, IsADirectoryError, PermissionError) as exc:
            # checked at validation; the file went away (or became unreadable) since
            raise ParameterError("reducer.case", self.reducer.case, str(exc)) from None
        if design.case.kind != "rv_reducer":
            raise ParameterError(
                "reducer.case",
                self.reducer.case,
                f"is a {design.case.kind!r} case; need rv_reducer",
            )
        return design, rv.build_reducer(design.reducer)

    @model_validator(mode="after")
    def _measurements(self) -> MeasuredPartsCase:
        from gearte.errors import GearteError

        try:
            self._built = self._build()
        except GearteError as exc:
            raise ValueError(str(exc)) from None
        return self


def check_measured_against_design(
    red: Any,
    path: str,
    *,
    bores: dict | None = None,
    cams: dict | None = None,
    pins: dict | None = None,
) -> None:
    """Measured bore centres, cam eccentricities or pin diameters (as their readers return them)
    against the design reducer ``red``: a value far from the design's (a unit slip in the file's
    header) is a :class:`~gearte.errors.MeasurementFileError` naming file, line, column and unit
    (:func:`gearte.io.metrology.check_against_design`)."""
    import numpy as np

    from gearte.io import metrology as mt

    if bores is not None:
        m, r = red.cranks.count, red.cranks.circle_radius
        ang = 2.0 * np.pi * np.arange(m) / m
        nominal = r * np.stack([np.cos(ang), np.sin(ang)], -1)
        mt.check_against_design(path, "disc_bores", bores, nominal, r)
    if cams is not None:
        a = red.cranks.eccentricity
        ecc = {k: c.eccentricity for k, c in cams.items()}
        mt.check_against_design(path, "crank_eccentricity", ecc, np.asarray(a), a)
    if pins is not None:
        d = 2.0 * red.pins.pin_radius
        dia = {k: p.diameter for k, p in pins.items()}
        mt.check_against_design(path, "pins", dia, np.asarray(d), d)
