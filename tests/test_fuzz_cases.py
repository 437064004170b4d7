"""The case-file fuzzing harness (tests/fuzzing.py) at a small size, driven by hypothesis: a
mutant of a bundled case is accepted without silent coercion or rejected with one line per
problem naming the key; never an internal error. The long job is ``make fuzz``."""

from __future__ import annotations

import random

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzing import check_text, corpus, mutant_text, to_toml

CORPUS = corpus()
NAMES = sorted(CORPUS)


def test_every_bundled_case_round_trips_through_the_fuzzer_toml_writer(tmp_path):
    for name in NAMES:
        assert check_text(to_toml(CORPUS[name]), tmp_path).status == "accepted", name


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**32 - 1))
def test_fuzzed_case_file_is_accepted_cleanly_or_rejected_naming_the_key(tmp_path, name, seed):
    text, done = mutant_text(CORPUS[name], random.Random(seed))
    out = check_text(text, tmp_path)
    assert out.status in ("accepted", "rejected"), f"{name}: {done}: {out.status} {out.detail}"
