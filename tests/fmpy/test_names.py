"""Errors that say what to do, and named choices: the package checks names and values against the
model description before anything runs (one line naming the valid choices, nearest first; a
non-zero exit without a traceback from the command line), Enumeration items are accepted by name,
`pressure_for_force` answers in Pa, and the demo and the FMU pages carry no noise."""

import json
import re
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description

from actuator_fmus import Slave, UsageError, pressure_for_force, simulate
from actuator_fmus.names import nearest_first
from conftest import FMU_DIR, ROOT

CLI = [sys.executable, "-m", "actuator_fmus.cli"]
DEMO = ROOT / "scenes" / "fig2_3_ideal_mckibben.json"

BLADDER = ["none", "thin_wall", "layers", "exact_wall", "dissertation_thin_wall", "dissertation_layers",
           "dissertation_continuum"]
# Every Integer that selects among named options, by model: (variable, type, item names in value order).
ENUMERATIONS = {
    "McKibbenMuscle": {"preset": ["none", "A", "B", "C", "D", "DMSP_10", "DMSP_40", "DMSP_5", "DMSP_20"],
                       "bladder_model": BLADDER,
                       "effective_bladder_model": BLADDER,
                       "out_of_range_policy": ["ok", "warning", "discard"]},
    "McKibbenJoint": {"preset": ["none", "A", "B", "C", "D", "DMSP_10", "DMSP_40", "DMSP_5", "DMSP_20"],
                      "bladder_model": BLADDER,
                      "command_mode": ["pressure_difference", "joint_torque"],
                      "out_of_range_policy": ["ok", "warning", "discard"]},
    "KnittedMuscle": {"preset": ["none", "prototype", "fig_1_16"],
                      "shape_model": ["ideal_cylinder", "tubular_knit", "non_cylindrical"],
                      "bladder_model": BLADDER,
                      "out_of_range_policy": ["ok", "warning", "discard"]},
    "FreeBladder": {"out_of_range_policy": ["ok", "warning", "discard"]},
    "MultiferroicMotor": {"onion_model": ["quasi_static", "gilbert_relaxation"],
                          "schedule": ["inputs", "stepping_schedule"]},
}


def run_cli(*args, cwd=ROOT):
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600)


def test_nearest_name_comes_first():
    assert nearest_first("bladder_modle", ["pressure", "bladder_layers", "bladder_model"])[0] == "bladder_model"
    assert nearest_first("zzz", ["b", "a"]) == ["b", "a"]  # nothing close: the order as given


def test_a_misspelt_parameter_names_the_valid_ones_nearest_first():
    with pytest.raises(UsageError) as e:
        Slave("McKibbenMuscle", bladder_modle=1)
    text = str(e.value)
    assert "\n" not in text
    assert re.search(r"'bladder_modle' is not a parameter or input; valid: bladder_model,", text), text


def test_a_value_outside_its_declared_range_is_refused_with_the_range():
    with pytest.raises(UsageError, match=r"turns = 0 1? ?is outside its declared range 0\.001 \.\. 10000"):
        Slave("McKibbenMuscle", turns=0.0)
    with pytest.raises(UsageError, match=r"length = -0.1 m is outside its declared range 0 \.\. 10 m"):
        simulate("McKibbenMuscle", start_values={"length": -0.1}, stop_time=0.01)


def test_an_output_is_checked_before_the_simulation_runs():
    # A long run (10 s of 1 ms steps) that must not start: the typo is found in well under its time.
    start = time.perf_counter()
    with pytest.raises(UsageError, match=r"'forse' is not a variable it reports; valid outputs: force,"):
        simulate("McKibbenMuscle", output=["forse"], stop_time=10.0, output_interval=1e-3)
    assert time.perf_counter() - start < 2.0


def test_inputs_are_checked_sample_by_sample():
    t = np.linspace(0, 1, 11)
    signals = np.array(list(zip(t, 1e9 * t)), dtype=[("time", float), ("pressure", float)])
    with pytest.raises(UsageError, match=r"pressure = 2e\+08 Pa is outside its declared range -101325 \.\. "
                                         r"1e\+08 Pa \(input signal at t = 0\.2 s\)"):
        simulate("McKibbenMuscle", input=signals, stop_time=1.0)
    bad = np.array(list(zip(t, t)), dtype=[("time", float), ("presure", float)])
    with pytest.raises(UsageError, match=r"'presure' is not an input; valid: pressure,"):
        simulate("McKibbenMuscle", input=bad, stop_time=1.0)


def test_an_unknown_fmu_names_the_packaged_ones():
    with pytest.raises(UsageError, match=r"no FMU named 'McKibenMuscle'; available: McKibbenMuscle,"):
        simulate("McKibenMuscle")


@pytest.mark.parametrize("model", sorted(ENUMERATIONS))
def test_named_choices_are_enumerations_with_named_items(model):
    md = read_model_description(str(FMU_DIR / f"{model}.fmu"))
    found = {v.name: v for v in md.modelVariables if v.type == "Enumeration"}
    assert set(found) == set(ENUMERATIONS[model])
    for name, items in ENUMERATIONS[model].items():
        declared = found[name].declaredType
        assert [(i.name, int(i.value)) for i in declared.items] == list(zip(items, range(len(items))))
    # No Integer left that the description says selects among numbered options ("0 ..., 1 ...").
    for v in md.modelVariables:
        if v.type == "Integer":
            assert not re.search(r"\b0 [a-z].*\b1 [a-z]", v.description or ""), v.name


