"""Every recipe in recipes/ runs from the repository root and exits 0 (each asserts its own
results) without printing a warning. docs/recipes.md explains them; this test keeps them working."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RECIPES = sorted((ROOT / "recipes").glob("*.py"))


def test_there_are_recipes_and_each_is_documented():
    assert RECIPES
    doc = (ROOT / "docs" / "recipes.md").read_text()
    missing = [r.name for r in RECIPES if f"recipes/{r.name}" not in doc]
    assert not missing, f"not in docs/recipes.md: {missing}"


@pytest.mark.parametrize("recipe", RECIPES, ids=[r.stem for r in RECIPES])
def test_recipe_runs(recipe):
    run = subprocess.run([sys.executable, str(recipe.relative_to(ROOT))], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"{recipe.name} exited {run.returncode}\n{run.stdout}\n{run.stderr}"
    assert run.stdout.strip(), f"{recipe.name} printed nothing"
    # A recipe a user copies must not teach them to ignore warnings: none is printed.
    noise = [line for line in (run.stdout + run.stderr).splitlines() if re.search(r"Warning\b", line)]
    assert not noise, f"{recipe.name} warns:\n" + "\n".join(noise)
