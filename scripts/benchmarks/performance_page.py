"""Writes the tables and figures of ``docs/performance.md`` from ``docs/performance/results.json``.

The page's prose is written by hand; every measured figure on it sits between markers

    <!-- results: NAME -->
    ...generated Markdown...
    <!-- end results -->

and is written here from the records of the results file (``scripts/benchmarks/results.py``
describes a record), so that the page cannot drift from the measurements. The figures
``docs/figures/performance_scaling.png`` (rate against N) and
``docs/figures/performance_dilute_events.png`` (rate against events per collision) are drawn
from the same records.

Usage::

    python scripts/benchmarks/performance_page.py            # rewrite the page and its figures
    python scripts/benchmarks/performance_page.py --check    # exit 1 if the page differs from the file

The README's Performance section holds the page's summary in a ``readme`` block, written the same way.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import results  # noqa: E402

PAGE = results.ROOT / "docs" / "performance.md"
README = results.ROOT / "README.md"  # its Performance section shows the page's summary
FIGURES = results.ROOT / "docs" / "figures"
BLOCK = re.compile(r"(<!-- results: ([\w-]+) -->\n)(.*?)(<!-- end results -->)", re.S)


def fmt(x, digits=None):
    """A figure as the page shows it: a range ``[a, b]`` as ``a–b``, None as empty."""
    if x is None:
        return ""
    if isinstance(x, list):
        return "–".join(fmt(v, digits) for v in x)
    if isinstance(x, (int, float)) and digits is not None:
        return f"{x:.{digits}f}"
    return f"{x:g}" if isinstance(x, float) else str(x)


def power(n):
    """N as the page writes it: 10976 -> 10976, 1000000 -> 10^6 (MathML by the maths hook)."""
    n = int(n)
    k = len(str(n)) - 1
    return f"\\(10^{k}\\)" if n == 10**k else str(n)


def rule_name(rule):
    if rule == "elastic":
        return "elastic"
    if rule == "viscoelastic":
        return "viscoelastic (damping 0.1)"
    try:
        return f"constant ε = {float(rule):g}"
    except ValueError:
        return rule


def scene_name(scene):
    if scene.startswith("driven:"):
        return f"white-noise driving, H = {scene.partition(':')[2]}"
    return {"walls": "walls on the last axis"}.get(scene, scene)


class Table:
    """A Markdown table whose rows cite their measurement: date, commit and a numbered command."""

    def __init__(self, header, align):
        self.header, self.align, self.rows, self.commands = header, align, [], []

    def add(self, cells, rec):
        if rec["command"] not in self.commands:
            self.commands.append(rec["command"])
        k = self.commands.index(rec["command"]) + 1
        self.rows.append([*cells, f"{rec['date']}, {rec['commit']} [{k}]"])

    def markdown(self):
        lines = ["| " + " | ".join([*self.header, "measured"]) + " |",
                 "|" + "|".join([*self.align, "---"]) + "|"]
        lines += ["| " + " | ".join(r) + " |" for r in self.rows]
        lines.append("")
        lines += [f"[{k}] `{c}`  " for k, c in enumerate(self.commands, 1)]
        lines[-1] = lines[-1].rstrip()
        return "\n".join(lines) + "\n"


def by_table(data, name):
    return [r for r in data["records"] if r["table"] == name]


def engine_sort(r):
    return (r["dim"], r["rule"], r["neighbours"], r["packing"], r["n"])


def engine_table(recs):
    t = Table(["d", "packing", "neighbours", "rule", "N", "M collisions/s (CPU)", "events / collision",
               "state B / particle"], ["--:", "--:", "---", "---", "--:", "--:", "--:", "--:"])
    for r in sorted(recs, key=engine_sort):
        t.add([str(r["dim"]), fmt(r["packing"]), r["neighbours"], rule_name(r["rule"]), power(r["n"]),
               f"**{fmt(r['rate_cpu'], 3)}**", fmt(r.get("events_per_collision"), 2),
               fmt(r.get("bytes_per_particle"))], r)
    return t.markdown()


def block_engine_elastic(data):
    return engine_table([r for r in by_table(data, "engine") if r["scene"] == "periodic" and r["rule"] == "elastic"])


def block_engine_rules(data):
    return engine_table([r for r in by_table(data, "engine") if r["scene"] == "periodic" and r["rule"] != "elastic"
                         and not r["rule"].replace(".", "").isdigit()])


def block_engine_scenes(data):
    recs = [r for r in by_table(data, "engine") if r["rule"].replace(".", "").isdigit()]
    base = {(r["n"], r["packing"], r["dim"]): r["rate_cpu"] for r in recs if r["scene"] == "periodic"}
    t = Table(["scene", "d", "packing", "rule", "N", "M collisions/s (CPU)", "cost / periodic",
               "wall collisions / collision"], ["---", "--:", "--:", "---", "--:", "--:", "--:", "--:"])
    for r in sorted(recs, key=lambda r: (r["n"], r["scene"] != "periodic", r["scene"])):
        ref = base.get((r["n"], r["packing"], r["dim"]))
        t.add([scene_name(r["scene"]), str(r["dim"]), fmt(r["packing"]), rule_name(r["rule"]), power(r["n"]),
               f"**{fmt(r['rate_cpu'], 3)}**", f"×{ref / r['rate_cpu']:.2f}" if ref else "",
               fmt(r.get("wall_collisions_per_collision"))], r)
    return t.markdown()


def block_c_code(data):
    t = Table(["N", "packing", "neighbours", "granulargas", "C code", "ratio", "rounds"],
              ["--:", "--:", "---", "--:", "--:", "--:", "--:"])
    for r in sorted(by_table(data, "c_code"), key=lambda r: (r["n"], r["neighbours"], r["packing"])):
        t.add([power(r["n"]), fmt(r["packing"]), r["neighbours"], fmt(r["rate_cpu"], 3),
               f"{fmt(r['c_rate_cpu'], 3)} ({r['c_variant']})", f"**×{r['rate_cpu'] / r['c_rate_cpu']:.2f}**",
               str(r["rounds"])], r)
    return t.markdown()


def block_dilute(data):
    recs = by_table(data, "dilute")
    t = Table(["mode", "width or shell (diameters)", "packing", "M collisions/s (CPU)", "events / collision"],
              ["---", "--:", "--:", "--:", "--:"])
    for r in sorted(recs, key=lambda r: (r["packing"], r["mode"].split(":")[0], r["width"])):
        t.add([r["mode"].split(":")[0], fmt(r["width"]), fmt(r["packing"]), fmt(r["rate_cpu"], 3),
               fmt(r["events_per_collision"], 2)], r)
    return t.markdown()


def block_crossover(data):
    from granulargas.engine.simulation import neighbour_mode

    t = Table(["d", "packing", "N", "cells: M collisions/s (CPU)", "lists", "cells / lists", "auto uses"],
              ["--:", "--:", "--:", "--:", "--:", "--:", "---"])
    for r in sorted(by_table(data, "crossover"), key=lambda r: (r["dim"], r["packing"], r["n"])):
        t.add([str(r["dim"]), fmt(r["packing"]), power(r["n"]), fmt(r["cells_rate_cpu"], 3),
               fmt(r["lists_rate_cpu"], 3), f"**×{r['cells_rate_cpu'] / r['lists_rate_cpu']:.2f}**",
               neighbour_mode("auto", r["packing"], r["dim"])], r)
    return t.markdown()


def block_memory(data):
    t = Table(["what", "d", "packing", "bytes / particle"], ["---", "--:", "--:", "--:"])
    for r in sorted(by_table(data, "memory"), key=lambda r: (r["what"], r["dim"], str(r["packing"]))):
        t.add([r["what"], str(r["dim"]), fmt(r["packing"]) or "any", f"**{fmt(r['bytes_per_particle'])}**"], r)
    return t.markdown()


def block_startup(data):
    t = Table(["run", "CPU of the process (s)", "of it compiling (s)"], ["---", "--:", "--:"])
    for r in sorted(by_table(data, "startup"), key=lambda r: r["id"]):
        spread = f" ({fmt(r['cpu_range'])})" if r.get("cpu_range") else ""
        t.add([r["what"], f"**{fmt(r['cpu_seconds'])}**{spread}", fmt(r["compile_seconds"])], r)
    return t.markdown()


def block_compile(data):
    t = Table(["engine build", "first compile, CPU (s)", "cached load, CPU (s)"], ["---", "--:", "--:"])
    for r in sorted(by_table(data, "compile"), key=lambda r: r["id"]):
        t.add([f"{r['neighbours']} (3D, 64 spheres)", f"**{fmt(r['first_seconds'])}**",
               fmt(r["cached_seconds"])], r)
    return t.markdown()


def block_initial(data):
    t = Table(["d", "packing", "N", "threads", "wall clock (s)", "CPU (s)"], ["--:", "--:", "--:", "--:", "--:", "--:"])
    for r in sorted(by_table(data, "initial"), key=lambda r: (r["dim"], r["n"], r["packing"], r["threads"])):
        t.add([str(r["dim"]), fmt(r["packing"]), power(r["n"]), str(r["threads"]), f"**{fmt(r['wall_seconds'])}**",
               fmt(r.get("cpu_seconds"))], r)
    return t.markdown()


def block_scene_costs(data):
    t = Table(["scene", "against", "d", "N", "packing", "neighbours", "CPU per collision, ratio", "rounds"],
              ["---", "---", "--:", "--:", "--:", "---", "--:", "--:"])
    for r in sorted(by_table(data, "scene_cost"), key=lambda r: (r["scene"], r["n"], r["packing"])):
        spread = f" ({fmt(r['quartiles'])})" if r.get("quartiles") else ""
        t.add([r["scene"], r["reference"], str(r["dim"]), str(r["n"]), fmt(r["packing"]), r["neighbours"],
               f"**×{r['ratio']:.2f}**{spread}", str(r["rounds"])], r)
    return t.markdown()


def block_rough(data):
    t = Table(["d", "N", "packing", "neighbours", "constant β_t = +1 / smooth", "Coulomb / smooth",
               "state B / particle, smooth → rough", "rounds"], ["--:", "--:", "--:", "---", "--:", "--:", "--:", "--:"])
    for r in sorted(by_table(data, "rough"), key=lambda r: (r["n"], r["packing"], r["neighbours"])):
        t.add([str(r["dim"]), power(r["n"]), fmt(r["packing"]), r["neighbours"], f"**×{r['ratio']:.2f}**",
               f"×{r['ratio_coulomb']:.2f}", f"{fmt(r['bytes_per_particle_smooth'])} → {fmt(r['bytes_per_particle'])}",
               str(r["rounds"])], r)
    return t.markdown()


def block_shear_edmd(data):
    t = Table(["d", "N", "packing", "ε", "neighbours", "CPU per collision, sheared / periodic", "rounds"],
              ["--:", "--:", "--:", "--:", "---", "--:", "--:"])
    recs = [r for r in by_table(data, "uniform_shear") if r["method"] == "edmd"]
    for r in sorted(recs, key=lambda r: (r["n"], r["neighbours"])):
        spread = f" ({fmt(r['ratio_range'])})" if r.get("ratio_range") else ""
        t.add([str(r["dim"]), power(r["n"]), fmt(r["packing"]), fmt(r["restitution"]), r["neighbours"],
               f"**×{r['ratio']:.2f}**{spread}", str(r["rounds"])], r)
    return t.markdown()


def block_shear_dsmc(data):
    t = Table(["d", "N", "packing", "ε", "M collisions/s (CPU)", "runs"], ["--:", "--:", "--:", "--:", "--:", "--:"])
    recs = [r for r in by_table(data, "uniform_shear") if r["method"] == "dsmc"]
    for r in sorted(recs, key=lambda r: r["n"]):
        spread = f" ({fmt(r['rate_range'])})" if r.get("rate_range") else ""
        t.add([str(r["dim"]), power(r["n"]), fmt(r["packing"]), fmt(r["restitution"]), f"**{fmt(r['rate_cpu'])}**{spread}",
               str(r["rounds"])], r)
    return t.markdown()


def block_dsmc(data):
    t = Table(["d", "N", "DSMC, M collisions/s (CPU)", "acceptance", "engine at packing 0.02", "engine at 0.3",
               "DSMC / engine at 0.02", "at 0.3"], ["--:", "--:", "--:", "--:", "--:", "--:", "--:", "--:"])
    for r in sorted(by_table(data, "dsmc"), key=lambda r: (-r["dim"], r["n"])):
        e02, e3 = r.get("engine_rate_cpu_0.02"), r.get("engine_rate_cpu_0.3")
        t.add([str(r["dim"]), power(r["n"]), f"**{fmt(r['rate_cpu'])}**", fmt(r["acceptance"]), fmt(e02), fmt(e3),
               f"×{r['rate_cpu'] / e02:.0f}" if e02 else "", f"×{r['rate_cpu'] / e3:.0f}" if e3 else ""], r)
    return t.markdown()


def block_dem(data):
    recs = sorted(by_table(data, "dem"), key=lambda r: r["id"])
    ref = recs[0]["wall_seconds"] if recs else 1.0
    t = Table(["run", "contact time / mean free time", "timestep", "steps", "wall clock (s)", "ratio"],
              ["---", "--:", "--:", "--:", "--:", "--:"])
    for r in recs:
        t.add([r["run"], fmt(r["contact_fraction"]), fmt(r["timestep"]) or "—",
               f"{r['steps']:,} {r['steps_what']}".replace(",", " "), fmt(r["wall_seconds"]),
               f"**{r['wall_seconds'] / ref:.0f}**"], r)
    return t.markdown()


def block_resolved_lammps(data):
    recs = sorted(by_table(data, "resolved_lammps"), key=lambda r: r["contact_fraction"])
    steps = sorted({k for r in recs for k in r["lammps"]}, key=int)
    t = Table(["\\(t_c/t_\\mathrm{free}\\)", "instantaneous", "resolved", *[f"LAMMPS \\(t_c/{s}\\)" for s in steps]],
              ["--:", "--:", "--:", *["--:"] * len(steps)])
    for r in recs:
        t.add([fmt(r["contact_fraction"]), fmt(r["instantaneous"]), fmt(r["resolved"]) or "refused",
               *[fmt(r["lammps"].get(s)) for s in steps]], r)
    return t.markdown()


def block_kernels(data):
    t = Table(["one call, in a compiled loop", "µs"], ["---", "--:"])
    for r in sorted(by_table(data, "kernels"), key=lambda r: r["id"]):
        t.add([r["what"], f"**{fmt(r['microseconds'])}**"], r)
    return t.markdown()


def block_machine(data):
    lines = []
    for key, m in sorted(data["machines"].items()):
        n = sum(r["machine"] == key for r in data["records"])
        lines.append(f"* `{key}` ({n} records): {m.get('description') or m['cpu']}; "
                     f"{m['cores']} cores, {m.get('system', '')}, Python {m.get('python', '')}.")
    return "\n".join(lines) + "\n"


def _find(data, table, **match):
    for r in by_table(data, table):
        if all(r.get(k) == v for k, v in match.items()):
            return r
    raise KeyError(f"{table}: no record with {match}")


def headline(data, plain=False):
    """The page's summary in one paragraph; ``plain``: for the README (no maths markup)."""
    def m(tex, text):
        return text if plain else f"\\({tex}\\)"

    dense = [_find(data, "c_code", neighbours="lists", packing=0.3, n=n) for n in (10976, 108000, 1000188)]
    dilute = [_find(data, "c_code", neighbours="cells", packing=eta, n=10976) for eta in (0.05, 0.1)]
    dilute5 = _find(data, "c_code", neighbours="cells", packing=0.05, n=108000)
    quick = _find(data, "startup", id=min(r["id"] for r in by_table(data, "startup")))
    lists = [r["bytes_per_particle"] for r in by_table(data, "memory") if r["what"].endswith("neighbour lists")]
    init = _find(data, "initial", dim=3, packing=0.5, n=10**6, threads=2)
    dsmc = [r["rate_cpu"] for r in by_table(data, "dsmc")]

    def x(r):
        return f"×{r['rate_cpu'] / r['c_rate_cpu']:.2f}"

    def rate(r):
        return fmt(r["rate_cpu"], 3)

    n4, n5, n6 = m("N \\approx 10^4", "N ≈ 10⁴"), m("10^5", "10⁵"), m("10^6", "10⁶")
    compiling = (f", {fmt(quick['compile_seconds'])} s of it compiling (once)" if quick.get("compile_seconds")
                 else ", most of it compiling (once)")
    return (f"Elastic hard spheres at packing 0.3, one core, side by side with a compiled C reference code: "
            f"{x(dense[0])} at {n4}, {x(dense[1])} at {n5} and "
            f"{x(dense[2])} at {n6} ({rate(dense[0])}, {rate(dense[1])} and {rate(dense[2])} million "
            f"collisions per CPU second). Dilute gases (cell crossings): {x(dilute[0])} at packing 0.05 and "
            f"{x(dilute[1])} at 0.1 for {n4}, {x(dilute5)} at 0.05 for "
            f"{n5}. The quickstart's first run on a fresh install: {fmt(quick['cpu_seconds'])} s of "
            f"CPU{compiling}. Engine state {min(lists)}–{max(lists)} "
            f"bytes per particle. The initial state of {n6} spheres at packing 0.5 in "
            f"{fmt(init['wall_seconds'])} s (two threads). The DSMC: {fmt(min(dsmc))}–{fmt(max(dsmc))} million "
            f"collisions per CPU second.\n")


