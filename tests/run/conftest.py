"""Small configs for io tests (a few hundred particles, short runs)."""

import pytest

SMALL_3D = """
[system]
dimension = 3
particles = 300
packing_fraction = 0.15
seed = 4

[collision]
model = "viscoelastic"
damping = 0.1

[run]
end_time = 4.0

[output]
file = "{out}"
snapshot_interval = 1.0
observables_interval = 0.25
"""


@pytest.fixture
def write_config(tmp_path):
    """write_config(text, name="c.toml", out="runs/out.h5") -> path of a config in tmp_path."""

    def make(text=SMALL_3D, name="c.toml", out=None):
        out = out or str(tmp_path / "runs" / "out.h5")
        p = tmp_path / name
        p.write_text(text.replace("{out}", out))
        return p

    return make


@pytest.fixture
def small_3d():
    """The template text of a small 3D viscoelastic config ({out}: output file)."""
    return SMALL_3D
