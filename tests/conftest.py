"""Shared pytest configuration and fixtures.

The default run skips tests marked ``slow``; ``-m slow`` selects them. The
tests are a package (``tests``): helpers are imported as ``tests.<area>.<module>``
(e.g. :mod:`tests.engine.factories`, :mod:`tests.contact.truths`).
"""

import pytest


def pytest_collection_modifyitems(config, items):
    if config.getoption("-m"):
        return
    skip_slow = pytest.mark.skip(reason="slow physics test: run with -m slow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip_slow)


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    """A fresh, private restitution-table cache directory."""
    d = tmp_path / "cache"
    monkeypatch.setenv("GRANULARGAS_CACHE_DIR", str(d))
    return d
