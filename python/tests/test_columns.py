"""Telemetry as it comes: column maps, spreadsheets, arrays and DataFrames
(docs/data-format.md, "Column maps"; docs/python.md)."""

from __future__ import annotations

import datetime
import pathlib
import subprocess
import sys
from typing import Optional

import numpy as np
import pytest

import fastcal

FAST_MAP = {
    "format": "fastcal-columns-1",
    "delimiter": ";",
    "decimal": ",",
    "header_line": 2,
    "skip_after_header": 1,
    "time": {"column": "SysTime", "format": "iso8601", "zone": "+08:00"},
    "columns": {
        "x_m": {"column": "SDP_PhaPos_X", "unit": "mm"},
        "y_m": {"column": "SDP_PhaPos_Y", "unit": "mm"},
        "z_m": {"column": "SDP_PhaPos_Z", "unit": "mm"},
        "yaw_deg": "SDP_SwtDPose_Y",
        "pitch_deg": "SDP_SwtDPose_P",
        "roll_deg": "SDP_SwtDPose_R",
        **{f"T{i}_kN": {"column": f"CableForce{i}", "unit": "N"} for i in range(1, 7)},
    },
    "unmapped": "ignore",
}
START = 1714564800.0  # 2024-05-01T20:00:00+08:00


def test_the_bundled_export_reads_through_its_map_as_the_survey(data_dir: pathlib.Path) -> None:
    survey = fastcal.read_dataset(data_dir / "realistic_survey.csv")
    exported = fastcal.read_dataset(
        data_dir / "fast_export.csv", columns=data_dir / "fast_export.columns.yaml"
    )
    assert len(exported) == len(survey)
    np.testing.assert_array_equal(exported.position_m, survey.position_m)
    np.testing.assert_array_equal(exported.tension_kN, survey.tension_kN)
    np.testing.assert_array_equal(exported.planned_rpy_deg, survey.planned_rpy_deg)
    np.testing.assert_array_equal(exported.time_s - START, survey.time_s)
    assert exported.time_offset_s == 8 * 3600
    # The map as a dict: the same.
    as_dict = fastcal.read_dataset(data_dir / "fast_export.csv", columns=FAST_MAP)
    np.testing.assert_array_equal(as_dict.tension_kN, survey.tension_kN)


def test_map_errors_name_the_key_and_line(tmp_path: pathlib.Path, data_dir: pathlib.Path) -> None:
    bad = tmp_path / "map.yaml"
    bad.write_text(
        "format: fastcal-columns-1\ntime: SysTime\ncolumns:\n  x_m: {column: X, unit: inch}\n"
    )
    with pytest.raises(fastcal.InputError, match=r"map.yaml:4: columns.x_m.unit: unknown unit 'inch'"):
        fastcal.read_dataset(data_dir / "fast_export.csv", columns=bad)
    # A dict has no lines: the key path alone.
    broken = dict(FAST_MAP, columns={**FAST_MAP["columns"], "y_m": {"column": "SDP_PhaPos_X"}})
    with pytest.raises(fastcal.InputError) as error:
        fastcal.read_dataset(data_dir / "fast_export.csv", columns=broken)
    assert str(error.value).startswith("columns (dict): columns.y_m.column: source column ")
    with pytest.raises(FileNotFoundError):
        fastcal.read_dataset(data_dir / "fast_export.csv", columns=tmp_path / "missing.yaml")


