"""Installing (issue 39): `pip install --no-build-isolation .` in a venv gives an importable
module (no package index), and `cmake --install` puts the man pages, the bash completion,
the docs and the recommended specs under share/ beside the executable."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import sys

import pytest


def _build_dir(cli: str | None) -> pathlib.Path:
    if not cli:
        pytest.skip("the fastcal executable (FASTCAL_BIN) is not set")
    return pathlib.Path(cli).resolve().parents[1]  # build/bin/fastcal


def test_pip_installs_the_module_into_a_venv(
    source_dir: pathlib.Path, cli: str | None, tmp_path: pathlib.Path
) -> None:
    build = _build_dir(cli)
    venv = tmp_path / "venv"
    # Debian's venv sees Debian's NumPy (--system-site-packages); no index is asked.
    made = subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)],
                          capture_output=True, text=True)
    if made.returncode != 0:
        pytest.skip(f"no venv module for {sys.executable} (python3-venv): {made.stderr[-200:]}")
    env = dict(os.environ, FASTCAL_BUILD_DIR=str(build), PIP_NO_INDEX="1")
    env.pop("PYTHONPATH", None)  # the venv's own fastcal, not the build tree's
    pip = subprocess.run(
        [str(venv / "bin" / "pip"), "install", "--no-build-isolation", "--no-deps", "--quiet",
         str(source_dir)],
        env=env, capture_output=True, text=True, cwd=tmp_path)
    assert pip.returncode == 0, pip.stdout[-2000:] + pip.stderr[-2000:]
    probe = subprocess.run(
        [str(venv / "bin" / "python"), "-c",
         "import fastcal; r = fastcal.solve([0, 0, 150]); print(fastcal.__file__); "
         "print(round(float(r.lower_tension_kN.flat[0]), 1))"],
        env=env, capture_output=True, text=True, cwd=tmp_path)
    assert probe.returncode == 0, probe.stderr[-2000:]
    where, tension = probe.stdout.split()
    assert str(venv) in where
    assert 100.0 < float(tension) < 400.0  # a cable of the 30 t cabin at the home pose


def test_cmake_install_puts_man_pages_completion_docs_and_specs(
    cli: str | None, tmp_path: pathlib.Path
) -> None:
    build = _build_dir(cli)
    prefix = tmp_path / "prefix"
    done = subprocess.run(["cmake", "--install", str(build), "--prefix", str(prefix)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    share = prefix / "share"
    if shutil.which("help2man"):
        assert (share / "man" / "man1" / "fastcal-calibrate.1").is_file()
        assert (share / "man" / "man1" / "fastcal.1").is_file()
    assert (share / "bash-completion" / "completions" / "fastcal").is_file()
    assert (share / "doc" / "fastcal" / "cli.md").is_file()
    spec = share / "fastcal" / "calibration_data" / "spec_realistic.yaml"
    assert spec.is_file()
    # The installed program runs with the installed spec alone (no source tree).
    installed = prefix / "bin" / "fastcal"
    out = subprocess.run([str(installed), "simulate", "--trajectory=random", "--samples=200",
                          f"--out={tmp_path / 's.csv'}"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    cal = subprocess.run([str(installed), "calibrate", f"--spec={spec}",
                          f"--data={tmp_path / 's.csv'}", f"--out={tmp_path / 'cal'}"],
                         capture_output=True, text=True)
    assert cal.returncode == 0, cal.stderr[-2000:]
    # The completion offers a command's flags, read from its help.
    script = share / "bash-completion" / "completions" / "fastcal"
    flags = subprocess.run(
        ["bash", "-c", f"source {script}; COMP_WORDS=({installed} calibrate --sp); "
                       "COMP_CWORD=2; _fastcal; echo ${COMPREPLY[@]}"],
        capture_output=True, text=True)
    assert "--spec" in flags.stdout.split(), flags.stdout + flags.stderr
