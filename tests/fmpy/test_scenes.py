"""Every catalogue scene (scenes/*.json), fast variant, under FMPy: it runs, writes its CSV and plot,
gives finite outputs, and the seed's numbers it names hold."""

import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scenes"))
import run as scenes  # noqa: E402

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