def block_headline(data):
    return headline(data)


def block_readme(data):
    return headline(data, plain=True)


BLOCKS = {name[len("block_"):].replace("_", "-"): fn for name, fn in globals().items() if name.startswith("block_")}


def render(page_text, data):
    """The page with every results block rewritten from ``data``; raises on an unknown block name."""
    def one(m):
        name = m.group(2)
        if name not in BLOCKS:
            raise KeyError(f"unknown results block {name!r}; known: {', '.join(sorted(BLOCKS))}")
        return m.group(1) + BLOCKS[name](data) + m.group(4)

    return BLOCK.sub(one, page_text)


def figure_scaling(data, path):
    """Collision rate against N for the cases that the C code ran too: granulargas solid, the C code
    dashed, one colour per (packing, neighbour search)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    pairs = sorted({(r["packing"], r["neighbours"], r["c_variant"]) for r in by_table(data, "c_code")})
    for k, (eta, nb, variant) in enumerate(pairs):
        ours = sorted((r["n"], r["rate_cpu"]) for r in by_table(data, "engine")
                      if (r["dim"], r["scene"], r["rule"], r["packing"], r["neighbours"]) == (3, "periodic", "elastic",
                                                                                            eta, nb))
        theirs = sorted((r["n"], r["c_rate_cpu"]) for r in by_table(data, "c_code")
                        if (r["packing"], r["neighbours"]) == (eta, nb))
        if len(theirs) < 2:
            continue
        ax.plot(*zip(*ours), "o-", color=f"C{k}", label=f"granulargas, packing {eta:g}, {nb}")
        ax.plot(*zip(*theirs), "s--", color=f"C{k}", alpha=0.6, label=f"C code ({variant}), packing {eta:g}")
    ax.set_xscale("log")
    ax.set_xlabel("particles N")
    ax.set_ylabel("million collisions per CPU second")
    ax.set_ylim(bottom=0)
    ax.set_title("Elastic hard spheres (3D), one core: rate against N")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_dilute(data, path):
    """Rate against events per collision, one panel per N and packing (cells of several widths, list shells)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    recs = by_table(data, "dilute")
    cases = sorted({(r["n"], r["packing"]) for r in recs})  # one panel per N and packing
    fig, axes = plt.subplots(1, len(cases), figsize=(4.8 * len(cases), 4.0), squeeze=False)
    for ax, (n, eta) in zip(axes[0], cases):
        rows = [r for r in recs if (r["n"], r["packing"]) == (n, eta)]
        for kind, marker, colour in (("lists", "s", "C0"), ("cells", "o", "C1")):
            pts = sorted((r["events_per_collision"], r["rate_cpu"], r["width"]) for r in rows
                         if r["mode"].split(":")[0] == kind)
            if not pts:
                continue
            x, y, w = zip(*pts)
            ax.plot(x, y, marker=marker, color=colour, label=f"{kind} (labels: "
                    + ("cell width" if kind == "cells" else "shell") + ", diameters)")
            for xi, yi, wi in pts:
                ax.annotate(f"{wi:g}", (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=8, color=colour)
        for k, r in enumerate(r for r in by_table(data, "c_code") if (r["n"], r["packing"]) == (n, eta)
                              and r["neighbours"] == "cells"):
            ax.axhline(r["c_rate_cpu"], color=f"C{k + 2}", ls="--", label=f"C code ({r['c_variant']}, {r['date']})")
        ax.axvline(2.0, color="0.6", ls=":", lw=1, label="2 events per collision")
        ax.set_xlabel("events per collision")
        ax.set_ylabel("million collisions per CPU second")
        ax.set_title(f"N = {n}, packing {eta:g}")
        ax.set_ylim(0.0, 1.15 * max(r["rate_cpu"] for r in rows))
        ax.set_xlim(0.0, 1.12 * max(max(r["events_per_collision"] for r in rows), 2.0))
        ax.legend(fontsize=8, loc="upper left")
    fig.suptitle("Speed against events per collision (3D, elastic)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if the page differs from the results file")
    p.add_argument("--results", type=Path, default=results.RESULTS)
    args = p.parse_args(argv)
    data = results.load(args.results)
    stale = []
    for page in (PAGE, README):
        text = page.read_text()
        new = render(text, data)
        if new != text:
            stale.append(page)
            if not args.check:
                page.write_text(new)
    if args.check:
        for page in stale:
            print(f"{page}: figures differ from {args.results}; run python scripts/benchmarks/performance_page.py",
                  file=sys.stderr)
        return 1 if stale else 0
    figure_scaling(data, FIGURES / "performance_scaling.png")
    figure_dilute(data, FIGURES / "performance_dilute_events.png")
    print(f"wrote {PAGE}, {FIGURES / 'performance_scaling.png'}, {FIGURES / 'performance_dilute_events.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
