"""The benchmark results file: every measured figure of the performance page as one record.

``docs/performance/results.json`` holds ``{"machines": {id: {...}}, "records": [...]}``. A
record is one measured case: ``table`` (which table of ``docs/performance.md`` shows it),
``id`` (what was measured, unique within its table: a new measurement of the same case
replaces the old one), the figures themselves, and where they come from: ``machine`` (a key
of ``machines``), ``date`` (``YYYY-MM-DD``), ``commit`` (the source tree measured),
``command`` (the command that printed the figures) and, where known, ``load`` (the load
average during the run). ``scripts/benchmarks/performance_page.py`` writes the page's tables
and figures from this file; the benchmark scripts add to it with ``--record``.
"""

from __future__ import annotations

import datetime
import json
import os
import platform
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "performance" / "results.json"
REQUIRED = ("table", "id", "machine", "date", "commit", "command")


def load(path=RESULTS):
    """The results file as a dict (``machines``, ``records``)."""
    with open(path) as f:
        return json.load(f)


def save(data, path=RESULTS):
    """Write the results file (records sorted by table and id; a failed write leaves the old file)."""
    data = dict(data, records=sorted(data["records"], key=lambda r: (r["table"], r["id"])))
    tmp = Path(str(path) + ".tmp")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1, ensure_ascii=False)
        f.write("\n")
    os.replace(tmp, path)


def this_machine():
    """(key, description) of the machine this process runs on: CPU model and core count."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    cores = os.cpu_count()
    key = "-".join(model.lower().replace("(r)", "").replace("(tm)", "").split()[:3]) + f"-{cores}cpu"
    return key, {"cpu": model, "cores": cores, "system": f"{platform.system()} {platform.release()}",
                 "python": platform.python_version()}


def this_commit(tree=ROOT):
    """Short hash of the source tree's HEAD, with ``+changes`` when its working tree differs."""
    try:
        head = subprocess.run(["git", "-C", str(tree), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(tree), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+changes" if dirty else "")


def record(new, command, path=RESULTS, load_average=None, commit=None):
    """Add measured records (dicts with ``table``, ``id`` and the figures) to the results file,
    stamped with this machine, today's date, the commit and ``command``; a record of the same
    table and id is replaced. ``commit``: the source tree measured (default: this tree's HEAD now;
    a long run passes the commit it started from)."""
    data = load(path)
    key, desc = this_machine()
    data["machines"].setdefault(key, desc)
    stamp = {"machine": key, "date": datetime.date.today().isoformat(), "commit": commit or this_commit(),
             "command": command}
    if load_average is not None:
        stamp["load"] = round(load_average, 1)
    fresh = [dict(r, **stamp) for r in new]
    done = {(r["table"], r["id"]) for r in fresh}
    data["records"] = [r for r in data["records"] if (r["table"], r["id"]) not in done] + fresh
    save(data, path)
    return fresh


def record_and_render(new, command, load_average=None, commit=None):
    """:func:`record` the measured records, then rewrite ``docs/performance.md`` from the file."""
    import performance_page  # scripts/benchmarks: imports this module

    fresh = record(new, command, load_average=load_average, commit=commit)
    performance_page.main([])
    return fresh
