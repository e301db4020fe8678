"""MkDocs hook (mkdocs.yml `hooks:`): each FMU's own page, the `documentation/` folder that
`package_fmus` writes into target/fmu/<Model>.fmu, joins the site as fmu/<Model>/, so the site
shows exactly what an importer's user sees and the strict build checks links into it."""
import zipfile
from pathlib import Path

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
FMU_DIR = ROOT / "target" / "fmu"


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
                    files.append(File.generated(config, uri, content=archive.read(name)))
    return files
