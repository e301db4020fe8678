"""Every catalogue scene (scenes/*.json), fast variant, under FMPy: it runs, writes its CSV and plot,
gives finite outputs, and the dissertation's numbers it names hold."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
from actuator_fmus import scene as scenes  # noqa: E402

SCENES = sorted((ROOT / "scenes").glob("*.json"))


def test_the_catalogue_is_there():
    assert len(SCENES) >= 10


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_scene(path, tmp_path):
    scene = scenes.load_scene(path, fast=True)
    runs = scenes.run_scene(scene, progress=False)
    for _, result in runs:
        for name in result.dtype.names:
            assert np.all(np.isfinite(result[name])), f"{name} is not finite"
    scenes.write_outputs(scene, runs, tmp_path)
    assert (tmp_path / f"{path.stem}.csv").exists()
    if scene.get("plot"):
        assert (tmp_path / f"{path.stem}.png").exists()
    for ok, text in scenes.evaluate_checks(scene, runs):
        assert ok, text


def test_csv_input_signal(tmp_path):
    # The PassThrough FMU echoes a CSV column, linearly interpolated at the communication points.
    (tmp_path / "u.csv").write_text("time,u\n0,0\n0.5,1\n1,0\n")
    scene_file = tmp_path / "echo.json"
    scene_file.write_text(
        '{"fmu": "PassThrough", "description": "echo: a CSV input", "step": 0.125, "stop_time": 1.0,'
        ' "inputs": {"u": {"type": "csv", "file": "u.csv", "column": "u"}}, "outputs": ["u", "y"]}'
    )
    (_, result), = scenes.run_scene(scenes.load_scene(scene_file), progress=False)
    # Outputs at t + h follow the input applied at t (FMPy's recording convention).
    expected = np.interp(result["time"] - 0.125, [0, 0.5, 1], [0, 1, 0])
    assert np.allclose(result["y"][1:], expected[1:])
    assert np.array_equal(result["u"], result["y"])


def test_a_misspelt_or_mistyped_field_is_refused_with_its_path(tmp_path):
    scene = json.loads((ROOT / "scenes" / "fig2_3_ideal_mckibben.json").read_text())
    scene["inputs"]["length"]["form"] = scene["inputs"]["length"].pop("from")
    scene["step"] = "0.01"
    scene["plot"]["y_limit"] = [0, 1]
    scene["checks"][0]["kind"] = "zero"
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(scenes.SceneError) as refused:
        scenes.load_scene(path)
    text = str(refused.value)
    for line in ["inputs.length.form: unknown field", "step: '0.01' is not of type 'number'",
                 "plot.y_limit: unknown field", "checks[0].kind: 'zero' is not one of"]:
        assert line in text, text
    run = subprocess.run([sys.executable, "-m", "actuator_fmus.cli", "scene", str(path)],
                         capture_output=True, text=True)
    assert run.returncode == 2 and "inputs.length.form: unknown field" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "Traceback" not in run.stderr, run.stderr


def test_the_shipped_schema_accepts_every_catalogue_scene():
    assert all(scenes.schema_errors(json.loads(p.read_text())) == [] for p in SCENES)
