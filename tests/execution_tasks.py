"""Chunk functions for tests/test_execution.py that must be importable in worker processes."""

from __future__ import annotations

import os
from pathlib import Path

from gearte.execution.check import sample_chunk


def crash_once(task):
    """``sample_chunk`` of the chunk, but the first process to run chunk 3 dies abruptly
    (as if killed or out of memory); a marker file makes the rerun succeed."""
    marker, chunk = task
    if chunk.index == 3 and not Path(marker).exists():
        Path(marker).write_text("crashed")
        os._exit(1)
    return sample_chunk(chunk)
