"""Parameter sweeps (issue 7): grid parsing, validation of every point, table and plots, CLI,
identical results on every backend (common random numbers across points)."""

from __future__ import annotations

import csv
import json
import math

import pytest
from click.testing import CliRunner

from gearte.errors import CaseFileError, ParameterError
from gearte.studies import register_kind
from gearte.sweep import grid_points, parse_vary, run_sweep, write_sweep

register_kind("mc_test", "sweep_mc_kind")

DEMO = {"case": {"kind": "foundation_test", "title": "demo"}, "demo": {"length_mm": 1.0}}
MC = {"case": {"kind": "mc_test", "title": "mc", "name": "mc"}, "mc": {"sigma_mm": 1.0}}


@pytest.mark.parametrize(
    "spec, key, values",
    [
        ("s.e_mm=1.0:1.5:6", "s.e_mm", (1.0, 1.1, 1.2, 1.3, 1.4, 1.5)),
        ("a.n=2:8:4", "a.n", (2, 4, 6, 8)),
        ("a.n=1:2:3", "a.n", (1.0, 1.5, 2.0)),
        ("a.x = 0.5", "a.x", (0.5,)),
        ("a.x=1,2.5,true,steel", "a.x", (1, 2.5, True, "steel")),
        ("a.x=3:3:1", "a.x", (3,)),
    ],
)
def test_parse_vary(spec, key, values):
    v = parse_vary(spec)
    assert v.key == key and v.values == values


@pytest.mark.parametrize(
    "spec, match",
    [
        ("a.x", "KEY=START:STOP:N"),
        ("=1:2:3", "KEY=START:STOP:N"),
        ("a.x=1:2", "START:STOP:N"),
        ("a.x=1:2:0", "integer ≥ 1"),
        ("a.x=1:2:2.5", "integer ≥ 1"),
        ("a.x=one:2:3", "numbers"),
        ("a.x=1:2:1", "one point"),
        ("a.x=1:inf:3", "finite"),
    ],
)
def test_bad_vary_specs_name_the_spec(spec, match):
    with pytest.raises(ParameterError, match=match) as err:
        parse_vary(spec)
    assert "vary" in err.value.field


def test_grid_is_full_factorial_first_key_slowest():
    pts = grid_points([parse_vary("a=1,2"), parse_vary("b=x,y,z")])
    assert [(p["a"], p["b"]) for p in pts] == [
        (1, "x"),
        (1, "y"),
        (1, "z"),
        (2, "x"),
        (2, "y"),
        (2, "z"),
    ]


def test_sweep_table_has_every_scalar_per_point():
    r = run_sweep(DEMO, {"demo.length_mm": "1:10:4", "demo.count": [2, 4]}, progress=False)
    assert len(r.points) == 8 and r.keys == ["demo.length_mm", "demo.count"]
    # arrays ("x [mm]") are left out; mappings are flattened
    assert r.columns == ["demo.total_length [mm]", "demo.map.a", "demo.n"]
    for p, total in zip(r.points, r.column("demo.total_length [mm]"), strict=True):
        # foundation kind: sum of linspace(0, L, count) = L * count / 2
        assert total == pytest.approx(p["demo.length_mm"] * p["demo.count"] / 2)
    assert all(e is None for e in r.errors)


@pytest.mark.parametrize(
    "vary, exc, field",
    [
        ({"demo.colour": "1,2"}, CaseFileError, "demo.colour"),
        ({"demo.length_mm": "-3:-1:3"}, CaseFileError, "demo.length_mm"),  # no valid point
        ({"demo.count": "1:2:3"}, CaseFileError, "demo.count"),  # 1.5 is not a count
        ({"demo.length_mm.x": "1,2"}, ParameterError, "demo.length_mm.x"),
        ({"case.kind": "x"}, ParameterError, "case.kind"),
        ({}, ParameterError, "vary"),
    ],
)
def test_bad_keys_and_values_are_clear_errors_when_no_point_is_valid(vary, exc, field):
    with pytest.raises(exc) as err:
        run_sweep(DEMO, vary, progress=False)
    assert field in str(err.value)


