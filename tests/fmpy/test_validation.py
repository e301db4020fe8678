"""Every packaged FMU passes FMPy's validation with nothing to report."""

import zipfile

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from conftest import FMU_DIR

FMUS = sorted(FMU_DIR.glob("*.fmu"))


def test_fmus_were_built():
    assert FMUS, "no FMU in target/fmu: run `make fmus`"


@pytest.mark.parametrize("fmu", FMUS, ids=lambda p: p.stem)
def test_validate_fmu_reports_nothing(fmu):
    assert validate_fmu(str(fmu)) == []


@pytest.mark.parametrize("fmu", FMUS, ids=lambda p: p.stem)
def test_archive_layout(fmu):
    md = read_model_description(str(fmu))
    names = zipfile.ZipFile(fmu).namelist()
    identifier = md.coSimulation.modelIdentifier
    assert f"binaries/linux64/{identifier}.so" in names
    # Windows 64-bit, and 64-bit ARM Linux in the FMI 3.0 platform tuple that FMI 2.0.4 section 2.3
    # points to (docs/compatibility.md, "Platforms").
    assert f"binaries/win64/{identifier}.dll" in names
    assert f"binaries/aarch64-linux/{identifier}.so" in names
    assert "documentation/index.html" in names
    html = zipfile.ZipFile(fmu).read("documentation/index.html").decode()
    for v in md.modelVariables:
        assert f"<code>{v.name}</code>" in html, f"{v.name} is missing from the documentation"
    assert "Eq. 2.1" in html or md.modelName != "McKibbenMuscle"


@pytest.mark.parametrize("fmu", FMUS, ids=lambda p: p.stem)
def test_units_are_si_and_declared(fmu):
    md = read_model_description(str(fmu))
    declared = {u.name for u in md.unitDefinitions}
    si = {"1", "m", "m2", "m3", "N", "Pa", "N/m", "s", "rad", "rad/s", "N.m", "J", "kg", "kg.m2", "N.m.s", "A/m", "kg/m3", "Pa.s", "m/s2", "Pa/rad", "Pa.s/rad", "rad/s2", "m3/Pa"}
    for v in md.modelVariables:
        if v.type == "Real":
            assert v.unit in declared, f"{v.name}: unit {v.unit} undeclared"
            assert v.unit in si, f"{v.name}: {v.unit} is not an SI unit"
