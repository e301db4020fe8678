"""The win64 DLL (under wine) and the aarch64-linux .so (under qemu-user) of every FMU give the
linux64 outputs bit for bit (the motor and FreeBladder under wine to 1e-12: wine's libm): Real, Integer and
Boolean outputs, directional derivatives every tenth step, and an FMU state saved and restored
mid-run. One small C master (tests/cross/harness.c), built natively, with mingw-w64 and with the
aarch64 cross gcc, runs the same script on each binary: every scene (fast variant, parameters and
inputs included) whose FMU it is, then the FMU's cross-check input. `make fmus` builds the
binaries and `make cross-deps` installs the toolchains and emulators."""

import os
import pathlib
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description

from conftest import FMU_DIR, ROOT

from actuator_fmus import scene as scenes  # noqa: E402

HARNESS = ROOT / "tests" / "cross" / "harness.c"
STUB = ROOT / "tests" / "cross" / "bcryptprimitives.c"
FMUS = sorted(p.stem for p in FMU_DIR.glob("*.fmu"))
RTOL = 1e-12
# Under wine the DLL calls wine's msvcrt libm, whose sin/cos/exp/log may differ from glibc's in the
# last bit: MultiferroicMotor differs by 1.6e-13 relative there, FreeBladder (the exact tube's
# logarithm) by 4.2e-15. Every other FMU is asserted bit-identical under wine, and all seven under
# qemu, which runs glibc's code.
LIBM_HEAVY = {"MultiferroicMotor", "FreeBladder"}
CROSS_STEPS = 200


def script_for(model, gilbert=False):
    """The harness script: every scene of this FMU, then its cross-check input; and the number of
    runs in it. `gilbert`: the motor's cross-check input under the Gilbert onion alone."""
    md = read_model_description(str(FMU_DIR / f"{model}.fmu"))
    by_name = {v.name: v for v in md.modelVariables}
    outputs = [v.valueReference for v in md.modelVariables
               if v.type == "Real" and v.causality in ("output", "calculatedParameter")]
    discrete = {kind: " ".join(str(v.valueReference) for v in md.modelVariables
                               if v.type == kind and v.causality == "output")
                for kind in ("Integer", "Boolean")}
    get = f"G {' '.join(map(str, outputs))} ; {discrete['Integer']} ; {discrete['Boolean']}\n"
    # Directional derivatives of every Real output by every Real input, after each step.
    inputs = [v.valueReference for v in md.modelVariables
              if v.type == "Real" and v.causality == "input"]
    derivatives = "".join(f"D {u} {k}\n" for u in outputs for k in inputs
                          if md.coSimulation.providesDirectionalDerivative
                          and by_name_vr(md, u).causality == "output")

    def set_line(name, value):
        v = by_name[name]
        code = {"Real": "R", "Integer": "I", "Enumeration": "I", "Boolean": "B"}[v.type]
        value = float(value) if v.type == "Real" else int(value)
        return f"{code} {v.valueReference} {value!r}\n"

    runs = []  # (parameters, times, {input: values})
    for path in sorted((ROOT / "scenes").glob("*.json")):
        scene = scenes.load_scene(path, fast=True)
        if scene["fmu"] != model:
            continue
        for _, _, parameters, inputs in scenes.sweep_runs(scene):
            n = min(int(round(scene["stop_time"] / scene["step"])), CROSS_STEPS)
            t = np.arange(n + 1) * scene["step"]
            signals = {name: scenes.signal_values(s, t, scene["stop_time"], scene["_dir"])
                       for name, s in inputs.items()}
            runs.append((parameters, t, signals))
    d = ROOT / "crosscheck" / model
    opt = dict(line.split(",") for line in (d / f"{model}_ref.opt").read_text().splitlines() if line)
    stop, step = float(opt["StopTime"]), float(opt["StepSize"])
    n = min(int(round(stop / step)), CROSS_STEPS)
    t = np.arange(n + 1) * (stop / n)
    signals = {}
    if (d / f"{model}_in.csv").is_file():
        data = np.genfromtxt(d / f"{model}_in.csv", delimiter=",", names=True)
        signals = {name: np.interp(t, data["time"], data[name]) for name in data.dtype.names[1:]}
    runs.append(({}, t, signals))

    if gilbert:
        runs = [({"onion_model": 1}, runs[-1][1], runs[-1][2])]

    lines = []
    for k, (parameters, t, signals) in enumerate(runs):
        if k:
            lines.append("N\n")
        lines += [set_line(name, value) for name, value in parameters.items()]
        lines.append("X\n")
        for i in range(len(t) - 1):
            lines += [set_line(name, values[i]) for name, values in signals.items()]
            lines.append(get if i == 0 else "")
            # An FMU state saved a third of the way through and restored two steps later,
            # the step then taken again: fmi2GetFMUstate and fmi2SetFMUstate on every platform.
            save = i == (len(t) - 1) // 3 and i + 2 < len(t) - 1
            if save:
                lines.append("F\n")
            lines.append(f"S {float(t[i + 1] - t[i])!r}\n")
            lines.append(get)
            lines.append(derivatives if i % 10 == 0 else "")
            if save:
                lines += [f"S {float(t[i + 2] - t[i + 1])!r}\n", get, "L\n",
                          f"S {float(t[i + 1] - t[i])!r}\n", get]
    return "".join(lines), len(runs)


def by_name_vr(md, vr):
    return next(v for v in md.modelVariables if v.type == "Real" and v.valueReference == vr)


def tool(name):
    # Debian's wine64 package installs its loader outside PATH.
    path = shutil.which(name) or next(
        (str(p) for p in [pathlib.Path("/usr/lib/wine") / name] if p.is_file()), None)
    if path is None:
        pytest.fail(f"{name} is missing: run `make cross-deps`")
    return path


