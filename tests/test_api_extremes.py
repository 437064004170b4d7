"""Extreme values through the public model API: the Python twin of the case files' sweep.

``python tests/fuzzing.py --count -1`` (docs/errors.md, "The extreme-value sweep and the
plausibility floors") sets every number of every bundled case file to 1e-300, × 1e-9 and × 1e9;
the case-file path refuses each impossible value at validation. A user of the Python API passes
the same physical sizes as plain arguments, so here each numeric argument of the public model
functions a user calls with a load torque, a modulus or a stiffness is set in turn to 1e-300,
× 1e-9 and × 1e9 of a real value (and to 0, -1, NaN and inf where the function documents a
domain for it), the others left at that real value. Each call must either return finite numbers
or raise a :class:`gearte.errors.GearteError` that names the argument: no other exception type,
no NaN or inf in a result, no message naming another input. The plausibility floors of the case
files (``gearte.limits.FLOORS``, converted to the function's unit) decide what is refused.

What the sweep found before (each now refused, naming the argument):

* ``tooth_contact``, ``contact_law="hu2020"``, compiled: ``ZeroDivisionError`` at
  ``torque=1e-300``, at ``disc_share=1e-300`` and at ``E=1e300`` with a torque of 1e6 or 1e30
  N·mm (at 1 N·mm a ``ConvergenceError`` naming no input, at 1e300 N·mm non-finite results);
  with either law at ``mu=-1`` (``contact_modulus``: 1 − ν² = 0). ``E=1e-300`` was named
  ``F_start`` and ``E × 1e-9`` ``torque``; a torque of 1e30 N·mm was named ``F_start``
  (``"hu2020"``); ``E=1e300`` gave non-finite results (``"line_contact"``).
* The compiled rotation solver of ``tooth_contact(contact_law="line_contact")`` and
  ``loaded_contact`` returned, for a torque beyond the contact law's range (× 1e9, and torques
  from about 1e9 N·mm up on the bundled stages), a finite "solution" whose pins carried
  5 % – 1e-7 of the torque; now the torque balance is checked and the torque named.
* ``contact_modulus(E, nu=-1)``: ``ZeroDivisionError``; ``half_width``: inf or NaN for E ≤ 0,
  a NaN E or ν, ν × 1e9; ``loaded_contact``: its out-of-range error named ``torque``, not
  ``torque_Nmm``.
* ``rv_load_sharing.contact_law(stiffness=...)`` accepted 0, -1, NaN, inf and 1e-300 N/mm (a
  linear law of 1e-300 N/mm gave an output error of -4e8 rad); ``transmission_error`` at × 1e9
  of the rated torque ended in a ``ConvergenceError`` that named no input.
* ``rv_load_sharing.load_sharing`` beyond the pin contact law's range returned finite numbers
  that passed the finiteness check but were wrong (han2023_rv110e, one position: the discs'
  moments sum to 0.963 of the torque at the rated torque and up to 1e8 N·mm, to 0.38 at 1e9,
  0.04 at 1e10 and 0 at × 1e9, with an output error of -4e5 rad). Now ``load_sharing`` and
  ``transmission_error`` refuse a torque whose estimated pin pressure exceeds the case files'
  ceiling (``gearte.limits.MAX_CONTACT_PRESSURE_MPA``, 10 000 MPa: about 1.4e8 N·mm on
  han2023_rv110e), naming ``torque``; the ``rv_catalogue`` functions refuse such a rated torque,
  naming ``reducer.rated_torque``.
* ``rectangular_mesh_stiffness_fourier`` and ``cycloid_mesh_stiffness_fourier`` accepted NaN,
  inf, 0 and negative stiffnesses (now: finite and > 0; no floor, the values are derived, e.g.
  a mesh stiffness at its floor over the contact ratio).
* ``hysteresis_values(rated_torque=1e-300)``: a division by zero (an infinite rigidity);
  ``torsional_rigidity`` of branches split at the real rated torque, given 1e-300, × 1e9 or 0 of
  it: a division by zero, NaN or inf for NaN or inf; ``lost_motion`` and ``backlash_at_zero``
  read anything (1.3 rad of lost motion at × 1e9).

Covered (argument: values):

* ``cycloid_contact.tooth_contact`` — both contact laws, both implementations: ``torque``,
  ``disc_share``, ``E``, ``mu``: all seven values.
* ``cycloid_contact``: ``compliance_constants``, ``half_width``, ``max_normal_deformation``
  (``E``, ``mu``: all seven; the force ``F``: the three scales); ``start_force`` (``T_c``: the
  three scales, no domain documented).
* ``contact_law``: ``contact_modulus``, ``hertz_half_width``, ``max_contact_pressure``, and for
  both laws ``log_law_coefficients``, ``approach``, ``secant_stiffness``, ``tangent_stiffness``,
  ``force``: ``E``, ``nu``: all seven; the force ``F`` or the approach ``delta``: the three
  scales (``force`` at × 1e9 of the approach: inf by contract, checked on its own).
* ``cycloid_loaded_contact``: ``CycloidPinPair(youngs_modulus_MPa, poisson_ratio)`` (then
  solved), ``loaded_contact(torque_Nmm)`` (both laws), ``mesh_period_contact(torque_Nmm)``:
  all seven.
* ``rv_load_sharing``: ``load_sharing(torque)`` (signed, 0 included: its documented domain is
  "finite"), ``transmission_error(torque)`` ("> 0"), ``contact_law(stiffness)`` with the
  ``"linear"`` law, then solved: all seven; both torques also at 1e9 and 1e10 N·mm, and the
  discs' moments against the torque's balance identity at 1e8 N·mm.
* ``rv_catalogue``: ``torsion_test``, ``backlash``, ``virtual_loop``, ``catalogue_values`` with
  the reducer's rated torque × 1e9.
* ``catalogue``: ``hysteresis_values(rated_torque)`` and, on branches split at the real rated
  torque, ``torsional_rigidity``, ``lost_motion``, ``backlash_at_zero``: all seven.
* ``rv_dynamics``: ``rectangular_mesh_stiffness_fourier(single_pair_stiffness)``,
  ``cycloid_mesh_stiffness_fourier(mean_N_per_mm)``: all seven.

Left, and why:

* ``load_sharing`` between the pressure ceiling and the end of the pin law's range: the
  ceiling is an estimate, not the solver's residual. On han2023_rv110e the discs' moments still
  balance the torque at 3e8 N·mm (about 14 700 MPa) and stop at 5e8 (0.73 of the torque), so
  nothing the ceiling lets through is wrong there; another design's margin is not checked.
* The force, approach and arm arrays (``F``, ``delta``, ...) of the one-equation functions
  beyond their three scales: element-wise array inputs, not a torque, modulus or stiffness.
* ``solvers.contact.solve_rotation`` / ``cycloid_loaded_contact.solve_rotation``: reached through
  ``loaded_contact`` (the same wrapper); their other inputs are solver arrays.
* ``rv_dynamics.disc_rotation_error(torque_per_disc)``, ``errors_from_reducer(output_torque_Nm)``:
  only their refusals (a torque beyond the pins' ceiling, 0, -1, NaN, inf on han2023_rv110e with
  one oversize pin), not the scales they accept: the loaded-rotation solve behind them takes
  seconds per call.
* ``rv_compensation.compensate(torque)``: an optimiser running ``load_sharing`` hundreds of times
  (its torque goes to ``transmission_error``, which checks it); ``read_catalogue`` passes its
  ``rated_torque`` to ``hysteresis_values`` (covered).
* Parameter objects with many fields (``RVDynamicsParameters``, ``ReducedRV``, the
  ``gearte.geometry`` descriptions): their case-file keys are floored at validation; of their
  fields only the discs' Young's modulus (``gearte.geometry.rv.Discs``) checks its floor here.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from gearte.errors import CaseFileError, GearteError, ParameterError
from gearte.io.case_file import load_case
from gearte.limits import FLOORS, MAX_CONTACT_PRESSURE_MPA, check_floor, floor_reason
from gearte.models import catalogue as cat
from gearte.models import contact_law as cl
from gearte.models import cycloid_contact as cc
from gearte.models import cycloid_loaded_contact as lc
from gearte.models import rv_catalogue as rc
from gearte.models import rv_load_sharing as ls
from gearte.models.rv_dynamics import (
    cycloid_mesh_stiffness_fourier,
    rectangular_mesh_stiffness_fourier,
)
from gearte.studies.cycloid_stage import build_stage
from gearte.studies.rv_reducer import build_reducer
from li2023_data import li2023_pair

#: The three scales of the case-file sweep, then the domain edges a function may document.
SCALES = ("1e-300", "x1e-9", "x1e9")
EDGES = ("0", "-1", "nan", "inf")


def extreme(label: str, real: float) -> float:
    """The swept value ``label`` of an argument whose real value is ``real``."""
    return {
        "1e-300": 1e-300,
        "x1e-9": real * 1e-9,
        "x1e9": real * 1e9,
        "0": 0.0,
        "-1": -1.0,
        "nan": math.nan,
        "inf": math.inf,
    }[label]


def names(exc: GearteError, arg: str) -> bool:
    """Whether the error names ``arg``: the field of a :class:`ParameterError`, else the word
    in the message (written with spaces or underscores)."""
    if isinstance(exc, ParameterError) and exc.field == arg:
        return True
    words = {arg, arg.replace("_", " ")}
    return any(re.search(rf"(?<![\w.]){re.escape(w)}(?![\w])", str(exc)) for w in words)


def outcome(call: Callable[[], Any], arg: str, numbers: Callable[[Any], list[Any]]) -> str:
    """``"ok"`` when ``call()`` returns finite ``numbers(result)``, ``"refused"`` when it raises
    a :class:`GearteError` naming ``arg``; anything else fails the test."""
    try:
        result = call()
    except GearteError as exc:
        assert names(exc, arg), f"the error does not name {arg!r}: {type(exc).__name__}: {exc}"
        return "refused"
    for x in numbers(result):
        x = np.asarray(x, dtype=float)
        assert np.all(np.isfinite(x)), f"non-finite result for {arg}: {x}"
    return "ok"


def fields(*names_: str) -> Callable[[Any], list[Any]]:
    """The named attributes of a result (those that must be finite)."""
    return lambda r: [getattr(r, n) for n in names_]


def itself(r: Any) -> list[Any]:
    return list(r) if isinstance(r, tuple) else [r]


# --- fixtures -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def stage():
    return build_stage(load_case("hu2020_rv80e_initial").stage)


@pytest.fixture(scope="module")
def reducer():
    return build_reducer(load_case("han2023_rv110e").reducer)


@pytest.fixture(scope="module")
def pair():
    return li2023_pair(modified=True)


def _loop(tr=784e3, k=1.2e6, play=2e-4, friction=5e-5, n=101):
    """Analytic loop (as in tests/test_bench_catalogue.py): θ = T/k ± play/2 ∓ friction/2."""
    down = np.linspace(tr, -tr, n)
    t = np.concatenate([np.linspace(0, tr, n)[1:], down, down[::-1]])
    d = np.concatenate([np.ones(n - 1), -np.ones(n), np.ones(n)])
    ang = t / k + 0.5 * play * np.where(t > 0, 1, np.where(t < 0, -1, -d)) - 0.5 * friction * d
    return t, ang, d


# --- the cycloid-stage tooth contact ------------------------------------------------------------

TOOTH_REAL = {"torque": 1.078e6, "disc_share": 0.55, "E": 2.06e5, "mu": 0.3}  # Hu 2020 Table 3
TOOTH_RESULT = fields("F_max", "delta_max", "approach", "force", "pressure", "T_c", "rho")


@pytest.mark.parametrize("value", SCALES + EDGES)
@pytest.mark.parametrize("arg", list(TOOTH_REAL))
@pytest.mark.parametrize("implementation", ["numba", "plain"])
@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
def test_tooth_contact_extremes(stage, law, implementation, arg, value):
    kw = dict(TOOTH_REAL)
    kw[arg] = extreme(value, TOOTH_REAL[arg])
    torque = kw.pop("torque")

    def call():
        return cc.tooth_contact(stage, torque, contact_law=law, implementation=implementation, **kw)

    got = outcome(call, arg, TOOTH_RESULT)
    if value in ("1e-300", "0", "-1", "nan", "inf") and arg != "mu":
        assert got == "refused"  # below every floor, or outside the domain


@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
def test_tooth_contact_at_the_floors_runs_and_below_is_refused_as_in_case_files(stage, law):
    # torque 1 N·mm (= 1 mN·m), disc share 0.01, E 1000 MPa: each at its floor, all at once
    tc = cc.tooth_contact(stage, 1.0, disc_share=0.01, E=1000.0, mu=0.3, contact_law=law)
    assert all(np.all(np.isfinite(x)) for x in TOOTH_RESULT(tc))
    assert tc.T_c == pytest.approx(0.01)
    with pytest.raises(ParameterError) as err:
        cc.tooth_contact(stage, 0.5, disc_share=0.55, E=2.06e5, mu=0.3, contact_law=law)
    assert err.value.field == "torque"
    assert err.value.reason == floor_reason("load_torque", scale=1000.0, unit="N·mm")
    assert err.value.reason.startswith("must be >= 1 N·mm: below 1 mN·m")


def test_tooth_contact_e_1e300_and_huge_torques_are_named():
    """The combinations of the issue: torque 1e30 with E = 1e300, torque 1e-20 with
    disc_share = 1e-300."""
    st = build_stage(load_case("hu2020_rv80e_initial").stage)
    for law in ("hu2020", "line_contact"):
        for torque, kw, arg in (
            (1e30, {"disc_share": 0.55, "E": 1e300}, "E"),
            (1e-20, {"disc_share": 1e-300, "E": 2.06e5}, "torque"),
            (1e30, {"disc_share": 0.55, "E": 2.06e5}, "torque"),
        ):
            with pytest.raises(ParameterError) as err:
                cc.tooth_contact(st, torque, mu=0.3, contact_law=law, **kw)
            assert err.value.field == arg


# --- the one-equation functions of the contact laws ---------------------------------------------

MATERIAL = {"rho": -43.598, "r": 2.978, "E": 2.06e5, "nu": 0.3, "b": 11.0}  # Hu 2020 at φ0
CONTACT_LAW_CALLS: dict[str, tuple[Callable[..., Any], dict[str, float]]] = {
    "contact_modulus": (cl.contact_modulus, {"E": 2.06e5, "nu": 0.3}),
    "hertz_half_width": (cl.hertz_half_width, {"F": 1810.0, **MATERIAL}),
    "max_contact_pressure": (cl.max_contact_pressure, {"F": 1810.0, **MATERIAL}),
}
for _law in ("hu2020", "line_contact"):
    CONTACT_LAW_CALLS[f"log_law_coefficients/{_law}"] = (
        functools.partial(cl.log_law_coefficients, law=_law),
        dict(MATERIAL),
    )
    for _name in ("approach", "secant_stiffness", "tangent_stiffness"):
        CONTACT_LAW_CALLS[f"{_name}/{_law}"] = (
            functools.partial(getattr(cl, _name), law=_law),
            {"F": 1810.0, **MATERIAL},
        )
    CONTACT_LAW_CALLS[f"force/{_law}"] = (
        functools.partial(cl.force, law=_law),
        {"delta": 0.005, **MATERIAL},
    )
CONTACT_LAW_CASES = [
    (name, arg, value)
    for name, (_, real) in CONTACT_LAW_CALLS.items()
    for arg in ("E", "nu", "F", "delta")
    if arg in real
    for value in (SCALES + EDGES if arg in ("E", "nu") else SCALES)
    if not (arg == "delta" and value == "x1e9")  # beyond the law's range: inf by contract
]


@pytest.mark.parametrize(("name", "arg", "value"), CONTACT_LAW_CASES)
def test_contact_law_extremes(name, arg, value):
    fn, real = CONTACT_LAW_CALLS[name]
    kw = dict(real)
    kw[arg] = extreme(value, real[arg])
    got = outcome(lambda: fn(**kw), arg, itself)
    if arg == "E" and value != "inf" or arg == "nu" and value in ("-1", "nan", "inf"):
        assert got == "refused"


def test_force_beyond_the_range_of_the_law_is_inf_by_contract():
    assert np.isinf(cl.force(0.005e9, "line_contact", **MATERIAL))


CYCLOID_MATERIAL = {"rho": -43.598, "r": 2.978, "E": 2.06e5, "mu": 0.3, "b": 11.0}
CYCLOID_CALLS: dict[str, tuple[Callable[..., Any], dict[str, float]]] = {
    "compliance_constants": (
        lambda **k: cc.compliance_constants(law="hu2020", **k),
        dict(CYCLOID_MATERIAL),
    ),
    "half_width": (cc.half_width, {"F": 1910.3, **CYCLOID_MATERIAL}),
    "max_normal_deformation/hu2020": (
        lambda **k: cc.max_normal_deformation(law="hu2020", **k),
        {"F": 1910.3, **CYCLOID_MATERIAL},
    ),
    "max_normal_deformation/line_contact": (
        lambda **k: cc.max_normal_deformation(law="line_contact", **k),
        {"F": 1910.3, **CYCLOID_MATERIAL},
    ),
    "start_force": (cc.start_force, {"T_c": 5.929e5, "K1": 0.72, "z_c": 39, "r_p": 64.0}),
}
CYCLOID_CASES = [
    (name, arg, value)
    for name, (_, real) in CYCLOID_CALLS.items()
    for arg in ("E", "mu", "F", "T_c")
    if arg in real
    for value in (SCALES + EDGES if arg in ("E", "mu") else SCALES)
]


@pytest.mark.parametrize(("name", "arg", "value"), CYCLOID_CASES)
def test_cycloid_contact_helpers_extremes(name, arg, value):
    fn, real = CYCLOID_CALLS[name]
    kw = dict(real)
    kw[arg] = extreme(value, real[arg])
    outcome(lambda: fn(**kw), arg, itself)


# --- the Li 2023 loaded contact -----------------------------------------------------------------

LOADED_RESULT = fields(
    "force",
    "rotation",
    "tangential_force",
    "radial_force",
    "pressure_angle",
    "mesh_stiffness",
    "torsional_stiffness",
    "pressure",
)


@pytest.mark.parametrize("value", SCALES + EDGES)
@pytest.mark.parametrize("arg", ["youngs_modulus_MPa", "poisson_ratio"])
def test_cycloid_pin_pair_material_extremes(pair, arg, value):
    real = getattr(pair, arg)

    def call():
        p = dataclasses.replace(pair, **{arg: extreme(value, real)})
        return lc.loaded_contact(p, 225e3, 0.0)

    outcome(call, arg, LOADED_RESULT)


@pytest.mark.parametrize("value", SCALES + EDGES)
@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
def test_loaded_contact_torque_extremes(pair, law, value):
    p = dataclasses.replace(pair, contact_law=law)
    t = extreme(value, 225e3)  # N·mm per disc, paper 004 section 4.1
    outcome(lambda: lc.loaded_contact(p, t, [0.0, 0.05]), "torque_Nmm", LOADED_RESULT)


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_mesh_period_contact_torque_extremes(pair, value):
    t = extreme(value, 225e3)
    outcome(
        lambda: lc.mesh_period_contact(pair, t, 4),
        "torque_Nmm",
        fields("pressure_angle", "mesh_stiffness", "max_force"),
    )


# --- the RV reducer's load sharing --------------------------------------------------------------

LOAD_RESULT = fields(
    "pin_force", "cam_bearing_load", "mesh_force", "disc_torque", "output_error", "contact_pressure"
)


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_load_sharing_torque_extremes(reducer, value):
    t = extreme(value, reducer.rated_torque)
    got = outcome(lambda: ls.load_sharing(reducer, t, np.array([0.0])), "torque", LOAD_RESULT)
    if value in ("x1e9", "nan", "inf"):
        assert got == "refused"  # beyond what the pins carry (x1e9 returned wrong numbers)


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_transmission_error_torque_extremes(reducer, value):
    t = extreme(value, reducer.rated_torque)
    got = outcome(
        lambda: ls.transmission_error(reducer, t, np.array([0.0, 0.3]), mesh_samples=2),
        "torque",
        fields("total", "geometric", "elastic", "total_pp"),
    )
    if value in ("x1e9", "0", "-1", "nan", "inf"):
        assert got == "refused"  # beyond what the pins carry (x1e9), not > 0, or not finite


def _pressure_reason(reducer, torque: float) -> str:
    """The reason of the pin-pressure ceiling at ``torque`` [N·mm], written out from the
    estimate (the wording of ``gearte.io.plausibility`` without its N·m hint)."""
    d = reducer.discs
    p = cl.pin_pressure_estimate(
        ls.cycloid_stage(reducer), torque, 1.0 / d.count, d.youngs_modulus, d.poisson_ratio
    )
    assert p > MAX_CONTACT_PRESSURE_MPA
    return (
        f"is implausible for this stage: it gives a pin–disc contact pressure of about "
        f"{p:,.0f} MPa (ideal load share, Hu 2020 eq 30), above the 10,000 MPa no steel "
        f"carries ({torque:g} N·mm = {torque / 1000:g} N·m)"
    )


@pytest.mark.parametrize("torque", ["1e9", "1e10", "x1e9"])
@pytest.mark.parametrize("name", ["load_sharing", "transmission_error"])
def test_a_torque_beyond_what_the_pins_carry_is_refused_naming_it(reducer, name, torque):
    """han2023_rv110e, before the check: the discs' moments summed to 0.38 of the torque at 1e9
    N·mm, 0.04 at 1e10 and 0 at × 1e9 of the rated torque (output error -4e5 rad), finite."""
    t = reducer.rated_torque * 1e9 if torque == "x1e9" else float(torque)
    with pytest.raises(ParameterError) as err:
        getattr(ls, name)(reducer, t, np.array([0.0]))
    assert (err.value.field, err.value.value) == ("torque", t)
    assert err.value.reason == _pressure_reason(reducer, t)


def test_the_pin_pressure_error_at_1e10_n_mm_reads_as_documented(reducer):
    with pytest.raises(ParameterError) as err:
        ls.load_sharing(reducer, 1e10, np.array([0.0]))
    assert str(err.value) == (
        "torque = 10000000000.0: is implausible for this stage: it gives a pin–disc contact "
        "pressure of about 84,970 MPa (ideal load share, Hu 2020 eq 30), above the 10,000 MPa "
        "no steel carries (1e+10 N·mm = 1e+07 N·m)"
    )
    with pytest.raises(ParameterError, match=r"^torque = -10000000000\.0: is implausible"):
        ls.load_sharing(reducer, -1e10, np.array([0.0]))  # the magnitude counts


def test_below_the_ceiling_the_discs_moments_balance_the_torque(reducer):
    """Every pin normal passes through the pitch point P, a z_p from the reducer's centre along
    the eccentricity, so the pins' moment about a disc's centre (a from the centre) is z_c/z_p of
    their moment about the reducer's centre, the ring's reaction T (1 − 1/i) (the sun carries
    T/i): Σ M_disc = (z_c / z_p)(1 − 1/i) T, 39/40 · 80/81 = 26/27 = 0.963 on han2023_rv110e.
    It holds to round-off (1e-14 here) while the pins carry the torque; beyond the law's range it
    fell to 0.38 at 1e9 N·mm. 1e8 N·mm (8 497 MPa) lies just below the ceiling."""
    z_c, z_p, i = reducer.cycloid_teeth, reducer.pins.count, reducer.ratio
    expected = z_c / z_p * (1.0 - 1.0 / i)
    assert expected == pytest.approx(26 / 27, rel=1e-15)
    got = ls.load_sharing(reducer, 1e8, np.array([0.0, 0.7, 2.0]))
    np.testing.assert_allclose(got.disc_torque.sum(axis=1) / 1e8, expected, rtol=1e-9, atol=0)


def test_the_pin_pressure_estimate_is_the_same_through_both_import_paths(reducer, tmp_path):
    """``pin_pressure_estimate`` and ``MAX_CONTACT_PRESSURE_MPA`` moved below the model layer;
    ``gearte.io.plausibility`` re-exports them, and the case files and the API give the same
    pressure for the same torque (1e6 N·m = 1e9 N·mm on han2023_rv110e)."""
    from gearte import limits
    from gearte.io import plausibility

    assert plausibility.pin_pressure_estimate is cl.pin_pressure_estimate
    assert plausibility.MAX_CONTACT_PRESSURE_MPA == limits.MAX_CONTACT_PRESSURE_MPA == 10_000.0
    d = reducer.discs
    args = (ls.cycloid_stage(reducer), 1e9, 0.5, d.youngs_modulus, d.poisson_ratio)
    p = plausibility.pin_pressure_estimate(*args)
    assert p == cl.pin_pressure_estimate(*args)
    assert p == pytest.approx(26_870, abs=0.5)  # docs/errors.md's example
    # the case-file path: the same pressure, then its N·m hint
    from gearte.cases import case_path

    text = case_path("han2023_rv110e").read_text(encoding="utf-8")
    assert text.count("rated_torque_Nm = 1078.0") == 1
    (tmp_path / "c.toml").write_text(
        text.replace("rated_torque_Nm = 1078.0", "rated_torque_Nm = 1000000.0"), encoding="utf-8"
    )
    with pytest.raises(CaseFileError) as info:
        load_case(tmp_path / "c.toml")
    with pytest.raises(ParameterError) as api:
        ls.load_sharing(reducer, 1e9, np.array([0.0]))
    common = api.value.reason.split(" (1e+09 N·mm")[0]
    assert common.endswith("above the 10,000 MPa no steel carries")
    assert info.value.errors == [
        (
            "reducer.rated_torque_Nm",
            f"1e+06 N·m {common}; was it given in N·mm? (1e+06 N·mm = 1000 N·m)",
        )
    ]


@pytest.mark.parametrize("name", ["torsion_test", "backlash", "virtual_loop", "catalogue_values"])
def test_the_catalogue_test_refuses_a_rated_torque_beyond_what_the_pins_carry(reducer, name):
    big = reducer.replace(rated_torque=reducer.rated_torque * 1e9)
    with pytest.raises(ParameterError) as err:
        getattr(rc, name)(big)
    assert (err.value.field, err.value.value) == ("reducer.rated_torque", big.rated_torque)
    assert err.value.reason == _pressure_reason(big, big.rated_torque)


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_linear_pin_contact_stiffness_extremes(reducer, value):
    k = extreme(value, 2.0e5)  # N/mm, the default start value

    def call():
        law = ls.contact_law(reducer, "linear", stiffness=k)
        return ls.load_sharing(reducer, reducer.rated_torque, np.array([0.0]), law=law)

    got = outcome(call, "stiffness", LOAD_RESULT)
    if value != "x1e9":
        assert got == "refused"


# --- the catalogue quantities of a hysteresis curve ---------------------------------------------

TR = 784e3  # N·mm


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_hysteresis_values_rated_torque_extremes(value):
    t, a, _ = _loop(TR)
    outcome(
        lambda: cat.hysteresis_values(t, a, extreme(value, TR)),
        "rated_torque",
        fields("torsional_rigidity", "lost_motion", "backlash", "hysteresis_loss"),
    )


@pytest.mark.parametrize("value", SCALES + EDGES)
@pytest.mark.parametrize("name", ["torsional_rigidity", "lost_motion", "backlash_at_zero"])
def test_catalogue_readings_rated_torque_extremes(name, value):
    t, a, d = _loop(TR)
    branches = cat.split_branches(t, a, TR, d)
    got = outcome(lambda: getattr(cat, name)(branches, extreme(value, TR)), "rated_torque", itself)
    # every swept value is below the floor, outside the domain or beyond the branches' reach
    assert got == "refused"


# --- the mesh-stiffness excitation of the dynamics ----------------------------------------------


@pytest.mark.parametrize("value", SCALES + EDGES)
def test_mesh_stiffness_series_extremes(value):
    k = extreme(value, 4.0e5)  # N/mm, an involute single-pair stiffness
    outcome(
        lambda: rectangular_mesh_stiffness_fourier(k, 1.6, 5),
        "single_pair_stiffness",
        itself,
    )
    outcome(
        lambda: cycloid_mesh_stiffness_fourier(np.full(16, 2.0e5), 4, mean_N_per_mm=k),
        "mean_N_per_mm",
        itself,
    )


# --- the floor table and its helper -------------------------------------------------------------


def test_floors_live_in_limits_and_io_re_exports_the_same_table():
    from gearte.io import plausibility
    from gearte.io.schema import floored

    assert plausibility.FLOORS is FLOORS
    field = floored("youngs_modulus", 2.06e5)
    assert field.json_schema_extra["plausibility_floor"] == floor_reason("youngs_modulus")
    assert floor_reason("youngs_modulus").startswith("must be >= 1000 MPa: softer than any")
    assert floor_reason("disc_share").startswith("must be >= 0.01: a disc")  # "-": no unit
    check_floor("stiffness", 1.0, "linear_stiffness")  # the floor itself passes
    for bad in (0.999, math.nan, -math.inf):
        with pytest.raises(ParameterError, match=r"^k = .*: must be >= 1 N/mm: no part"):
            check_floor("k", bad, "linear_stiffness")


@pytest.fixture(scope="module")
def reducer_with_pin_errors(reducer):
    """han2023_rv110e with a 2 µm oversize pin 1: an error the dynamics turn into each disc's
    loaded rotation excitation (:func:`gearte.models.rv_dynamics.excitation.has_pin_errors`)."""
    from gearte.geometry.rv import PinRing
    from gearte.models.rv_dynamics.excitation import has_pin_errors

    p = reducer.pins
    errors = np.zeros(p.count)
    errors[0] = 2e-3
    out = reducer.replace(pins=PinRing(p.count, p.pin_radius, p.circle_radius, errors))
    assert has_pin_errors(out)
    return out


@pytest.mark.parametrize("torque", ["1e9", "1e10", "x1e9", "0", "-1", "nan", "inf"])
def test_the_dynamics_pin_error_excitation_refuses_a_torque_the_pins_cannot_carry(
    reducer_with_pin_errors, torque
):
    """``errors_from_reducer(output_torque_Nm)`` [N·m] and ``disc_rotation_error
    (torque_per_disc)`` [N·mm] have the case files' ceiling too, naming their own argument;
    before, a torque beyond the pins' law reached the loaded-rotation solve (seconds per call)
    and was refused there naming ``torque``, or passed where the solve happened to balance."""
    from gearte.models.rv_dynamics import errors_from_reducer
    from gearte.models.rv_dynamics.excitation import disc_rotation_error

    r = reducer_with_pin_errors
    n = r.discs.count
    t_nmm = r.rated_torque * 1e9 if torque == "x1e9" else float(torque)
    beyond = t_nmm > 0 and math.isfinite(t_nmm)
    # the same estimate as load_sharing's, the whole torque over the discs: "... about N MPa"
    pressure = _pressure_reason(r, t_nmm).split(" (")[0] if beyond else "must be finite and > 0"
    with pytest.raises(ParameterError) as err:
        errors_from_reducer(r, output_torque_Nm=t_nmm / 1000.0)
    assert err.value.field == "output_torque_Nm"
    assert err.value.value == t_nmm / 1000.0 or math.isnan(t_nmm)
    assert err.value.reason.startswith(pressure), err.value.reason
    with pytest.raises(ParameterError) as err:
        disc_rotation_error(r, t_nmm / n)
    assert err.value.field == "torque_per_disc"
    assert err.value.reason.startswith(pressure), err.value.reason


@pytest.mark.parametrize("torque", ["1e10", "x1e9"])
def test_the_selective_assembly_linear_model_refuses_a_torque_the_pins_cannot_carry(
    reducer, torque
):
    """``runners.selective_assembly.linear_te_model`` solves the design's equilibrium directly
    (``solve_positions``, not ``load_sharing``): it has the same ceiling, naming ``torque``."""
    from gearte.runners.selective_assembly import linear_te_model

    t = reducer.rated_torque * 1e9 if torque == "x1e9" else float(torque)
    with pytest.raises(ParameterError) as err:
        linear_te_model(reducer, t, np.array([0.0]))
    assert (err.value.field, err.value.value) == ("torque", t)
    assert err.value.reason == _pressure_reason(reducer, t)