def test_value_errors_name_the_source_column_and_the_fastcal_name(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "export.csv"
    path.write_text(
        "t;X;Y;Z;R;P;W;F1;F2;F3;F4;F5;F6\n0;1000;0;150000;0;0;0;2e5;2e5;abc;2e5;2e5;2e5\n"
    )
    columns = {
        "format": "fastcal-columns-1",
        "time": "t",
        "columns": {
            "x_m": {"column": "X", "unit": "mm"},
            "y_m": {"column": "Y", "unit": "mm"},
            "z_m": {"column": "Z", "unit": "mm"},
            "roll_deg": "R",
            "pitch_deg": "P",
            "yaw_deg": "W",
            **{f"T{i}_kN": {"column": f"F{i}", "unit": "N"} for i in range(1, 7)},
        },
    }
    with pytest.raises(fastcal.InputError, match=r"export.csv:2: column 'F3' \(T3_kN, N\): 'abc'"):
        fastcal.read_dataset(path, columns=columns)


def _survey_arrays(data_dir: pathlib.Path) -> fastcal.Dataset:
    return fastcal.read_dataset(data_dir / "realistic_survey.csv")


def test_from_arrays_checks_as_the_reader_does(data_dir: pathlib.Path) -> None:
    survey = _survey_arrays(data_dir)
    data = fastcal.Dataset.from_arrays(
        survey.time_s, survey.position_m, survey.tension_kN, rpy_deg=survey.rpy_deg,
        planned_rpy_deg=survey.planned_rpy_deg, s0_m=survey.s0_m,
    )
    assert len(data) == len(survey)
    # Tensions are held in N: kN to N and back, to the last bit or one ulp.
    np.testing.assert_allclose(data.tension_kN, survey.tension_kN, rtol=3e-16, atol=0)
    np.testing.assert_array_equal(data.position_m, survey.position_m)
    np.testing.assert_array_equal(data.rpy_deg, survey.rpy_deg)
    assert data.line[0] == 1  # rows, from 1
    tension = survey.tension_kN.copy()
    tension[2, 1] = -5.0
    with pytest.raises(fastcal.InputError, match=r"^arrays, row 3: column 'T2_kN': -5 kN is negative"):
        fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, tension, rpy_deg=survey.rpy_deg)
    position = survey.position_m.copy()
    position[4, 2] = np.nan
    with pytest.raises(fastcal.InputError, match=r"row 5: column 'z_m': value is not finite"):
        fastcal.Dataset.from_arrays(survey.time_s, position, survey.tension_kN, rpy_deg=survey.rpy_deg)
    with pytest.raises(fastcal.InputError, match="rpy_deg or quat"):
        fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, survey.tension_kN)
    with pytest.raises(fastcal.InputError, match=r"tension_kN must have shape \(1441, 6\)"):
        fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, survey.tension_kN[:, :5],
                                    rpy_deg=survey.rpy_deg)
    # Radians under degrees, as the file reader refuses them.
    with pytest.raises(fastcal.InputError, match="look like radians"):
        fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, survey.tension_kN,
                                    rpy_deg=np.radians(survey.rpy_deg),
                                    planned_rpy_deg=np.radians(survey.planned_rpy_deg))
    skipped = fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, tension,
                                          rpy_deg=survey.rpy_deg, skip_invalid_rows=True)
    assert len(skipped) == len(survey) - 1
    assert skipped.skipped[0].startswith("arrays, row 3: ")
    sessions = ["a" if k < 700 else "b" for k in range(len(survey))]
    labelled = fastcal.Dataset.from_arrays(survey.time_s, survey.position_m, survey.tension_kN,
                                           quat=survey.quat, session=sessions)
    assert labelled.session_labels == ["a", "b"]


def test_from_dataframe(data_dir: pathlib.Path) -> None:
    pd = pytest.importorskip("pandas", reason="python3-pandas is not installed")
    survey = _survey_arrays(data_dir)
    frame = pd.DataFrame({"time_s": survey.time_s})
    for k, name in enumerate(("x_m", "y_m", "z_m")):
        frame[name] = survey.position_m[:, k]
    for k, name in enumerate(("roll_deg", "pitch_deg", "yaw_deg")):
        frame[name] = survey.rpy_deg[:, k]
    for i in range(6):
        frame[f"T{i + 1}_kN"] = survey.tension_kN[:, i]
    data = fastcal.Dataset.from_dataframe(frame)
    np.testing.assert_allclose(data.tension_kN, survey.tension_kN, rtol=3e-16, atol=0)
    np.testing.assert_array_equal(data.time_s, survey.time_s)
    # The export's names, a datetime column and newtons, through a map.
    export = pd.DataFrame(
        {
            "SysTime": pd.Timestamp("2024-05-01 20:00:00") + pd.to_timedelta(survey.time_s, unit="s"),
            "SDP_PhaPos_X": survey.position_m[:, 0] * 1e3,
            "SDP_PhaPos_Y": survey.position_m[:, 1] * 1e3,
            "SDP_PhaPos_Z": survey.position_m[:, 2] * 1e3,
            "SDP_SwtDPose_Y": survey.rpy_deg[:, 2],
            "SDP_SwtDPose_P": survey.rpy_deg[:, 1],
            "SDP_SwtDPose_R": survey.rpy_deg[:, 0],
            "WindSpeed": 2.0,
        }
    )
    for i in range(6):
        export[f"CableForce{i + 1}"] = survey.tension_kN[:, i] * 1e3
    mapped = fastcal.Dataset.from_dataframe(export, columns=FAST_MAP)
    np.testing.assert_allclose(mapped.position_m, survey.position_m, rtol=1e-15, atol=1e-12)
    np.testing.assert_allclose(mapped.tension_kN, survey.tension_kN, rtol=1e-15)
    np.testing.assert_array_equal(mapped.time_s, START + survey.time_s)
    # A map whose time is a text pattern (for the CSV export) reads the datetime column too.
    patterned = dict(FAST_MAP)
    patterned["time"] = {"column": "SysTime", "format": "%Y/%m/%d %H:%M:%S", "zone": "+08:00"}
    np.testing.assert_array_equal(
        fastcal.Dataset.from_dataframe(export, columns=patterned).time_s, START + survey.time_s)
    # Indexed by time: the index is the time column (a DataFrame's usual shape).
    indexed = export.set_index("SysTime")
    np.testing.assert_array_equal(
        fastcal.Dataset.from_dataframe(indexed, columns=FAST_MAP).time_s, START + survey.time_s)
    canonical = frame.copy()
    canonical.index = pd.to_datetime(START + survey.time_s, unit="s", utc=True)
    canonical = canonical.drop(columns="time_s")
    np.testing.assert_array_equal(
        fastcal.Dataset.from_dataframe(canonical).time_s, START + survey.time_s)
    with pytest.raises(fastcal.InputError, match="without a zone"):
        fastcal.Dataset.from_dataframe(canonical.tz_localize(None))
    export.loc[7, "CableForce2"] = -3.0
    with pytest.raises(fastcal.InputError, match=r"^DataFrame, row 8: column 'CableForce2' \(T2_kN, N\)"):
        fastcal.Dataset.from_dataframe(export, columns=FAST_MAP)


def _write_workbook(path: pathlib.Path, survey: fastcal.Dataset, rows: int) -> None:
    openpyxl = pytest.importorskip("openpyxl", reason="python3-openpyxl is not installed")
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "Telemetry"
    sheet.append(["FAST feed cabin telemetry, export of 2024-05-01"])
    sheet.append(["SysTime", "SDP_PhaPos_X", "SDP_PhaPos_Y", "SDP_PhaPos_Z", "SDP_SwtDPose_Y",
                  "SDP_SwtDPose_P", "SDP_SwtDPose_R"] + [f"CableForce{i}" for i in range(1, 7)]
                 + ["WindSpeed"])
    sheet.append(["(Beijing time)", "mm", "mm", "mm", "deg", "deg", "deg"] + ["N"] * 6 + ["m/s"])
    start = datetime.datetime(2024, 5, 1, 20, 0, 0)
    for k in range(rows):
        sheet.append(
            [start + datetime.timedelta(seconds=float(survey.time_s[k]))]
            + [float(v) * 1e3 for v in survey.position_m[k]]
            + [float(survey.rpy_deg[k, 2]), float(survey.rpy_deg[k, 1]), float(survey.rpy_deg[k, 0])]
            + [float(v) * 1e3 for v in survey.tension_kN[k]]
            + [2.5]
        )
    book.save(path)


