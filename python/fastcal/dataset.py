"""Datasets: read (CSV, column maps, spreadsheets, DataFrames) and simulate telemetry."""

from __future__ import annotations

import difflib
import json
import os
import re
import warnings
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _fastcal
from ._fastcal import Dataset, InputError, Model

from ._common import ArrayLike, PathLike, _INT32_MAX, _UINT64_MAX, _attitude, _call_with_names, _number, _rows, _whole
from .statics import ColumnsLike, _DICT_COLUMNS, _SPREADSHEET_SUFFIXES


def _columns_argument(columns: Optional[ColumnsLike]) -> Tuple[str, str]:
    """A column map as (YAML text, name for messages): a file's text, or a dict as JSON
    (which is YAML); ("", "") for none."""
    if columns is None:
        return "", ""
    if isinstance(columns, Mapping):
        return json.dumps(columns, indent=1), _DICT_COLUMNS
    path = os.fspath(columns)
    with open(path, encoding="utf-8") as f:  # FileNotFoundError as open() gives it
        return f.read(), path


def _map_errors(call: Any) -> Any:
    """Runs call(); a dict column map's messages name its key path (a dict has no lines)."""
    try:
        return call()
    except InputError as error:
        message = re.sub(rf"{re.escape(_DICT_COLUMNS)}:\d+: ", f"{_DICT_COLUMNS}: ", str(error))
        raise InputError(message) from None


def _cell_text(value: Any, decimal: str) -> str:
    """A spreadsheet cell as the text a CSV export would hold."""
    import datetime

    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        text = repr(value)
        return text.replace(".", ",") if decimal == "," else text
    if isinstance(value, datetime.datetime):
        return value.isoformat(sep=" ")
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    return str(value)


# An .xlsx inflates to at most this many bytes before it is read (a workbook of 10^6 rows
# is ~0.3 GB of XML), and no member more than this many times its compressed size (a zip
# bomb: 31 MB took 84 s and 1.9 GB before, issue 37).
_MAX_WORKBOOK_BYTES = 1 << 30
_MAX_WORKBOOK_RATIO = 200
# Excel's and LibreOffice's largest sheet (2^20 rows).
_MAX_SHEET_ROWS = 1 << 20


