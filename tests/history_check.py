#!/usr/bin/env python3
"""History stays out of the product: what changed lives in CHANGELOG.md and in git, not in the
README, the documentation, the code (src, build, tools, benches), the tests, the Makefile or
Cargo.toml.

Fails, naming file and line, on:
- a commit hash (7 to 40 hex digits with at least one digit and one letter, not a `0x` literal);
- an issue or pull-request number ("issue 12", "issues 15 and 18", "PR #3");
- a development date ("2 December 2026", "2026-12-02", "December 2026");
- a development narrative ("this session", "the third round", "round 2");
- a reference to a DESIGN.md that is not in the repository.

    python3 tests/history_check.py          # exit 0: nothing found
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FILES = ["README.md", "CONTRIBUTING.md", "Makefile", "Cargo.toml", "mkdocs.yml"]
FOLDERS = ["docs", "src", "build", "tests", "benches", "tools"]
TEXT = {".md", ".rs", ".py", ".toml", ".json", ".txt", ".c", ".h", ".sh", ".yml", ".yaml", ".html",
        ".supp", ".ssd", ".xml", ".cfg", ".ini"}
# The checker and its test name the patterns they look for.
SELF = {Path(__file__).resolve(), ROOT / "tests" / "fmpy" / "test_history.py"}

MONTH = ("(?:January|February|March|April|May|June|July|August|September|October|November|"
         "December)")
ORDINAL = "(?:first|second|third|fourth|fifth|sixth|previous|last|next|earlier|later|this|that)"
PATTERNS = [
    # Not a number: `1e5`-style mantissas, `0.0425f64` literals and GUID parts (between dashes).
    ("commit hash", re.compile(r"(?<![0-9A-Za-z_.-])(?![0-9]+e[0-9]*(?![0-9a-f]))"
                               r"(?![0-9]+(?:e[0-9]+)?f(?:32|64))(?=[0-9a-f]*[a-f])"
                               r"(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![0-9A-Za-z_-])")),
    ("issue number", re.compile(r"\b(?:issues?|PRs?|pull requests?)\s*#?\d+", re.I)),
    ("issue number", re.compile(r"(?<![A-Za-z])issue_\d+|\bthe issue\b", re.I)),
    ("date", re.compile(rf"\b\d{{1,2}} {MONTH}\b|\b{MONTH} \d{{4}}\b|\b20\d\d-[01]\d-[0-3]\d\b")),
    ("narrative", re.compile(rf"\b{ORDINAL} (?:rounds?|sessions?)\b|\bround \d+\b|\bsessions?\b",
                             re.I)),
]
DESIGN = re.compile(r"\bDESIGN\.md\b")


def files():
    for name in FILES:
        if (ROOT / name).is_file():
            yield ROOT / name
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*")):
            if path.is_file() and path.suffix in TEXT and path.resolve() not in SELF:
                yield path


def findings():
    design_exists = (ROOT / "DESIGN.md").is_file()
    for path in files():
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for kind, pattern in PATTERNS:
                for match in pattern.finditer(line):
                    yield f"{path.relative_to(ROOT)}:{number}: {kind}: {match.group(0)!r}"
            if not design_exists and DESIGN.search(line):
                yield f"{path.relative_to(ROOT)}:{number}: DESIGN.md is not in the repository"


def main():
    found = list(findings())
    for line in found:
        print(line)
    if found:
        print(f"{len(found)} traces of history (they belong in CHANGELOG.md or git)", file=sys.stderr)
        return 1
    print("no history in README, docs, src, build, tools, benches, tests, Makefile, Cargo.toml")
    return 0


if __name__ == "__main__":
    sys.exit(main())
