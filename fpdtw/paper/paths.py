"""Every path fpdtw reads or writes, in one place; environment variables (``FPDTW_DATA_DIR``,
``FPDTW_MIRROR``, ``FPDTW_RESULTS_DIR``, ``FPDTW_FIGURES_DIR``, ``FPDTW_MANIFEST_DIR``,
``FPDTW_EXECUTED_DIR``) override the defaults."""

from __future__ import annotations

import os
from pathlib import Path

import pooch

#: Root of the source checkout (the folder holding ``pyproject.toml``).
REPO_ROOT = Path(__file__).resolve().parents[2]


def _env_path(var: str, default: Path) -> Path:
    value = os.environ.get(var)
    return Path(value).expanduser().resolve() if value else default


def data_dir() -> Path:
    """Folder of the verified data cache (``<repo>/data_cache`` in a writable checkout, else the
    user cache folder)."""
    if (REPO_ROOT / "pyproject.toml").is_file() and os.access(REPO_ROOT, os.W_OK):
        default = REPO_ROOT / "data_cache"
    else:
        default = Path(pooch.os_cache("fpdtw"))
    return _env_path("FPDTW_DATA_DIR", default)


def mirror() -> str | None:
    """The mirror given by ``FPDTW_MIRROR`` (folder or base URL, docs/data.md), or None."""
    return os.environ.get("FPDTW_MIRROR", "").strip() or None


def manifest_dir() -> Path:
    """Folder of the data manifests (one TOML file per dataset)."""
    return _env_path("FPDTW_MANIFEST_DIR", REPO_ROOT / "data_manifest")


def results_dir() -> Path:
    """Folder of experiment results (one file per algorithm)."""
    return _env_path("FPDTW_RESULTS_DIR", REPO_ROOT / "results")


def figures_dir() -> Path:
    """Folder of figures (PDF + PNG) and tables (CSV + Markdown)."""
    return _env_path("FPDTW_FIGURES_DIR", REPO_ROOT / "figures")


def notebooks_dir() -> Path:
    """Folder of the source notebooks."""
    return REPO_ROOT / "notebooks"


def executed_dir() -> Path:
    """Folder where papermill writes executed notebooks."""
    return _env_path("FPDTW_EXECUTED_DIR", REPO_ROOT / "build" / "notebooks")
