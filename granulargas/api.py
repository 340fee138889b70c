"""A config run and its result from Python: the functions behind ``import granulargas as gg``.

::

    import granulargas as gg

    cfg = gg.load_config("configs/quickstart.toml", overrides={"output.file": "runs/nb.h5"})
    res = gg.simulate(cfg, overwrite=True)      # the run of `granulargas run`, then its file opened
    df = res.observables()                      # pandas DataFrame indexed by time
    df.plot(y="temperature", loglog=True)
    res.analyze()                               # the analysis of `granulargas analyze`

:func:`simulate` runs a config as the ``run`` command does (the same checks before
anything is written, the same file) and returns a :class:`Result`; :func:`load_run`
opens the file of any earlier run. A :class:`Result` reads its file when asked (one
frame at a time for snapshots) and holds no open file. The deep modules stay for
those who need them: :mod:`granulargas.io.h5md` (readers returning numpy arrays),
:mod:`granulargas.run.runner` (:func:`~granulargas.run.runner.run_config`),
:mod:`granulargas.analysis`.

The engine itself (:class:`granulargas.engine.Simulation`) runs any initial state
built in Python (:func:`granulargas.initial.random_state`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterator

import numpy as np

from granulargas.errors import ConfigError, InputFileError
from granulargas.io import h5md
from granulargas.io.config import RunConfig, load_config, parse_config

__all__ = ["Result", "analyze", "load_run", "simulate"]

#: column suffixes of vector observables (momentum: one column per axis)
AXES = ("x", "y", "z")


class Result:
    """The H5MD file of a run: its observables as a table, its snapshots, its analysis.

    Parameters
    ----------
    path : str or Path
        A file written by ``granulargas run`` or :func:`simulate` (checked: exists, is ours,
        not damaged; :class:`~granulargas.errors.InputFileError` otherwise).
    summary : granulargas.run.runner.RunSummary, optional
        What the run that wrote the file reported (set by :func:`simulate`).

    Attributes
    ----------
    path : Path
    summary : RunSummary or None
    """

    def __init__(self, path, summary=None):
        self.path = Path(path)
        with h5md.open_run(self.path):  # ours and readable, or one line naming what is wrong
            pass
        self.summary = summary
        self._parameters = None

    def __repr__(self) -> str:
        p = self.parameters
        return (f"Result({str(self.path)!r}: {p.get('method', 'edmd')}, {p.get('dimension', '?')}D, "
                f"N = {p.get('particles', '?')}, {self.snapshot_count()} snapshots)")

    @property
    def parameters(self) -> dict:
        """The file's ``parameters/`` group as a dict (:func:`granulargas.io.h5md.read_parameters`):
        ``config`` (the resolved TOML), ``seed``, ``collision``, ``summary``, ..."""
        if self._parameters is None:
            self._parameters = h5md.read_parameters(self.path)
        return self._parameters

    @property
    def config(self) -> RunConfig:
        """The run's configuration, parsed from the resolved TOML the file keeps."""
        text = self.parameters.get("config")
        if not isinstance(text, str):
            raise InputFileError(f"{self.path}: holds no run configuration (parameters/config)")
        try:
            return parse_config(text, source=f"{self.path}:parameters/config")
        except ConfigError as exc:
            raise InputFileError(f"{exc}") from None

    def observables(self):
        """The sampled observables as a :class:`pandas.DataFrame`, one row per sample.

        The index is the time (``time``); one column per observable of the file
        (``temperature``, ``kinetic_energy``, ``collisions``, ``events``, ``pressure``,
        ``sonine_a2``, ... as :mod:`granulargas.io.h5md` describes them), a vector
        observable as one column per axis (``momentum_x``, ``momentum_y``, ...), and
        ``step`` (events since the start). Observables a run did not sample at a time
        are NaN there. Needs pandas (``pip install 'granulargas[pandas]'``).
        """
        try:
            import pandas as pd  # optional dependency: only this table needs it
        except ImportError:
            raise ModuleNotFoundError("Result.observables() returns a pandas DataFrame and pandas is not "
                                      "installed: pip install 'granulargas[pandas]' (or use "
                                      "Result.observables_dict(), numpy arrays)", name="pandas") from None
        params = h5md.read_parameters(self.path)
        names = params["species"]["names"] if isinstance(params.get("species"), dict) else None
        columns = observable_columns(self.observables_dict(), self.path, species=names)
        frame = pd.DataFrame(columns)
        return frame.set_index("time")

    def observables_dict(self) -> dict:
        """The observables as ``{name: (step, time, value)}`` numpy arrays
        (:func:`granulargas.io.h5md.read_observables`)."""
        return h5md.read_observables(self.path)

    def snapshot_count(self) -> int:
        """How many snapshots (frames) the file holds."""
        return h5md.snapshot_count(self.path)

    def snapshot(self, index: int = -1) -> h5md.Snapshot:
        """One snapshot (:class:`granulargas.io.h5md.Snapshot`; negative indices count from the end)."""
        return h5md.load_snapshot(self.path, index)

    def snapshots(self) -> Iterator[h5md.Snapshot]:
        """The snapshots in time order, one frame in memory at a time."""
        return h5md.iter_snapshots(self.path)

    def analyze(self, **options):
        """The analysis of ``granulargas analyze`` (:func:`analyze`)."""
        return analyze(self.path, **options)


