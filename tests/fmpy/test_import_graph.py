"""No import circles in src/ (tools/import_graph.py), between files and between a layer's top-level
modules. The checker is held to its rules with planted graphs first."""
import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("import_graph", ROOT / "tools" / "import_graph.py")
import_graph = importlib.util.module_from_spec(spec)
spec.loader.exec_module(import_graph)


def test_the_checker_finds_planted_circles_and_spares_a_chain():
    a, b, c, d = ("physics", "a"), ("physics", "b"), ("physics", "c"), ("models", "m")
    assert import_graph.circles({d: {a}, a: {b}, b: {c}, c: set()}) == []
    assert import_graph.circles({d: {a}, a: {b}, b: {c}, c: {a}}) == [sorted([a, b, c])]
    # Children of one module call each other freely; a circle between two modules through
    # their children is still a circle.
    inner = {("physics", "x", "p"): {("physics", "x", "q")}, ("physics", "x", "q"): {("physics", "x", "p")}}
    assert import_graph.circles(import_graph.collapse(inner)) == []
    across = {("physics", "x", "p"): {("physics", "y")}, ("physics", "y"): {("physics", "x", "q")}}
    assert import_graph.circles(import_graph.collapse(across)) == [[("physics", "x"), ("physics", "y")]]


def test_src_has_no_import_circles():
    run = subprocess.run([sys.executable, str(ROOT / "tools" / "import_graph.py")],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "0 circles" in run.stdout, run.stdout
