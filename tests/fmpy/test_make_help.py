"""`make help` lists the user targets, one line each, and is the one list of them (the README
points to it): every name it prints is a target of the Makefile, and internal targets stay out."""
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
INTERNAL = {"deps", "py-deps", "cross-deps", "interop-deps", "test-rust", "test-fmpy"}


def help_targets():
    out = subprocess.run(["make", "--no-print-directory", "help"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    return re.findall(r"^  ([a-z][a-z0-9-]*) +\S", out, re.M)


def makefile_targets():
    # The rule database without running anything (-q -p with no target and no default rules).
    out = subprocess.run(["make", "-qpRr", "-f", "Makefile", ":"], cwd=ROOT, capture_output=True,
                         text=True).stdout
    return set(re.findall(r"^([a-z][a-z0-9-]*):", out, re.M))


def test_every_listed_target_exists_once_and_internal_ones_stay_out():
    listed = help_targets()
    assert len(listed) >= 15
    assert len(listed) == len(set(listed))
    assert set(listed) - makefile_targets() == set()
    assert INTERNAL.isdisjoint(listed)
    assert {"demo", "test", "fmus", "docs", "help"} <= set(listed)
