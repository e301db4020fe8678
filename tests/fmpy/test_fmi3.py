"""The FMI 3.0 FMUs (target/fmu-fmi3/) under FMPy: valid, the same models as the FMI 2.0 FMUs
(target/fmu/) with results equal bit for bit in Co-Simulation and Model Exchange on every catalogue
scene, and the same bad-input policy through the FMI 3.0 C API."""

import pathlib
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from actuator_fmus import scene as scenes
from actuator_fmus.paths import FMI2_DIR, FMI3_DIR, ROOT

SCENES = sorted((ROOT / "scenes").glob("*.json"))
FMI2_FMUS = sorted(FMI2_DIR.glob("*.fmu"))
MODELS = [p.stem for p in FMI2_FMUS]


def fmi3_path(model):
    return str(FMI3_DIR / f"{model}.fmu")


def test_every_fmi2_fmu_has_its_fmi3_fmu():
    assert MODELS, "run `make fmus` first"
    assert sorted(p.stem for p in FMI3_DIR.glob("*.fmu")) == MODELS


@pytest.mark.parametrize("model", MODELS)
def test_validate_fmu_reports_nothing(model):
    assert validate_fmu(fmi3_path(model)) == []


@pytest.mark.parametrize("model", MODELS)
def test_the_description_is_the_fmi2_one_in_fmi3_terms(model):
    md2 = read_model_description(str(FMI2_DIR / f"{model}.fmu"))
    md3 = read_model_description(fmi3_path(model))
    assert md3.fmiVersion == "3.0"
    assert md3.instantiationToken == md2.guid
    v2 = {v.name: v for v in md2.modelVariables}
    v3 = {v.name: v for v in md3.modelVariables}
    # FMI 3.0 adds the independent variable, the event indicators as variables, and the array
    # outputs (FMI 2.0 has no arrays; tests/fmpy/test_fmi3_arrays.py tests them).
    arrays = {name for name, v in v3.items() if v.dimensions}
    added = set(v3) - set(v2) - arrays
    assert added == {"time"} | {f"event_indicator[{k + 1}]" for k in range(md2.numberOfEventIndicators)}
    assert not arrays & set(v2)
    assert md3.numberOfEventIndicators == md2.numberOfEventIndicators
    assert md3.numberOfContinuousStates == md2.numberOfContinuousStates
    fmi3_type = {"Real": {"Float64"}, "Integer": {"Int32", "Enumeration"}, "Boolean": {"Boolean"},
                 "Enumeration": {"Enumeration"}}
    for name, a in v2.items():
        b = v3[name]
        assert b.type in fmi3_type[a.type], name
        assert (b.causality, b.variability, b.start, b.unit) == \
            (a.causality, a.variability, a.start, a.unit), name
        if a.type == "Enumeration" and a.min is None:
            # FMI 3.0 writes the Enumeration's range: its items.
            items = [int(i.value) for i in a.declaredType.items]
            assert (int(b.min), int(b.max)) == (min(items), max(items)), name
        else:
            assert (b.min, b.max) == (a.min, a.max), name
        if a.type == "Real":
            assert b.valueReference == a.valueReference, name
        if b.type == "Enumeration":
            assert b.declaredType.name == a.declaredType.name
    # The same ModelStructure, by name.
    for list2, list3 in [(md2.outputs, md3.outputs), (md2.derivatives, md3.derivatives),
                         (md2.initialUnknowns, md3.initialUnknowns)]:
        by_name = lambda unknowns: {u.variable.name: sorted(d.name for d in u.dependencies) for u in unknowns
                                    if u.variable.name not in arrays}
        assert by_name(list3) == by_name(list2)


@pytest.mark.parametrize("model", MODELS)
def test_the_binaries_are_the_fmi2_ones_under_fmi3_platform_tuples(model):
    tuples = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "aarch64-linux": "aarch64-linux"}
    with zipfile.ZipFile(FMI2_DIR / f"{model}.fmu") as z2, zipfile.ZipFile(fmi3_path(model)) as z3:
        binaries2 = {n: z2.read(n) for n in z2.namelist() if n.startswith("binaries/")}
        names3 = set(n for n in z3.namelist() if n.startswith("binaries/"))
        assert binaries2
        for name, data in binaries2.items():
            platform = name.split("/")[1]
            renamed = name.replace(f"binaries/{platform}/", f"binaries/{tuples[platform]}/")
            assert renamed in names3
            assert z3.read(renamed) == data


