"""Resource bounds decided before any work starts (issue 13), and the plausibility floors.

Every input that sizes an allocation or a loop has a bound in its schema (``Field(le=...)``);
where the size comes from a combination of inputs (the harmonics of planetary terms, a sweep grid,
a ``--samples`` override) an estimate of memory and time is checked here, at validation time,
against a budget. The budgets are generous for a workstation and can be raised per run through
environment variables (see ``docs/errors.md``):

=========================  =======================  ===========================================
budget                     default                  override
=========================  =======================  ===========================================
memory of one analysis     4 GB                     ``GEARTE_MAX_MEMORY_GB``
time of one analysis       3600 s (estimated)       ``GEARTE_MAX_SECONDS``
points of a sweep          1000                     ``GEARTE_MAX_SWEEP_POINTS``
Dask cluster with no       300 s, then the cluster  ``GEARTE_NO_WORKER_TIMEOUT_S`` (0: forever)
worker                     counts as lost
=========================  =======================  ===========================================

``--samples N`` sets each kind's main sample count (bounded by that field's cap,
``gearte.studies.check_samples_override``) and caps every other count of sampled work — Sobol
base samples, bootstrap, kept worst samples, allocation search and verification, random
assemblies, diagnosis draws, speed-sweep points, quasi-random starts — at ``N``, never below the
field's own minimum (``gearte.studies.sample_cap``; docs/errors.md, "``--samples N``").

Plausibility floors (:data:`FLOORS`): the smallest value of each physical size (a load torque, a
Young's modulus, a stiffness, ...) that gearte accepts. They live here, in the lowest layer, so
that the case files (``gearte.io.schema.floored``) and the model functions that take such a size
as an argument (:func:`check_floor`) refuse the same values with the same message. The ceiling of
a torque against the drive's size, :data:`MAX_CONTACT_PRESSURE_MPA`, lives here for the same
reason.
"""

from __future__ import annotations

import errno
import os
import stat
from typing import Any

from gearte.errors import ParameterError

__all__ = [
    "FLOORS",
    "MAX_CONTACT_PRESSURE_MPA",
    "floor_reason",
    "check_floor",
    "check_load_torque",
    "max_memory_bytes",
    "max_seconds",
    "max_sweep_points",
    "check_memory",
    "check_time",
    "check_sweep_points",
    "no_worker_timeout_s",
    "read_input_file",
]

#: Plausibility floors of physical sizes: ``name -> (smallest value, unit, why)``. A case-file key
#: of such a size (``gearte.io.schema.floored``) refuses a value below its floor at validation,
#: and a model function that takes such a size as an argument refuses it too
#: (:func:`check_floor`, the floor converted to the function's unit), naming the key or the
#: argument, the value, the floor and the reason, where before a value such as 1e-300 or
#: a stiffness × 1e-9 passed the schema (``> 0``) and ended in ``run`` as "analysis failed: ...
#: did not converge" or "non-finite output", naming no key (the systematic sweep ``python
#: tests/fuzzing.py --count -1``, docs/errors.md). Each floor lies two to five decades below
#: the smallest value a real robot-joint reducer has, and every bundled case runs with each of
#: its floored keys set to the floor (tests/test_plausibility_floors.py).
FLOORS: dict[str, tuple[float, str, str]] = {
    "linear_stiffness": (
        1.0,
        "N/mm",
        "no part of a reducer is that soft (bearings, meshes, shafts and supports have "
        "1e4 - 1e7 N/mm); the equilibrium solvers lose the stiffer parts' deflections to "
        "round-off below it",
    ),
    "torsional_stiffness": (
        1.0,
        "N·m/rad",
        "no shaft of a reducer is that soft (1e3 - 1e6 N·m/rad); the static equilibrium "
        "loses the stiffer parts' deflections to round-off below it",
    ),
    "part_length": (
        0.1,
        "mm",
        "thinner than any gear, disc or bearing roller (needle rollers start at about 1 mm)",
    ),
    "eccentricity": (
        1e-3,
        "mm",
        "no cycloid or crank eccentricity is below 0.2 mm; far below it the tooth height 2a "
        "is lost to the round-off of the radii (the root radius equals the tip radius)",
    ),
    "bearing_reference_load": (
        1.0,
        "N",
        "Palmgren's secant stiffness at a reference load below 1 N is not the stiffness of a "
        "bearing that carries a reducer's loads (kN)",
    ),
    "youngs_modulus": (
        1000.0,
        "MPa",
        "softer than any engineering material a reducer is made of (polymers 1 000 - 3 000 "
        "MPa, steel 206 000 MPa)",
    ),
    "load_torque": (
        1e-3,
        "N·m",
        "below 1 mN·m the elastic deflections of the contacts (< 1e-7 mm) are lost to the "
        "round-off of the geometry and the load solvers cannot converge; no analysis of a "
        "reducer is meaningful there",
    ),
    "disc_share": (
        0.01,
        "-",
        "a disc that carries less than 1 % of the torque is not a load case of the stage",
    ),
    "tolerance_sigmas": (
        1.0,
        "-",
        "±t must span at least ±1σ (68 % inside); below it the drawn errors mostly fall "
        "outside the tolerance they model, and at 1e-300 σ overflows",
    ),
}


