"""The batched RV solver (many reducers × steps in one compiled call) against the per-case one."""

from __future__ import annotations

import numpy as np
import pytest

import gearte
from gearte.runners import rv_yield_batch as rb
from gearte.runners.yield_models import RVReducerYield, rv_error_keys
from gearte.solvers.rv_batch import solve_batch
from gearte.studies.rv_reducer import build_reducer
from gearte.tolerance.yield_mc import Tolerance, ToleranceSet


def _reducer(clearance_um: float = 0.0):
    case = gearte.load_case("han2023_rv110e")
    red = case.reducer
    if clearance_um:
        cb = red.cranks.cam_bearing.model_copy(update={"radial_clearance_um": clearance_um})
        red = red.model_copy(update={"cranks": red.cranks.model_copy(update={"cam_bearing": cb})})
    return build_reducer(red)


def _every_family(red) -> ToleranceSet:
    """A tolerance on every error family the batch maps (eccentricities, disc run-out and
    pitch, seats, pins, per-disc modifications)."""
    keys = rv_error_keys(red)
    tols = []
    for fam in (
        "cam",
        "disc_crank_bore",
        "carrier_crank_bore",
        "planet_base_circle",
        "disc_radial_runout",
        "disc_cumulative_pitch",
        "sun_eccentricity",
        "sun_assembly",
        "output_assembly",
    ):
        tols += [Tolerance(k, "rayleigh", 6.0, phase=True, family=fam) for k in keys[fam]]
    for fam in (
        "pins.radius_errors",
        "pins.radial_position_errors",
        "pins.tangential_position_errors",
        "discs.equidistant_modification_errors",
        "discs.shift_modification_errors",
    ):
        tols += [Tolerance(k, "normal", 4.0, family=fam) for k in keys[fam]]
    return ToleranceSet(tuple(tols))


@pytest.mark.parametrize("clearance_um", [0.0, 4.0], ids=["no_clearance", "cam_clearance"])
def test_batched_rv_yield_equals_the_per_case_solver_on_sampled_reducers(clearance_um):
    """Three reducers drawn with every error family: the batched solver (rows mapped from the
    drawn errors, condensed, all steps in one call) gives the per-sample path's catalogue values,
    TE, pin load and pressure. The per-sample path solves each reducer's positions through the
    same kernel (``solve_positions``' default, Newton on the exact law): to 1e-9 relative; with
    the secant fixed point (the former per-case algorithm) to 1e-9 relative or 1e-9 arcmin (the
    fixed point stops at a relative stiffness change of 1e-9: that is its own accuracy)."""
    red = _reducer(clearance_um)
    per_case = RVReducerYield(red, positions=12, batched=False)
    batched = RVReducerYield(red, positions=12)
    errs = _every_family(red).sample(np.random.default_rng(7), 3)
    ref = per_case(errs)
    fixed_point = rb.batch_quantities(batched, errs, 3, exact=False)
    newton = batched(errs)
    for k, v in ref.items():
        np.testing.assert_allclose(newton[k], v, rtol=1e-9, atol=0.0, err_msg=k)
        np.testing.assert_allclose(fixed_point[k], v, rtol=1e-9, atol=1e-9, err_msg=k)
    assert np.ptp(ref["angular_te [arcmin]"]) > 0  # the samples differ


def test_batched_solver_compiled_equals_its_plain_twin():
    red = _reducer()
    model = RVReducerYield(red, positions=2)
    errs = _every_family(red).sample(np.random.default_rng(1), 1)
    p = rb.cached_plan(model, list(errs))
    h, en, gap = rb.batch_inputs(model, p, errs, 1)
    steps = slice(16, 18)  # the loaded TE at both positions
    args = (p.problem, h, en, gap, p.step_g[steps], p.step_T[steps], p.cold[steps])
    a = solve_batch(*args, p.record[steps])
    b = solve_batch(*args, p.record[steps], compiled=False)
    np.testing.assert_allclose(b.output, a.output, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(b.forces, a.forces, rtol=1e-9, atol=1e-9)


def test_batched_error_rows_are_linear_in_the_drawn_errors():
    """The maps from drawn errors to spring offsets and clearances reproduce the model's own
    assembly of a sampled reducer (so the batch sees the same physics)."""
    from gearte.models.rv_load_sharing import assemble

    red = _reducer()
    model = RVReducerYield(red, positions=4)
    errs = _every_family(red).sample(np.random.default_rng(3), 2)
    p = rb.cached_plan(model, list(errs))
    _, _, gap = rb.batch_inputs(model, p, errs, 2)
    for s in range(2):
        one = model.reducer_for({k: float(v[s]) for k, v in errs.items()})
        sys_ = assemble(one, p.theta)
        np.testing.assert_allclose(gap[s], sys_.contact_gap, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    ("law_name", "clearance_um"),
    [("line_contact", 0.0), ("hu2020", 0.0), ("line_contact", 10.0)],
    ids=["per_contact_law", "per_disc_law", "cam_clearance"],
)
def test_solve_positions_batched_equals_the_per_position_solver(law_name, clearance_um):
    """``solve_positions``' default (the positions as the steps of one batched-kernel sample,
    condensed, exact-law Newton) against its dense per-position kernel (the secant fixed point)
    on han2023_rv110e with its measured errors: displacements, pin forces, the loaded pins'
    secant stiffness and the per-disc stiffness to 1e-9 relative (the fixed point's tolerance),
    cold and warm-started; the plain-Python twin of the batched path to round-off."""
    from gearte.models.rv_load_sharing import assemble, contact_law, output_positions, solver_law
    from gearte.solvers.rv_batch import solve_positions

    red = _reducer(clearance_um)
    system = assemble(red, output_positions(5))
    law = solver_law(red, system, contact_law(red, law_name))
    T = red.rated_torque
    ref = solve_positions(system, T, law, method="per_position")
    start = {"q0": ref.q[2], "k0": ref.contact_stiffness[2]}
    for kw in ({}, start):
        a = solve_positions(system, T, law, **kw)
        b = solve_positions(system, T, law, method="per_position", **kw)
        scale = np.abs(b.q).max(axis=0)
        np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-9 * scale.max())
        fmax = b.contact_force.max()
        np.testing.assert_allclose(a.contact_force, b.contact_force, rtol=0, atol=1e-9 * fmax)
        loaded = b.contact_force > 1e-6 * fmax
        np.testing.assert_allclose(a.pin_stiffness[loaded], b.pin_stiffness[loaded], rtol=1e-9)
        np.testing.assert_allclose(a.contact_stiffness, b.contact_stiffness, rtol=1e-9)
    twin = solve_positions(system, T, law, compiled=False)
    np.testing.assert_allclose(twin.q, solve_positions(system, T, law).q, rtol=1e-12, atol=1e-18)


