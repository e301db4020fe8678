"""Where the project's files are: the repository, the packaged FMUs, the native tools.

The package is installed editable from a clone (`make .venv/.installed`), so the repository is two
folders above this file. `make fmus` writes the FMI 2.0 FMUs to target/fmu/ and the FMI 3.0 FMUs
(same models, same names) to target/fmu-fmi3/. The package uses the FMI 2.0 ones unless
`ACTUATOR_FMUS_FMI=3` picks the FMI 3.0 ones; `ACTUATOR_FMUS_DIR` points it at any other folder of
`.fmu` files.
"""

import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMI2_DIR = ROOT / "target" / "fmu"
FMI3_DIR = ROOT / "target" / "fmu-fmi3"
FMU_DIR = pathlib.Path(os.environ.get(
    "ACTUATOR_FMUS_DIR", FMI3_DIR if os.environ.get("ACTUATOR_FMUS_FMI") == "3" else FMI2_DIR))
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