#: Largest pin–disc Hertz pressure a torque may give [MPa] (2.5× the static capacity of bearing
#: steel in line contact, about 4 000 MPa, ISO 76: far beyond any real design, reached by a torque
#: given in N·mm where N·m is asked for, which multiplies the pressure by √1000 ≈ 32). The case
#: files (``gearte.io.plausibility``) and the RV model API
#: (``gearte.models.rv_load_sharing.check_reducer_torque``) refuse a torque above it, estimated by
#: ``gearte.models.contact_law.pin_pressure_estimate``.
MAX_CONTACT_PRESSURE_MPA = 10_000.0


def floor_reason(quantity: str, *, scale: float = 1.0, unit: str | None = None) -> str:
    """The reason a value below the floor of ``quantity`` is refused: ``"must be >= <floor>
    <unit>: <why>"`` (the wording of the case files' floor message, ``gearte.io.schema.floored``).

    Parameters
    ----------
    quantity : str
        Key of :data:`FLOORS` (``"load_torque"``, ``"youngs_modulus"``, ...).
    scale : float
        Size of one unit of :data:`FLOORS` in the caller's unit [-] (1000 for a torque in N·mm
        against the floor's N·m: ``float(gearte.units.Nm_to_Nmm(1.0))``).
    unit : str, optional
        The caller's unit (default the floor's own); ``"-"`` for a dimensionless size.

    Returns
    -------
    str
        E.g. ``"must be >= 1 N·mm: below 1 mN·m the elastic deflections ..."``.
    """
    floor, floor_unit, why = FLOORS[quantity]
    shown = floor_unit if unit is None else unit
    unit_text = "" if shown == "-" else f" {shown}"
    return f"must be >= {floor * scale:g}{unit_text}: {why}"


def check_floor(
    field: str, value: float, quantity: str, *, scale: float = 1.0, unit: str | None = None
) -> None:
    """Raise :class:`ParameterError` naming ``field`` when ``value`` lies below the plausibility
    floor of ``quantity`` (or is NaN).

    The floor is ``FLOORS[quantity][0] * scale`` in the caller's unit; ``inf`` passes (a caller
    that needs a finite value checks that itself).

    Parameters
    ----------
    field : str
        The argument or key that carried the value (named in the error).
    value : float
        Its value [the caller's unit: the floor's unit times ``scale``].
    quantity : str
        Key of :data:`FLOORS`.
    scale : float
        Size of one unit of :data:`FLOORS` in the caller's unit [-] (see :func:`floor_reason`).
    unit : str, optional
        The caller's unit, for the message (default the floor's own).

    Raises
    ------
    ParameterError
        ``value`` below the floor: ``"<field> = <value>: must be >= <floor> <unit>: <why>"``.

    Examples
    --------
    >>> check_floor("torque", 5.0, "load_torque", scale=1000.0, unit="N·mm")  # 5 N·mm: passes
    >>> check_floor("disc_share", 0.001, "disc_share")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    gearte.errors.ParameterError: disc_share = 0.001: must be >= 0.01: a disc that carries ...
    """
    if not value >= FLOORS[quantity][0] * scale:
        raise ParameterError(field, value, floor_reason(quantity, scale=scale, unit=unit))


def check_load_torque(field: str, torque_Nmm: float) -> None:  # noqa: N803 - unit in the name
    """:func:`check_floor` of a load torque given in N·mm, the models' unit (the floor of
    :data:`FLOORS` is in N·m: 1e-3 N·m = 1 N·mm).

    Parameters
    ----------
    field : str
        The argument that carried the torque (named in the error).
    torque_Nmm : float
        The torque [N·mm].

    Raises
    ------
    ParameterError
        ``"<field> = <value>: must be >= 1 N·mm: <why>"``.

    Examples
    --------
    >>> check_load_torque("torque", 5.0)  # 5 N·mm: passes
    """
    from gearte.units import Nm_to_Nmm

    check_floor(field, torque_Nmm, "load_torque", scale=float(Nm_to_Nmm(1.0)), unit="N·mm")


_DEFAULTS = {"GEARTE_MAX_MEMORY_GB": 4.0, "GEARTE_MAX_SECONDS": 3600.0}
_DEFAULT_SWEEP_POINTS = 1000
_DEFAULT_NO_WORKER_S = 300.0


def _env_float(name: str, default: float) -> float:
    text = os.environ.get(name)
    if text is None or not text.strip():
        return default
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(name, text, "must be a positive number") from None
    if not value > 0 or value == float("inf"):
        raise ParameterError(name, text, "must be a positive finite number")
    return value


def max_memory_bytes() -> float:
    """Memory budget of one analysis [bytes] (``GEARTE_MAX_MEMORY_GB``, default 4)."""
    return _env_float("GEARTE_MAX_MEMORY_GB", _DEFAULTS["GEARTE_MAX_MEMORY_GB"]) * 1e9


def max_seconds() -> float:
    """Estimated-time budget of one analysis [s] (``GEARTE_MAX_SECONDS``, default 3600)."""
    return _env_float("GEARTE_MAX_SECONDS", _DEFAULTS["GEARTE_MAX_SECONDS"])


