"""Readable labels of gearte's result names, for reports, figures and tables.

Result names are identifiers with their unit (``"peak_pin_load [N]"``,
``"mc_random_assembly_half_tolerance"``); people read ``Peak pin load [N]`` and
``Monte-Carlo: random assembly, half tolerance``. :func:`label` is the one place that turns the
first into the second: an explicit registry (:data:`LABELS`) first, then word by word
(:data:`WORDS`), with the unit spelled by :func:`gearte.units.unit_text`.
"""

from __future__ import annotations

import re

from gearte.units import split_unit, unit_text

__all__ = [
    "LABELS",
    "WORDS",
    "PHRASES",
    "VALUE_LABELS",
    "label",
    "label_with_unit",
    "value_label",
    "is_identifier",
]

#: Whole names whose word-by-word reading is wrong or clumsy (name without its unit).
LABELS: dict[str, str] = {
    "K1": "Short-width coefficient K1",
    "ratio_i_H": "Ratio i_H",
    "pitch_radius_r_c": "Pitch radius r_c",
    "mc_random_assembly": "Monte-Carlo: random assembly",
    "mc_random_assembly_half_tolerance": "Monte-Carlo: random assembly, half tolerance",
    "mc_allocated_assembly_random_magnitudes": "Monte-Carlo: allocated assembly, random magnitudes",
    "mc_optimal_assembly_random_magnitudes": "Monte-Carlo: optimal assembly, random magnitudes",
    "mc_random_magnitudes_random_assembly": "Monte-Carlo: random magnitudes, random assembly",
    "random_assembly": "random assembly",
    "random_assembly_half_tolerance": "random assembly, half tolerance",
    "allocated_assembly_random_magnitudes": "allocated assembly, random magnitudes",
    "optimal_assembly_random_magnitudes": "optimal assembly, random magnitudes",
    "random_magnitudes_random_assembly": "random magnitudes, random assembly",
    "mc_sd": "Monte-Carlo standard deviation",
    "mc_p2p_mean": "Monte-Carlo mean peak-to-peak",
    "cpk": "Process capability Cpk",
    "cp": "Process capability Cp",
    "out_of_spec_fraction": "Out-of-spec fraction",
    "sobol_first_order": "Sobol first-order index",
    "sobol_total": "Sobol total index",
    "speeds": "Speeds",
    "rhs_evaluations": "ODE right-hand-side evaluations",
    "solver_residual_evaluations": "Solver residual evaluations",
}

#: Word-by-word readings of abbreviations inside names.
WORDS: dict[str, str] = {
    "te": "TE",
    "dte": "DTE",
    "mc": "Monte-Carlo",
    "sd": "SD",
    "p2p": "peak-to-peak",
    "rss": "RSS",
    "rv": "RV",
    "dms": "(°′″)",
    "cpk": "Cpk",
    "cp": "Cp",
    "id": "ID",
    "csv": "CSV",
    "phi0": "φ = 0",
    "rpm": "rpm",
    "i": "i",
}


#: Phrases read together after the words are joined.
PHRASES: dict[str, str] = {"peak to peak": "peak-to-peak"}


def label(name: str) -> str:
    """Readable label of a result name, without its unit: ``"peak_pin_load [N]"`` → ``"Peak pin
    load"``; names already written for people (with spaces or capitals) are kept."""
    base, _ = split_unit(str(name))
    if base in LABELS:
        return LABELS[base]
    if " " in base or "_" not in base and base != base.lower():
        return base
    words = [WORDS.get(w, WORDS.get(w.lower(), w)) for w in base.split("_") if w]
    if not words:
        return base
    text = " ".join(words)
    for a, b in PHRASES.items():
        text = text.replace(a, b)
    return text[0].upper() + text[1:]


def label_with_unit(name: str) -> str:
    """:func:`label` of ``name`` (a result name) followed by the unit in brackets:
    ``"Peak pin load [N]"``, ``"Output TE [arcsec]"``, ``"Backlash [µm]"``."""
    _, unit = split_unit(str(name))
    text = label(name)
    return f"{text} [{unit_text(unit)}]" if unit else text


#: Values that are identifiers (an option, a factor, a law, a kind), as people read them. Others
#: are read word by word (:func:`label`); paper symbols (``beta_s``) become ``β_s``.
VALUE_LABELS: dict[str, str] = {
    "line_contact": "line contact (Johnson 1985)",
    "hu2020": "Hu et al. 2020 (eq. 38–39)",
    "equal_share": "equal share",
    "truncated_normal": "truncated normal",
    "rv_reducer": "RV reducer",
    "spur_pair": "spur pair",
    "bevel_pair": "bevel pair",
    "gear_pair": "gear pair",
    "gear_chain": "gear chain",
    "cycloid_stage": "cycloid stage",
}

_IDENTIFIER = re.compile(r"[a-z][a-z0-9]*(?:_[a-z0-9]+)+")
_SYMBOL = re.compile(
    r"(alpha|beta|gamma|delta|epsilon|theta|phi|psi|omega|sigma|tau|mu|nu|rho)_([a-z0-9]+)"
)
_GREEK = {
    "alpha": "α",
    "beta": "β",
    "gamma": "γ",
    "delta": "δ",
    "epsilon": "ε",
    "theta": "θ",
    "phi": "φ",
    "psi": "ψ",
    "omega": "ω",
    "sigma": "σ",
    "tau": "τ",
    "mu": "μ",
    "nu": "ν",
    "rho": "ρ",
}


def is_identifier(text: str) -> bool:
    """Whether ``text`` reads as a program identifier (``shifted_modification``,
    ``line_contact``): lower-case words joined by underscores, nothing else."""
    return bool(_IDENTIFIER.fullmatch(text))


def value_label(value: str) -> str:
    """A text *value* (an option, a factor's name, a law) as people read it.

    ``"shifted_modification"`` → ``"Shifted modification"``; ``"line_contact"`` → ``"line
    contact (Johnson 1985)"`` (:data:`VALUE_LABELS`); ``"beta_s"`` → ``"β_s"``; a result name
    ``"geometric_te [arcmin]"`` → ``"Geometric TE [arcmin]"``. Text that is not an identifier (a
    sentence, a file name, a number) is returned as it is.
    """
    if not isinstance(value, str):
        return value
    base, unit = split_unit(value)
    if unit and is_identifier(base):  # a result name: "geometric_te [arcmin]"
        return label_with_unit(value)
    if value in VALUE_LABELS:
        return VALUE_LABELS[value]
    if not is_identifier(value):
        return value
    sym = _SYMBOL.fullmatch(value)
    if sym:
        return f"{_GREEK[sym.group(1)]}_{sym.group(2)}"
    return label(value)
