"""MkDocs hook (mkdocs.yml `hooks:`): each FMU's own page, the `documentation/` folder that
`package_fmus` writes into target/fmu/<Model>.fmu, joins the site as fmu/<Model>/, so the site
shows exactly what an importer's user sees and the strict build checks links into it. A link to a
repository file outside docs/ is checked to exist and shown as its path."""
import re
import zipfile
from pathlib import Path

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
FMU_DIR = ROOT / "target" / "fmu"
# The site's copy of an FMU page links back to the site (the page inside the .fmu stays as shipped).
BACK = (b'<body>\n<p><a href="../../index.html">actuator-fmus documentation</a> &rsaquo; '
        b'<a href="../../fmus/MODEL.html">MODEL</a> &rsaquo; variables</p>')


def models():
    return sorted(p.stem for p in (ROOT / "modelDescription").glob("*.xml"))


def on_files(files, config):
    for model in models():
        fmu = FMU_DIR / f"{model}.fmu"
        if not fmu.is_file():
            raise PluginError(f"{fmu.relative_to(ROOT)} is missing: run `make fmus` first (`make docs` does)")
        with zipfile.ZipFile(fmu) as archive:
            for name in archive.namelist():
                if name.startswith("documentation/") and not name.endswith("/"):
                    uri = f"fmu/{model}/{name.removeprefix('documentation/')}"
                    content = archive.read(name)
                    if uri.endswith("/index.html"):
                        content = content.replace(b"<body>", BACK.replace(b"MODEL", model.encode()), 1)
                    files.append(File.generated(config, uri, content=content))
    return files


LINK = re.compile(r"(?<!!)\[([^\]]+)\]\(([^)\s]+)\)")


def on_page_markdown(markdown, page, config, files):
    """A link from a page to a file of the repository outside docs/ (a script, a scene, the
    README) must name a file that exists; the site does not host the sources, so it is shown as
    the file's path in code. A link to a missing file fails the build, as a broken link does."""
    docs = Path(config["docs_dir"]).resolve()
    here = (docs / page.file.src_path).parent
    parts = re.split(r"(^```.*?^```)", markdown, flags=re.M | re.S)

    def outside(match):
        label, target = match.group(1), match.group(2)
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            return match.group(0)
        path = (here / target.split("#", 1)[0]).resolve()
        if path.is_relative_to(docs):
            return match.group(0)
        if not path.is_relative_to(ROOT) or not path.exists():
            raise PluginError(f"{page.file.src_path}: the link {target!r} names no file of the repository")
        shown = path.relative_to(ROOT).as_posix()
        return f"`{shown}`" if label.strip("`") == shown else f"{label} (`{shown}`)"

    return "".join(part if part.startswith("```") else LINK.sub(outside, part) for part in parts)
