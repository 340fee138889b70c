"""Every example config through ``advise``, ``run`` and ``analyze`` (small and short, by --set):
each tool says only what applies to the config's scene (:class:`granulargas.io.scene.Scene`), and
advise's predicted temperature at the run's end is the run summary's and agrees with the one
analyze measures.

The agreement is checked against the temperature analyze measures at the end (a driven run: its
steady temperature, the mean after the relaxation), within :data:`TOLERANCE`; the theory is that
of a homogeneous gas of identical particles, so a polydisperse mix gets
:data:`POLYDISPERSE_TOLERANCE` (advise says so in a note) and a run in a box above the
instability length is only required to be warned about (its clusters leave the homogeneous law).
"""

import contextlib
import io
import json
import re
from pathlib import Path

import pytest

from granulargas.cli import main
from granulargas.io.config import load_config
from granulargas.io.scene import Scene

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

#: measured / predicted temperature at the end, allowed deviation (homogeneous scenes; N = 500 to
#: 2000: the final temperature of one run scatters by about 1-3 %)
TOLERANCE = 0.05
#: ... for a polydisperse mix, compared with the theory of identical particles of the mean diameter
POLYDISPERSE_TOLERANCE = 0.10
#: ... for a sheared inelastic gas, compared with the steady temperature of the Grad solution: the
#: engine and DSMC agree with each other and find a* = a/nu0 about 3.5 % above Grad's at eps = 0.8
#: (tests/dsmc/test_dsmc_shear.py), and T goes as a*^-2 at a given rate
SHEAR_TOLERANCE = 0.10

#: config -> overrides that keep it small and short; (method, kind) of its scene
EXAMPLES = {
    "quickstart": ({"system.particles": 1000, "run.end_time": 20.0}, ("edmd", "cooling")),
    "haff_3d": ({"system.particles": 1000, "run.collisions_per_particle": 10}, ("edmd", "cooling")),
    "haff_2d": ({"system.particles": 400, "run.collisions_per_particle": 10}, ("edmd", "cooling")),
    "elastic_3d": ({"system.particles": 500, "run.end_time": 2.0}, ("edmd", "elastic")),
    "walls_3d": ({"system.particles": 500, "run.end_time": 5.0}, ("edmd", "elastic")),
    "driven_3d": ({"system.particles": 500, "run.end_time": 300.0}, ("edmd", "driven")),
    "hcs_dsmc_3d": ({"system.particles": 20000, "run.end_time": 200.0}, ("dsmc", "cooling")),
    "material_3d": ({"system.particles": 1000, "run.end_time": 20.0}, ("edmd", "cooling")),
    "polydisperse_3d": ({"system.particles": 1000, "run.end_time": 20.0}, ("edmd", "cooling")),
    "viscoelastic_3d": ({"system.particles": 1000, "run.end_time": 50.0}, ("edmd", "cooling")),
    "clustering_2d_constant": ({"system.particles": 2000, "run.end_time": 20.0}, ("edmd", "cooling")),
    "clustering_2d_viscoelastic": ({"system.particles": 1000, "run.end_time": 100.0,
                                    "output.first_snapshot": 0.5}, ("edmd", "cooling")),
    "mixture_hcs_3d": ({"system.particles": 20000, "run.collisions_per_particle": 30}, ("dsmc", "cooling")),
    "glass_steel_3d": ({"system.particles": 1000, "run.collisions_per_particle": 20}, ("edmd", "cooling")),
    "rough_hcs_3d": ({"system.particles": 1000, "run.collisions_per_particle": 10}, ("edmd", "cooling")),
    "rough_driven_2d": ({"system.particles": 400, "run.end_time": 600.0, "output.snapshot_interval": 100.0},
                        ("edmd", "driven")),
    "rough_mpemba_hot": ({"system.particles": 1000}, ("edmd", "driven")),
    "rough_mpemba_cold": ({"system.particles": 1000}, ("edmd", "driven")),
    "shear_3d": ({"system.particles": 1000, "run.end_time": 600.0}, ("edmd", "shear")),
    "shear_2d": ({"system.particles": 400, "run.end_time": 300.0}, ("edmd", "shear")),
    "shear_dsmc_3d": ({"system.particles": 10000, "run.end_time": 300.0}, ("dsmc", "shear")),
    "shear_elastic_3d": ({"system.particles": 500, "run.end_time": 60.0}, ("edmd", "shear")),
    "shear_elastic_2d": ({"system.particles": 400, "run.end_time": 100.0}, ("edmd", "shear")),
}

#: vibrated scenes (gravity, thermal or vibrating walls): no free cooling to predict, so no
#: temperature to agree on; each tool shows the scene's own numbers instead
VIBRATED = {
    "vibrated_bed_2d": {"run.end_time": 20.0},
    "vibrated_bed_3d": {"system.particles": 500, "run.end_time": 5.0},
    "shaken_cell_3d": {"system.particles": 500, "run.end_time": 5.0},
}


def test_every_example_config_is_covered():
    assert {p.stem for p in CONFIGS.glob("*.toml")} == set(EXAMPLES) | set(VIBRATED)


