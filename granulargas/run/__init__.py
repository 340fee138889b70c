"""The run workflow: from a validated config to a finished H5MD file.

* :mod:`~granulargas.run.prepare` -- config -> collision rule, restitution table,
  initial state (fresh or restarted) and the file's ``parameters/``;
* :mod:`~granulargas.run.schedule` -- the output schedule (a function of the config only);
* :mod:`~granulargas.run.runner` -- :func:`~granulargas.run.runner.run_config`: the run
  loop, progress bar, H5MD writing and the summary;
* :mod:`~granulargas.run.validity` -- is the model valid over the whole run (predicted
  with kinetic theory, nothing simulated);
* :mod:`~granulargas.run.advise` -- is a constant restitution good enough for a config;
* :mod:`~granulargas.run.sweep` -- parameter sweeps and ensembles on any executor.
"""