def test_reads_an_xlsx_workbook_through_a_map(tmp_path: pathlib.Path, data_dir: pathlib.Path) -> None:
    survey = _survey_arrays(data_dir)
    path = tmp_path / "export.xlsx"
    _write_workbook(path, survey, 40)
    columns = dict(FAST_MAP)
    del columns["delimiter"]
    columns["decimal"] = "."
    data = fastcal.read_dataset(path, columns=columns)
    assert len(data) == 40
    assert data.line[0] == 4  # the sheet's row
    np.testing.assert_allclose(data.position_m, survey.position_m[:40], rtol=1e-15, atol=1e-12)
    np.testing.assert_allclose(data.tension_kN, survey.tension_kN[:40], rtol=1e-15)
    np.testing.assert_array_equal(data.time_s, START + survey.time_s[:40])
    same = fastcal.read_dataset(path, columns=columns, sheet="Telemetry")
    np.testing.assert_array_equal(same.time_s, data.time_s)
    # The map of the CSV export (a text pattern for SysTime) reads the workbook's date cells
    # as the instants they are: one map serves both files (issue 39).
    patterned = dict(columns)
    patterned["time"] = {"column": "SysTime", "format": "%Y/%m/%d %H:%M:%S", "zone": "+08:00"}
    from_pattern = fastcal.read_dataset(path, columns=patterned)
    np.testing.assert_array_equal(from_pattern.time_s, data.time_s)
    with pytest.raises(fastcal.InputError, match=r"no sheet 'Other' \(sheets: Telemetry\)"):
        fastcal.read_dataset(path, columns=columns, sheet="Other")
    # A bad cell: the sheet's row and the source column.
    import openpyxl

    book = openpyxl.load_workbook(path)
    book.active["H10"] = "n/a"
    book.save(path)
    with pytest.raises(fastcal.InputError,
                       match=r"export.xlsx\[Telemetry\]:10: column 'CableForce1' \(T1_kN, N\): 'n/a'"):
        fastcal.read_dataset(path, columns=columns)


