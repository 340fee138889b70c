"""Output paths a user types: a directory that does not exist is an error naming it (never
created), for every command that writes; one line, exit 2, nothing created."""

import pytest

from granulargas.cli import main
from granulargas.io.config import load_config
from granulargas.run.runner import run_config

CONFIG = """
[system]
particles = 64
packing_fraction = 0.1
[collision]
model = "viscoelastic"
damping = 0.1
[run]
end_time = 1.0
[output]
file = "run.h5"
snapshots = 3
"""


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c.toml").write_text(CONFIG)
    return tmp_path


@pytest.fixture
def run_file(here):
    run_config(load_config(here / "c.toml"))
    return here / "run.h5"


def _refused(capsys, argv, here, fragment):
    before = sorted(p.relative_to(here) for p in here.rglob("*"))
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and err.startswith("error: ") and fragment in err, err
    assert sorted(p.relative_to(here) for p in here.rglob("*")) == before


def test_run(here, capsys):
    _refused(capsys, ["run", "c.toml", "--output", "nodir/x.h5"], here,
             'output.file = "nodir/x.h5": directory nodir does not exist (it is not created')
    # the default output runs/<config name>.h5 needs runs/ too
    (here / "d.toml").write_text(CONFIG.replace('file = "run.h5"\n', ""))
    _refused(capsys, ["run", "d.toml"], here, 'output.file = "runs/d.h5": directory runs does not exist')


def test_analyze_plot(run_file, here, capsys):
    _refused(capsys, ["analyze", "run.h5", "--plot", "nodir/x.png"], here,
             "--plot nodir/x.png: directory nodir does not exist")


def test_analyze_plot_without_a_path_writes_beside_the_file(run_file, here, capsys):
    assert main(["analyze", "run.h5", "--no-snapshots", "--plot"]) == 0
    assert "wrote run.png" in capsys.readouterr().out
    assert (here / "run.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_analyze_plot_never_overwrites_a_run_file(run_file, here, capsys):
    (here / "other.h5").write_bytes(b"data")
    _refused(capsys, ["analyze", "run.h5", "--plot", "other.h5"], here, "--plot other.h5: give a figure file (.png")
    _refused(capsys, ["analyze", "run.h5", "--velocity", "c.toml"], here, "--velocity c.toml: give a figure file")
    assert (here / "other.h5").read_bytes() == b"data"


def test_export_gsd(run_file, here, capsys):
    pytest.importorskip("gsd.hoomd", reason="gsd not installed (pip install 'granulargas[export]')")
    _refused(capsys, ["export", "gsd", "run.h5", "-o", "nodir/x.gsd"], here, "nodir/x.gsd: directory nodir does not exist")


def test_export_lammps(here, capsys):
    _refused(capsys, ["export", "lammps", "c.toml", "-o", "nodir/lmp"], here,
             "--output nodir/lmp: directory nodir does not exist")
    assert main(["export", "lammps", "c.toml", "-o", "lmp"]) == 0  # the directory itself is made
    assert (here / "lmp" / "in.granulargas").is_file()


def test_unknown_key_suggests_the_nearest(here, capsys):
    (here / "c.toml").write_text(CONFIG.replace("particles = 64", "partcles = 64"))
    _refused(capsys, ["run", "c.toml"], here, "system.partcles = 64: unknown key; did you mean `particles`?")
    _refused(capsys, ["run", "c.toml", "--set", "sytem.seed=2"], here, "did you mean `system.seed`?")
    (here / "c.toml").write_text(CONFIG.replace("[run]", "[rnu]"))
    _refused(capsys, ["run", "c.toml"], here, "[rnu]: unknown section")


def test_too_dense_names_the_packing_that_works(here, capsys):
    (here / "c.toml").write_text(CONFIG.replace("packing_fraction = 0.1", "packing_fraction = 0.7"))
    _refused(capsys, ["run", "c.toml"], here, "random placement works up to about 0.54 in 3D")
