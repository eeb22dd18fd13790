"""fastcal.loop: the cabin in its control loop, as `fastcal loop` runs it, on DataFrames
(docs/model.md, "The closed loop"): a controller's mass centre 5 cm off leaves the cabin
off by what the statics say where the feed-forward alone holds it, the PID takes it away,
bad options are named."""
import pytest

import fastcal

SEGMENTS = 12  # coarse chains: quick, and the comparison takes their offset out


def _shifted(dx):
    model = fastcal.Model.nominal()
    centre = model.mass_centre_m.copy()
    centre[0] += dx
    model.mass_centre_m = centre
    return model


def test_a_mass_centre_off_is_the_cabins_error_until_the_pid_takes_it() -> None:
    p = fastcal.focal_grid(max_off_axis_deg=20, off_axis_step_deg=20, azimuth_step_deg=360)[-1]
    q = fastcal.focal_attitude(p)
    right = fastcal.loop(p, quat=q, hold_s=5, segments=SEGMENTS, pid=(0, 0, 0))
    off = fastcal.loop(p, quat=q, controller=_shifted(0.05), hold_s=5, segments=SEGMENTS,
                       pid=(0, 0, 0))
    assert list(off.columns[:4]) == ["time_s", "x_m", "y_m", "z_m"]
    assert len(off) == 51  # 5 s at 10 Hz, both ends
    # The statics' answer: the truth hangs at the controller's lengths.
    s0 = fastcal.solve(p, quat=q, model=_shifted(0.05)).s0_m
    located = fastcal.locate(s0).position_m - p
    chains = right[["x_m", "y_m", "z_m"]].to_numpy()[-1] - p
    loop = off[["x_m", "y_m", "z_m"]].to_numpy()[-1] - p - chains
    assert abs(loop - located).max() < 3e-4, (loop, located)
    assert off.attrs["summary"]["error_rms_mm"] > 8.0
    settled = fastcal.loop(p, quat=q, controller=_shifted(0.05), hold_s=150, segments=SEGMENTS,
                           summary_from_s=100)
    assert settled.attrs["summary"]["error_rms_mm"] < 1.0


def test_bad_options_are_named() -> None:
    with pytest.raises(fastcal.InputError, match="control_period_s"):
        fastcal.loop((0, 0, 140), control_period_s=0, hold_s=1, segments=SEGMENTS)
    with pytest.raises(fastcal.InputError, match="pid"):
        fastcal.loop((0, 0, 140), pid=(1, 2), hold_s=1, segments=SEGMENTS)
    with pytest.raises(fastcal.InputError, match="kp"):
        fastcal.loop((0, 0, 140), pid=(-1, 0, 0), hold_s=1, segments=SEGMENTS)
    with pytest.raises(fastcal.InputError, match="frequency_ghz"):
        fastcal.loop((0, 0, 140), frequency_ghz=0, hold_s=1, segments=SEGMENTS)
