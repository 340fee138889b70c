"""The package's numba decorators: a cached function is recompiled when code it inlines changes."""

import os
import subprocess
import sys
import textwrap

from granulargas import _numba

_CALLEE = """
from granulargas._numba import inlined


@inlined
def value():
    return {value}
"""

_CALLER = """
from granulargas._numba import jit
from cachedpkg.callee import value


@jit
def caller():
    return value()
"""


def _write_package(root, value):
    pkg = root / "cachedpkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "callee.py").write_text(_CALLEE.format(value=value))
    (pkg / "caller.py").write_text(_CALLER)


def _run_caller(root, cache_dir):
    """(result, whether it came from numba's on-disk cache) in a fresh interpreter."""
    code = ("from cachedpkg.caller import caller; r = caller(); "
            "print(r, sum(caller.stats.cache_hits.values()))")
    path = [str(root)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path), NUMBA_CACHE_DIR=str(cache_dir))
    env.pop("GRANULARGAS_NO_CACHE", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=root, capture_output=True,
                         text=True, check=True).stdout.split()
    return int(out[0]), int(out[1])


def test_an_edit_of_an_inlined_callee_in_another_file_recompiles_the_cached_caller(tmp_path):
    cache = tmp_path / "cache"
    _write_package(tmp_path, 1)
    assert _run_caller(tmp_path, cache) == (1, 0)
    assert _run_caller(tmp_path, cache) == (1, 1)  # loaded from the cache
    _write_package(tmp_path, 2)  # caller.py itself is unchanged
    assert _run_caller(tmp_path, cache) == (2, 0)
    assert _run_caller(tmp_path, cache) == (2, 1)


def test_source_stamp_changes_with_any_source_file_and_only_with_sources(tmp_path):
    sub = tmp_path / "sub"
    sub.mkdir()
    (tmp_path / "a.py").write_text("x = 1\n")
    (sub / "b.py").write_text("y = 2\n")
    (sub / "notes.txt").write_text("not a source\n")
    stamp = _numba.source_stamp.__wrapped__
    s0 = stamp(str(tmp_path))
    assert stamp(str(tmp_path)) == s0
    (sub / "notes.txt").write_text("changed\n")
    assert stamp(str(tmp_path)) == s0
    (sub / "b.py").write_text("y = 3\n")
    s1 = stamp(str(tmp_path))
    assert s1 != s0
    (sub / "b.py").rename(sub / "c.py")
    assert stamp(str(tmp_path)) not in (s0, s1)



def _fresh_interpreter(tmp_path, package, source):
    """Write ``package`` (one module ``funcs`` holding ``source``) under ``tmp_path``; returns
    ``run(code)``: the stripped output of ``code`` in a fresh interpreter that imports it, with
    its numba cache in ``tmp_path``."""
    pkg = tmp_path / package
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "funcs.py").write_text(source)
    path = [str(tmp_path)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path), NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("GRANULARGAS_NO_CACHE", None)

    def run(code):
        return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, cwd=tmp_path,
                              capture_output=True, text=True, check=True).stdout.strip()

    return run


_LOADED = """
import numpy as np

from granulargas._numba import jit, kernel


@jit
def histogram(keys):
    counts = {keys[0]: 0}  # a dict: hashing, reference-counted memory
    for k in keys:
        counts[k] = counts.get(k, 0) + 1
    out = np.zeros(keys.max() + 1, dtype=np.int64)  # an allocation (the reference-counting runtime)
    for k, n in counts.items():
        out[k] = n
    return out


@kernel
def total(values):
    s = 0.0
    for v in values:
        s += v
    return s
"""


def test_a_cached_function_loads_without_refreshing_numbas_target_context(tmp_path):
    """Loaded machine code runs (allocation, hashing) without the context refresh that a
    compilation needs; a compilation still refreshes it."""
    run = _fresh_interpreter(tmp_path, "loadedpkg", _LOADED)
    code = """
        import numpy as np
        from numba.core.base import BaseContext
        refreshed = []
        original = BaseContext.refresh
        BaseContext.refresh = lambda self: (refreshed.append(1), original(self))[1]
        from loadedpkg.funcs import histogram, total
        h = histogram(np.array([3, 1, 3, 2, 3], dtype=np.int64))
        t = total(np.arange(5.0))
        hits = sum(histogram.stats.cache_hits.values()) + sum(total.stats.cache_hits.values())
        print(h.tolist(), t, hits, len(refreshed) > 0)
    """
    assert run(code) == "[0, 1, 1, 3] 10.0 0 True"  # compiled: numba refreshes its context
    assert run(code) == "[0, 1, 1, 3] 10.0 2 False"  # loaded: no refresh


_WITH_DOT = _LOADED + """

@jit
def dot(a, b):
    return np.dot(a, b)
"""


def test_the_first_compilation_finds_blas_without_importing_scipy_linalg(tmp_path):
    """numba's array maths probes for BLAS by importing scipy.linalg; the package's first
    compilation imports the array maths with a probe that only finds scipy. np.dot still
    compiles against BLAS (and imports scipy.linalg when it is lowered)."""
    run = _fresh_interpreter(tmp_path, "blaspkg", _WITH_DOT)
    out = run("""
        import sys
        import numpy as np
        from blaspkg.funcs import dot, total
        t = total(np.arange(5.0))
        before = "scipy.linalg" in sys.modules
        from numba.np import arraymath, linalg
        probe_restored = linalg.ensure_blas.__name__ == "ensure_blas"
        d = dot(np.arange(3.0), np.arange(3.0))
        print(t, before, arraymath._HAVE_BLAS, probe_restored, d, "scipy.linalg" in sys.modules)
    """)
    assert out == "10.0 False True True 5.0 True"


def test_a_function_loaded_from_the_cache_says_that_its_typed_ir_is_not_kept(tmp_path):
    run = _fresh_interpreter(tmp_path, "annpkg", _LOADED)
    code = """
        import io, contextlib
        import numpy as np
        from annpkg.funcs import total
        total(np.arange(5.0))
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            total.inspect_types()
        print(sum(total.stats.cache_hits.values()), "not cached" in text.getvalue())
    """
    assert run(code) == "0 False"  # compiled here: numba's own listing of the typed IR
    assert run(code) == "1 True"


def test_the_garbage_collector_runs_less_often_while_numba_compiles():
    """The first generation's threshold is raised for a compilation and restored after it."""
    import gc

    import numba
    from numba.core import event

    seen = []

    class Probe(event.Listener):  # registered after the package's own listener: sees its threshold
        def on_start(self, ev):
            seen.append(gc.get_threshold())

        def on_end(self, ev):
            pass

    before = gc.get_threshold()
    with event.install_listener("numba:compile", Probe()):
        assert numba.njit(lambda x: x + 1)(1) == 2
    assert seen and seen[0][0] == max(_numba.GC_THRESHOLD_COMPILING, before[0])
    assert seen[0][1:] == before[1:]
    assert gc.get_threshold() == before
