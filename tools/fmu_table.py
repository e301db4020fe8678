#!/usr/bin/env python3
"""The README's table of FMUs, every input and output with its unit and declared range, from
modelDescription/*.xml (the single source of the variables).

    python3 tools/fmu_table.py           # prints the table (Markdown)
    python3 tools/fmu_table.py --check   # exit 1 if README.md's copy differs

The README holds the table between `<!-- fmu-table -->` and `<!-- /fmu-table -->`; paste the printed
table there after changing a model description (`make test` checks it is in sync). No script
rewrites the README."""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- fmu-table -->", "<!-- /fmu-table -->"


def number(text):
    value = float(text)
    if value == int(value) and abs(value) < 1e5:
        return str(int(value))
    return f"{value:g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


def describe(var):
    """`name` (unit, min .. max) for a Real or Integer; the type's name for the others."""
    typed = next(iter(var))
    kind = typed.tag
    unit = typed.get("unit")
    lo, hi = typed.get("min"), typed.get("max")
    parts = []
    if kind == "Real":
        parts.append(unit if unit and unit != "1" else "1")
    elif kind == "Boolean":
        parts.append("Boolean")
    elif kind == "Enumeration":
        parts.append("Enumeration")
    else:
        parts.append(kind)
    if lo is not None or hi is not None:
        parts.append(f"{number(lo) if lo is not None else '-inf'} .. {number(hi) if hi is not None else 'inf'}")
    return f"`{var.get('name')}` ({', '.join(parts)})"


def table():
    rows = ["| FMU | inputs (unit, declared range) | outputs (unit, declared range) |", "|---|---|---|"]
    for path in sorted((ROOT / "modelDescription").glob("*.xml")):
        root = ET.parse(path).getroot()
        variables = root.find("ModelVariables")
        by = {"input": [], "output": []}
        for var in variables:
            if var.get("causality") in by:
                by[var.get("causality")].append(describe(var))
        name = root.get("modelName")
        link = f"[{name}](docs/fmus/{name}.md)"
        rows.append(f"| {link} | {'<br>'.join(by['input'])} | {'<br>'.join(by['output'])} |")
    return "\n".join(rows)


def readme_copy():
    text = (ROOT / "README.md").read_text()
    i, j = text.find(START), text.find(END)
    if i < 0 or j < i:
        return None
    return text[i + len(START):j].strip()


def main():
    if "--check" in sys.argv:
        if readme_copy() != table():
            print(f"README.md's FMU table is out of date: paste the output of `python3 tools/fmu_table.py` "
                  f"between {START} and {END}", file=sys.stderr)
            return 1
        print("README.md's FMU table matches modelDescription/*.xml")
        return 0
    print(table())
    return 0


if __name__ == "__main__":
    sys.exit(main())
