"""Li et al. 2023 (paper 004) prototype for the model-level tests, read from the bundled cases.

The paper's Tables 1–3 are data of ``examples/li2023_rv*.toml`` only (issue 11: no paper data as
code defaults); these helpers build the model-level objects from those files through the same
builder the ``rv_reducer`` kind uses, so a test of the model exercises the case's numbers.
"""

from __future__ import annotations

import dataclasses
from functools import cache

import numpy as np

from gearte.io.case_file import load_case


@cache
def _built(name: str):
    from gearte.studies._rv_dynamics import build_dynamic_model
    from gearte.studies.rv_reducer import build_reducer

    case = load_case(name)
    model, _ = build_dynamic_model(case, build_reducer(case.reducer))
    return model


def li2023_parameters(modified: bool = False, **changes):
    """``RVDynamicsParameters`` of Tables 1–2: the unmodified pair with its time-varying
    stiffness (``li2023_rv_unmodified``) or, ``modified=True``, the section 4.1 modification
    (pair of ``li2023_rv``); ``changes`` replace fields."""
    params = _built("li2023_rv" if modified else "li2023_rv_unmodified").params
    if modified:
        params = dataclasses.replace(params, cycloid_stiffness="fourier")
    return dataclasses.replace(params, **changes)


def table3_errors(placement: str = "first", **clearances):
    """``RVErrors`` of Table 3 (``li2023_rv_errors``): ``"first"`` as the case places them (each
    per-part error on crank 1 / disc 1), ``"all"`` the same error on every crank and disc."""
    err = _built("li2023_rv_errors").errors
    if placement == "all":
        err = dataclasses.replace(
            err,
            planet_eccentricity=np.broadcast_to(err.planet_eccentricity[0], (3, 2)).copy(),
            carrier_hole=np.broadcast_to(err.carrier_hole[0], (3, 2)).copy(),
            disc_hole=np.broadcast_to(err.disc_hole[0, 0], (3, 2, 2)).copy(),
            cam=np.broadcast_to(err.cam[0, 0], (3, 2, 2)).copy(),
        )
    elif placement != "first":
        raise ValueError(placement)
    return dataclasses.replace(err, **clearances)


def table3_tolerances():
    """``ErrorTolerances`` = the Table 3 amplitudes (the ``li2023_rv_errors`` batch)."""
    from gearte.runners.rv_dynamics_sim import ErrorTolerances

    e = _built("li2023_rv_errors").errors
    return ErrorTolerances(
        sun_eccentricity=e.sun_eccentricity[0],
        planet_eccentricity=float(e.planet_eccentricity[:, 0].max()),
        sun_assembly=e.sun_assembly[0],
        disc_hole=float(e.disc_hole[..., 0].max()),
        cam=float(e.cam[..., 0].max()),
        carrier_hole=float(e.carrier_hole[:, 0].max()),
        output_assembly=e.output_assembly[0],
    )


def li2023_pair(modified: bool = False):
    """The cycloid–pin pair of Table 1 (``CycloidPinPair``) as the bundled cases build it:
    unmodified (``li2023_rv_unmodified``) or with the section 4.1 modification Δr_rp = −0.01,
    Δr_p = −0.05 mm (``li2023_rv``)."""
    return li2023_parameters(modified).pair
