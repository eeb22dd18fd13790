#!/usr/bin/env python3
"""Writes calibration_data/fast_export.csv: calibration_data/realistic_survey.csv as a
telescope's database would export it (docs/data-format.md, "A FAST export"), to be read
through calibration_data/fast_export.columns.yaml.

What it changes, and nothing else: a title line above the names and a unit row below
them; ';' between fields and decimal commas; FAST's channel names (SDP_* measured, TRP_*
planned); the time as a Beijing-time date and time without a zone (SysTime, UTC+8) from
2024-05-01 20:00:00; positions and commanded cable lengths in mm and tensions in N (the
decimal digits moved, not recomputed: reading through the map gives back the same
numbers); and two channels fastcal does not need (wind speed, air temperature).

    python3 scripts/make_fast_export.py            # rewrites the bundled file
    python3 scripts/make_fast_export.py --check    # exit 1 if it differs

With --feed it writes calibration_data/fast_feed_export.csv the same way from
calibration_data/fast_feed_survey.csv (a survey simulated with calibration_data/fast_feed.yaml:
the data's poses are the feed's phase centre and the Stewart platform's attitude), with the
rotator's angles and the platform's shifts as channels of their own (ABRot_A, ABRot_B in
deg, SwtD_Shift_X/Y/Z in mm; the example's names), read through
calibration_data/fast_feed_export.columns.yaml with the model fast_feed.yaml. The survey:

    build/bin/fastcal simulate --truth=calibration_data/fast_feed.yaml --trajectory=random \
        --max-off-axis-deg=40 --samples=360 --seed=58 --joint-law=focal \
        --prismatic-spread-m=0.05 --interval-s=8 --mass-centre=0.22,0.11,0.5 \
        --tension-noise-percent=3 --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=1.5 \
        --out=calibration_data/fast_feed_survey.csv
"""
import datetime
import decimal
import math
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
FEED = "--feed" in sys.argv[1:]
SOURCE = ROOT / "calibration_data" / ("fast_feed_survey.csv" if FEED else "realistic_survey.csv")
TARGET = ROOT / "calibration_data" / ("fast_feed_export.csv" if FEED else "fast_export.csv")
# Beijing time (UTC+8), as SysTime holds it.
START = datetime.datetime(2024, 5, 2 if FEED else 1, 20, 0, 0)
# The rotator's and platform's channels (--feed): fastcal's joint column, the export's
# name, its unit, and the decimal digits moved (mm: 3).
JOINTS = [("rotator_a_deg", "ABRot_A", "deg", 0), ("rotator_b_deg", "ABRot_B", "deg", 0),
          ("stewart_x_m", "SwtD_Shift_X", "mm", 3), ("stewart_y_m", "SwtD_Shift_Y", "mm", 3),
          ("stewart_z_m", "SwtD_Shift_Z", "mm", 3)]


def shifted(text: str, digits: int) -> str:
    """The decimal `text` times 10^digits, exactly, with a decimal comma."""
    value = decimal.Decimal(text).scaleb(digits)
    out = format(value, "f")
    if "." in out:
        out = out.rstrip("0").rstrip(".")
    if out in ("-0", ""):
        out = "0"
    return out.replace(".", ",")


def comma(text: str) -> str:
    return shifted(text, 0)


def main() -> int:
    lines = [l for l in SOURCE.read_text().splitlines() if l and not l.startswith("#")]
    names = lines[0].split(",")
    column = {n: k for k, n in enumerate(names)}
    header = (
        ["SysTime", "SDP_PhaPos_X", "SDP_PhaPos_Y", "SDP_PhaPos_Z", "SDP_SwtDPose_Y",
         "SDP_SwtDPose_P", "SDP_SwtDPose_R", "TRP_SwtDPose_Y", "TRP_SwtDPose_P",
         "TRP_SwtDPose_R"]
        + [f"CableForce{i}" for i in range(1, 7)]
        + [f"TRP_CableLen{i}" for i in range(1, 7)]
        + ([name for _, name, _, _ in JOINTS] if FEED else [])
        + ["WindSpeed", "AirTemp"]
    )
    units = ["(Beijing time)", "mm", "mm", "mm", "deg", "deg", "deg", "deg", "deg", "deg"]
    units += ["N"] * 6 + ["mm"] * 6 + ([unit for _, _, unit, _ in JOINTS] if FEED else [])
    units += ["m/s", "degC"]
    title = ("FAST feed cabin telemetry;export of 2024-05-02;survey 2024-05-02 20:00 to 20:48"
             if FEED else
             "FAST feed cabin telemetry;export of 2024-05-01;survey 2024-05-01 20:00 to 20:48")
    out = [
        title,
        ";".join(header),
        ";".join(units),
    ]
    for line in lines[1:]:
        f = line.split(",")
        t = float(f[column["time_s"]])
        stamp = START + datetime.timedelta(seconds=t)
        row = [stamp.strftime("%Y-%m-%d %H:%M:%S.") + f"{stamp.microsecond // 1000:03d}"]
        row += [shifted(f[column[n]], 3) for n in ("x_m", "y_m", "z_m")]
        row += [comma(f[column[n]]) for n in ("yaw_deg", "pitch_deg", "roll_deg")]
        row += [comma(f[column[n]])
                for n in ("planned_yaw_deg", "planned_pitch_deg", "planned_roll_deg")]
        row += [shifted(f[column[f"T{i}_kN"]], 3) for i in range(1, 7)]
        row += [shifted(f[column[f"s0_{i}_m"]], 3) for i in range(1, 7)]
        if FEED:
            row += [shifted(f[column[name]], digits) for name, _, _, digits in JOINTS]
        row += [f"{2.0 + 0.8 * math.sin(t / 317.0):.2f}".replace(".", ","),
                f"{18.5 - 0.6 * t / 2880.0:.1f}".replace(".", ",")]
        out.append(";".join(row))
    text = "\r\n".join(out) + "\r\n"  # a Windows export
    if "--check" in sys.argv[1:]:
        same = TARGET.exists() and TARGET.read_bytes() == text.encode()
        print(f"{TARGET}: {'up to date' if same else 'differs from what this script writes'}")
        return 0 if same else 1
    TARGET.write_bytes(text.encode())
    print(f"wrote {TARGET} ({len(out) - 3} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
