"""Runs every scene in scenes/ (full length) and writes docs/figures.md with each plot beside what
the dissertation says, and the dissertation's numbers beside ours. `make figures`."""

import re
import shutil

from . import scene as scenes
from .paths import ROOT


def main(args=None):
    """Runs every scene and writes docs/figures.md and docs/figures/*.png; returns 0."""
    out = ROOT / "out"
    figures = ROOT / "docs" / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    lines = [
        "# Figure catalogue",
        "",
        "Each scene in `scenes/` reproduces the model side of one of the figures of E. Ball, *Novel Methods in",
        "Meso-Scale and Nano-Scale Actuation*, M.S. thesis, Cornell University, 2014 (\"the dissertation\"; the",
        "README's [The source](../README.md#the-source) says how to obtain it). Regenerate this page with",
        "`make figures`; run one scene with `.venv/bin/actuator-fmus scene scenes/<scene>.json`. The scene",
        "format is [`scenes/schema/scene.schema.json`](../scenes/schema/scene.schema.json).",
        "",
    ]
    def figure_order(path):
        return [int(x) if x.isdigit() else x for x in re.split(r"(\d+)", path.stem)]

    for path in sorted((ROOT / "scenes").glob("*.json"), key=figure_order):
        scene = scenes.load_scene(path)
        scenes.check_scene(scene)
        runs = scenes.run_scene(scene)
        scenes.write_outputs(scene, runs, out)
        title, _, said = scene["description"].partition(": ")
        lines += [f"## {title} (`scenes/{path.name}`)", "", said[:1].upper() + said[1:], ""]
        if scene.get("plot"):
            shutil.copy(out / f"{path.stem}.png", figures / f"{path.stem}.png")
            lines += [f"![{title}](figures/{path.stem}.png)", ""]
        for ok, text in scenes.evaluate_checks(scene, runs):
            lines.append(f"- {'holds' if ok else 'FAILS'}: {text}")
        lines.append("")
    (ROOT / "docs" / "figures.md").write_text("\n".join(lines))
    print(f"wrote docs/figures.md and {len(list(figures.glob('*.png')))} plots")
    return 0
