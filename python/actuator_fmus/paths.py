"""Where the project's files are: the repository, the packaged FMUs, the native tools.

The package is installed editable from a clone (`make .venv/.installed`), so the repository is two
folders above this file. `ACTUATOR_FMUS_DIR` points the package at another folder of `.fmu` files.
"""

import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU_DIR = pathlib.Path(os.environ.get("ACTUATOR_FMUS_DIR", ROOT / "target" / "fmu"))
RELEASE = ROOT / "target" / "release"
DOCS = ROOT / "docs"
OUT = ROOT / "out"


class UsageError(ValueError):
    """A mistake the user can fix (a name, a value, a missing file). Its message is one line that
    says what is valid; the command line prints it without a traceback."""


def models():
    """Names of the packaged FMUs in FMU_DIR, sorted."""
    return sorted(p.stem for p in FMU_DIR.glob("*.fmu"))


def fmu_path(model: str) -> str:
    """Path of the packaged `<model>.fmu`; UsageError naming the available models if there is none."""
    path = FMU_DIR / f"{model}.fmu"
    if path.exists():
        return str(path)
    available = models()
    if not available:
        raise UsageError(f"no FMUs in {FMU_DIR}: run `make fmus` first")
    from .names import nearest_first

    raise UsageError(f"no FMU named {model!r}; available: {', '.join(nearest_first(model, available))}")