def max_sweep_points() -> int:
    """Largest sweep grid (``GEARTE_MAX_SWEEP_POINTS``, default 1000)."""
    return int(_env_float("GEARTE_MAX_SWEEP_POINTS", _DEFAULT_SWEEP_POINTS))


def no_worker_timeout_s() -> float:
    """Seconds sampled work waits on a Dask cluster without any worker before the cluster counts
    as lost [s] (``GEARTE_NO_WORKER_TIMEOUT_S``, default 300; ``0`` waits forever)."""
    text = os.environ.get("GEARTE_NO_WORKER_TIMEOUT_S", "").strip()
    if text in ("0", "0.0"):
        return 0.0
    return _env_float("GEARTE_NO_WORKER_TIMEOUT_S", _DEFAULT_NO_WORKER_S)


def check_memory(field: str, value: Any, nbytes: float, what: str) -> None:
    """Raise :class:`ParameterError` when ``nbytes`` exceeds the memory budget.

    Parameters
    ----------
    field : str
        The input the budget check is about (named in the error).
    value : Any
        Its value (echoed in the error).
    nbytes : float
        Estimated memory need [bytes].
    what : str
        What needs it, for the message.

    Raises
    ------
    ParameterError
        Over the budget (``GEARTE_MAX_MEMORY_GB``).
    """
    limit = max_memory_bytes()
    if nbytes > limit:
        raise ParameterError(
            field,
            value,
            f"{what} needs about {nbytes / 1e9:.3g} GB of memory, over the budget of "
            f"{limit / 1e9:.3g} GB (raise it with GEARTE_MAX_MEMORY_GB if you mean it)",
        )


def check_time(field: str, value: Any, seconds: float, what: str) -> None:
    """Raise :class:`ParameterError` when an estimated run time exceeds the time budget.

    Parameters
    ----------
    field : str
        The input the budget check is about (named in the error).
    value : Any
        Its value (echoed in the error).
    seconds : float
        Estimated run time [s].
    what : str
        What takes it, for the message.

    Raises
    ------
    ParameterError
        Over the budget (``GEARTE_MAX_SECONDS``).
    """
    limit = max_seconds()
    if seconds > limit:
        raise ParameterError(
            field,
            value,
            f"{what} would take about {seconds:.3g} s, over the budget of {limit:.3g} s "
            "(raise it with GEARTE_MAX_SECONDS if you mean it)",
        )


def check_sweep_points(n: int) -> None:
    """Raise :class:`ParameterError` when a sweep grid has more points than allowed.

    Parameters
    ----------
    n : int
        Number of grid points [-].

    Raises
    ------
    ParameterError
        Over ``GEARTE_MAX_SWEEP_POINTS``.
    """
    limit = max_sweep_points()
    if n > limit:
        raise ParameterError(
            "--vary",
            n,
            f"the grid has {n} points, over the limit of {limit} "
            "(raise it with GEARTE_MAX_SWEEP_POINTS if you mean it)",
        )


def read_input_file(path: str | os.PathLike[str], max_bytes: int) -> bytes:
    """The bytes of an input file (a case, measurement, bench or points file), read only when
    it is a regular file of at most ``max_bytes``.

    The file is opened without blocking (a FIFO with no writer does not wait) and checked on the
    open descriptor before any byte is read: a device (``/dev/zero``, ``/dev/urandom``), a FIFO,
    a socket or a folder is refused at once, and so is a file over ``max_bytes``; a file that
    grows while it is read is cut off at ``max_bytes + 1`` bytes and refused, so no input can
    make the reader run out of memory or wait for ever.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    max_bytes : int
        Largest file accepted [bytes].

    Returns
    -------
    bytes
        The file's content.

    Raises
    ------
    OSError
        With ``strerror`` saying why: missing or unreadable (the system's reason), a folder
        (:class:`IsADirectoryError`), not a regular file, or over ``max_bytes``. ``ValueError``
        for a path the system cannot take (a NUL byte).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    name = os.fspath(path)
    fd = os.open(name, flags)
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(errno.EISDIR, "is a folder, not a file", name)
        if not stat.S_ISREG(st.st_mode):
            what = (
                "a FIFO (named pipe)"
                if stat.S_ISFIFO(st.st_mode)
                else "a device"
                if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
                else "a socket"
                if stat.S_ISSOCK(st.st_mode)
                else "not a regular file"
            )
            raise OSError(errno.EINVAL, f"is {what}, not a regular file", name)
        if st.st_size > max_bytes:
            raise OSError(
                errno.EFBIG, f"is {st.st_size} bytes; the limit is {max_bytes} bytes", name
            )
        parts: list[bytes] = []
        got = 0
        while got <= max_bytes:
            block = os.read(fd, min(1 << 20, max_bytes + 1 - got))
            if not block:
                break
            parts.append(block)
            got += len(block)
        if got > max_bytes:
            raise OSError(errno.EFBIG, f"grew past the limit of {max_bytes} bytes", name)
        return b"".join(parts)
    finally:
        os.close(fd)
