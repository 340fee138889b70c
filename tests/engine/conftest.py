"""Engine test configuration: the factories live in engine_factories.py."""

import pytest

from engine_factories import make_sim


@pytest.fixture
def factory():
    return make_sim