def test_a_failing_point_is_recorded_not_fatal(tmp_path):
    case = {**MC, "mc": {"sigma_mm": 1.0, "fail_above_mm": 2.5, "samples": 2_000}}
    r = run_sweep(case, {"mc.sigma_mm": "1:3:3"}, workers=1, progress=False)
    assert [e is None for e in r.errors] == [True, True, False]
    assert "ConvergenceError" in r.errors[2]
    assert math.isnan(r.column("error.sd [mm]")[2])
    paths = write_sweep(r, tmp_path, plots=False)
    rows = list(csv.DictReader(paths["csv"].open()))
    assert rows[2]["error"].startswith("ConvergenceError") and rows[2]["error.sd [mm]"] == ""


def _mc_sweep(**kw):
    return run_sweep(
        MC, {"mc.sigma_mm": "1,2,4", "mc.offset_mm": "0,0.5"}, seed=11, progress=False, **kw
    )


def test_sweep_results_identical_on_every_backend_and_common_random_numbers():
    ref = _mc_sweep(workers=1)
    assert ref.backend.startswith("sequential")
    for kw in ({"workers": 2}, {"scheduler": "local-cluster", "workers": 2}):
        other = _mc_sweep(**kw)
        assert other.values == ref.values, kw
    # fewer points than workers: the points run one after another, samples in parallel; an
    # executor passed in is left open for its owner
    from gearte.execution import open_executor

    with open_executor("threads", 2) as ex:
        one = run_sweep(MC, {"mc.sigma_mm": "2"}, seed=11, scheduler=ex, progress=False)
        assert "samples in parallel" in one.backend
        assert one.values[0] == ref.values[2]
        again = run_sweep(MC, {"mc.sigma_mm": "2"}, seed=11, scheduler=ex, progress=False)
        assert again.values == one.values
    # same seed at every point: sd scales exactly with sigma, mean shifts with the offset
    sd = dict(
        zip(
            [(p["mc.sigma_mm"], p["mc.offset_mm"]) for p in ref.points],
            ref.column("error.sd [mm]"),
            strict=True,
        )
    )
    assert sd[(2, 0)] == pytest.approx(2 * sd[(1, 0)], rel=1e-12)
    assert sd[(4, 0.5)] == pytest.approx(4 * sd[(1, 0)], rel=1e-12)


def test_outputs_csv_json_and_one_plot_per_varying_result(tmp_path):
    r = run_sweep(DEMO, {"demo.length_mm": "1:3:3", "demo.count": "2,3"}, progress=False)
    paths = write_sweep(r, tmp_path / "sw")
    rows = list(csv.DictReader(paths["csv"].open()))
    assert len(rows) == 6 and rows[0]["demo.length_mm"] == "1" and rows[0]["error"] == ""
    assert float(rows[5]["demo.total_length [mm]"]) == pytest.approx(4.5)
    data = json.loads(paths["json"].read_text())
    assert data["vary"] == {"demo.length_mm": [1, 2, 3], "demo.count": [2, 3]}
    assert data["points"][5]["values"]["demo.total_length [mm]"] == pytest.approx(4.5)
    # one figure per result that varies (total length; map.a and n are constant), one panel
    # per varied key
    assert data["constant_columns"] == ["demo.map.a", "demo.n"]
    assert [p.name for p in paths["plots"]] == ["demo.total_length_mm.png"]
    assert all(p.stat().st_size > 1000 for p in paths["plots"])


