"""Physical-plausibility checks made at validation time (issue 15 item 6).

A value can lie inside its schema range and still be impossible for the drive it is given for:
a torque typed in N·mm where the key asks for N·m passes ``torque_Nm <= 1e6`` on a small reducer
and fails only in ``run`` (or gives a result no material could carry). These checks relate such a
value to the drive's size and refuse it at ``gearte validate``, naming the key and the value in
the user's units.

A study kind checks its case with a ``plausibility(case)`` function (found by name, as its
``preflight``: :func:`implausible_values`), building its drive with its own builder. Torque against
size (``cycloid_stage``, ``rv_reducer``, :func:`torque_problem`): the torque a disc carries is
turned into the force on the most loaded pin with Hu et al. (2020) eq 30 (all z_p/2 pins of the
loaded flank share the torque: F = 4 T_c / (K1 z_c r_p), a lower bound of the real F_max) and into
the largest Hertz line-contact pressure of that pin on the flank at its first-contact phase φ0
(Johnson eq 4.45; :func:`gearte.models.contact_law.pin_pressure_estimate`, re-exported here). Above
:data:`MAX_CONTACT_PRESSURE_MPA` no steel carries the load even once (through-hardened bearing
steel: about 4 000 MPa static line contact, ISO 76), so the torque is refused with the pressure and
the torque read as N·mm beside it. A torque that is high but possible is left to the analyses (and
to ``allowable_contact_pressure_MPa``, which warns).

References
----------
Hu Y., Li G., Zhu W., Cui J. (2020). Applied Sciences 10(2), 481. doi:10.3390/app10020481
Johnson K. L. (1985). Contact Mechanics, eq 4.45. doi:10.1017/CBO9781139171731
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gearte.errors import ParameterError

# re-exported: the table, the ceiling and the estimate live in lower layers, where the model API
# checks them too (gearte.models.rv_load_sharing.check_reducer_torque)
from gearte.limits import FLOORS, MAX_CONTACT_PRESSURE_MPA

if TYPE_CHECKING:  # pragma: no cover
    from gearte.models.contact_law import pin_pressure_estimate

__all__ = [
    "FLOORS",
    "MAX_CONTACT_PRESSURE_MPA",
    "implausible_values",
    "pin_pressure_estimate",
    "plausibility_problems",
    "torque_problem",
]


def __getattr__(name: str) -> Any:
    # imported on first use: gearte.models.contact_law imports numba (~0.3 s), which validating
    # a case of a kind without a torque check (or without any kernel) must not pay
    if name == "pin_pressure_estimate":
        from gearte.models.contact_law import pin_pressure_estimate

        return pin_pressure_estimate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def torque_problem(
    field: str, torque_Nm: float, stage: Any, share: float, E: float, nu: float
) -> tuple[str, float, str] | None:
    """``(field, torque [N·m], reason)`` when ``torque_Nm`` on one disc's share of the stage
    loads its most loaded pin beyond any steel (:data:`MAX_CONTACT_PRESSURE_MPA`), else ``None``.

    Parameters
    ----------
    field : str
        The key named in the message.
    torque_Nm : float
        The torque as given [N·m].
    stage : CycloidStage
        The stage (built by its kind's one builder).
    share : float
        Share of the torque one disc carries [-].
    E : float
        Young's modulus [MPa].
    nu : float
        Poisson's ratio [-].
    """
    from gearte.models.contact_law import implausible_pin_pressure
    from gearte.units import Nm_to_Nmm

    reason = implausible_pin_pressure(stage, float(Nm_to_Nmm(torque_Nm)), share, E, nu)
    if reason is None:
        return None
    return (
        field,
        torque_Nm,
        f"{reason}; was it given in N·mm? ({torque_Nm:g} N·mm = {torque_Nm / 1000:g} N·m)",
    )


def implausible_values(kind: str, case: Any) -> list[tuple[str, float, str]]:
    """``(field, value, reason)`` for each implausible value of a validated ``case`` of
    ``kind``: the value in the key's unit (every check so far is a torque's, [N·m]) and why it
    is refused (``"is implausible for this stage: ..."``).

    Parameters
    ----------
    kind : str
        The study kind.
    case : Case
        The case (validated; its sections may be placeholders of sections that did not validate,
        whose use stops the check: see ``gearte.io.case_file``).

    Returns
    -------
    list of (str, float, str)
        Empty when every value is plausible, or when the drive itself cannot be built (the
        schema's own checks report that).
    """
    from gearte.io.kinds import get_kind

    try:
        check = getattr(get_kind(kind), "plausibility", None)
    except KeyError:
        return []
    if check is None:
        return []
    try:
        return list(check(case))
    except (ParameterError, ValueError):  # the geometry itself is refused: the schema says so
        return []


def plausibility_problems(kind: str, case: Any) -> list[tuple[str, str]]:
    """``(field, message)`` for each implausible value of a validated ``case`` of ``kind``
    (:func:`implausible_values`, the message led by the value: ``"500000 N·m is implausible
    ..."``).

    Parameters
    ----------
    kind : str
        The study kind.
    case : Case
        The case (validated; see :func:`implausible_values`).

    Returns
    -------
    list of (str, str)
        Empty when every value is plausible or the drive cannot be built.
    """
    return [(f, f"{v:g} N·m {reason}") for f, v, reason in implausible_values(kind, case)]
