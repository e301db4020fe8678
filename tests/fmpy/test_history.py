"""History stays out of the product (tests/history_check.py): no commit hashes, issue numbers,
development dates or round/session narratives in README, docs, src, build, tests, the Makefile or
Cargo.toml. The checker is held to its patterns with planted examples first."""
import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("history_check", ROOT / "tests" / "history_check.py")
history_check = importlib.util.module_from_spec(spec)
spec.loader.exec_module(history_check)


def kinds(line):
    return sorted({kind for kind, pattern in history_check.PATTERNS if pattern.search(line)})


def test_the_patterns_find_history_and_spare_numbers():
    assert kinds("measured at commit 4f86991 on the idle machine") == ["commit hash"]
    assert kinds("fixed in 988e5ff") == ["commit hash"]
    assert kinds("Issue 15's goals") == ["issue number"]
    assert kinds("see issues 7 and 15") == ["issue number"]
    assert kinds("fn keeps_the_basin_of_issue_16()") == ["issue number"]
    assert kinds("measured 2 December 2026") == ["date"]
    assert kinds("on 2026-12-01") == ["date"]
    assert kinds("Before this round the ratio was 1.5x") == ["narrative"]
    assert kinds("this session's runs") == ["narrative"]
    # Numbers, literals and GUIDs are not history.
    for line in ["x = 0.0425f64.powi(2)", "0.987873212108272e-5", "let h = 0xcbf29ce484222325;",
                 "{01234567-89ab-cdef-0123-456789abcdef}", "rounded to 1e-12", "a round trip of the state",
                 "E. Ball, Cornell University, 2014", "Table 2.1, eq. 2.19-2.20"]:
        assert kinds(line) == [], line


def test_no_history_in_the_product():
    run = subprocess.run([sys.executable, str(ROOT / "tests" / "history_check.py")],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr
