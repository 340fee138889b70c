import subprocess
import sys

from granulargas import __version__
from granulargas.cli import main


def test_version_via_module():
    out = subprocess.run([sys.executable, "-m", "granulargas", "--version"], capture_output=True, text=True)
    assert out.returncode == 0
    assert __version__ in out.stdout


def test_no_command_prints_help_and_fails(capsys):
    assert main([]) == 2
    assert "usage" in capsys.readouterr().out
