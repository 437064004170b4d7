"""gearte._frames: a command's frames get one roomy chunk of CPython's frame stack
(gh-142183 workaround); results and exceptions are the callable's own."""

from __future__ import annotations

import resource
import sys

import pytest

from gearte._frames import _ROOMY, ROOM_SLOTS, with_frame_room


def test_returns_what_the_callable_returns() -> None:
    obj = object()
    assert with_frame_room(lambda: obj) is obj


def test_raises_what_the_callable_raises() -> None:
    def boom() -> None:
        raise KeyError("boom")

    with pytest.raises(KeyError, match="boom"):
        with_frame_room(boom)


def test_deep_recursion_inside_the_room() -> None:
    def depth(n: int) -> int:
        return 0 if n == 0 else 1 + depth(n - 1)

    assert with_frame_room(lambda: depth(800)) == 800


@pytest.mark.skipif(sys.implementation.name != "cpython", reason="CPython's frame stack only")
def test_the_roomy_frame_declares_the_room() -> None:
    """The frame reserves ROOM_SLOTS slots beyond what its own code needs: CPython gives it a
    chunk of its own with ~half of it free below."""
    assert _ROOMY.__code__.co_stacksize >= ROOM_SLOTS
    assert _ROOMY.__code__.co_code == with_frame_room.__globals__["_call"].__code__.co_code


def test_the_cli_and_run_case_use_it() -> None:
    """Both ways into a run go through the room (source check: the call is the mechanism)."""
    import inspect

    import gearte.cli
    import gearte.studies

    assert "with_frame_room(main)" in inspect.getsource(gearte.cli.entry)
    assert "with_frame_room(" in inspect.getsource(gearte.studies.run_case)


def test_pool_chunks_run_in_the_room() -> None:
    """A local pool runs each chunk through the room, in threads and in processes, and so does a
    Dask cluster (gearte's local one here), with the chunk's own result."""
    from gearte.execution import map_chunks

    for scheduler in ("threads", "processes", "local-cluster"):
        if scheduler == "local-cluster":
            pytest.importorskip("distributed")
        out = map_chunks(_chunk_faults, [0, 1, 2], workers=2, scheduler=scheduler, progress=False)
        assert [o[0] for o in out] == [0, 1, 2]
        assert max(max(o[1]) for o in out) < CALLS // 10, scheduler


CALLS = 2000


def _faults_at_each_depth(max_depth: int = 200) -> list[int]:
    """Minor page faults of CALLS calls of ``leaf``, made at each stack depth from 0 to
    ``max_depth`` (more than one 16 KiB chunk of ``at`` frames). ``leaf``'s frame (64 local
    slots) is larger than ``at``'s, so at the deepest ``at`` that still fits in a chunk,
    ``leaf`` does not fit after it, wherever the stack starts: every call there allocates a
    chunk and frees it."""
    ns: dict[str, object] = {}
    exec("def leaf(" + ", ".join(f"a{i}=0" for i in range(64)) + "):\n    return a0", ns)
    leaf = ns["leaf"]

    def at(depth: int) -> int:
        if depth:
            return at(depth - 1)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(CALLS):
            leaf()  # type: ignore[operator]
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

    return [at(d) for d in range(max_depth)]


@pytest.mark.skipif(sys.implementation.name != "cpython", reason="CPython's frame stack only")
def test_no_chunk_churn_inside_the_room() -> None:
    """Inside the room no depth makes a call allocate a chunk: at most a few page faults for
    CALLS calls at any depth. Outside it, on CPython 3.11 and 3.12 (not fixed there), the same
    scan finds the depth where every call allocates and frees a chunk (a fresh page each time):
    the measurement sees the churn the room removes."""
    inside = with_frame_room(_faults_at_each_depth)
    assert max(inside) < CALLS // 10, max(inside)
    if sys.version_info < (3, 13):
        outside = _faults_at_each_depth()
        assert max(outside) >= CALLS, max(outside)


def _chunk_faults(task: int) -> tuple[int, list[int]]:
    """A chunk function (module level: process pools pickle it): the depth scan, in whatever
    frame the pool runs its chunks."""
    return task, _faults_at_each_depth()
