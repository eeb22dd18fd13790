"""docs/python.md's worked example runs as written."""

from __future__ import annotations

import importlib.util
import os
import pathlib
import re
from typing import Dict

import pytest


def example_blocks(source_dir: pathlib.Path) -> Dict[str, str]:
    """The fenced Python blocks after "<!-- example -->" / "<!-- example: NAME -->"."""
    text = (source_dir / "docs" / "python.md").read_text()
    blocks = re.findall(r"<!-- example(?:: (\w+))? -->\n```python\n(.*?)```", text, re.S)
    return {name or "main": code for name, code in blocks}


def test_worked_example(
    source_dir: pathlib.Path, tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocks = example_blocks(source_dir)
    assert set(blocks) == {"main", "plot", "columns", "loop"}
    # Run where the example expects to be: beside calibration_data/.
    (tmp_path / "calibration_data").symlink_to(source_dir / "calibration_data")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(blocks["main"], "docs/python.md (example)", "exec"), namespace)
    assert namespace["result"].verdict == "ok"
    assert namespace["predicted_kN"].shape == (360, 6)
    if importlib.util.find_spec("matplotlib") is None:
        pytest.skip("matplotlib (python3-matplotlib) is missing: the example ran, its plot did not")
    os.environ.setdefault("MPLBACKEND", "Agg")
    exec(compile(blocks["plot"], "docs/python.md (plot)", "exec"), namespace)
    assert (tmp_path / "out" / "tensions.png").stat().st_size > 0
    # Nothing else written beside calibration_data/: the outputs go under out/.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["calibration_data", "out"]


def test_columns_example(
    source_dir: pathlib.Path, tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/python.md's "Telemetry as it comes" runs as written."""
    blocks = example_blocks(source_dir)
    (tmp_path / "calibration_data").symlink_to(source_dir / "calibration_data")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(blocks["columns"], "docs/python.md (columns)", "exec"), namespace)
    assert len(namespace["export"]) == 1441
    assert len(namespace["arrays"]) == 1441


def test_loop_example(
    source_dir: pathlib.Path, tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/python.md's "The cabin in its control loop" runs as written: the nominal
    model's error where the feed-forward alone holds the cabin, a few mm with the PID."""
    blocks = example_blocks(source_dir)
    (tmp_path / "calibration_data").symlink_to(source_dir / "calibration_data")
    monkeypatch.chdir(tmp_path)
    if importlib.util.find_spec("matplotlib") is not None:
        monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {}
    exec(compile(blocks["loop"], "docs/python.md (loop)", "exec"), namespace)
    runs = namespace["runs"]
    alone = runs["feed-forward alone"].attrs["summary"]["error_rms_mm"]
    pid = runs["with the PID"]
    assert alone > 30.0
    assert pid.error_mm.to_numpy()[-300:].mean() < 5.0
    if importlib.util.find_spec("matplotlib") is not None:
        assert (tmp_path / "out" / "loop.png").stat().st_size > 0
