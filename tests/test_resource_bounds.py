"""Resource bounds decided at validation time (issue 13): every input that sizes an allocation or
a loop is bounded, and combinations are checked by a memory/time estimate before any work, with an
error naming the override."""

from __future__ import annotations

import tomllib

import pytest
from click.testing import CliRunner

from gearte.cases import case_path
from gearte.cli import EXIT_BAD_INPUT, main
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case_dict


def _eq9() -> dict:
    return tomllib.loads(case_path("wang2013_2kh_eq9").read_text(encoding="utf-8"))


@pytest.mark.parametrize("frequency", [1000000.0, 0.1234567, "1/123457"])
def test_reproducer_planetary_frequency_is_bounded_at_validation(frequency):
    """Issue 13 reproducer: ``frequency = 1000000.0`` (or ``0.1234567``) passed validate and
    then allocated > 5 GB; now it is a case error naming the term's frequency."""
    data = _eq9()
    data["errors"]["terms"][0]["frequency"] = frequency
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    (field, msg), *_ = err.value.errors
    assert field == "errors.terms.0.frequency" and "<=" in msg


def test_planetary_grid_memory_is_estimated_before_work():
    """Two terms each within bounds whose common period is huge (10000 and 1/9973 x input:
    largest harmonic ~1e8) are refused by the estimate, naming the override."""
    data = _eq9()
    data["errors"]["terms"][0]["frequency"] = 10000
    data["errors"]["terms"][1]["frequency"] = "1/9973"
    with pytest.raises(CaseFileError, match="GEARTE_MAX_MEMORY_GB") as err:
        load_case_dict(data)
    assert "errors.terms.frequency" in str(err.value)


def test_planetary_time_is_estimated_before_work(monkeypatch):
    data = _eq9()
    data["analyses"]["monte_carlo"] = {"samples": 100_000_000}
    monkeypatch.setenv("GEARTE_MAX_SECONDS", "1")
    with pytest.raises(CaseFileError, match="GEARTE_MAX_SECONDS"):
        load_case_dict(data)
    monkeypatch.delenv("GEARTE_MAX_SECONDS")
    load_case_dict(data)  # the default budget allows it


def test_budget_override_must_be_a_positive_number(monkeypatch):
    from gearte.limits import max_memory_bytes

    monkeypatch.setenv("GEARTE_MAX_MEMORY_GB", "lots")
    with pytest.raises(ParameterError, match="GEARTE_MAX_MEMORY_GB"):
        max_memory_bytes()


def test_samples_option_obeys_the_case_cap():
    """``--samples 10**12`` was accepted although the case field caps at 10**10."""
    r = CliRunner().invoke(main, ["run", "jiang2024_spur_pair", "--samples", str(10**12)])
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert "--samples" in r.output and "monte_carlo_samples" in r.output


@pytest.mark.parametrize(
    "vary", [["demo.length_mm=1:2:100000"], ["demo.length_mm=1:2:100", "demo.x=1:2:100"]]
)
def test_sweep_points_are_capped_before_the_grid_is_built(tmp_path, vary):
    case = tmp_path / "c.toml"
    case.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    args = ["sweep", str(case), "--out", str(tmp_path / "o")]
    for v in vary:
        args += ["--vary", v]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert "GEARTE_MAX_SWEEP_POINTS" in r.output and not (tmp_path / "o").exists()


def _case_dict(name: str) -> dict:
    return tomllib.loads(case_path(name).read_text(encoding="utf-8"))


def test_samples_caps_every_secondary_count_never_below_its_lower_bound():
    """``--samples N`` caps each count of sampled work it does not set: Sobol base samples,
    bootstrap, kept worst samples, allocation samples, random assemblies, diagnosis draws,
    speed-sweep points, quasi-random starts (each at least the field's own lower bound)."""
    from gearte.studies import RunOptions, sample_cap
    from gearte.studies._rv_dynamics import SpeedSweepOptions
    from gearte.studies._yield import AllocationEntry, YieldSection
    from gearte.studies.planetary import AssemblyOptions
    from gearte.studies.rv_bench import DiagnosisSection
    from gearte.studies.rv_lot import SelectiveAssemblySection

    four = RunOptions(samples=4)
    y = YieldSection(sobol_samples=2000, bootstrap=100, keep_worst=3)
    assert sample_cap(y, "bootstrap", four) == 4 and sample_cap(y, "keep_worst", four) == 3
    assert sample_cap(y, "sobol_samples", four, low=50) == 50
    assert sample_cap(y, "bootstrap", RunOptions()) == 100  # no override: the case's count
    alloc = AllocationEntry(target_yield=0.9, costs={"a": {"b": 1.0}}, samples=5000)
    assert sample_cap(alloc, "samples", four) == 100  # ge=100
    assert sample_cap(DiagnosisSection(draws=2000), "draws", four) == 100
    assert sample_cap(SpeedSweepOptions(count=100), "count", four) == 4
    assert sample_cap(SpeedSweepOptions(count=100), "count", RunOptions(samples=1)) == 2
    assert sample_cap(AssemblyOptions(starts=4096), "starts", four) == 16
    sa = SelectiveAssemblySection.model_fields["random_assemblies"]
    assert any(getattr(m, "ge", None) == 100 for m in sa.metadata)


