"""The Dask design sweep (`actuator-fmus sweep`) on a small local cluster: its net work per stroke
is the one examples/mckibben_muscles.py reports for Table 2.1's muscle A, and the grid comes back
complete through the scheduler, with the numbers of a run in this process."""

import math

import pytest

from conftest import FMU_DIR


def _sweep_module():
    from actuator_fmus import sweep

    return sweep


def test_net_work_of_muscle_a_matches_the_work_table():
    # Work table of docs/fmus/McKibbenMuscle.md: muscle A (3% pre-strain), thick wall of 16 layers, 690 kPa: 1.313 J.
    sd = _sweep_module()
    fmu = (FMU_DIR / "McKibbenMuscle.fmu").read_bytes()
    [(_, _, work)] = sd.run_batch(fmu, [(0.10325 / 0.1005 - 1, 1.6e-3)], layers=16, n_lengths=4000)
    assert work == pytest.approx(1.313, abs=5e-4)


def test_a_bladder_that_does_not_fit_gives_nan_not_an_error():
    sd = _sweep_module()
    fmu = (FMU_DIR / "McKibbenMuscle.fmu").read_bytes()
    [(_, _, work)] = sd.run_batch(fmu, [(0.0, 3.2e-3)], layers=4, n_lengths=60)
    assert math.isnan(work)


def test_sweep_on_a_local_dask_cluster():
    sd = _sweep_module()
    prestrains, thicknesses = [0.0, 0.5, 0.9], [0.8e-3, 1.6e-3]
    rows, seconds = sd.sweep(prestrains, thicknesses, workers=2, batch=2, layers=4, n_lengths=60, progress=False)
    assert seconds > 0
    assert [(p, t) for p, t, _ in rows] == sorted((p, t) for p in prestrains for t in thicknesses)
    # The cluster only distributes: the same cases run in this process give the same numbers.
    fmu = (FMU_DIR / "McKibbenMuscle.fmu").read_bytes()
    local = sd.run_batch(fmu, [(p, t) for p, t, _ in rows], layers=4, n_lengths=60)
    for (p, t, w), (_, _, w_local) in zip(rows, local):
        assert math.isfinite(w) and w > 0, (p, t, w)
        assert w == w_local