def test_an_item_by_name_equals_its_value():
    by_name = Slave("McKibbenMuscle", preset="DMSP_40", length=0.36)
    by_value = Slave("McKibbenMuscle", preset=6, length=0.36)
    assert by_name.at("force", pressure=3e5) == by_value.at("force", pressure=3e5)
    assert by_name.get("effective_bladder_model") == 3  # the exact wall, as the Festo presets fit
    by_name.close()
    by_value.close()
    with pytest.raises(UsageError, match=r"preset = 'DMSP40' is not one of its items; valid: DMSP_40, DMSP_20, DMSP_10,"):
        Slave("McKibbenMuscle", preset="DMSP40")
    with pytest.raises(UsageError, match=r"preset = 9 is not one of its items; valid: 0 none, 1 A,"):
        Slave("McKibbenMuscle", preset=9)


def test_pressure_for_force_answers_in_pascal():
    # The forward model at the answer gives the force back: an independent check of the unit.
    pressure_pa, out_of_reach = pressure_for_force(2000.0, 0.36, {"preset": "DMSP_40"})
    assert not out_of_reach
    assert 1e5 < pressure_pa < 6e5  # Pa: a DMSP-40 pulls 2000 N at 10% contraction below 600 kPa
    r = simulate("McKibbenMuscle", start_values={"preset": "DMSP_40", "pressure": pressure_pa, "length": 0.36},
                 output=["force"], stop_time=0.001)
    assert r["force"][-1] == pytest.approx(2000.0, rel=1e-6)


def test_the_command_line_says_one_line_and_exits_2(tmp_path):
    scene = json.loads(DEMO.read_text())
    scene["parameters"] = {"bladder_modle": 0}
    path = tmp_path / "typo.json"
    path.write_text(json.dumps(scene))
    run = run_cli("scene", path, "--out", tmp_path)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert "'bladder_modle' is not a parameter or input; valid: bladder_model," in run.stderr
    assert not (tmp_path / "typo.csv").exists()  # nothing ran

    run = run_cli("pressure-for-force", 2000, 0.36, "--set", "preset=DMSP40")
    assert run.returncode == 2 and "Traceback" not in run.stderr and "valid: DMSP_40" in run.stderr, run.stderr
    run = run_cli("info", "McKibenMuscle")
    assert run.returncode == 2 and "available: McKibbenMuscle" in run.stderr, run.stderr


def test_info_names_the_choices():
    run = run_cli("info", "McKibbenJoint")
    assert run.returncode == 0, run.stderr
    assert "command_mode: one of pressure_difference (0), joint_torque (1), start 0 (pressure_difference)" in run.stdout
    assert "FMI 2.0: Co-Simulation, Model Exchange" in run.stdout


def test_the_demo_scene_runs_without_a_warning(tmp_path):
    # The scene sets only pressure and length; FMPy warned about the third input (target_force)
    # once per run: the runner now holds it at its start value.
    run = run_cli("scene", DEMO, "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    assert "arning" not in run.stdout + run.stderr, run.stdout + run.stderr


@pytest.mark.parametrize("model", sorted(ENUMERATIONS) + ["PulleyJoint"])
def test_fmu_page_states_both_interfaces_and_the_choices(model):
    md = read_model_description(str(FMU_DIR / f"{model}.fmu"))
    with zipfile.ZipFile(FMU_DIR / f"{model}.fmu") as z:
        page = z.read("documentation/index.html").decode()
    interfaces = "Co-Simulation and Model Exchange" if md.modelExchange else "Co-Simulation,"
    assert f"FMI 2.0 {interfaces}" in page
    for items in ENUMERATIONS.get(model, {}).values():
        assert all(f"<code>{item}</code>" in page for item in items)


def test_the_presets_table_gives_each_presets_values():
    with zipfile.ZipFile(FMU_DIR / "McKibbenMuscle.fmu") as z:
        page = z.read("documentation/index.html").decode()
    table = page.split("<h2>Presets</h2>", 1)[1].split("</table>", 1)[0]
    header = re.findall(r"<th><code>(\w+)</code></th>", table)
    assert header == ENUMERATIONS["McKibbenMuscle"]["preset"]
    row = re.search(r"<td><code>effective_nominal_length</code></td><td>m</td>(.*?)</tr>", table).group(1)
    # Table 2.1's listed lengths (mm) and the Festo presets' nominal lengths, in m.
    assert re.findall(r'<td class="n">([^<]*)</td>', row) == ["0.10325", "0.10325", "0.1088", "0.0989",
                                                               "0.1358", "0.25", "0.4", "0.1", "0.3"]


def test_inputs_without_a_column_keep_their_start_values_and_nothing_warns(capfd):
    # The signal gives only the length; the pressure is a start value the run must keep (FMPy
    # would warn about its missing column; the package holds it instead).
    t = np.linspace(0.0, 0.01, 11)
    signals = np.array(list(zip(t, np.full_like(t, 0.09))), dtype=[("time", float), ("length", float)])
    r = simulate("McKibbenMuscle", start_values={"pressure": 3e5}, input=signals, output=["force"],
                 stop_time=0.01, output_interval=1e-3)
    muscle = Slave("McKibbenMuscle", length=0.09)
    assert r["force"][-1] == pytest.approx(muscle.at("force", pressure=3e5), rel=1e-12)
    muscle.close()
    out, err = capfd.readouterr()
    assert "arning" not in out + err