def test_an_xlsx_without_openpyxl_names_the_package(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "export.xlsx"
    path.write_bytes(b"PK\x03\x04")
    monkeypatch.setitem(sys.modules, "openpyxl", None)  # import openpyxl now fails
    with pytest.raises(ImportError, match="apt-get install python3-openpyxl"):
        fastcal.read_dataset(path, columns=FAST_MAP)


def test_the_cli_refuses_an_xlsx_naming_the_python_route(
    tmp_path: pathlib.Path, cli: Optional[str]
) -> None:
    if cli is None:
        pytest.skip("the fastcal executable was not built")
    path = tmp_path / "export.xlsx"
    path.write_bytes(b"PK\x03\x04 a workbook")
    run = subprocess.run([cli, "evaluate", f"--data={path}"], capture_output=True, text=True,
                         check=False)
    assert run.returncode == 2
    assert "fastcal.read_dataset(" in run.stderr
    assert "xlsx2csv" in run.stderr


def test_the_bundled_export_is_what_its_script_writes(source_dir: pathlib.Path) -> None:
    run = subprocess.run(
        [sys.executable, str(source_dir / "scripts" / "make_fast_export.py"), "--check"],
        capture_output=True, text=True, check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr


def test_an_xlsx_with_a_stale_dimension_reads_every_row_and_a_bomb_is_refused(
    tmp_path: pathlib.Path, data_dir: pathlib.Path
) -> None:
    # Issue 37: a workbook whose <dimension> says A1:N53 while it holds 203 rows lost 150
    # of them silently; a zip bomb took 84 s and 1.9 GB before it was refused.
    import re
    import zipfile

    survey = _survey_arrays(data_dir)
    path = tmp_path / "export.xlsx"
    _write_workbook(path, survey, 200)
    stale = tmp_path / "stale.xlsx"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(stale, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename.startswith("xl/worksheets/sheet"):
                data = re.sub(rb'<dimension ref="[^"]*"/>', b'<dimension ref="A1:N53"/>', data)
            dst.writestr(item, data)
    columns = dict(FAST_MAP)
    del columns["delimiter"]
    columns["decimal"] = "."
    assert len(fastcal.read_dataset(stale, columns=columns)) == 200
    bomb = tmp_path / "bomb.xlsx"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("xl/worksheets/sheet1.xml", b"\0" * (64 << 20))
    with pytest.raises(fastcal.InputError, match="inflates .* times"):
        fastcal.read_dataset(bomb, columns=columns)
    # A bomb within the ratio: 2^20 + 1 empty rows after the data, with random text that
    # keeps the compression under 200x (a review's took 8 GB and minutes): refused by the
    # sheet's row count, read as it goes.
    import base64
    import random

    filler = base64.b64encode(random.Random(37).randbytes(96 << 10))
    rows_bomb = tmp_path / "rows_bomb.xlsx"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(rows_bomb, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename.startswith("xl/worksheets/sheet"):
                data = data.replace(b"</sheetData>",
                                    b"<row/>" * ((1 << 20) + 1) + b"</sheetData><!-- " + filler
                                    + b" -->")
            dst.writestr(item, data)
    with pytest.raises(fastcal.InputError, match="more than 1048576 rows"):
        fastcal.read_dataset(rows_bomb, columns=columns)
    # One cell of 2 MiB of text, within every ratio (a review's of 0.9 GB took 25 s and
    # 6.2 GB): refused by the prescan before openpyxl builds it.
    text_bomb = tmp_path / "text_bomb.xlsx"
    cell = base64.b64encode(random.Random(38).randbytes(3 << 19))  # 2 MiB of text
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(text_bomb, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename.startswith("xl/worksheets/sheet"):
                data = data.replace(b"</sheetData>",
                                    b'<row r="300"><c r="A300" t="inlineStr"><is><t>' + cell
                                    + b"</t></is></c></row></sheetData>")
            dst.writestr(item, data)
    with pytest.raises(fastcal.InputError, match="holds a text of more than 65536 bytes"):
        fastcal.read_dataset(text_bomb, columns=columns)
    # A second re-check's variants: the text broken by a '>' every 16 KiB (legal in XML
    # text: 6.5 GB before), and rows with a namespace prefix (<x:row>: not counted, 89 s).
    gt_bomb = tmp_path / "gt_bomb.xlsx"
    broken = b">".join(cell[k:k + (16 << 10)] for k in range(0, len(cell), 16 << 10))
    prefixed = tmp_path / "prefixed.xlsx"
    with zipfile.ZipFile(path) as src, \
            zipfile.ZipFile(gt_bomb, "w", zipfile.ZIP_DEFLATED) as gt, \
            zipfile.ZipFile(prefixed, "w", zipfile.ZIP_DEFLATED) as px:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename.startswith("xl/worksheets/sheet"):
                gt.writestr(item.filename, data.replace(
                    b"</sheetData>", b'<row r="300"><c r="A300" t="inlineStr"><is><t>' + broken
                    + b"</t></is></c></row></sheetData>"))
                px.writestr(item.filename, data.replace(
                    b"</sheetData>", b"<x:row/>" * ((1 << 20) + 1) + b"</sheetData><!-- "
                    + filler[:60000] + b" -->"))
            else:
                gt.writestr(item.filename, data)
                px.writestr(item.filename, data)
    with pytest.raises(fastcal.InputError, match="holds a text of more than 65536 bytes"):
        fastcal.read_dataset(gt_bomb, columns=columns)
    with pytest.raises(fastcal.InputError, match="more than 1048576 rows"):
        fastcal.read_dataset(prefixed, columns=columns)
    # A member whose bytes do not match its CRC: a damaged workbook, not a raw BadZipFile.
    damaged = tmp_path / "damaged.xlsx"
    with zipfile.ZipFile(damaged, "w", zipfile.ZIP_STORED) as z:
        z.writestr("xl/worksheets/sheet1.xml", b"<sheetData>" + b"<row/>" * 10 + b"</sheetData>")
    raw = damaged.read_bytes()
    at = raw.index(b"<row/>")
    damaged.write_bytes(raw[:at] + b"<rox/>" + raw[at + 6:])
    with pytest.raises(fastcal.InputError, match="a damaged .xlsx workbook"):
        fastcal.read_dataset(damaged, columns=columns)
