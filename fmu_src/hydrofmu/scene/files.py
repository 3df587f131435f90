"""The files a scene file names: its decks, BEM results and current files (what a build
of it depends on besides the scene itself)."""
import tomllib
from pathlib import Path


def files_named(value, base):
    """Existing files that string values of a TOML document name (relative to ``base``)."""
    if isinstance(value, dict):
        value = list(value.values())
    if isinstance(value, list):
        return [f for v in value for f in files_named(v, base)]
    if isinstance(value, str) and value:
        try:
            f = (base / value).resolve()
            return [f] if f.is_file() else []
        except (OSError, ValueError):
            return []
    return []


def scene_files(path: str | Path) -> list[Path]:
    """The existing files a scene file's values name (decks, BEM results, current files),
    resolved; [] when it cannot be read as TOML."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_bytes().decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return []
    return sorted(set(files_named(doc, path.resolve().parent)))
