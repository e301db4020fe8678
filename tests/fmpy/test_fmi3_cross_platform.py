"""The FMI 3.0 FMUs' x86_64-windows DLL (under wine) and aarch64-linux .so (under qemu-user) through
the FMI 3.0 API: a small C master (tests/cross/fmi3_harness.c), built natively, with mingw-w64 and
with the aarch64 cross gcc, steps each FMU through its description's test operating points.

On every platform the FMI 3.0 transcript equals, bit for bit, the FMI 2.0 master's
(tests/cross/harness.c) on the same binary with the same script. Across platforms: aarch64 under
qemu equals x86_64-linux bit for bit; so does Windows under wine, but for the FMUs that call libm
(wine's msvcrt may differ from glibc in the last bit, and the motor's rotor carries such a bit
through its transient; tests/fmpy/test_cross_platform.py measures it)."""

import os
import pathlib
import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description

from actuator_fmus.paths import FMI3_DIR, ROOT

HARNESS = ROOT / "tests" / "cross" / "fmi3_harness.c"
FMI2_HARNESS = ROOT / "tests" / "cross" / "harness.c"
STUB = ROOT / "tests" / "cross" / "bcryptprimitives.c"
MODELS = sorted(p.stem for p in FMI3_DIR.glob("*.fmu"))
LIBM_HEAVY = {"MultiferroicMotor", "FreeBladder"}


def tool(name):
    # Debian's wine64 package installs its loader outside PATH.
    path = shutil.which(name) or next(
        (str(p) for p in [pathlib.Path("/usr/lib/wine") / name] if p.is_file()), None)
    if path is None:
        pytest.fail(f"{name} is missing: run `make cross-deps`")
    return path


# Its own prefix: the module's wineserver is stopped at its end without touching another module's.
WINE_ENV = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=",
                WINEPREFIX=str(ROOT / "target" / "wine-prefix-fmi3"))


