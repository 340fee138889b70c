"""The numba decorators the package uses.

``cache=True`` everywhere (compiled code is reused across processes); no
``fastmath`` (it breaks ``inf`` sentinels and event ordering). Set
``GRANULARGAS_NO_CACHE=1`` to disable the on-disk cache.

:func:`kernel` is :func:`jit` without numba's reference counting (``_nrt=False``),
for compiled code that allocates no arrays. Numba counts references to every
array argument of a compiled function (an atomic increment at entry and a
decrement at exit, through a call it cannot inline); the event loop passes a
few dozen arrays to each of its per-event calls, and these counts cost ~20 % of
its time (``scripts/profiling/profile_loop.py``). A kernel may not create arrays
(``np.empty`` etc. fail to compile in it); it may read and write the arrays it
is given and call other kernels or jit functions.

:func:`inlined` is a kernel that every compiled caller inlines: it is compiled
and optimised once, as a function of its own, and LLVM inlines the optimised
code at each call site (the ``alwaysinline`` attribute: numba's
``forceinline``). The event loop's hot kernels are of this kind. An inlined
kernel has no Python entry point (``python=True`` keeps one, for the few that
tests call directly): calling one from Python crashes the interpreter.

:func:`inlined_ir` is a kernel that numba inlines at the level of its own IR
(``inline="always"``): the callee's IR is rebuilt, deep-copied and typed again
at every call site, as part of the caller, and the callee is never compiled on
its own. Numba compiles every jit function a compiled function calls as a
library of its own -- typed, lowered, optimised by LLVM with the code of all
its callees, and turned into machine code -- and then links that code into the
caller and optimises it again there; for a function with a single call site,
whose code only its caller needs, that is work done twice, and IR inlining
does it once -- unless the same code serves several builds of the loop: the pair
collision (``collide_pair``) is compiled once as an :func:`inlined` library, which the
first run caches and every later build (other neighbour mode, walls, driving) links and
inlines without typing it again. At several call sites (or nested several levels deep) the copies
and the typing repeat at each and cost more than the library saves: the loop's
per-event steps (one call site in each build of the loop) are of this kind,
the shared helpers are :func:`inlined` or plain kernels. The copy is made in
Python (numba deep-copies the callee's IR blocks and runs its untyped passes,
its own IR inlining included), so a large callee with IR-inlined callees of its
own can cost more to inline than to compile once more as a library: the list
rebuild, inlined this way into the list loop, added 1.3 s to the loop's
inlining pass against 0.8-1.2 s for its own library, and stays a real call.
A branch on ``x is None`` is pruned before IR inlining only where ``x`` is an
argument of the function being compiled: inside an IR-inlined callee the branch
on the callee's own argument survives until after the callee's IR-inlined calls
have been copied in. So an IR-inlined call that only one build of the loop
needs sits under a branch of the loop itself (the sheared list expiry: its
rebuild inlined from inside a shared expiry step cost every list loop ~6 s).

Features switched off by a None-typed argument (contacts, spins, species, the
profiler's probe) are small :func:`inlined` kernels that branch on
``x is None`` for their own argument, which numba prunes before typing. Numba
overloads would do the same, but their implementations (lambdas made when the
overload is resolved) cannot be cached: every process that compiles a loop
compiled them again.

No function here has numba's C-callable wrapper (``no_cfunc_wrapper``): it serves a
function passed as a first-class function value (``FunctionType``), which the package
never does, and costs a wrapper's lowering, LLVM optimisation and machine code in every
compiled function's library. Python calls go through the CPython wrapper, compiled code
calls the function itself.

Literal arguments. A compiled function called from compiled code with a constant
argument (``f(x, 3)``) is typed with that argument's literal type (``Literal[int](3)``)
and compiled once per distinct constant and once more for a variable argument: a few
of the cell scans' and the calendar's kernels are compiled twice for that reason
(``scripts/profiling/compile_profile.py`` lists them). Their constant-specialised code
is kept: passing ``np.int64(3)`` instead saves the copy but measured 3-4 % slower in a
paired comparison of the cell-crossing loop (``scripts/ab/paired.py``). A variable that
starts as a constant and changes later (``m = 0`` ... ``m += 1``) is typed as that
literal in type inference's first pass, so a compiled function it is passed to is
compiled for the literal too, a copy no call uses (``compile_profile.py`` lists the
functions compiled with several signatures); ``np.int64(0)`` as the start avoids it.

Every function here is compiled with ``forceinline`` set explicitly (False
unless :func:`inlined`): numba otherwise inherits the flag from the function
whose compilation triggered the callee's, so that a kernel first compiled from
within an inlined kernel would be inlined into all its callers.

The on-disk cache. Numba stores a compiled function with a stamp of its own
source file and reuses it while that file is unchanged. But the machine code
of a function holds the code of every jit function it calls (inlined or linked
in) and the module constants it reads, from other files too: after an edit of
``_geometry.py`` alone, the cached event loop of ``_loop.py`` would still run
the old geometry. The functions compiled here are therefore cached with a
stamp that adds :func:`source_stamp`, a hash of every Python source file of
the package (and of the package that holds the function, if another one): any
change to the package's sources recompiles everything once.
An installed package never changes, so its cache stays valid.

Loading. numba refreshes its target context before it loads a function from the
cache: it imports and registers the typing and lowering of everything numba supports,
which a compilation needs but loaded machine code does not (about 0.3 s of CPU, a
third of a small run's start-up). The cache here loads without it and installs only
the runtime's symbols that machine code calls (:func:`_install_runtime_symbols`); a
function that is not in the cache is compiled, and numba's compiler refreshes the
context itself first. That refresh is most of numba's first compilation in a process
(about 0.2 s of CPU for a one-line function, 0.03 s for the next one). Numba's array
maths, which the refresh imports, probes for BLAS (for ``np.dot``) by importing
``scipy.linalg``, whose array-API layer imports ``numpy.f2py``: another 0.3 s of CPU,
which a run that needs no scipy otherwise (the elastic and constant-restitution theory)
would pay for a flag. Before the first compilation :func:`_import_array_maths` imports
the array maths with a probe that only looks for scipy (a dependency of the package); a
compiled ``np.dot`` still loads BLAS and checks it when it is lowered.

Start-up. The first run of each kind compiles its kernels (several seconds of
CPU) and every later run loads them from the cache (milliseconds).
:class:`CompileWatch` sees numba's compilations (numba's ``numba:compile``
events, sent only when a function is compiled, never when it is loaded from the
cache): it announces the first one, so that the pause is explained before it
starts, and adds up the time they take, so that a run can count it as start-up;
:func:`cache_location` is where the compiled code is kept.

Garbage collection while compiling. Numba's compiler makes millions of small Python objects
(IR nodes, types, LLVM IR text) that live until the compilation ends, and Python's cyclic
garbage collector, run after every 700 net allocations, traverses them again and again:
about a tenth of a compilation's CPU time (1.3 s of a quickstart's 12 s of compiling, 0.75 s
of a dense 3D run's 6.5 s after it). :class:`_CompilerGC`, listening to every compilation,
raises the first generation's threshold to :data:`GC_THRESHOLD_COMPILING` while one runs
(nested ones included) and restores the previous thresholds after it: 0.4-0.5 and 0.2 s of
collecting in those two runs, for some 15 MB more memory at the peak. The net saving is
smaller than the collector's own time, 0.2-0.5 s of CPU per first run side by side
(``scripts/benchmarks/startup.py --trees``): cycles are still collected, only less often and
later, and memory that is freed later is reused less while it is still in cache.
"""