def test_samples_caps_the_sobol_and_allocation_runs_of_a_yield(monkeypatch):
    """Issue 13: ``han2023_rv110e_yield``'s Sobol indices (and an allocation's search) ran their
    full counts under ``--samples``, past the fuzzing time-out; now they are capped."""
    import gearte.tolerance.allocation as allocation
    import gearte.tolerance.yield_contributions as yc
    from gearte.studies import RunOptions, run_case

    seen: dict[str, int] = {}
    real_sobol, real_allocate = yc.sobol_tolerances, allocation.allocate

    def sobol(model, ts, q, n, **kw):
        seen["sobol"], seen["bootstrap"] = n, kw["bootstrap"]
        return real_sobol(model, ts, q, n, **kw)

    def allocate(*a, **kw):
        seen["allocation"] = kw["n"]
        return real_allocate(*a, **kw)

    monkeypatch.setattr(yc, "sobol_tolerances", sobol)
    monkeypatch.setattr(allocation, "allocate", allocate)
    data = _case_dict("hu2020_rv80e_yield")
    data["analyses"]["yield"]["sobol_samples"] = 5000
    res = run_case(data, RunOptions(progress=False, samples=60, workers=1))
    (y,) = [a for a in res.analyses if a.name == "yield"]
    assert y.values["samples"] == 60
    # sobol and bootstrap capped at 60; allocation not below what can show 0.99 (381)
    assert seen == {"sobol": 60, "bootstrap": 60, "allocation": 381}


@pytest.mark.parametrize(
    ("name", "where", "value", "key"),
    [
        ("hu2020_rv80e_yield", ("analyses", "yield", "sobol_samples"), 10, "sobol_samples"),
        ("jiang2024_spur_pair", ("analysis", "sobol_samples"), 20, "sobol_samples"),
        ("hu2020_rv80e_yield", ("analyses", "yield", "allocation", "samples"), 200, "381"),
        ("hu2020_rv80e_yield", ("analyses", "yield", "spec"), {}, "spec limit"),
    ],
)
def test_sample_counts_run_would_refuse_are_refused_by_validate(name, where, value, key):
    """``sobol_samples = 10`` passed validate and failed in ``run`` (a Sobol estimate needs 50
    base samples, 100 for a gear pair); an allocation search too small to show its target
    yield or without a spec limit failed after the Monte-Carlo. They are case errors now, naming
    the key."""
    data = _case_dict(name)
    node = data
    for k in where[:-1]:
        node = node[k]
    node[where[-1]] = value
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    assert any(key in f"{field}: {msg}" for field, msg in err.value.errors), err.value.errors


def test_allocation_cost_of_an_unknown_tolerance_is_refused_before_the_monte_carlo(monkeypatch):
    """The check needs the drive's tolerance families (known when the analysis starts): it now
    runs before the yield Monte-Carlo, not after it and the Sobol indices."""
    import gearte.tolerance.yield_mc as yield_mc
    from gearte.studies import RunOptions, run_case

    def no_work(*a, **kw):
        raise AssertionError("the Monte-Carlo ran before the check")

    monkeypatch.setattr(yield_mc, "run_yield", no_work)
    data = _case_dict("hu2020_rv80e_yield")
    data["analyses"]["yield"]["allocation"]["costs"]["nonsense"] = {"b": 1.0}
    with pytest.raises(ParameterError, match="allocation.costs.nonsense"):
        run_case(data, RunOptions(progress=False, samples=60, workers=1))


@pytest.mark.parametrize(
    ("key", "match"),
    [
        ("planet_mass_kg", "reducer.dynamics"),  # no finite elastic mode (was IndexError, exit 3)
        ("sun_inertia_kgm2", "RK4 integration of"),  # ~1e151 steps (was OverflowError, exit 3)
    ],
)
def test_absurd_dynamics_inertia_is_bad_input_before_any_step(key, match, monkeypatch):
    """Found by the fuzzing run through ``gearte run``: a mass or inertia of 1e-300 passes its
    schema bound (> 0); the dynamics then failed with an internal error. Now a clear error
    naming the dynamics input, or the step count against the time budget, before integrating."""
    from gearte.studies import RunOptions, run_case

    monkeypatch.setenv("GEARTE_MAX_SECONDS", "20")
    data = _case_dict("li2023_rv_unmodified")
    data["reducer"]["dynamics"][key] = 1e-300
    with pytest.raises(ParameterError, match=match) as err:
        run_case(data, RunOptions(progress=False, samples=4, workers=1))
    assert "\n" not in str(err.value)
