"""The fuzzing harness (tests/fuzzing.py) at a small size, driven by hypothesis: a mutant of a
bundled case is accepted without silent coercion or rejected with one line per problem naming
the key, never an internal error; accepted mutants run through ``gearte run`` with exit 0, 1 or
2 only; a mutated measurement file is read whole or refused with one line naming the file. The
long job is ``make fuzz``."""

from __future__ import annotations

import random

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzing import (
    check_measurement,
    check_text,
    corpus,
    measurement_corpus,
    mutant_text,
    mutate_csv,
    run_cli,
    to_toml,
)

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


FILES = measurement_corpus()
FILE_NAMES = sorted(FILES)


def test_every_measurement_base_file_is_read_whole(tmp_path):
    for name in FILE_NAMES:
        reader, text = FILES[name]
        assert check_measurement(reader, text, tmp_path).status == "accepted", name


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(name=st.sampled_from(FILE_NAMES), seed=st.integers(0, 2**32 - 1))
def test_fuzzed_measurement_file_is_read_whole_or_refused_naming_the_file(tmp_path, name, seed):
    reader, text = FILES[name]
    mutant, done = mutate_csv(text, random.Random(seed))
    out = check_measurement(reader, mutant, tmp_path)
    assert out.status in ("accepted", "rejected"), f"{name}: {done}: {out.status} {out.detail}"


#: Kinds quick enough to run in the suite (``make fuzz`` runs mutants of every bundled case).
FAST = ["jiang2024_spur_pair", "wang2013_2kh_eq9", "jiang2024_bevel_pair", "hu2020_rv80e_initial"]


def test_fuzzed_case_files_run_with_exit_0_1_or_2_and_no_coercion(tmp_path):
    """Accepted mutants of quick bundled cases through ``gearte run`` (in this process, the
    CLI's entry point; --samples 4): never exit 3, no time-out, the recorded input keeps the
    given types."""
    rng = random.Random(2026)
    ran = []
    for i in range(400):
        name = FAST[i % len(FAST)]
        text, done = mutant_text(CORPUS[name], rng)
        if check_text(text, tmp_path).status != "accepted":
            continue
        out = run_cli(text, tmp_path, timeout_s=120)
        assert out.status in ("run_exit_0", "run_exit_1", "run_exit_2"), f"{name}: {done}: {out}"
        ran.append(out.status)
        if len(ran) == 4:
            break
    assert len(ran) == 4
