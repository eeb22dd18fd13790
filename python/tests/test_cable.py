"""fastcal.Cable (cable.h): one cable's end point, inverse, tension, mass and lumped chain,
against the statics of the whole robot and its own round trips."""

from __future__ import annotations

import numpy as np
import pytest

import fastcal

GRAVITY = -9.8
# The exact statics close every cable's end to 1e-12 of its chord; checked to a micrometre.
END_M = 1e-6
RELATIVE = 1e-9  # the inverse's forces against the statics' (both converge to 1e-12)


def _cable_one_at_k1(model: fastcal.Model):
    """Cable 1 at the paper's K1 = (0, 0, 140): its lower-end forces (N) and s0."""
    r = fastcal.solve([0.0, 0.0, 140.0], model=model)
    force = r.force_kN[0] * 1e3
    return float(np.hypot(force[0], force[1])), float(force[2]), float(r.s0_m[0]), r


@pytest.mark.parametrize("built", [False, True])
def test_end_and_forces_agree_with_the_statics(built: bool) -> None:
    model = fastcal.Model.nominal()
    if built:
        model.attachments = [[{"at_m": 4.0, "mass_kg": 450.0},
                              {"from_m": 0.0, "to_m": 160.0, "added_density_kg_per_m": 1.0}]] + [[]] * 5
    fl, fz, s0, r = _cable_one_at_k1(model)
    cable = fastcal.Cable.of(model, 1)
    assert cable.uniform is not built
    end = cable.end(fl, fz, s0)
    assert end["lower_tension_n"] == pytest.approx(r.lower_tension_kN[0] * 1e3, rel=RELATIVE)
    assert end["upper_tension_n"] == pytest.approx(r.upper_tension_kN[0] * 1e3, rel=1e-7)
    # The end lands on the tower: the inverse from that end gives the statics' forces back.
    back = cable.forces(end["span_m"], end["rise_m"], s0)
    assert back == pytest.approx((fl, fz), rel=RELATIVE)
    assert cable.tension(fl, fz, 0.0) == pytest.approx(end["lower_tension_n"], rel=1e-12)


def test_mass_and_lumped_chain() -> None:
    cable = fastcal.Cable(2.4656e7, 11.718)
    fl, fz = cable.forces(250.0, 120.0, 277.0)
    chain = cable.lumped([0.0, 0.0, 150.0], [250.0, 0.0, 270.0], fl, fz, 277.0, segments=12)
    assert chain["nodes_m"].shape == (13, 3)
    assert np.allclose(chain["nodes_m"][-1], [250.0, 0.0, 270.0], atol=END_M)
    assert chain["node_mass_kg"] * 12 == pytest.approx(cable.mass_kg(277.0), rel=1e-12)
    assert np.all(np.diff(chain["tension_n"]) > 0)  # heavier toward the top


def test_bad_cables_and_calls_are_named() -> None:
    with pytest.raises(fastcal.InputError, match="EA and linear density"):
        fastcal.Cable(0.0, 11.7)
    with pytest.raises(fastcal.InputError, match="cable must be 1..6"):
        fastcal.Cable.of(fastcal.Model.nominal(), 7)
    cable = fastcal.Cable(2.4656e7, 11.718)
    with pytest.raises(fastcal.InputError, match="fl_n > 0"):
        cable.end(-1.0, 0.0, 277.0)
    with pytest.raises(fastcal.InputError, match="tension: finite"):
        cable.tension(float("nan"), -1e5, 10.0)
    with pytest.raises(fastcal.InputError, match="mass_kg: s0_m"):
        cable.mass_kg(float("inf"))
    with pytest.raises(fastcal.InputError, match="forces: "):
        cable.forces(250.0, 120.0, -1.0)
    with pytest.raises(fastcal.InputError, match="misses its upper end"):
        cable.lumped([0, 0, 0], [250.0, 0, 120.0], 1e5, -1e5, 277.0, segments=8)
