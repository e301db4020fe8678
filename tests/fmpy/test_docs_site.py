"""The documentation site: `mkdocs build --strict` (a broken link or anchor fails), then every built
page opened in headless Chromium from a local HTTP server (one browser, each page in turn in an
iframe). A page passes when the browser asked
the server for nothing it lacks (no missing image, script, stylesheet or font), every image on the
page decoded, no script raised an error, and the page's title heading is in the rendered DOM.
A screenshot of one page goes to out/docs_site/ for a person to look at."""
import functools
import html
import json
import http.server
import os
import re
import shutil
import subprocess
import threading
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MKDOCS = ROOT / ".venv" / "bin" / "mkdocs"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars"]
# Served at the end of every HTML page: once the page has loaded, writes onto <body> the images
# that did not decode and the script errors, for --dump-dom to return.
# Served at the top of every HTML page's <head>: records script errors and failed resources.
LISTEN = b"""<head><script>
window.__errors = [];
window.addEventListener('error', e => window.__errors.push(
  e.message || ('failed to load ' + (e.target && (e.target.src || e.target.href)))), true);
</script>"""
# Served at the end of every HTML page: once the page has loaded, writes onto <body> the images
# that did not decode and the errors, for --dump-dom to return.
PROBE = b"""<script>
window.addEventListener('load', () => setTimeout(() => {
  const broken = [...document.images].filter(i => !i.complete || i.naturalWidth === 0)
    .map(i => i.getAttribute('src'));
  document.body.setAttribute('data-probe', JSON.stringify({broken, errors: window.__errors}));
}, 300));
</script></body>"""


def test_mkdocs_strict_build_has_no_warning(site):
    built, log = site
    assert built.joinpath("index.html").is_file(), log


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    run = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(out)], cwd=ROOT,
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, f"mkdocs build --strict failed:\n{run.stdout}\n{run.stderr}"
    return out, run.stderr


class Recorder(http.server.SimpleHTTPRequestHandler):
    """Serves the built site; records every request's path and status (200, or 304 when the
    browser's cache holds it), and adds PROBE to HTML."""
    log = []
    harness = b""

    def send_head(self):
        path = Path(self.translate_path(self.path))
        if self.path == "/__harness__.html" or (path.is_file() and path.suffix == ".html"):
            body = Recorder.harness if self.path == "/__harness__.html" else (
                path.read_bytes().replace(b"<head>", LISTEN, 1).replace(b"</body>", PROBE, 1))
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            return _Bytes(body)
        return super().send_head()

    def log_request(self, code="-", size="-"):
        Recorder.log.append((self.path, int(getattr(code, "value", code))))

    def log_message(self, *args):
        pass


class _Bytes:
    def __init__(self, data):
        self.data = data

    def read(self, *args):
        data, self.data = self.data, b""
        return data

    def close(self):
        pass


@pytest.fixture(scope="module")
def server(site):
    built, _ = site
    handler = functools.partial(Recorder, directory=str(built))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


def pages(built):
    # 404.html is served by a web server for any missing path; it links its assets from the site root.
    return sorted(str(p.relative_to(built)) for p in built.rglob("*.html") if p.name != "404.html")


def chromium(profile, *args):
    return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--window-size=1280,1600",
                           "--virtual-time-budget=3000", *args], capture_output=True, text=True, timeout=120)


# Opens each page in turn in an iframe of one browser and collects, once it has loaded, what PROBE
# wrote and the rendered title heading; then writes them all onto its own <body>.
HARNESS = """<!doctype html><html><body><script>
const pages = PAGES;
const results = {};
(async () => {
  for (const name of pages) {
    const frame = document.createElement('iframe');
    frame.width = 1280; frame.height = 1600;
    const loaded = new Promise(done => frame.addEventListener('load', done, {once: true}));
    frame.src = name;
    document.body.appendChild(frame);
    await loaded;
    await new Promise(done => setTimeout(done, 800));
    const doc = frame.contentDocument;
    const h1 = doc.querySelector('h1');
    results[name] = {probe: doc.body.getAttribute('data-probe'), h1: h1 ? h1.textContent : null};
    frame.remove();
  }
  document.body.setAttribute('data-results', JSON.stringify(results));
})();
</script></body></html>"""


