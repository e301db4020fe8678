"""Each FMU's documentation/index.html, rendered by headless Chromium in a 1200 px wide window:
the page needs no horizontal scrolling (the variable table fits), no number is printed with more
than 7 significant digits, and the dissertation is cited by title. The screenshots go to
out/fmu_pages/<Model>.png for a person to look at."""
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FMU_DIR = ROOT / "target" / "fmu"
MODELS = sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))
WIDTH = 1200
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars"]
# Appended to a copy of the page only: writes the page's layout width into the DOM.
MEASURE = ("<script>document.body.setAttribute('data-scroll-width', "
           "document.documentElement.scrollWidth);</script></body>")

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (make test installs it)")


def page(model, tmp_path):
    with zipfile.ZipFile(FMU_DIR / f"{model}.fmu") as z:
        z.extractall(tmp_path / model, [n for n in z.namelist() if n.startswith("documentation/")])
    return tmp_path / model / "documentation" / "index.html"


def chromium(tmp_path, *args):
    profile = tmp_path / "profile"
    return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", f"--window-size={WIDTH},1600", *args],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("model", MODELS)
def test_page_fits_1200_px_and_reads_at_a_glance(model, tmp_path):
    html = page(model, tmp_path)
    text = html.read_text()
    assert "Novel Methods in Meso-Scale and Nano-Scale Actuation" in text
    cells = re.findall(r'<td class="n">([^<]*)</td>', text)
    long_numbers = [c for c in cells if re.search(r"\d{8,}", c.replace("&nbsp;..&nbsp;", " "))]
    assert not long_numbers, long_numbers

    measured = html.with_name("measure.html")
    measured.write_text(text.replace("</body>", MEASURE))
    dom = chromium(tmp_path, "--dump-dom", measured.as_uri())
    found = re.search(r'data-scroll-width="(\d+)"', dom.stdout)
    assert found, dom.stderr[-2000:]
    assert int(found.group(1)) <= WIDTH, f"{model}: the page is {found.group(1)} px wide at a {WIDTH} px window"

    out = ROOT / "out" / "fmu_pages"
    out.mkdir(parents=True, exist_ok=True)
    shot = chromium(tmp_path, f"--screenshot={out / f'{model}.png'}", html.as_uri())
    assert (out / f"{model}.png").stat().st_size > 10_000, shot.stderr[-2000:]