@pytest.mark.parametrize("law_name", ["line_contact", "hu2020"], ids=["per_contact", "per_disc"])
def test_solve_system_restart_equals_one_call_per_sweep(law_name):
    """``solve_system(..., restart=L)`` (the TE's refinement windows in one kernel call): every
    array of the solution bit for bit that of one ``solve_system`` call per sweep of ``L``
    positions, each warm-started from its row of ``q0``/``k0`` — the per-contact law's secant
    stiffnesses included (their "last loaded" does not reach across sweeps)."""
    from gearte.models.rv_load_sharing import assemble, contact_law, output_positions, solver_law
    from gearte.solvers.rv_batch import solve_system

    red = _reducer(4.0)
    coarse_sys = assemble(red, output_positions(6))
    law = contact_law(red, law_name)
    T = red.rated_torque
    coarse = solve_system(coarse_sys, T, solver_law(red, coarse_sys, law))
    L, near = 5, [1, 4, 2]
    thetas = [coarse_sys.theta[n] + np.linspace(0.0, 0.02, L) for n in near]
    whole = assemble(red, np.concatenate(thetas))
    a = solve_system(
        whole,
        T,
        solver_law(red, whole, law),
        q0=coarse.q[near],
        k0=coarse.contact_stiffness[near],
        restart=L,
    )
    for i, (th, n) in enumerate(zip(thetas, near, strict=True)):
        one = assemble(red, th)
        b = solve_system(
            one, T, solver_law(red, one, law), q0=coarse.q[n], k0=coarse.contact_stiffness[n]
        )
        rows = slice(i * L, (i + 1) * L)
        for name in ("q", "contact_force", "contact_stiffness", "iterations", "pin_stiffness"):
            np.testing.assert_array_equal(getattr(a, name)[rows], getattr(b, name), err_msg=name)


def test_solve_system_restart_checks_its_inputs():
    from gearte.errors import ParameterError
    from gearte.models.rv_load_sharing import assemble, output_positions, solver_law
    from gearte.solvers.rv_batch import solve_system

    red = _reducer()
    system = assemble(red, output_positions(6))
    law = solver_law(red, system, None)
    with pytest.raises(ParameterError, match="restart"):
        solve_system(system, red.rated_torque, law, restart=4)  # 6 positions: not a multiple
    with pytest.raises(ParameterError, match="q0 and k0"):
        solve_system(system, red.rated_torque, law, restart=3)


def test_batched_rv_yield_equals_the_per_case_solver_on_a_shifted_profile():
    """hu2020_rv80e_initial_reducer (shifted modification Δr_p = −0.0437 mm): the rows take the
    normals and arms at the true contact point of the design's profile, the same for every
    sample; drawn modification errors of the discs enter the clearances only. The batch gives
    the per-sample path's values, pin pressures (the flank curvature at the true contact point)
    included: to 1e-9 relative or 1e-9 absolute (the backlash of a preloaded sample is ~6e-4
    arcmin)."""
    red = build_reducer(gearte.load_case("hu2020_rv80e_initial_reducer").reducer)
    keys = rv_error_keys(red)
    tols = [Tolerance(k, "rayleigh", 6.0, phase=True, family="cam") for k in keys["cam"]]
    for fam in ("discs.equidistant_modification_errors", "discs.shift_modification_errors"):
        tols += [Tolerance(k, "normal", 4.0, family=fam) for k in keys[fam]]
    errs = ToleranceSet(tuple(tols)).sample(np.random.default_rng(3), 3)
    ref = RVReducerYield(red, positions=6, batched=False)(errs)
    new = RVReducerYield(red, positions=6)(errs)
    for k, v in ref.items():
        np.testing.assert_allclose(new[k], v, rtol=1e-9, atol=1e-9, err_msg=k)
    assert np.ptp(ref["angular_te [arcmin]"]) > 0  # the samples differ
