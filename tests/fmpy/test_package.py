"""The Python side is one installed package: `actuator_fmus` imports from anywhere, its command
`actuator-fmus` lists the jobs, every public function says what it does (and in which units), and
no user-facing script edits sys.path or imports the test suite."""

import importlib
import inspect
import pkgutil
import re
import subprocess
from pathlib import Path

import actuator_fmus
from conftest import ROOT

USER_FACING = ["python", "recipes", "examples", "benches", "scenes", "docs", "calibration", "crosscheck", "systems"]
COMMANDS = ["scene", "figures", "info", "calibrate", "pressure-for-force", "crosscheck", "robot-joint", "systems",
            "sweep", "knitted-bag", "motor", "linearized", "chapter2-claims"]


def test_the_package_is_installed_and_imports_outside_the_repository(tmp_path):
    run = subprocess.run([str(Path(__import__("sys").executable)), "-c",
                          "import actuator_fmus, sys; print(actuator_fmus.FMU_DIR)"],
                         cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert Path(run.stdout.strip()) == ROOT / "target" / "fmu"


def test_the_command_lists_every_job():
    exe = Path(__import__("sys").executable).with_name("actuator-fmus")
    assert exe.exists(), "make .venv/.installed installs the package with its command"
    run = subprocess.run([str(exe), "--help"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    for command in COMMANDS:
        assert re.search(rf"^\s+{re.escape(command)}\b", run.stdout, re.M), command


def test_no_user_facing_code_edits_sys_path_or_imports_the_tests():
    offenders = []
    for folder in USER_FACING:
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text()
            if "sys.path" in text or re.search(r"^\s*(from|import) conftest\b", text, re.M):
                offenders.append(str(path.relative_to(ROOT)))
    assert not offenders, offenders


def test_every_public_function_is_documented():
    undocumented = []
    for module in pkgutil.iter_modules(actuator_fmus.__path__):
        mod = importlib.import_module(f"actuator_fmus.{module.name}")
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__:
                continue
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and not inspect.getdoc(obj):
                undocumented.append(f"{mod.__name__}.{name}")
    assert not undocumented, undocumented
