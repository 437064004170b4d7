"""Plausibility of the RV stiffness chain against catalogue values (docs/rv-stiffness-chain.md).

Runs three RV-E-like designs (40/80/110-class) through the ``rv_reducer`` kind's catalogue
analysis (virtual torsion test + stiffness chain) and prints, or writes into the docs page
between its ``<!-- rv-stiffness-catalogue:begin/end -->`` markers, the predicted torsional
rigidity, lost motion and backlash beside the catalogue values, and the compliance breakdown.

    python docs/rv_stiffness_catalogue.py            # print the tables
    python docs/rv_stiffness_catalogue.py --write    # and write them into the page

Geometry comes from the bundled paper cases; what the papers do not give is an assumption,
stated in ASSUMED below and in the page.
"""

from __future__ import annotations

import argparse
import copy
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "rv-stiffness-chain.md"
BEGIN, END = "<!-- rv-stiffness-catalogue:begin -->", "<!-- rv-stiffness-catalogue:end -->"

#: Nabtesco RV-E catalogue (rating table): rated torque [N·m], torsional rigidity
#: [N·m/arcmin], lost motion [arcmin] (max., at ±3 % of rated torque), backlash [arcmin] (max.).
CATALOGUE = {
    "RV-40E": (412.0, 108.0, 1.0, 1.0),
    "RV-80E": (784.0, 196.0, 1.0, 1.0),
    "RV-110E": (1078.0, 294.0, 1.0, 1.0),
}

#: The three designs: bundled case, catalogue size, changes to the case (ASSUMED, stated).
DESIGNS = [
    (
        "li2023_rv",
        "RV-40E",
        {
            # Li et al. 2023's experimental reducer (Table 1 geometry, Table 2 stiffnesses of
            # both crank bearings, crank bending and torsion: given); rated torque of the
            # catalogue size; ASSUMED pin seat over the disc stack (2 x 12 mm + 4 mm)
            ("reducer", "rated_torque_Nm"): 412.0,
            ("reducer", "pins", "seat_length_mm"): 28.0,
            ("reducer", "cranks", "bending_stiffness_N_per_mm"): 5.55e5,
            ("reducer", "cranks", "torsional_stiffness_Nm_per_rad"): 6.99e4,
        },
    ),
    ("hu2020_rv80e_initial_reducer", "RV-80E", {}),
    ("han2023_rv110e_no_errors", "RV-110E", {}),
]


def _case(name: str, changes: dict) -> dict:
    data = tomllib.loads((ROOT / "examples" / f"{name}.toml").read_text(encoding="utf-8"))
    data = copy.deepcopy(data)
    for path, value in changes.items():
        d = data
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value
    # the catalogue analysis only (it holds the stiffness chain)
    data["analyses"] = {"catalogue": {"position_deg": 0.0, "torque_sweep": [0.0, 1.0, 0.0, -1.0]}}
    data["reducer"].pop("dynamics", None)
    data.pop("operation", None)
    return data


def run() -> list[dict]:
    from gearte.io.case_file import load_case_dict
    from gearte.studies.rv_reducer import run as run_study

    rows = []
    for name, size, changes in DESIGNS:
        case = load_case_dict(_case(name, changes), name=name)
        cat = run_study(case)["catalogue"]
        v = cat.values
        rows.append({"case": name, "size": size, "values": v})
    return rows


def tables(rows: list[dict]) -> str:
    out = [
        "| design (case) | rigidity [N·m/arcmin] model / catalogue | lost motion [arcmin] "
        "model / catalogue max | backlash [arcmin] model / catalogue max | compliance the "
        "catalogue rigidity leaves beyond the model |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        v = r["values"]
        _, k_cat, lm_cat, bl_cat = CATALOGUE[r["size"]]
        k = v["torsional_rigidity [N*m/arcmin]"]
        extra = 100.0 * (1.0 - k_cat / k)  # share of the catalogue compliance not in the model
        out.append(
            f"| {r['size']}-like (`{r['case']}`) | {k:.0f} / {k_cat:.0f} | "
            f"{v['lost_motion [arcmin]']:.2f} / {lm_cat:.1f} | {v['backlash [arcmin]']:.3f} / "
            f"{bl_cat:.1f} | {extra:.0f} % |"
        )
    out += [
        "",
        "Compliance breakdown at rated torque (share of the output torsional compliance):",
        "",
    ]
    elements: list[str] = []
    for r in rows:
        for e in r["values"]["compliance_shares"]:
            if e not in elements:
                elements.append(e)
    out.append("| element | " + " | ".join(f"{r['size']}-like" for r in rows) + " |")
    out.append("|---|" + "---|" * len(rows))
    for e in elements:
        cells = []
        for r in rows:
            s = r["values"]["compliance_shares"].get(e)
            cells.append("left out" if s is None else f"{100.0 * s:.1f} %")
        out.append(f"| {e} | " + " | ".join(cells) + " |")
    out.append(
        "| *tangent rigidity at rated [N·m/arcmin]* | "
        + " | ".join(f"{r['values']['tangent_rigidity_at_rated [N*m/arcmin]']:.0f}" for r in rows)
        + " |"
    )
    out.append(
        "| *cam / carrier bearing load at rated [kN]* | "
        + " | ".join(
            f"{r['values']['cam_bearing_load_at_rated [N]'] / 1e3:.1f} / "
            f"{r['values']['carrier_bearing_load_at_rated [N]'] / 1e3:.1f}"
            for r in rows
        )
        + " |"
    )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help=f"write the tables into {PAGE.name}")
    args = ap.parse_args(argv)
    text = tables(run())
    print(text)
    if args.write:
        page = PAGE.read_text(encoding="utf-8")
        head, rest = page.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        PAGE.write_text(
            f"{head}{BEGIN}\n<!-- generated by docs/rv_stiffness_catalogue.py: do not edit -->\n\n"
            f"{text}\n\n{END}{tail}",
            encoding="utf-8",
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
