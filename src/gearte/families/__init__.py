"""Drive families: the one registry of the drives gearte models.

A *drive family* is everything gearte knows about one kind of drive, registered through one
object, :class:`DriveFamily`, that its own module (``gearte.families.<kind>``) defines as
``FAMILY``:

* its **description**: the case sections that describe one drive (``sections``), turned into the
  model object by ``to_object(case)`` and back into those sections by ``to_sections(obj)`` — one
  function each way, so a case written from an object (a worst Monte-Carlo sample, an exported
  design) reads back as the same object;
* its **Drive** (:mod:`gearte.drives`): ``drive(case, name)`` answers lost motion, stiffness,
  transmission error and spread for chains and sweeps;
* its **own tolerances in a chain's yield**: ``chain_yield(case, slug)`` gives the laws of its
  errors (keys ``<stage slug>.<error>``) and a vectorised model of its lost motion from them, so a
  chain's Monte-Carlo draws each drive's own tolerances and ranks them in its contributions
  (:class:`StageYield`);
* its study kind (``gearte.studies.<kind>``, the same name: ``gearte run`` of one drive, its
  figures and report) and its warm-up cases.

Chains (``gearte.studies.gear_chain``, ``gearte.studies._drives``), sweeps, yield and the warm-up
find the families here and nowhere else: adding a family is its own modules plus one line in
:data:`FAMILY_MODULES`.

The modules are imported on first use only (a family module imports its study kind lazily), so
listing the kinds costs nothing.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "FAMILY_MODULES",
    "DriveFamily",
    "StageYield",
    "families",
    "family_kinds",
    "get_family",
]

#: The registered drive families, one module each (the module's last name is the family's kind).
FAMILY_MODULES: tuple[str, ...] = (
    "gearte.families.gear_pair",
    "gearte.families.planetary",
    "gearte.families.cycloid_stage",
    "gearte.families.rv_reducer",
    "gearte.families.strain_wave",
)


@dataclass(frozen=True)
class StageYield:
    """A drive's own tolerances inside a chain's yield run.

    Attributes
    ----------
    laws : mapping
        Error key (``<stage slug>.<error>``) → its default law, a
        :class:`gearte.studies._yield.ToleranceEntry`.
    units : mapping
        Error key → the unit its values are drawn in (``"um"``, ``"deg"``, ``"arcmin"``).
    nominal : mapping
        Error key → the value used where a batch does not draw it (in its unit); a key left out
        has nominal 0 unless its law gives one.
    model : callable
        ``model(errors, n)`` → the stage's lost motion [rad] at its output, an array of ``n``
        (``errors``: key → array of drawn values, in the keys' units). Picklable (a module-level
        class), so processes and Dask can run it.
    radial : frozenset of str
        Keys drawn as a magnitude with a direction ``<key>_phase_rad`` (entering as ``r sin φ``).
    grade_um : callable, optional
        ``grade_um(key, grade)`` → :class:`gearte.studies._yield.GradeTolerance` or ``None``: the
        tolerance an accuracy grade implies for one of its keys.
    families : mapping
        Family key → its instance keys (``<slug>.cam`` → ``<slug>.cam.c1.d1`` …): a law on a
        family applies to each instance, drawn independently.
    """

    laws: Mapping[str, Any]
    units: Mapping[str, str]
    nominal: Mapping[str, float]
    model: Callable[[Mapping[str, Any], int], Any]
    radial: frozenset[str] = frozenset()
    grade_um: Callable[[str, int], Any] | None = None
    families: Mapping[str, list[str]] = field(default_factory=dict)


@dataclass(frozen=True)
class DriveFamily:
    """One drive family, registered as ``FAMILY`` in ``gearte.families.<kind>``.

    Attributes
    ----------
    kind : str
        The family's name: its study kind (``gearte.studies.<kind>``) and the ``kind`` of a
        chain's ``[chain.stages.drive]``.
    sections : tuple of str
        The case sections that describe one drive (inline in a chain stage).
    to_object : callable
        ``to_object(case)`` → the model object the validated case describes.
    drive : callable
        ``drive(case, name)`` → the :class:`~gearte.drives.Drive` of a validated case.
    to_sections : callable, optional
        ``to_sections(obj)`` → the sections (a JSON-able dict, section name → table) that
        describe ``obj``; ``to_object`` of a case made of them gives the same object
        (``None``: the family's description is not written back from an object yet).
    lost_motion : bool
        Whether its model has a lost motion (``False``: a chain stage gives it beside the drive).
    chain_yield : callable, optional
        ``chain_yield(case, slug)`` → :class:`StageYield` (its own tolerances in a chain's yield)
        or ``None`` where the description has no tolerances (a measured drive: its lost motion
        is held constant).
    drive_kinds : tuple of str
        The ``Drive.kind`` values its drives report.
    warm_cases, bench_case
        Bundled cases that compile its kernels (``gearte warm-cache``) and its first-run
        benchmark case (``benchmarks/bench_compile.py``).
    warm_uses : tuple of str
        A family without warm-up cases of its own: the kinds whose kernels it calls (warming it
        warms those, :data:`gearte.warm.WARM_USES`).
    labels : mapping
        Readable labels of its own result names (added to :data:`gearte.labels.LABELS`).
    """

    kind: str
    sections: tuple[str, ...]
    to_object: Callable[[Any], Any]
    drive: Callable[[Any, str], Any]
    to_sections: Callable[[Any], dict[str, Any]] | None = None
    lost_motion: bool = True
    chain_yield: Callable[[Any, str], StageYield | None] | None = None
    drive_kinds: tuple[str, ...] = ()
    warm_cases: tuple[str, ...] = ()
    warm_uses: tuple[str, ...] = ()
    bench_case: str | None = None
    labels: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # its labels join the registry when its module is imported: in every process that reads
        # one of its results (unpickling the case imports the family's description module),
        # the report's background process included
        if self.labels:
            from gearte.labels import LABELS

            for name, text in self.labels.items():
                LABELS.setdefault(name, text)


def family_kinds() -> tuple[str, ...]:
    """The registered families' kinds, in registration order (nothing imported)."""
    return tuple(m.rsplit(".", 1)[1] for m in FAMILY_MODULES)


_LOADED: dict[str, DriveFamily] = {}


def get_family(kind: str) -> DriveFamily:
    """The registered family ``kind``.

    Raises
    ------
    KeyError
        Naming the registered kinds when ``kind`` is none of them.
    """
    if kind in _LOADED:
        return _LOADED[kind]
    kinds = family_kinds()
    if kind not in kinds:
        raise KeyError(f"unknown drive family {kind!r}; registered: {list(kinds)}")
    family = importlib.import_module(FAMILY_MODULES[kinds.index(kind)]).FAMILY
    if family.kind != kind:  # pragma: no cover - a registration error
        raise RuntimeError(f"{FAMILY_MODULES[kinds.index(kind)]}.FAMILY.kind is {family.kind!r}")
    _LOADED[kind] = family
    return family


def families() -> dict[str, DriveFamily]:
    """All registered families, kind → family (imports their modules)."""
    return {k: get_family(k) for k in family_kinds()}