def heading(page_html):
    found = re.search(r"<h1[^>]*>(.*?)</h1>", page_html, re.S)
    # Without the permalink sign that the toc extension appends.
    return html.unescape(re.sub(r"<[^>]+>", "", found.group(1))).replace("¶", "").strip() if found else None


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (make test installs it)")
def test_every_page_renders_with_every_image_and_script(site, server, tmp_path):
    built, _ = site
    names = pages(built)
    assert len(names) >= 30, names  # 23 Markdown pages, 2 calibration reports and 7 FMU pages at least

    Recorder.harness = HARNESS.replace("PAGES", json.dumps(names)).encode()
    run = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1400,1700",
                          "--virtual-time-budget=300000", "--dump-dom", f"{server}/__harness__.html"],
                         capture_output=True, text=True, timeout=600)
    found = re.search(r'data-results="([^"]*)"', run.stdout)
    assert found, f"the harness never finished: {run.stderr[-2000:]}"
    results = json.loads(html.unescape(found.group(1)))

    problems = []
    for name in names:
        result = results.get(name, {})
        if result.get("probe") is None:
            problems.append(f"{name}: the page never finished loading")
            continue
        if json.loads(result["probe"]) != {"broken": [], "errors": []}:
            problems.append(f"{name}: {result['probe']}")
        title = heading((built / name).read_text())
        shown = (result.get("h1") or "").replace("¶", "").strip() or None
        if title != shown:
            problems.append(f"{name}: heading {title!r} rendered as {shown!r}")
    # The browser asks for /favicon.ico by itself when a page names no icon (the FMU pages).
    missing = sorted({path for path, status in Recorder.log
                      if status not in (200, 304) and path != "/favicon.ico"})
    assert not missing, f"requested but not in the site: {missing}"
    assert not problems, "\n".join(problems)
    requested = {path.split("?")[0].lstrip("/") for path, _ in Recorder.log}
    assert set(names) <= requested

    out = ROOT / "out" / "docs_site"
    out.mkdir(parents=True, exist_ok=True)
    shot = out / "McKibbenMuscle.png"
    run = chromium(tmp_path / "shot", f"--screenshot={shot}", f"{server}/fmus/McKibbenMuscle.html")
    assert shot.is_file() and shot.stat().st_size > 20_000, run.stderr[-2000:]


def test_every_generated_table_has_one_place_in_the_docs_and_none_in_the_readme():
    """benches/report.py (`make report`, `make parity`) writes its tables between
    `<!-- report:NAME -->` markers of the documentation pages; each must exist exactly once, and the
    README holds none, so no script rewrites it."""
    sources = (ROOT / "benches" / "report.py").read_text() + (ROOT / "benches" / "knitted_shape_init.py").read_text()
    names = set(re.findall(r'write_docs_block\("([^"]+)"', sources))
    assert names >= {"cost-per-step", "continuum-wall", "knitted-shape-init", "fmi-parity"}
    pages = {p: p.read_text() for p in (ROOT / "docs").rglob("*.md")}
    for name in names:
        holders = [p for p, text in pages.items() if f"<!-- report:{name} -->" in text]
        assert len(holders) == 1, (name, holders)
    assert "<!-- report:" not in (ROOT / "README.md").read_text()


def test_a_link_to_a_repository_file_must_name_one_that_exists():
    """tools/docs_site.py shows a link to a source file as the file's path, and fails the build on
    a link to a file that is not in the repository."""
    import importlib.util
    from types import SimpleNamespace

    from mkdocs.exceptions import PluginError
    spec = importlib.util.spec_from_file_location("docs_site", ROOT / "tools" / "docs_site.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    page = SimpleNamespace(file=SimpleNamespace(src_path="fmus/X.md"))
    config = {"docs_dir": str(ROOT / "docs")}
    text = ("[the joint](../../examples/robot_joint.json), [`recipes/pressure_for_force.py`](../../recipes/pressure_for_force.py), "
            "[recipes/calibrate_datasheet.py](../../recipes/calibrate_datasheet.py), [A](../calibration.md#x)")
    assert hook.on_page_markdown(text, page, config, None) == (
        "the joint (`examples/robot_joint.json`), `recipes/pressure_for_force.py`, `recipes/calibrate_datasheet.py`, "
        "[A](../calibration.md#x)")
    with pytest.raises(PluginError, match="no file of the repository"):
        hook.on_page_markdown("[gone](../../examples/gone.py)", page, config, None)


# Top-level folders of the repository whose paths the README and the docs name in code spans.
REPO_FOLDERS = ("src", "tests", "tools", "benches", "examples", "recipes", "scenes", "build", "calibration",
                "crosscheck", "systems", "data", "fuzz", "docs", "python", "modelDescription")
# Named in the docs, made by the commands they describe, ignored by git.
MADE_BY_RUNS = {"fuzz/artifacts", "fuzz/corpus-run"}


def test_every_repository_path_the_docs_name_exists():
    """A file or folder named in a code span of README.md, CONTRIBUTING.md or docs/ (`src/...`,
    `examples/...`) exists, so a moved or renamed file cannot leave the documentation behind.
    Placeholders (`<Model>`, `*`, `{a,b}`) are skipped."""
    texts = [ROOT / "README.md", ROOT / "CONTRIBUTING.md", *sorted((ROOT / "docs").rglob("*.md"))]
    stale = []
    for path in texts:
        for name in re.findall(r"`([A-Za-z0-9_./-]+)`", path.read_text()):
            name = name.rstrip("/")
            if name.split("/")[0] in REPO_FOLDERS and "/" in name and name not in MADE_BY_RUNS:
                if not (ROOT / name).exists():
                    stale.append(f"{path.relative_to(ROOT)}: {name}")
    assert not stale, "\n".join(stale)
