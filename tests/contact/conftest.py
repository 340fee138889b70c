"""Fixtures for the contact tests."""

import pytest


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    """A fresh, private table cache directory."""
    d = tmp_path / "cache"
    monkeypatch.setenv("GRANULARGAS_CACHE_DIR", str(d))
    return d
