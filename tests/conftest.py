import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(autouse=True, scope="session")
def _register_foundation_kind():
    from gearte.studies import register_kind

    register_kind("foundation_test", "foundation_kind")
    yield
