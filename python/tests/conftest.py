"""Shared fixtures of the Python tests: where the bundled data and the CLI are."""

from __future__ import annotations

import os
import pathlib
import shutil
from typing import Optional

import pytest


@pytest.fixture(scope="session")
def source_dir() -> pathlib.Path:
    """The repository (CTest sets FASTCAL_SOURCE_DIR)."""
    return pathlib.Path(os.environ.get("FASTCAL_SOURCE_DIR", pathlib.Path(__file__).parents[2]))


@pytest.fixture(scope="session")
def data_dir(source_dir: pathlib.Path) -> pathlib.Path:
    return source_dir / "calibration_data"


@pytest.fixture(scope="session")
def cli() -> Optional[str]:
    """The fastcal executable (CTest sets FASTCAL_BIN), or None when it was not built."""
    path = os.environ.get("FASTCAL_BIN") or shutil.which("fastcal")
    return path if path and os.path.exists(path) else None