@pytest.fixture(scope="module")
def wineserver():
    """One wineserver for the module's wine runs: a run that starts its own waits for the server's
    linger on its output pipe (about 3 s a run)."""
    server = tool("wineserver")
    quiet = dict(env=WINE_ENV, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    pathlib.Path(WINE_ENV["WINEPREFIX"]).mkdir(parents=True, exist_ok=True)
    # Kept for 120 s after its last client, should the module not reach its teardown.
    subprocess.run([server, "-p120"], check=True, **quiet)
    subprocess.run([tool("wine64"), "cmd", "/c", "exit"], timeout=600, **quiet)
    yield
    subprocess.run([server, "-k"], env=WINE_ENV, stderr=subprocess.DEVNULL)


@pytest.fixture(scope="module")
def harnesses(tmp_path_factory, wineserver):
    d = tmp_path_factory.mktemp("fmi3_harness")
    win = d / "win"
    win.mkdir()
    mingw = tool("x86_64-w64-mingw32-gcc")
    for source, suffix in [(HARNESS, ""), (FMI2_HARNESS, "_fmi2")]:
        subprocess.run([tool("gcc"), "-O2", "-ffp-contract=off", "-o", d / f"native{suffix}", source, "-ldl"],
                       check=True)
        subprocess.run([tool("aarch64-linux-gnu-gcc"), "-O2", "-ffp-contract=off", "-o", d / f"aarch64{suffix}",
                        source, "-ldl"], check=True)
        subprocess.run([mingw, "-O2", "-o", win / f"harness{suffix}.exe", source], check=True)
    # wine 8.0 lacks bcryptprimitives.dll (ProcessPrng), which Rust's std imports: a stand-in next
    # to the .exe, where the loader looks first.
    subprocess.run([mingw, "-O2", "-shared", "-o", win / "bcryptprimitives.dll", STUB, "-ladvapi32"], check=True)
    return d


def script_for(model):
    """Exit initialization, then the description's test input points (Float64 inputs) in turn, three
    rounds, a step and every scalar Float64 output after each."""
    md = read_model_description(str(FMI3_DIR / f"{model}.fmu"))
    vr = {v.name: v.valueReference for v in md.modelVariables if v.type == "Float64"}
    inputs = {v.name for v in md.modelVariables if v.causality == "input" and v.type == "Float64"}
    # Scalars only: the FMI 2.0 master reads the same script, and FMI 2.0 has no arrays.
    outputs = [vr[v.name] for v in md.modelVariables
               if v.causality == "output" and v.type == "Float64" and not v.dimensions]
    source = (ROOT / "modelDescription" / f"{model}.xml").read_text()
    points = [dict(pair.split("=") for pair in values.split())
              for values in re.findall(r'<Inputs values="([^"]*)"', source)]
    points = [{k: float(v) for k, v in p.items() if k in inputs} for p in points] or [{}]
    step = md.defaultExperiment.stepSize if md.defaultExperiment and md.defaultExperiment.stepSize else 0.01
    lines = ["X"]
    for _ in range(3):
        for point in points:
            lines += [f"F {vr[name]} {value!r}" for name, value in point.items()]
            lines += [f"S {float(step)!r}", "G " + " ".join(map(str, outputs))]
    # The same script for the FMI 2.0 master: the Float64 value references are the FMI 2.0 Reals.
    fmi2 = [("R" + line[1:]) if line.startswith("F ") else line for line in lines]
    return "\n".join(lines) + "\n", "\n".join(fmi2) + "\n", md.instantiationToken


def transcript(command, script, env=None):
    r = subprocess.run(command, input=script, capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, f"{command[0]} failed ({r.returncode}): {r.stdout[-500:]} {r.stderr[-2000:]}"
    # The FMI 2.0 master starts each line with a tag (r: Reals); the values follow.
    return np.array([float(x) for line in r.stdout.splitlines()
                     for x in line.split()[1 if line[:1].isalpha() else 0:]])


def binary(model, platform, extension, directory):
    with zipfile.ZipFile(FMI3_DIR / f"{model}.fmu") as z:
        name = f"binaries/{platform}/{model}.{extension}"
        assert name in z.namelist(), f"{model}.fmu has no {name}: run `make fmus`"
        path = directory / f"{model}.{extension}"
        path.write_bytes(z.read(name))
    return path


def same_bits(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize("model", MODELS)
def test_fmi3_equals_fmi2_on_every_platform_and_the_platforms_agree(model, harnesses, tmp_path):
    script, fmi2_script, token = script_for(model)
    win = harnesses / "win"
    env = WINE_ENV
    so = binary(model, "x86_64-linux", "so", tmp_path)
    (tmp_path / "arm").mkdir()
    arm_so = binary(model, "aarch64-linux", "so", tmp_path / "arm")
    dll = binary(model, "x86_64-windows", "dll", win)
    qemu = [tool("qemu-aarch64"), "-L", "/usr/aarch64-linux-gnu"]
    runs = {}
    for api, text, suffix in [("fmi3", script, ""), ("fmi2", fmi2_script, "_fmi2")]:
        runs[api] = {
            "x86_64-linux": transcript([harnesses / f"native{suffix}", so, token], text),
            "aarch64-linux": transcript(qemu + [harnesses / f"aarch64{suffix}", arm_so, token], text),
            "x86_64-windows": transcript([tool("wine64"), str(win / f"harness{suffix}.exe"), dll.name, token],
                                         text, env),
        }
    native = runs["fmi3"]["x86_64-linux"]
    assert native.size > 0 and np.all(np.isfinite(native))
    for platform, values in runs["fmi3"].items():
        assert same_bits(values, runs["fmi2"][platform]), f"{model} {platform}: FMI 3.0 differs from FMI 2.0"
    assert same_bits(runs["fmi3"]["aarch64-linux"], native), f"{model}: aarch64 differs"
    windows = runs["fmi3"]["x86_64-windows"]
    worst = np.max(np.abs(windows - native) / np.maximum(np.abs(native), 1e-300), initial=0.0)
    print(f"{model}: {native.size} values; x86_64-windows under wine: max rel. diff {worst:.3g}")
    if model not in LIBM_HEAVY:
        assert same_bits(windows, native), f"{model}: x86_64-windows differs"