@pytest.mark.parametrize("model", MODELS)
def test_the_documentation_names_its_own_fmi_version(model):
    """The FMI 3.0 FMU ships the FMI 2.0 FMU's page but for the version it names."""
    with zipfile.ZipFile(FMI2_DIR / f"{model}.fmu") as z2, zipfile.ZipFile(fmi3_path(model)) as z3:
        page2 = z2.read("documentation/index.html").decode()
        page3 = z3.read("documentation/index.html").decode()
    assert "FMI 2.0 Co-Simulation" in page2 and "FMI 3.0" not in page2
    assert "FMI 3.0 Co-Simulation" in page3 and "FMI 2.0" not in page3
    assert page3 == page2.replace("FMI 2.0 Co-Simulation", "FMI 3.0 Co-Simulation")
    assert sorted(n for n in z3.namelist() if n.startswith("documentation/")) == \
        sorted(n for n in z2.namelist() if n.startswith("documentation/"))


def _largest_difference(a, b):
    worst = 0.0
    for name in a.dtype.names:
        x, y = a[name].astype(float), b[name].astype(float)
        assert x.shape == y.shape, name
        worst = max(worst, float(np.max(np.abs(x - y), initial=0.0)))
    return worst


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_scene_equals_the_fmi2_result_bit_for_bit(path, fmi_type):
    scene = scenes.load_scene(path, fast=True)
    runs2 = scenes.run_scene(scene, progress=False, fmi_type=fmi_type)
    runs3 = scenes.run_scene(scene, progress=False, fmu=fmi3_path(scene["fmu"]), fmi_type=fmi_type)
    assert len(runs2) == len(runs3)
    for (v2, r2), (v3, r3) in zip(runs2, runs3):
        assert v2 == v3
        assert r2.dtype.names == r3.dtype.names
        assert _largest_difference(r2, r3) == 0.0
        for name in r2.dtype.names:
            assert np.array_equal(r2[name], r3[name]), f"{name} differs"


def _exported(path, platform):
    """The function names a shared library exports, by the binutils of its platform."""
    import re
    import shutil
    import subprocess

    if platform.endswith("windows"):
        tool, flag = shutil.which("x86_64-w64-mingw32-objdump") or shutil.which("objdump"), "-p"
    elif platform.startswith("aarch64"):
        tool, flag = shutil.which("aarch64-linux-gnu-objdump"), "-T"
    else:
        tool, flag = shutil.which("objdump"), "-T"
    if tool is None:
        pytest.skip(f"no objdump for {platform} (make cross-deps installs it)")
    listing = subprocess.run([tool, flag, str(path)], capture_output=True, text=True, check=True).stdout
    return set(re.findall(r"\b(fmi[23][A-Za-z0-9]+)\b", listing))


def test_every_binary_exports_both_apis(tmp_path):
    """Every binary in the FMI 3.0 FMUs exports every function of FMPy's FMI 3.0 and FMI 2.0 bindings
    (FMPy resolves all of them when it loads a binary)."""
    import fmpy.fmi2
    import fmpy.fmi3

    fmi3_names = {n for n in dir(fmpy.fmi3._FMU3) if n.startswith("fmi3")} | \
        {n for cls in (fmpy.fmi3.FMU3Slave, fmpy.fmi3.FMU3Model) for n in dir(cls) if n.startswith("fmi3")}
    fmi2_names = {n for cls in (fmpy.fmi2.FMU2Slave, fmpy.fmi2.FMU2Model) for n in dir(cls) if n.startswith("fmi2")}
    assert len(fmi3_names) > 60 and len(fmi2_names) > 30
    with zipfile.ZipFile(fmi3_path("McKibbenMuscle")) as z:
        binaries = [n for n in z.namelist() if n.startswith("binaries/") and not n.endswith("/")]
        assert "binaries/x86_64-linux/McKibbenMuscle.so" in binaries
        for name in binaries:
            platform = name.split("/")[1]
            exported = _exported(z.extract(name, tmp_path), platform)
            assert fmi3_names <= exported, (platform, sorted(fmi3_names - exported))
            assert fmi2_names <= exported, (platform, sorted(fmi2_names - exported))