def observable_columns(observables: dict, source="observables", species=None) -> dict:
    """Columns of the observables table from :func:`granulargas.io.h5md.read_observables`:
    ``time``, ``step`` and one column per scalar observable (one per axis for a vector; the
    pressure tensor's independent components, ``pressure_tensor_xx``, ``pressure_tensor_xy``, ...; a
    mixture's per species, ``species_temperature_<name>``, and per pair of species,
    ``species_collisions_<a>_<b>``, with the species' ``species`` names or their indices).

    All observables of a run share one clock; one that is shorter than the longest (a
    sample cut short) is NaN at the missing times.
    """
    if not observables:
        return {"time": np.empty(0), "step": np.empty(0, dtype=np.int64)}
    step, time, _ = max(observables.values(), key=lambda x: len(x[1]))
    out = {"time": np.asarray(time, dtype=np.float64), "step": np.asarray(step, dtype=np.int64)}
    for name, (s, t, value) in observables.items():
        n = len(t)
        if not (np.array_equal(t, time[:n]) and np.array_equal(s, step[:n])):
            raise InputFileError(f"{source}: observables/{name} is not sampled on the clock of the others")
        value = np.asarray(value)
        if name == "pressure_tensor" and value.ndim == 3:  # one column per independent component
            d = value.shape[1]
            parts = {f"{name}_{AXES[a]}{AXES[b]}": value[:, a, b] for a in range(d) for b in range(a, d)}
        elif name.startswith("species_") and value.ndim >= 2:  # per species, per pair of species
            label = list(species) if species is not None else [str(k) for k in range(value.shape[1])]
            parts = ({f"{name}_{label[k]}": value[:, k] for k in range(value.shape[1])} if value.ndim == 2 else
                     {f"{name}_{label[a]}_{label[b]}": value[:, a, b] for a in range(value.shape[1])
                      for b in range(a, value.shape[1])})
        else:
            parts = {name: value} if value.ndim == 1 else {
                f"{name}_{AXES[k] if value.shape[1] <= len(AXES) else k}": value[:, k] for k in range(value.shape[1])}
        for column, v in parts.items():
            if n < time.size:
                v = np.concatenate([v.astype(np.float64), np.full(time.size - n, np.nan)])
            out[column] = v
    return out


def load_run(path) -> Result:
    """Open the H5MD file of a run (any run of ``granulargas run``, a sweep's or :func:`simulate`'s).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    Result
    """
    return Result(path)


def simulate(config, *, overrides: dict | None = None, overwrite: bool = False, progress=None,
             log=None) -> Result:
    """Run a config to the end, as ``granulargas run`` does, and open its file.

    The same checks come first (the config's values, the float64 range of the run, the
    output path, memory and disk), so a rejected run writes nothing.

    Parameters
    ----------
    config : RunConfig, str or Path
        A config from :func:`granulargas.io.config.load_config`, or the path of a TOML file.
    overrides : dict, optional
        Dotted keys set before validation, when ``config`` is a path
        (``{"collision.damping": 0.03, "output.file": "runs/d003.h5"}``).
    overwrite : bool
        Replace an existing output file.
    progress : None, bool or callable
        As :func:`granulargas.run.runner.run_config`: a callable ``progress(sim)`` is called
        between compiled chunks.
    log : callable, optional
        Receives the one-line warnings on the model's validity (default: print to stderr).

    Returns
    -------
    Result
        The run's file, with :attr:`Result.summary` the run's summary.
    """
    # the run layer loads numba: imported here, so that opening a result does not
    from granulargas.run.runner import run_config
    from granulargas.run.validity import raise_if_invalid

    if isinstance(config, (str, os.PathLike)):
        config = load_config(config, overrides)
    elif overrides:
        raise TypeError("overrides apply to a config path; a RunConfig is already validated "
                        "(give overrides to load_config)")
    if not isinstance(config, RunConfig):
        raise TypeError(f"config must be a RunConfig or a path, not {type(config).__name__}")
    raise_if_invalid(config)
    summary = run_config(config, overwrite=overwrite, quiet=progress is None, progress=progress, log=log)
    return Result(summary.output, summary=summary)


def analyze(run, **options):
    """Analyse a run's file against kinetic theory, as ``granulargas analyze`` does.

    Parameters
    ----------
    run : Result, str or Path
    **options
        ``t_range=(t0, t1)`` (the fit window of a cooling run), ``with_sonine=False``
        (skip the snapshots' Sonine coefficients).

    Returns
    -------
    The analysis of the run's kind (:data:`granulargas.analysis.kinds.ANALYSES`):
    ``CoolingAnalysis``, ``ElasticAnalysis`` or ``DrivenAnalysis``, each with ``summary()``
    (the numbers of ``analyze --json``).
    """
    from granulargas.analysis.kinds import analyze_file  # the theory layers load numba

    path = run.path if isinstance(run, Result) else Path(run)
    return analyze_file(str(path), **options)