def test_cli_sweep_writes_outputs_and_reports_bad_keys(tmp_path):
    from gearte.cli import main

    case = tmp_path / "demo.toml"
    case.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    runner = CliRunner()
    out = tmp_path / "out"
    r = runner.invoke(
        main,
        ["sweep", str(case), "--vary", "demo.length_mm=1:2:3", "--out", str(out), "--no-progress"],
    )
    assert r.exit_code == 0, r.output
    assert "3 points" in r.output
    assert (out / "sweep.csv").is_file() and (out / "sweep.json").is_file()
    assert len(list((out / "plots").glob("*.png"))) == 1
    for bad, field in (("demo.colour=1:2:3", "demo.colour"), ("demo.length_mm", "--vary")):
        r = runner.invoke(main, ["sweep", str(case), "--vary", bad, "--out", str(out)])
        assert r.exit_code == 2, r.output
        assert field in r.output and "Traceback" not in r.output


def test_sweep_of_a_bundled_case_centre_distance_tolerance_widens_the_backlash():
    """Real kind (gear_pair, Jiang et al. 2024 spur pair): a wider centre-distance tolerance
    widens the backlash distribution; the Monte-Carlo sd follows the analytic RSS sd."""
    pytest.importorskip("gearte.studies.gear_pair")
    r = run_sweep(
        "jiang2024_spur_pair",
        {"pair.centre_distance_tol_um": "10,20,30"},
        samples=20_000,
        workers=2,
        progress=False,
    )
    assert all(e is None for e in r.errors)
    sd = r.column("backlash.backlash_sd [um]")
    mc_sd = r.column("monte_carlo.mc_backlash_sd [um]")
    assert sd[0] < sd[1] < sd[2]
    # 20 000 samples: relative standard error of an sd ≈ 1/sqrt(2n) = 0.5 %; allow 3 %
    for a, b in zip(sd, mc_sd, strict=True):
        assert b == pytest.approx(a, rel=0.03)
    # the paper's case (±20 µm) sits in the middle of the sweep
    assert r.points[1]["pair.centre_distance_tol_um"] == 20


def test_sweep_with_an_invalid_point_finishes_and_lists_it(tmp_path):
    """Issue 15.5: a point that does not validate is skipped with its reason; the others run,
    and the table, sweep.json and the index page list it."""
    r = run_sweep(DEMO, {"demo.length_mm": "-1:1:3"}, progress=False)
    assert r.statuses == ["invalid", "invalid", "ok"]
    assert r.errors[0].startswith("invalid case: demo.length_mm")
    assert r.values[0] == {} and r.values[2]["demo.total_length [mm]"] == pytest.approx(1.5)
    paths = write_sweep(r, tmp_path / "sw", plots=False)
    rows = list(csv.DictReader(paths["csv"].open()))
    assert [row["status"] for row in rows] == ["invalid", "invalid", "ok"]
    assert "demo.length_mm" in rows[0]["error"]
    data = json.loads(paths["json"].read_text())
    assert data["invalid_points"] == 2 and data["points"][0]["status"] == "invalid"
    page = paths["index"].read_text()
    assert "2 invalid" in page and "greater than 0" in page


def test_index_page_links_every_figure_that_exists(tmp_path):
    import html.parser

    r = run_sweep(
        DEMO, {"demo.length_mm": "-1:3:5", "demo.count": "2,3"}, progress=False
    )  # two invalid rows (-1, 0) beside valid ones
    paths = write_sweep(r, tmp_path / "sw")
    assert paths["plots"]

    class Links(html.parser.HTMLParser):
        def __init__(self):
            super().__init__()
            self.refs: set[str] = set()

        def handle_starttag(self, tag, attrs):
            a = dict(attrs)
            for k in ("href", "src"):
                if a.get(k) and not a[k].startswith("#"):
                    self.refs.add(a[k])

    links = Links()
    links.feed(paths["index"].read_text())
    out = tmp_path / "sw"
    on_disk = {str(p.relative_to(out)) for p in (out / "plots").glob("*.png")}
    assert on_disk and on_disk <= links.refs
    assert all((out / ref).is_file() for ref in links.refs)  # no dead link