def _call(args):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(args)
    assert code == 0
    return out.getvalue()


#: advise's line labels and the statement (Scene.shows) each belongs to
LABELS = {"clustering": "instability", "homogeneous": "homogeneous_by_construction", "steady state": "driven_state",
          "shear flow": "shear_state",
          "eps spread": "eps_spread", "best const.": "constant_or_viscoelastic",
          "equivalent": "constant_or_viscoelastic", "duration": "duration"}


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_advise_run_and_analyze_agree_and_speak_of_the_scene(name, tmp_path):
    overrides, (method, kind) = EXAMPLES[name]
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    config = f"{CONFIGS / name}.toml"
    scene = Scene.from_config(load_config(config, overrides))
    assert (scene.method, scene.kind) == (method, kind)

    adv = json.loads(_call(["advise", config, "--json", *sets]))
    assert adv["scene"]["method"] == method and adv["scene"]["kind"] == kind
    text = _call(["advise", config, *sets])
    labels = {line[:12].strip() for line in text.splitlines()}
    for label, statement in LABELS.items():
        if label in labels:
            assert scene.shows(statement), (label, text)
    if kind != "cooling":
        assert "Haff" not in text and "cooling)" not in text and "clustering" not in labels
    if kind == "driven":
        assert "steady state" in labels
    if kind == "shear":
        assert "shear flow" in labels and "uniform shear flow" in text
    if method == "dsmc":
        assert "clustering" not in labels and "box" not in text.split("homogeneous", 1)[0]

    out = tmp_path / f"{name}.h5"
    summary = _call(["run", config, "--quiet", "-o", str(out), *sets])
    predicted = float(re.search(r"^validity +T \S+ -> (\S+)", summary, re.M).group(1))
    assert predicted == float(f"{adv['temperature_end']:.3g}")  # one prediction for both
    assert "centre-of-mass" not in summary
    unstable = "shear-instability length" in summary
    assert unstable == (scene.shows("instability") and adv["box"] > adv["instability_length"])
    if method == "dsmc":
        assert "box" not in summary and "L_c" not in summary

    assert Scene.from_file(out) == scene  # the file says what the config said
    report = _call(["analyze", str(out)])
    result = json.loads(_call(["analyze", str(out), "--json"]))
    assert result["scene"]["kind"] == kind and result["scene"]["method"] == method
    if method == "dsmc":
        assert "box length" not in report and "L_c" not in report
    # a driven run still on its way (no relaxed part, e.g. the Mpemba gases): the temperature at the end
    measured = result["T_steady"] if kind in ("driven", "shear") and result.get("T_steady") is not None else result["T_final"]
    ratio = measured / adv["temperature_end"]
    if not unstable:
        tol = (POLYDISPERSE_TOLERANCE if scene.polydisperse else
               SHEAR_TOLERANCE if kind == "shear" and scene.model != "elastic" else TOLERANCE)
        assert abs(ratio - 1.0) < tol, (name, measured, adv["temperature_end"])


@pytest.mark.parametrize("name", list(VIBRATED))
def test_a_vibrated_scene_gets_its_own_numbers_and_no_cooling_advice(name, tmp_path):
    overrides = VIBRATED[name]
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    config = f"{CONFIGS / name}.toml"
    scene = Scene.from_config(load_config(config, overrides))
    assert (scene.method, scene.kind) == ("edmd", "vibrated")

    adv = json.loads(_call(["advise", config, "--json", *sets]))
    assert adv["scene"]["kind"] == "vibrated" and adv["vibrated"]["walls"]
    assert adv["instability_length"] is None and adv["eps_best"] is None
    text = _call(["advise", config, *sets])
    labels = {line[:12].strip() for line in text.splitlines()}
    assert "scene" in labels and not labels & set(LABELS)
    for word in ("Haff", "cooling", "clustering", "L_c", "shear-instability"):
        assert word not in text, (word, text)

    out = tmp_path / f"{name}.h5"
    summary = _call(["run", config, "--quiet", "-o", str(out), *sets])
    assert "scene        " in summary
    for word in ("Haff", "homogeneous cooling", "shear-instability", "L_c"):
        assert word not in summary, (word, summary)
    assert Scene.from_file(out) == scene  # the file says what the config said
    result = json.loads(_call(["analyze", str(out), "--json"]))
    assert result["scene"]["kind"] == "vibrated" and result["kind"] == "vibrated"
    # the velocity distribution in layers and the centre of mass above the floor
    layers = result["layer_distributions"]
    assert 1 <= len(layers) <= 4 and all(a["to"] > a["from"] for a in layers)
    assert all(len(a["density_along"]) == len(a["gaussian"]) == len(a["bins"]) - 1 for a in layers)
    assert sum(a["samples_along"] for a in layers) > 0 and result["com_height"] > 0
    report = _call(["analyze", str(out)])
    assert "Haff" not in report and "L_c" not in report
    assert "velocity distribution in layers" in report and "centre of mass above the floor" in report
    _call(["analyze", str(out), "--plot", str(tmp_path / "profiles.png")])
    assert (tmp_path / "profiles.png").stat().st_size > 0