@pytest.fixture(scope="module")
def harnesses(tmp_path_factory):
    d = tmp_path_factory.mktemp("harness")
    subprocess.run([tool("gcc"), "-O2", "-o", d / "native", HARNESS, "-ldl"], check=True)
    subprocess.run([tool("aarch64-linux-gnu-gcc"), "-O2", "-o", d / "aarch64", HARNESS, "-ldl"], check=True)
    win = d / "win"
    win.mkdir()
    mingw = tool("x86_64-w64-mingw32-gcc")
    subprocess.run([mingw, "-O2", "-o", win / "harness.exe", HARNESS], check=True)
    # wine 8.0 lacks bcryptprimitives.dll (ProcessPrng), which Rust's std imports: a stand-in next
    # to the .exe, where the loader looks first.
    subprocess.run([mingw, "-O2", "-shared", "-o", win / "bcryptprimitives.dll", STUB, "-ladvapi32"], check=True)
    return d


def binary(model, platform, extension, directory):
    with zipfile.ZipFile(FMU_DIR / f"{model}.fmu") as z:
        name = f"binaries/{platform}/{model}.{extension}"
        assert name in z.namelist(), f"{model}.fmu has no {name}: run `make fmus`"
        path = directory / f"{model}.{extension}"
        path.write_bytes(z.read(name))
    return path


def transcript(command, script, env=None):
    r = subprocess.run(command, input=script, capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, f"{command[0]} failed ({r.returncode}): {r.stdout[-500:]} {r.stderr[-2000:]}"
    # One flat array: the lines differ in length (values, derivatives).
    return np.array([float(x) for line in r.stdout.splitlines() for x in line.split()])


def compare(model, native, other, platform, bit_identical):
    """Bit-identical where the same libm runs (or none is called); else to RTOL, the measured
    difference printed."""
    assert native.shape == other.shape, f"{model} {platform}: {native.shape} vs {other.shape}"
    scale = np.maximum(np.abs(native), 1e-300)
    worst = np.max(np.abs(other - native) / scale, initial=0.0)
    identical = np.array_equal(native.view(np.uint64), other.view(np.uint64))
    print(f"{model} {platform}: {native.size} values, {'bit-identical' if identical else f'max rel. diff {worst:.3g}'}")
    if bit_identical:
        assert identical, f"{model} {platform}: not bit-identical, max rel. diff {worst:.3g}"
    else:
        np.testing.assert_allclose(other, native, rtol=RTOL, atol=0)


@pytest.mark.parametrize("model", FMUS)
def test_win64_under_wine_and_aarch64_under_qemu_match_linux64(model, harnesses, tmp_path):
    script, runs = script_for(model)
    guid = read_model_description(str(FMU_DIR / f"{model}.fmu")).guid
    native = transcript([harnesses / "native", binary(model, "linux64", "so", tmp_path), guid], script)
    assert native.size > 0 and np.isfinite(native).all()

    arm_dir = tmp_path / "arm"
    arm_dir.mkdir()
    arm = transcript([tool("qemu-aarch64"), "-L", "/usr/aarch64-linux-gnu", harnesses / "aarch64",
                      binary(model, "aarch64-linux", "so", arm_dir), guid], script)
    # qemu runs glibc's own aarch64 code: every FMU bit-identical.
    compare(model, native, arm, "aarch64-linux under qemu", bit_identical=True)

    win = harnesses / "win"
    dll = binary(model, "win64", "dll", win)
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=",
               WINEPREFIX=str(ROOT / "target" / "wine-prefix"))
    windows = transcript([tool("wine64"), str(win / "harness.exe"), dll.name, guid], script, env)
    compare(model, native, windows, "win64 under wine", bit_identical=model not in LIBM_HEAVY)
    print(f"{model}: {runs} runs")


def test_gilbert_onion_bit_identical_under_qemu_and_its_wine_difference_measured(harnesses, tmp_path):
    """The motor's Gilbert onion over its cross-check input: bit-identical under qemu. Under wine
    its budget-limited relaxation carries wine's last-bit libm differences into the rotor's path
    (measured: 1e-6 relative within the run, order-one differences by its end), so only the
    difference is printed there, with the transcript's length and finiteness asserted."""
    model = "MultiferroicMotor"
    script, _ = script_for(model, gilbert=True)
    guid = read_model_description(str(FMU_DIR / f"{model}.fmu")).guid
    native = transcript([harnesses / "native", binary(model, "linux64", "so", tmp_path), guid], script)
    assert native.size > 0 and np.isfinite(native).all()
    arm_dir = tmp_path / "arm"
    arm_dir.mkdir()
    arm = transcript([tool("qemu-aarch64"), "-L", "/usr/aarch64-linux-gnu", harnesses / "aarch64",
                      binary(model, "aarch64-linux", "so", arm_dir), guid], script)
    compare(model, native, arm, "Gilbert onion, aarch64-linux under qemu", bit_identical=True)
    win = harnesses / "win"
    dll = binary(model, "win64", "dll", win)
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=",
               WINEPREFIX=str(ROOT / "target" / "wine-prefix"))
    windows = transcript([tool("wine64"), str(win / "harness.exe"), dll.name, guid], script, env)
    assert windows.shape == native.shape and np.isfinite(windows).all()
    differing = np.count_nonzero(windows != native)
    print(f"{model} Gilbert onion, win64 under wine: {differing} of {native.size} values differ, "
          f"largest absolute difference {np.max(np.abs(windows - native)):.3g}")