def test_coupled_keys_vary_together():
    v = parse_vary("mc.sigma_mm,mc.offset_mm=1:0,2:0.5")
    assert v.keys == ("mc.sigma_mm", "mc.offset_mm") and v.rows == ((1, 0), (2, 0.5))
    r = run_sweep(MC, [v, parse_vary("mc.samples=1000,2000")], seed=3, workers=1, progress=False)
    # the coupled pair is one axis: 2 x 2 points, not 2 x 2 x 2
    assert [(p["mc.sigma_mm"], p["mc.offset_mm"], p["mc.samples"]) for p in r.points] == [
        (1, 0, 1000),
        (1, 0, 2000),
        (2, 0.5, 1000),
        (2, 0.5, 2000),
    ]
    assert r.coupled_with("mc.offset_mm") == ("mc.sigma_mm", "mc.offset_mm")
    assert json.loads(r.to_json())["vary"]["mc.sigma_mm,mc.offset_mm"] == [[1, 0], [2, 0.5]]
    with pytest.raises(ParameterError, match="2 values"):
        parse_vary("a,b=1:2,3")


def test_points_table_is_one_coupled_axis(tmp_path):
    from gearte.cli import main

    case = tmp_path / "demo.toml"
    case.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    table = tmp_path / "points.csv"
    table.write_text("demo.length_mm,demo.count\n1.0,2\n2.0,4\n-1.0,2\n")
    out = tmp_path / "out"
    r = CliRunner().invoke(
        main, ["sweep", str(case), "--points", str(table), "--out", str(out), "--no-progress"]
    )
    assert r.exit_code == 0, r.output
    assert "1 point(s) did not validate" in r.output and "demo.length_mm=-1.0" in r.output
    data = json.loads((out / "sweep.json").read_text())
    assert [p["status"] for p in data["points"]] == ["ok", "ok", "invalid"]
    assert data["points"][1]["values"]["demo.total_length [mm]"] == pytest.approx(4.0)
    table.write_text("demo.length_mm,demo.count\n1.0\n")
    r = CliRunner().invoke(main, ["sweep", str(case), "--points", str(table), "--out", str(out)])
    assert r.exit_code == 2 and "line 2" in r.output


def test_index_page_groups_figures_by_analysis():
    from gearte.report.sweep_page import sweep_index_html

    r = run_sweep(DEMO, {"demo.length_mm": "1:2:2"}, progress=False)
    figs = [
        ("plots/a.png", "geometry.K1 vs x", "c"),
        ("plots/b.png", "geometry.tip vs x", "c"),
        ("plots/c.png", "compensation.change vs x", "c"),
    ]
    page = sweep_index_html(r, figs)
    assert "<a href='#fig-geometry'>geometry</a> (2)" in page
    assert page.index("id='fig-geometry'") < page.index("plots/b.png")
    assert page.index("id='fig-compensation'") < page.index("plots/c.png")


def test_sweep_points_leave_no_garbage_under_gearte_collector_settings():
    """The memory of a sweep does not grow with its points: under the collector settings of
    gearte's own processes (``gearte._gc``: the older generations collected every ~10^8
    allocations), each finished point's study result — whose analyses refer back to it, a
    reference cycle — was never freed during a sweep (~2 MB per hu2020_rv80e_initial point).
    After a sweep of 6 points none of its study results is alive (it fails with 6 when the
    sweep does not free each point's cycles)."""
    import gc

    from gearte._gc import fewer_collections
    from gearte.results import StudyResult

    def is_result(o: object) -> bool:
        try:
            return isinstance(o, StudyResult)
        except ReferenceError:  # a weak proxy whose referent is gone
            return False

    def alive() -> int:
        return sum(is_result(o) for o in gc.get_objects())

    gc.collect()
    before = alive()
    with fewer_collections():
        gc.collect()
        res = run_sweep("hu2020_rv80e_initial", {"stage.eccentricity_mm": "1.3:1.7:6"}, workers=1)
        left = alive() - before
    assert len(res.points) == 6
    assert left <= 0  # (an earlier test's result freed meanwhile counts below 0)
