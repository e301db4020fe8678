"""Every FMU ships FMI cross-check files (crosscheck/<Model>/, written by `actuator-fmus crosscheck`):
they pass FMPy's cross-check validator, and re-simulating <Model>_in.csv under FMPy with the
settings of <Model>_ref.opt reproduces <Model>_ref.csv."""

import shutil
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.cross_check.validate_vendor_repo import read_csv, validate_test_fmu
from fmpy.util import read_ref_opt_file, validate_result

from conftest import FMU_DIR, ROOT

FMUS = sorted(p.stem for p in FMU_DIR.glob("*.fmu"))
CROSSCHECK = ROOT / "crosscheck"


@pytest.mark.parametrize("model", FMUS)
def test_crosscheck_files_exist(model):
    d = CROSSCHECK / model
    for suffix in ("_ref.csv", "_ref.opt"):
        assert (d / f"{model}{suffix}").is_file(), f"run `make crosscheck` to write {d}/{model}{suffix}"


@pytest.mark.parametrize("model", FMUS)
def test_crosscheck_layout_passes_fmpy_validator(model, tmp_path):
    # The repository layout of the rules: fmus/2.0/cs/<platform>/<tool>/<version>/<model>/.
    d = tmp_path / "2.0" / "cs" / "linux64" / "actuator-fmus" / "0.1.0" / model
    shutil.copytree(CROSSCHECK / model, d)
    shutil.copy(FMU_DIR / f"{model}.fmu", d / f"{model}.fmu")
    assert validate_test_fmu(str(d)) == []


@pytest.mark.parametrize("model", FMUS)
def test_resimulating_the_inputs_reproduces_the_reference(model):
    d = CROSSCHECK / model
    opt = read_ref_opt_file(str(d / f"{model}_ref.opt"))
    reference = read_csv(str(d / f"{model}_ref.csv"))
    inputs = read_csv(str(d / f"{model}_in.csv")) if (d / f"{model}_in.csv").is_file() else None
    names = list(reference.dtype.names[1:])
    result = simulate_fmu(str(FMU_DIR / f"{model}.fmu"), start_time=opt["StartTime"], stop_time=opt["StopTime"],
                          output_interval=opt["StepSize"], relative_tolerance=opt["RelTol"], input=inputs, output=names)
    # The cross-check comparison (tube around the reference): no outliers.
    assert validate_result(result, reference, stop_time=opt["StopTime"]) == 0
    # Same binary, same inputs: the same numbers to rounding.
    assert len(result) == len(reference)
    np.testing.assert_allclose(result["time"], reference["time"], rtol=0, atol=1e-12 * opt["StopTime"])
    for n in names:
        scale = max(np.max(np.abs(reference[n])), 1e-300)
        np.testing.assert_allclose(result[n], reference[n], rtol=1e-9, atol=1e-9 * scale, err_msg=n)


@pytest.mark.parametrize("model", FMUS)
def test_documentation_shows_the_plot(model):
    names = zipfile.ZipFile(FMU_DIR / f"{model}.fmu").namelist()
    html = zipfile.ZipFile(FMU_DIR / f"{model}.fmu").read("documentation/index.html").decode()
    assert "documentation/plot.png" in names, "docs/fmu/<Model>.png is missing: run `make crosscheck`, then `make fmus`"
    assert '<img src="plot.png"' in html
    assert read_model_description(str(FMU_DIR / f"{model}.fmu")).modelName == model
