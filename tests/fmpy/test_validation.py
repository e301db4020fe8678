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


# SI symbols as exponents of (kg, m, s, A, K, mol, cd, rad): the base units, radian, and the
# derived units with special names that the descriptions may compose ("N.m", "Pa/rad").
SI_SYMBOLS = {
    "kg": (1, 0, 0, 0, 0, 0, 0, 0), "m": (0, 1, 0, 0, 0, 0, 0, 0), "s": (0, 0, 1, 0, 0, 0, 0, 0),
    "A": (0, 0, 0, 1, 0, 0, 0, 0), "K": (0, 0, 0, 0, 1, 0, 0, 0), "mol": (0, 0, 0, 0, 0, 1, 0, 0),
    "cd": (0, 0, 0, 0, 0, 0, 1, 0), "rad": (0, 0, 0, 0, 0, 0, 0, 1),
    "N": (1, 1, -2, 0, 0, 0, 0, 0), "Pa": (1, -1, -2, 0, 0, 0, 0, 0), "J": (1, 2, -2, 0, 0, 0, 0, 0),
    "W": (1, 2, -3, 0, 0, 0, 0, 0), "V": (1, 2, -3, -1, 0, 0, 0, 0),
}


def si_exponents(name):
    """The base-unit exponents of an SI unit name ("1", "N.m", "kg/m3", "Pa.s/rad"), or None if
    a factor is not an SI symbol (a prefixed or non-SI unit such as "kN", "bar", "deg")."""
    total = [0] * 8
    if name == "1":
        return tuple(total)
    for sign, part in zip((1, -1), (name.split("/", 1) + [""])[:2]):
        for factor in filter(None, part.split(".")):
            symbol = factor.rstrip("0123456789-")
            power = int(factor[len(symbol):] or 1)
            if symbol not in SI_SYMBOLS:
                return None
            total = [t + sign * power * e for t, e in zip(total, SI_SYMBOLS[symbol])]
    return tuple(total)


@pytest.mark.parametrize("fmu", FMUS, ids=lambda p: p.stem)
def test_units_are_si_and_declared(fmu):
    """Every Real's unit is declared, named by SI symbols without prefixes, and its BaseUnit
    (factor 1, offset 0) has the exponents its name says."""
    md = read_model_description(str(fmu))
    declared = {u.name: u for u in md.unitDefinitions}
    for v in md.modelVariables:
        if v.type == "Real":
            assert v.unit in declared, f"{v.name}: unit {v.unit} undeclared"
    for name, unit in declared.items():
        exponents = si_exponents(name)
        assert exponents is not None, f"{name} is not an SI unit"
        base = unit.baseUnit
        if base is None:
            assert name == "1", f"{name} declares no BaseUnit"
            continue
        assert (base.factor, base.offset) == (1, 0), f"{name}: factor {base.factor}, offset {base.offset}"
        declared_exponents = tuple(getattr(base, k) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"))
        assert declared_exponents == exponents, f"{name}: BaseUnit {declared_exponents}, name says {exponents}"