def _check_workbook_size(path: str) -> None:
    """Refuses a workbook whose members would inflate beyond the limits, from the zip's
    own directory (nothing decompressed)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            members = archive.infolist()
    except zipfile.BadZipFile as error:
        raise InputError(f"{path}: not an .xlsx workbook (a zip): {error}") from None
    total = sum(m.file_size for m in members)
    if total > _MAX_WORKBOOK_BYTES:
        raise InputError(f"{path}: the workbook inflates to {total} bytes, beyond the "
                         f"{_MAX_WORKBOOK_BYTES >> 20} MiB read from a spreadsheet: export "
                         "the sheet as CSV (streamed, no limit)")
    for m in members:
        if m.compress_size > 0 and m.file_size / m.compress_size > _MAX_WORKBOOK_RATIO:
            raise InputError(f"{path}: its member {m.filename} inflates {m.file_size // m.compress_size}"
                             f" times (beyond {_MAX_WORKBOOK_RATIO}): not a sheet of telemetry")


# No cell holds more text than this (a telemetry value is a number or a time stamp, a
# header a name): one cell of 0.9 GB, within the workbook's limits, took 25 s and 6.2 GB,
# a thousand of 900 KB 2.75 GB (issue 37).
_MAX_CELL_BYTES = 1 << 16
# A sheet's row element, with or without a namespace prefix (<row ...>, <x:row ...>).
_ROW_TAG = re.compile(rb"<(?:[A-Za-z_][\w.-]*:)?row[\s/>]")


def _prescan_workbook(path: str) -> None:
    """Streams the sheets' and shared strings' XML once, a MiB at a time, before openpyxl
    builds anything: refuses a run of more than _MAX_CELL_BYTES without a '<' (text may
    hold '>', never an unescaped '<': no cell's text is longer) and a sheet of more rows
    than a spreadsheet program writes (3.3 million took openpyxl 118 s to reach the
    limit, issue 37). The runs are measured with numpy."""
    import zipfile
    import zlib

    def refuse_text(name: str) -> None:
        raise InputError(f"{path}: {name} holds a text of more than {_MAX_CELL_BYTES} bytes "
                         "in one cell or tag: not a sheet of telemetry")

    try:
        _prescan_members(path, refuse_text)
    except (zipfile.BadZipFile, zlib.error, EOFError) as error:
        raise InputError(f"{path}: a damaged .xlsx workbook: {error}") from None


def _prescan_members(path: str, refuse_text) -> None:
    """_prescan_workbook's pass over the members."""
    import zipfile

    with zipfile.ZipFile(path) as archive:
        for member in archive.infolist():
            name = member.filename
            sheet = re.fullmatch(r"xl/worksheets/[^/]+\.xml", name) is not None
            if not sheet and name != "xl/sharedStrings.xml":
                continue
            rows = 0
            run = 0  # bytes since the last '<'
            tail = b""  # the chunk before's last bytes: a row tag cut in two counts once
            with archive.open(member) as stream:
                while True:
                    chunk = stream.read(1 << 20)
                    if not chunk:
                        break
                    if sheet:
                        rows += len(_ROW_TAG.findall(tail + chunk)) - len(_ROW_TAG.findall(tail))
                        tail = chunk[-64:]
                        if rows > _MAX_SHEET_ROWS:
                            raise InputError(
                                f"{path}: {name} has more than {_MAX_SHEET_ROWS} rows, more "
                                "than a spreadsheet program writes: not a sheet of telemetry "
                                "(export it as CSV)")
                    marks = np.flatnonzero(np.frombuffer(chunk, dtype=np.uint8) == 60)  # '<'
                    if marks.size == 0:
                        run += len(chunk)
                    else:
                        if run + int(marks[0]) > _MAX_CELL_BYTES:
                            refuse_text(name)
                        if marks.size > 1 and int(np.diff(marks).max()) - 1 > _MAX_CELL_BYTES:
                            refuse_text(name)
                        run = len(chunk) - int(marks[-1]) - 1
                    if run > _MAX_CELL_BYTES:
                        refuse_text(name)


def _spreadsheet_text(path: str, sheet: Optional[Union[str, int]], decimal: str) -> Tuple[str, str]:
    """The rows of a sheet of an .xlsx workbook as CSV text, one line per sheet row (so
    messages name the sheet's row numbers), and the source name for messages."""
    import csv
    import io

    try:
        import openpyxl
    except ImportError:
        raise ImportError(
            f"{path}: reading an .xlsx workbook needs openpyxl, which is not installed: "
            "apt-get install python3-openpyxl (Debian), or convert the sheet to CSV with "
            f"xlsx2csv {path} export.csv (Debian package xlsx2csv) and read that"
        ) from None
    if not os.path.exists(path):
        raise FileNotFoundError(2, "No such file or directory", path)
    _check_workbook_size(path)
    _prescan_workbook(path)
    book = openpyxl.load_workbook(path, read_only=True, data_only=True)
    try:
        if sheet is None:
            ws = book.worksheets[0]
        elif isinstance(sheet, int):
            if not 0 <= sheet < len(book.worksheets):
                raise InputError(
                    f"{path}: no sheet {sheet} (the workbook has {len(book.worksheets)}: "
                    f"{', '.join(book.sheetnames)})"
                )
            ws = book.worksheets[sheet]
        else:
            if sheet not in book.sheetnames:
                raise InputError(
                    f"{path}: no sheet {sheet!r} (sheets: {', '.join(book.sheetnames)})"
                )
            ws = book[sheet]
        # The sheet's declared <dimension> may be stale (50 of 200 rows read, issue 37):
        # read every row there is.
        if hasattr(ws, "reset_dimensions"):
            ws.reset_dimensions()
        # Blank rows kept as None (a run of them costs nothing), and no more rows than a
        # spreadsheet program can write: a workbook of millions of empty <row/>s (a bomb
        # within the ratio: 8 GB and minutes before, issue 37) is refused as it is read.
        rows = []
        for count, r in enumerate(ws.iter_rows(values_only=True), start=1):
            if count > _MAX_SHEET_ROWS:
                raise InputError(
                    f"{path}[{ws.title}]: more than {_MAX_SHEET_ROWS} rows, more than a "
                    "spreadsheet program writes: not a sheet of telemetry (export it as CSV)")
            rows.append(None if all(v is None for v in r) else list(r))
        name = ws.title
    finally:
        book.close()
    width = 0
    for r in rows:
        for k in range(len(r or ()) - 1, -1, -1):
            if r[k] is not None:
                width = max(width, k + 1)
                break
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    for r in rows:
        if r is None:
            out.write("\n")  # a blank row stays a (blank) line: row numbers hold
            continue
        cells = [_cell_text(v, decimal) for v in r[:width]]
        cells += [""] * (width - len(cells))
        writer.writerow(cells)
    return out.getvalue(), f"{path}[{name}]"


def read_dataset(
    path: Union[PathLike, Sequence[PathLike]],
    skip_invalid_rows: bool = False,
    columns: Optional[ColumnsLike] = None,
    sheet: Optional[Union[str, int]] = None,
    model: Optional[Model] = None,
) -> Dataset:
    """Reads telemetry (docs/data-format.md): a canonical CSV, an export through a
    column map, or a sheet of an .xlsx workbook; or several files as one session each.

    Args:
        path: a file, or a list of files (merged, one session per file labelled by its
            name without directory and extension; a file with a `session` column keeps
            its labels; Dataset.session_labels and Dataset.session say which sample is
            whose).
        skip_invalid_rows: leave out a row with a bad value, listed in Dataset.skipped,
            instead of raising.
        columns: a column map (format fastcal-columns-1, docs/data-format.md, "Column
            maps"): its file, or the same content as a dict, e.g.
            {"format": "fastcal-columns-1", "time": {"column": "SysTime", "format":
            "iso8601", "zone": "+08:00"}, "columns": {"x_m": {"column": "X", "unit":
            "mm"}, ...}, "unmapped": "ignore"}. None: the canonical columns.
        sheet: for an .xlsx workbook (read with openpyxl, python3-openpyxl), the sheet's
            name or 0-based index; None: the first. Its rows are read as a CSV export's
            lines (row numbers in messages are the sheet's), with the map's header_line,
            skip_after_header, units and time stamps; date cells are read as dates and
            times in the map's zone.
        model: the model the data are for: with moving parts (Model.joint_columns) its
            joint columns are read (Dataset.joints) and a file lacking any is an error
            naming them. None: no joint columns.

    Raises InputError naming the file (the sheet), line (row) and column, e.g.
    "data.csv:12: column 'T3_kN': 'abc' is not a number" or, through a map,
    "export.csv:12: column 'CableForce3' (T3_kN, N): 'abc' is not a number"; the map's
    own errors name its key and line; ImportError for an .xlsx without openpyxl.
    """
    if isinstance(path, (str, bytes, os.PathLike)):
        paths = [os.fspath(path)]
    else:
        paths = [os.fspath(p) for p in path]
    map_text, map_source = _columns_argument(columns)
    joints = list(model.joint_columns) if model is not None else []
    for p in paths:
        if str(p).lower().endswith((".xls", ".ods")):
            raise InputError(
                f"{p}: an .xls or .ods workbook: save it as .xlsx (read here, with "
                "openpyxl) or export the sheet as CSV"
            )
    spreadsheets = [p for p in paths if str(p).lower().endswith(_SPREADSHEET_SUFFIXES)]
    if spreadsheets:
        if len(paths) > 1:
            raise InputError(
                "read_dataset: a workbook is read on its own; read each and merge as CSV "
                "(Dataset.save), or give CSV files"
            )
        decimal = "."
        if map_text:
            decimal = _map_errors(lambda: _fastcal.column_map_decimal(map_text, map_source))
        text, source = _spreadsheet_text(paths[0], sheet, decimal)
        return _map_errors(
            lambda: _fastcal.parse_dataset(
                text, source, skip_invalid_rows, map_text, map_source, False, joints
            )
        )
    if sheet is not None:
        raise InputError(f"read_dataset: sheet= is for an .xlsx workbook, not {paths[0]}")
    return _map_errors(
        lambda: _fastcal.read_dataset(paths, skip_invalid_rows, map_text, map_source, joints)
    )


def _dataset_from_arrays(
    time_s: ArrayLike,
    position_m: ArrayLike,
    tension_kN: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    planned_rpy_deg: Optional[ArrayLike] = None,
    s0_m: Optional[ArrayLike] = None,
    session: Optional[Sequence[str]] = None,
    skip_invalid_rows: bool = False,
    joints: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
) -> Dataset:
    """A Dataset from numpy arrays, checked as a file is read (docs/data-format.md).

    Args:
        time_s: (n,) seconds (any epoch, or Unix seconds: times >= 1e8 s are shown as
            dates and times, UTC).
        position_m: (n, 3) measured position; tension_kN: (n, 6) measured tensions.
        rpy_deg: (n, 3) measured roll, pitch, yaw (deg), or quat: (n, 4) w, x, y, z;
            one of the two.
        planned_rpy_deg: (n, 3), optional; s0_m: (n, 6) unstretched lengths, optional.
        session: n labels (letters, digits, '-', '_'), optional.
        skip_invalid_rows: leave bad rows out (Dataset.skipped) instead of raising.
        joints: (n, J) the moving parts' joint values (deg and m) in the order of
            model.joint_columns; needed, and only allowed, with a model that has them.

    The same checks as the file reader (finite values, plausible positions, angles and
    tensions, unit quaternions, attitudes in radians): a bad value raises InputError
    naming the row (1-based) and the column, "arrays, row 3: column 'T2_kN': -5 kN is
    negative: a tension reading is >= 0". Dataset.line is the 1-based row.
    """
    t = np.asarray(time_s, dtype=np.float64).reshape(-1)
    n = t.shape[0]
    parts: List[Tuple[List[str], np.ndarray]] = [(["time_s"], t.reshape(n, 1))]

    def add(names: List[str], value: Optional[ArrayLike], label: str) -> None:
        if value is None:
            return
        array = np.asarray(value, dtype=np.float64)
        if array.ndim == 1 and len(names) > 1 and array.shape[0] == len(names) and n != len(names):
            array = np.broadcast_to(array, (n, len(names)))
        if array.shape != (n, len(names)):
            raise InputError(
                f"from_arrays: {label} must have shape ({n}, {len(names)}), got {array.shape}"
            )
        parts.append((names, array))

    add(["x_m", "y_m", "z_m"], position_m, "position_m")
    if rpy_deg is not None and quat is not None:
        raise InputError("from_arrays: give rpy_deg or quat, not both")
    if rpy_deg is None and quat is None:
        raise InputError("from_arrays: the measured attitude is needed: rpy_deg or quat")
    add(["roll_deg", "pitch_deg", "yaw_deg"], rpy_deg, "rpy_deg")
    add(["qw", "qx", "qy", "qz"], quat, "quat")
    add(["planned_roll_deg", "planned_pitch_deg", "planned_yaw_deg"], planned_rpy_deg,
        "planned_rpy_deg")
    add([f"T{i}_kN" for i in range(1, 7)], tension_kN, "tension_kN")
    add([f"s0_{i}_m" for i in range(1, 7)], s0_m, "s0_m")
    joint_columns = list(model.joint_columns) if model is not None else []
    if joints is not None and not joint_columns:
        raise InputError(
            "from_arrays: joints= needs model= with moving parts (cabin.moving_parts)"
        )
    if joint_columns and joints is None:
        raise InputError(
            "from_arrays: the model's moving parts need joints= of shape "
            f"({n}, {len(joint_columns)}): {', '.join(joint_columns)}"
        )
    add(joint_columns, joints, "joints")
    names = [name for group, _ in parts for name in group]
    values = np.ascontiguousarray(np.hstack([a for _, a in parts]))
    labels = [] if session is None else [str(s) for s in session]
    text = _fastcal.canonical_text(names, values, labels)
    return _map_errors(
        lambda: _fastcal.parse_dataset(
            text, "arrays", skip_invalid_rows, "", "", True, joint_columns
        )
    )


def _frame_with_time_column(df: Any, mapped: bool) -> Any:
    """The DataFrame with a time index (a DatetimeIndex, or any named index) made a column
    (named as the index, an unnamed DatetimeIndex as time_s), and, without a map, a
    datetime time_s column as Unix seconds: zone-aware stamps only (a naive one's zone is
    the map's to state, docs/data-format.md)."""
    if not hasattr(df, "reset_index"):
        return df
    import pandas

    index = df.index
    is_time = pandas.api.types.is_datetime64_any_dtype(index)
    if index.name is not None or is_time:
        frame = df.reset_index()
        if index.name is None:
            frame = frame.rename(columns={"index": "time_s"})
    else:
        frame = df.reset_index(drop=True)
    if not mapped and "time_s" in frame.columns and \
            pandas.api.types.is_datetime64_any_dtype(frame["time_s"]):
        stamps = frame["time_s"]
        if stamps.dt.tz is None:
            raise InputError(
                "DataFrame: time_s holds dates and times without a zone: localise them "
                "(df.index.tz_localize('Asia/Shanghai')) or read through a column map with "
                "time: {column: time_s, format: iso8601, zone: \"+08:00\"}")
        frame = frame.copy()
        frame["time_s"] = (stamps - pandas.Timestamp(0, tz="UTC")).dt.total_seconds()
    return frame


def _dataset_from_dataframe(
    df: Any,
    columns: Optional[ColumnsLike] = None,
    skip_invalid_rows: bool = False,
    model: Optional[Model] = None,
) -> Dataset:
    """A Dataset from a pandas DataFrame, checked as a file is read.

    Without `columns` the DataFrame's columns are fastcal's (time_s, x_m, ..., T6_kN,
    optionally session, docs/data-format.md); with a column map (a file or a dict,
    read_dataset) they are the export's, named and converted by the map (its
    header_line, skip_after_header and decimal do not apply: a DataFrame has its names
    and its numbers). Datetime columns are read as dates and times (the map's zone when
    they have none). Messages name the row (1-based, in the DataFrame's order) and the
    column: "DataFrame, row 3: column 'CableForce2' (T2_kN, N): ...". With a model that
    has moving parts its joint columns are read too (by those names, or through the map).
    """
    map_text, map_source = _columns_argument(columns)
    joints = list(model.joint_columns) if model is not None else []
    frame = _frame_with_time_column(df, bool(map_text))
    try:
        text = frame.to_csv(index=False, lineterminator="\n")
    except TypeError:  # pandas before 1.5
        text = frame.to_csv(index=False, line_terminator="\n")
    return _map_errors(
        lambda: _fastcal.parse_dataset(
            text, "DataFrame", skip_invalid_rows, map_text, map_source, True, joints
        )
    )


def _dataset_to_dataframe(self: Dataset) -> Any:
    """The samples as a pandas DataFrame in fastcal's column names and units (the
    canonical CSV's: time_s, x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg, the planned
    attitude, T1_kN..T6_kN, s0_1_m..s0_6_m and the joint columns where the data have
    them, session with its label), one row per sample; `line` is the file's line. When
    the times are Unix seconds (all after 1973), the index is their UTC DatetimeIndex
    named `time`, so that events and plots line up in dates (issue 59); otherwise a
    plain RangeIndex."""
    import pandas

    columns: Dict[str, Any] = {"time_s": self.time_s}
    for k, name in enumerate(("x_m", "y_m", "z_m")):
        columns[name] = self.position_m[:, k]
    for k, name in enumerate(("roll_deg", "pitch_deg", "yaw_deg")):
        columns[name] = self.rpy_deg[:, k]
    if self.planned_rpy_deg is not None:
        for k, name in enumerate(("planned_roll_deg", "planned_pitch_deg", "planned_yaw_deg")):
            columns[name] = self.planned_rpy_deg[:, k]
    for i in range(6):
        columns[f"T{i + 1}_kN"] = self.tension_kN[:, i]
    if self.s0_m is not None:
        for i in range(6):
            columns[f"s0_{i + 1}_m"] = self.s0_m[:, i]
    if self.joints is not None:
        for j, name in enumerate(self.joint_columns):
            columns[name] = self.joints[:, j]
    if self.session_labels:
        columns["session"] = [self.session_labels[k] for k in self.session]
    columns["line"] = self.line
    frame = pandas.DataFrame(columns)
    if len(self.time_s) > 0 and np.all(np.asarray(self.time_s) >= _UNIX_TIMES_FROM_S):
        frame.index = pandas.DatetimeIndex(
            pandas.to_datetime(np.asarray(self.time_s), unit="s", utc=True), name="time"
        )
    return frame


# Times at or after this are read as Unix seconds (1973-03-03); before, as seconds from
# any start (a simulated survey's 0, 1, 2 ...).
_UNIX_TIMES_FROM_S = 1e8


Dataset.to_dataframe = _dataset_to_dataframe  # type: ignore[attr-defined]
Dataset.from_arrays = staticmethod(_dataset_from_arrays)  # type: ignore[attr-defined]
Dataset.from_dataframe = staticmethod(_dataset_from_dataframe)  # type: ignore[attr-defined]


# simulate()'s keywords: the command line's flags (--attitude-control-deg:
# attitude_control_deg), each with the SimulationOptions field it sets where the two differ.
_SIMULATE_OPTION_FIELDS = {
    "attitude_control_deg": "attitude_control_sigma_deg",
    "attitude_noise_deg": "attitude_measurement_sigma_deg",
    "position_noise_m": "position_measurement_sigma_m",
    "tension_noise_kN": "tension_noise_kn",
    "sensor_bias_spread_kN": "sensor_bias_spread_kn",
    "interval_s": "sample_interval_s",
}
_SIMULATE_OPTIONS = sorted(
    list(_SIMULATE_OPTION_FIELDS)
    + [
        "attitude_control_time_s",
        "density_mismatch_percent",
        "length_noise_m",
        "length_offset_spread_m",
        "mass_centre_drift_m",
        "mass_centre_drift_time_s",
        "mass_centre_steps",
        "method",
        "outlier_fraction",
        "outlier_scale_percent",
        "seed",
        "sensor_bias_steps",
        "sensor_gain_spread_percent",
        "session_gap_s",
        "sessions",
        "start_time_s",
        "tension_drift_percent",
        "tension_drift_time_s",
        "tension_noise_percent",
    ]
)


def _simulation_fields(options: Mapping[str, Any]) -> Dict[str, Any]:
    """simulate()'s keywords as the library's fields; a former name (the field's) with a
    DeprecationWarning, an unknown one refused with the closest names."""
    old_names = {field: keyword for keyword, field in _SIMULATE_OPTION_FIELDS.items()}
    fields: Dict[str, Any] = {}
    for name, value in options.items():
        if name in old_names:
            warnings.warn(
                f"simulate({name}=...) is deprecated: use {old_names[name]}= (the command "
                f"line's --{old_names[name].replace('_', '-')})",
                DeprecationWarning,
                stacklevel=3,
            )
            name = old_names[name]
        if name not in _SIMULATE_OPTIONS:
            close = difflib.get_close_matches(name, _SIMULATE_OPTIONS, n=3)
            guess = f"; did you mean {' or '.join(close)}?" if close else ""
            raise InputError(f"simulate: unknown option '{name}'{guess} (accepted: " +
                             ", ".join(_SIMULATE_OPTIONS) + ")")
        fields[_SIMULATE_OPTION_FIELDS.get(name, name)] = value
    return fields


def simulate(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
    **options: Any,
) -> Tuple[Dataset, Model, Dict[str, Any]]:
    """Synthetic telemetry from a known ("truth") model at planned poses.

    The planned poses are positions (n, 3) with an attitude as in solve(). Options are
    `fastcal simulate`'s flags (docs/cli.md), with underscores:
    tension_noise_percent (3), tension_noise_kN, outlier_fraction,
    outlier_scale_percent, attitude_control_deg, attitude_control_time_s,
    attitude_noise_deg, position_noise_m, tension_drift_percent, tension_drift_time_s,
    mass_centre_drift_m, mass_centre_drift_time_s, sensor_gain_spread_percent,
    sensor_bias_spread_kN, density_mismatch_percent, length_offset_spread_m and
    length_noise_m (the s0 columns: encoder offsets drawn once, written into the truth
    model, and reading noise), interval_s (1), seed (1),
    method ('exact'), sessions (1: the samples cut into that many consecutive sessions,
    labelled 1..N), mass_centre_steps ([(time_s, (dx, dy, dz)), ...]: the mass centre
    moves by the shift at that time and stays), start_time_s (0: the first sample's
    time, e.g. a Unix time), session_gap_s (0: time between sessions; 86400 - a day's
    span makes a session a day), sensor_bias_steps ([(time_s, cable 1..6, shift_kN),
    ...]: one sensor re-zeroed). The former names, SimulationOptions' fields
    (attitude_control_sigma_deg, tension_noise_kn, sample_interval_s, ...), still work
    with a DeprecationWarning.

    Returns:
        (dataset, truth_used, summary): the telemetry, the truth model after the drawn
        per-cable mismatches (the one the tensions come from), and what was added
        (noise RMS per cable in kN, outliers, ...).
    """
    positions, _ = _rows(position_m, 3, "position_m")
    kind, attitude = _attitude(positions.shape[0], rpy_deg, quat)
    truth = model if model is not None else Model.nominal()
    fields = _simulation_fields(options)
    if "seed" in fields:
        fields["seed"] = _whole(fields["seed"], "seed", 0, _UINT64_MAX)
    if "sessions" in fields:
        fields["sessions"] = _whole(fields["sessions"], "sessions", 1, _INT32_MAX)
    for key, value in fields.items():
        if key not in ("seed", "sessions", "method", "mass_centre_steps", "sensor_bias_steps"):
            fields[key] = _number(value, key)
    return _call_with_names(
        _SIMULATE_OPTION_FIELDS, _fastcal.simulate, truth, positions, kind, attitude, fields
    )
