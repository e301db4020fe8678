"""The README is a user's front page: at most 300 lines with a table of contents whose links
resolve; its FMU table matches modelDescription/*.xml (tools/fmu_table.py); every Python snippet
runs and prints what the comment lines under it say; it points to `make help` for the targets."""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()


def anchor(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to dashes."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_at_most_300_lines_with_a_table_of_contents():
    assert len(README.splitlines()) <= 300
    contents = README.split("## Contents", 1)[1].split("\n## ", 1)[0]
    links = re.findall(r"\]\(#([^)]+)\)", contents)
    headings = [anchor(h) for h in re.findall(r"^## (.+)$", README, re.M)]
    assert len(links) >= 5
    assert set(links) <= set(headings), set(links) - set(headings)
    assert set(headings) - {"contents"} <= set(links), "every section is in the contents"


def test_cites_the_dissertation_by_title_and_gives_the_two_commands():
    assert "*Novel Methods in Meso-Scale and Nano-Scale Actuation*" in README
    assert "make demo" in README and "make test" in README and "make help" in README


def test_fmu_table_is_in_sync_with_the_model_descriptions():
    run = subprocess.run([sys.executable, str(ROOT / "tools" / "fmu_table.py"), "--check"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    table = README.split("<!-- fmu-table -->")[1].split("<!-- /fmu-table -->")[0]
    models = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
    assert [m for m in models if f"[{m}]" not in table] == []


def test_every_python_snippet_prints_what_it_says():
    blocks = re.findall(r"```python\n(.*?)```", README, re.S)
    assert len(blocks) >= 3
    for block in blocks:
        code = "\n".join(l for l in block.splitlines() if not l.startswith("# "))
        expected = [l[2:] for l in block.splitlines() if l.startswith("# ")]
        assert expected, f"a snippet without its output:\n{block}"
        run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr[-2000:]
        assert run.stdout.splitlines() == expected, f"{block}\nprinted:\n{run.stdout}"
        assert "Warning" not in run.stderr + run.stdout, run.stderr
