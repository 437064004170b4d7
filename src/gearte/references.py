"""The papers gearte implements, keyed by the short names used in docstrings, cases and results.

A study lists the keys it used; ``results.json`` carries the full citations.
"""

from __future__ import annotations

__all__ = ["REFERENCES", "cite"]

REFERENCES: dict[str, str] = {
    "hu2020": (
        "Hu, Li, Zhu, Cui (2020). An Elastic Transmission Error Compensation Method for Rotary "
        "Vector Speed Reducers Based on Error Sensitivity Analysis. Applied Sciences 10(2), 481. "
        "doi:10.3390/app10020481"
    ),
    "jiang2024": (
        "Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024). Gear backlash modeling and tolerance "
        "simulation of fully gear-coupled robot. Journal of Zhejiang University (Engineering "
        "Science) 58(8), 1533-1542. doi:10.3785/j.issn.1008-973X.2024.08.001"
    ),
    "wang2013": (
        "Wang C., Chen X., Li Y., Chen H. (2013). Coupling Compensation of Transmission Error for "
        "Planetary Gear. Transactions of the Chinese Society for Agricultural Machinery 44(8). "
        "doi:10.6041/j.issn.1000-1298.2013.08.049"
    ),
    "han2023": (
        "Han L., Xu W., Wang Y., Zhang Y. (2023). Impact of Manufacturing Errors on Tooth Surface "
        "Forces in RV Reducer Cycloid Pinwheels. Journal of Engineering Research and Reports "
        "25(8). doi:10.9734/JERR/2023/v25i8970"
    ),
    "li2023": (
        "Li, Huang, Ding, Guo, Niu (2023). Dynamic Modeling and Analysis of an RV Reducer "
        "Considering Tooth Profile Modifications and Errors. Machines 11(6), 626. "
        "doi:10.3390/machines11060626"
    ),
    "harmonicdrive2015": (
        "Harmonic Drive AG (2015). CHA Servo Actuator manual 1018854 12/2015, section 4.2 "
        "'Calculation of the torsion angle', equations 68.1-68.4 and worked example "
        "(three-segment torsional stiffness K1/K2/K3 with limit torques T1/T2)."
    ),
    "harmonicdrive_csf": (
        "Harmonic Drive LLC. CSF & CSG Series, cup type component sets and housed units: "
        "engineering data (torsional stiffness tables 41-43, hysteresis loss, positioning "
        "accuracy table 40)."
    ),
    "tuttle1992": (
        "Tuttle T. D. (1992). Understanding and modeling the behavior of a harmonic drive gear "
        "transmission. S.M. thesis, Massachusetts Institute of Technology; MIT Artificial "
        "Intelligence Laboratory technical report, May 1992."
    ),
    "jia2021": (
        "Jia H., Li J., Xiang G., Wang J., Xiao K., Han Y. (2021). Modeling and analysis of pure "
        "kinematic error in harmonic drive. Mechanism and Machine Theory 155, 104122. "
        "doi:10.1016/j.mechmachtheory.2020.104122"
    ),
}


def cite(key: str) -> str:
    """Full citation of a reference key; raises ``KeyError`` naming the known keys."""
    try:
        return REFERENCES[key]
    except KeyError:
        raise KeyError(f"unknown reference {key!r}; known: {sorted(REFERENCES)}") from None
