"""RV dynamics with open bearing clearances (li2023_rv_errors with cam and carrier bearing
clearances of 10 µm and more): the static equilibrium before each integration converges where
an equilibrium exists — it stopped at 100 modified-Newton iterations, and the run ended with
exit 1 naming neither key nor analysis — and a solver that does not converge names the analysis
and the clearance keys."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from gearte.errors import ConvergenceError
from gearte.io.case_file import load_case_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _case(clearance_um: float, analyses: dict | None = None):
    data = tomllib.loads((EXAMPLES / "li2023_rv_errors.toml").read_text(encoding="utf-8"))
    cranks = data["reducer"]["cranks"]
    cranks["cam_bearing"]["radial_clearance_um"] = clearance_um
    cranks["carrier_bearing"]["radial_clearance_um"] = clearance_um
    if analyses is not None:
        data["analyses"] = analyses
    return load_case_dict(data, base_dir=str(EXAMPLES))


def _model(case):
    from gearte.studies._rv_dynamics import build_dynamic_model
    from gearte.studies.rv_reducer import build_reducer

    red = build_reducer(case.reducer)
    return red, build_dynamic_model(case, red)[0]


def _residual(model, q) -> float:
    f = model.elastic_force(0.0, q) + model.external_force(0.0)
    return float(np.max(np.abs(f)) / np.max(np.abs(model.external_force(0.0))))


@pytest.mark.parametrize("clearance_um", [10.0, 50.0, 200.0])
def test_static_equilibrium_converges_with_open_clearances(clearance_um):
    """The DTE's starting point: 174 iterations at 10 µm, about 1 500 at 200 µm (was: stopped
    at 100)."""
    _, model = _model(_case(clearance_um))
    q = model.static_equilibrium(0.0)
    assert _residual(model, q) <= 1e-9


def test_batch_realisation_drifting_through_its_clearance_converges():
    """Realisation 4 of the case's batch at 10 µm: crank 1 crosses its clearance by a fixed
    step per iteration (about 34 000 iterations)."""
    from gearte.execution import spawn_generators
    from gearte.runners.rv_dynamics_sim import draw_errors
    from gearte.studies._rv_dynamics import batch_tolerances

    case = _case(10.0)
    red, model = _model(case)
    b = case.analyses.batch
    tol = batch_tolerances(red, b.tolerance_scale)
    clear = dict(
        turning_arm_clearance_mm=red.cranks.cam_bearing_clearance,
        crank_bearing_clearance_mm=red.cranks.carrier_bearing_clearance,
        output_bearing_clearance_mm=red.supports.main_bearing_clearance,
    )
    rng = spawn_generators(b.seed, b.samples)[4]
    m = model.with_errors(
        draw_errors(rng, tol, model.params.crank_count, model.params.disc_count, **clear)
    )
    q = m.static_equilibrium(0.0)
    assert _residual(m, q) <= 1e-9


def test_non_convergence_names_the_analysis_and_the_clearance_keys(monkeypatch):
    import gearte.models.rv_dynamics.assembly as assembly
    from gearte.studies import RunOptions, run_case

    monkeypatch.setattr(assembly, "STATIC_MAXIT", 20)
    case = _case(10.0, {"dte": {"duration_s": 0.01, "settle_s": 0.01}})
    with pytest.raises(ConvergenceError) as info:
        run_case(case, RunOptions(progress=False, workers=1))
    msg = str(info.value)
    assert msg.startswith("analyses.dte: static_equilibrium: modified Newton did not converge")
    assert "reducer.cranks.cam_bearing.radial_clearance_um = 10" in msg
    assert "reducer.cranks.carrier_bearing.radial_clearance_um = 10" in msg
    assert "operation.output_torque_Nm" in msg