import functools
import gc
import hashlib
import importlib.util
import os
import sys
import time

import numba
import numba.cpython.hashing  # noqa: F401  (installs the hash secret's symbols: _install_runtime_symbols)
from numba.core import caching, event
from numba.core.runtime import rtsys

_CACHE = os.environ.get("GRANULARGAS_NO_CACHE", "") not in ("1", "true", "yes")

_PACKAGE = os.path.dirname(os.path.abspath(__file__))


@functools.lru_cache(maxsize=None)
def source_stamp(root=_PACKAGE):
    """SHA-256 (hex) of the relative paths and contents of the ``.py`` files under ``root``."""
    digest = hashlib.sha256()
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = sorted(d for d in subfolders if d != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                digest.update(os.path.relpath(path, root).encode() + b"\0")
                with open(path, "rb") as f:
                    digest.update(f.read())
                digest.update(b"\0")
    return digest.hexdigest()


def _top_package(path):
    """Directory of the top-level package that holds the file ``path`` (None: not in a package)."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.exists(os.path.join(folder, "__init__.py")):
        return None
    while os.path.exists(os.path.join(os.path.dirname(folder), "__init__.py")):
        folder = os.path.dirname(folder)
    return folder


def _package_stamped(locator):
    """Subclass of numba cache locator ``locator`` whose source stamp adds :func:`source_stamp`
    of this package and of the package holding the function (test helpers, user code)."""

    class PackageStamped(locator):
        def get_source_stamp(self):
            own = getattr(self, "_py_file", None)
            own = _top_package(own) if own else None
            extra = source_stamp(own) if own and own != _PACKAGE else None
            return (super().get_source_stamp(), source_stamp(), extra)

    PackageStamped.__name__ = PackageStamped.__qualname__ = f"PackageStamped{locator.__name__}"
    return PackageStamped


class _CacheImpl(caching.CompileResultCacheImpl):
    _locator_classes = [_package_stamped(c) for c in caching.CompileResultCacheImpl._locator_classes]

    def reduce(self, cres):
        """numba's reduction of a compiled function for the cache, without the text of its typed
        IR (``str(cres.type_annotation)``, which only ``inspect_types`` shows: about 1 ms per
        function, 0.1 s of CPU over a quickstart's compilations)."""
        return cres._replace(type_annotation=_NOT_CACHED)._reduce()


#: what ``inspect_types`` shows for a function loaded from the cache
_NOT_CACHED = "(the typed IR is not cached: compile without the cache to inspect it)"


class _FunctionCache(caching.FunctionCache):
    """numba's per-function cache, with the package-wide source stamp (module docstring)."""

    _impl_class = _CacheImpl

    def load_overload(self, sig, target_context):
        """numba's load without its ``target_context.refresh()`` (module docstring, "Loading"):
        only the runtime's symbols that loaded machine code may call are installed."""
        _install_runtime_symbols(target_context)
        with self._guard_against_spurious_io_errors():
            loaded = self._load_overload(sig, target_context)
        if loaded is None:  # numba compiles next
            _import_array_maths()
        return loaded


def _import_array_maths():
    """Import numba's array maths (which the compiler's first refresh would) with its BLAS
    probe reduced to finding scipy, not importing ``scipy.linalg`` (module docstring,
    "Loading"); once per process, and nothing if numba has imported it already."""
    if "numba.np.arraymath" in sys.modules:
        return
    from numba.np import linalg

    probe = getattr(linalg, "ensure_blas", None)
    if probe is None:
        return

    def scipy_present():
        if importlib.util.find_spec("scipy") is None:
            raise ImportError("scipy is required for linear algebra")

    linalg.ensure_blas = scipy_present
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        linalg.ensure_blas = probe


def _install_runtime_symbols(target_context):
    """Install the symbols numba's machine code links against, as ``refresh`` would: the
    reference-counting runtime (NRT) and the hash secret (any cached code that hashes). The C
    helpers and the maths library are installed when the target context is created."""
    rtsys.initialize(target_context)


def jit(*args, **kwargs):
    """``numba.njit`` with the package defaults (cached with the package's stamp, no fastmath)."""
    cache = kwargs.pop("cache", _CACHE)
    kwargs.setdefault("forceinline", False)
    kwargs.setdefault("no_cfunc_wrapper", True)

    def decorate(func):
        dispatcher = numba.njit(**kwargs)(func)
        if cache and hasattr(dispatcher, "enable_caching"):  # not with NUMBA_DISABLE_JIT
            dispatcher._cache = _FunctionCache(dispatcher.py_func)
        return dispatcher

    if args:
        (func,) = args
        return decorate(func)
    return decorate


def kernel(*args, python=True, **kwargs):
    """:func:`jit` without reference counting (``_nrt=False``): for code that allocates nothing.

    ``python=False``: no Python entry point (numba's CPython and C wrappers, which
    unbox every argument, are not built; calling the kernel from Python crashes),
    for a kernel that only compiled code calls.
    """
    kwargs.setdefault("_nrt", False)
    if not python:
        kwargs["no_cpython_wrapper"] = True
        kwargs["no_cfunc_wrapper"] = True
    return jit(*args, **kwargs)


def inlined(*args, python=False, **kwargs):
    """:func:`kernel` inlined by LLVM into every compiled caller (``forceinline``).

    ``python=False`` (default): no Python entry point (numba's CPython and C
    wrappers are not built; calling it from Python crashes). ``python=True``
    keeps them, for a kernel that tests call from Python.
    """
    kwargs["forceinline"] = True
    return kernel(*args, python=python, **kwargs)


def inlined_ir(*args, **kwargs):
    """:func:`kernel` that numba inlines at the level of its IR into every caller
    (``inline="always"``; module docstring): never compiled on its own, so that
    it has no Python entry point. For a function with one call site in compiled code."""
    kwargs["inline"] = "always"
    return kernel(*args, python=False, **kwargs)


def _located():
    """A function of this module, whose cache locator tells where the package's code is cached."""


def cache_location() -> str:
    """Where numba keeps the package's compiled code: ``$NUMBA_CACHE_DIR`` when set, else the
    ``__pycache__`` folders beside the package's sources, or numba's user-wide cache folder
    when those are not writable (numba's choice, as for every cached function here)."""
    for locator_class in _CacheImpl._locator_classes:
        locator = locator_class.from_function(_located, os.path.abspath(__file__))
        if locator is not None:
            path = locator.get_cache_path()
            if numba.config.CACHE_DIR:
                return numba.config.CACHE_DIR
            if os.path.dirname(os.path.abspath(path)) == _PACKAGE:
                return os.path.join(_PACKAGE, "*", "__pycache__")
            return os.path.dirname(path)
    return "nowhere (numba's cache is not available here)"


class CompileWatch(event.Listener):
    """Within a ``with`` block: numba's compilations (cache misses) in this process.

    ``announce``: called once, with no argument, when the first compilation after
    :attr:`armed` is set starts (e.g. to say what is being compiled before the pause;
    ``armed`` is True unless given); ``seconds`` and
    ``cpu_seconds``: the wall-clock and CPU time spent compiling so far (outermost
    compilations only: a function compiled while compiling its caller counts once);
    ``count``: functions compiled. Numba sends no event for a function loaded from
    its cache, so a run whose code is all cached records nothing.
    """

    def __init__(self, announce=None, armed=True):
        self.announce = announce
        self.armed = armed
        self.announced = False
        self.seconds = 0.0
        self.cpu_seconds = 0.0
        self.count = 0
        self._depth = 0
        self._start = (0.0, 0.0)

    def on_start(self, ev):
        if self._depth == 0:
            if self.armed and not self.announced and self.announce is not None:
                self.announced = True
                self.announce()
            self._start = (time.perf_counter(), time.process_time())
        self._depth += 1
        self.count += 1

    def on_end(self, ev):
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._start[0]
            self.cpu_seconds += time.process_time() - self._start[1]

    def __enter__(self):
        event.register("numba:compile", self)
        return self

    def __exit__(self, *exc):
        event.unregister("numba:compile", self)
        return False


#: Python's first-generation garbage-collection threshold while numba compiles (module docstring)
GC_THRESHOLD_COMPILING = 20_000


class _CompilerGC(event.Listener):
    """The garbage collector's thresholds raised while numba compiles (module docstring).

    Numba sends ``numba:compile`` under its global compiler lock, so compilations in several
    threads do not interleave here; a compilation within a compilation (a callee) counts as
    part of the outermost one."""

    def __init__(self):
        self._depth = 0
        self._saved = None

    def on_start(self, ev):
        if self._depth == 0:
            self._saved = gc.get_threshold()
            gc.set_threshold(max(GC_THRESHOLD_COMPILING, self._saved[0]), *self._saved[1:])
        self._depth += 1

    def on_end(self, ev):
        self._depth -= 1
        if self._depth == 0:
            gc.set_threshold(*self._saved)


event.register("numba:compile", _CompilerGC())


def announcement(what: str) -> str:
    """The line that says what is being compiled, that it happens once, and where it is kept."""
    return f"compiling {what} (once; cached in {cache_location()})"

