"""Contributions of each tolerance, compared with the paper's 3DCS Tables 3 and 7.

3DCS built a 3-D model of each mechanism whose tolerance zones are not printed, so its
percentages are not reproducible from the paper's equations (docs/validation/jiang2024.md, "How
gearte's contributions relate to 3DCS's"). What *does* follow from the data and is tested:

* Table 3: both gears' tooth-thickness tolerances contribute equally (22.0 / 22.0 %); the driven
  gear's eccentricity outweighs the driving gear's by (F″i2/F″i1)² = (31/27)² = 1.318, which is
  3DCS's 13.0/9.9 = 1.313 within its printed precision (1.301-1.320); the reducer runout is the
  smallest contributor.
* Table 7: the two tooth thicknesses are equal and the largest contributors; the bearing
  clearances are the smallest.
"""

from __future__ import annotations

import pytest

from gearte.tolerance.contributions import group_shares, pareto, sobol_indices, variance_shares
from jiang2024_data import bevel_pair, spur_pair


def test_jiang2024_table3_spur_contributions():
    sh = variance_shares(spur_pair().backlash_stack())
    assert sum(sh.values()) == pytest.approx(1.0)
    assert sh["driving gear tooth thickness"] == pytest.approx(sh["driven gear tooth thickness"])
    ratio = sh["driven gear eccentricity"] / sh["driving gear eccentricity"]
    lo, hi = 12.95 / 9.95, 13.05 / 9.85  # 3DCS 13.0 % / 9.9 %, printed to 0.1 %
    assert lo <= ratio <= hi
    assert min(sh, key=sh.get) == "reducer output runout"


def test_jiang2024_table7_bevel_contributions():
    st = bevel_pair().backlash_stack()
    sh = variance_shares(st)
    g = group_shares(sh, st)
    assert sh["driving gear tooth thickness"] == pytest.approx(sh["driven gear tooth thickness"])
    order = [name for name, _, _ in pareto(g)]
    assert set(order[:2]) == {"driving gear tooth thickness", "driven gear tooth thickness"}
    assert order[-1] == "bearing radial clearance"
    assert pareto(g)[-1][2] == pytest.approx(1.0)


@pytest.mark.parametrize("make", [spur_pair, bevel_pair])
def test_sobol_first_order_equals_variance_share_for_linear_stacks(make):
    st = make().backlash_stack()
    sh = variance_shares(st)
    sob = sobol_indices(st, 20_000, seed=3)
    for k, v in sh.items():
        tol = max(4 * sob.first_order_se[k], 0.01)
        assert sob.first_order[k] == pytest.approx(v, abs=tol), k
        assert sob.total[k] == pytest.approx(v, abs=max(4 * sob.total_se[k], 0.01)), k
