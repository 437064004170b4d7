"""The papers gearte implements, keyed by the short names used in docstrings, cases and results.

A study lists the keys it used; ``results.json`` carries the full citations.
"""

from __future__ import annotations

__all__ = ["REFERENCES", "cite"]

REFERENCES: dict[str, str] = {
    "hu2020": (
        "Hu Y., Li G., Zhu W., Cui J. (2020). An Elastic Transmission Error Compensation Method "
        "for Rotary Vector Speed Reducers Based on Error Sensitivity Analysis. Applied Sciences "
        "10(2), 481. "
        "doi:10.3390/app10020481"
    ),
    "jiang2024": (
        "Jiang Z., Zhong Y., Lv X., Lai J., Jin X. (2024). Gear backlash modeling and tolerance "
        "simulation of fully gear-coupled robot. Journal of Zhejiang University (Engineering "
        "Science) 58(8). doi:10.3785/j.issn.1008-973X.2024.08.000"
    ),
    "wang2013": (
        "Wang S., Chen Z., Li X., Chen W. (2013). Coupling Compensation of Transmission Error for "
        "Planetary Gear. Transactions of the Chinese Society for Agricultural Machinery 44(8)."
    ),
    "han2023": (
        "Han X., Xu W., Wang J., Zhang Y. (2023). Impact of Manufacturing Errors on Tooth Surface "
        "Forces in RV Reducer Cycloid Pinwheels. Journal of Engineering Research and Reports 25(8)."
    ),
    "li2023": (
        "Li X., Huang C., Ding Y., Guo L., Niu W. (2023). Dynamic Modeling and Analysis of an RV "
        "Reducer Considering Tooth Profile Modifications and Errors. Machines 11(6), 626. "
        "doi:10.3390/machines11060626"
    ),
    "iso1328": "ISO 1328-1:2013 Cylindrical gears — ISO system of flank tolerance classification.",
    "jisb1702": "JIS B 1702-1 / GB/T 10095 gear accuracy grades.",
}


def cite(key: str) -> str:
    """Full citation of a reference key; raises ``KeyError`` naming the known keys."""
    try:
        return REFERENCES[key]
    except KeyError:
        raise KeyError(f"unknown reference {key!r}; known: {sorted(REFERENCES)}") from None
