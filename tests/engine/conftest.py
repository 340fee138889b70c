"""Engine test configuration: the factories live in :mod:`tests.engine.factories`."""

import pytest

from tests.engine.factories import make_sim


@pytest.fixture
def factory():
    return make_sim
