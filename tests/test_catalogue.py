"""Every preset: builds, documents its source, and follows the one sign convention."""

import numpy as np
import pytest

import jaxship as js
from jaxship._models._vessel.mariner import Mariner


@pytest.mark.parametrize("name", list(js.VESSELS))
def test_preset_turns_to_starboard_with_positive_rudder(name):
    vessel = js.get_vessel(name)
    assert js.VESSELS[name].description, "the factory docstring must name the model and source"
    x0 = js.straight_run(vessel)
    assert np.isfinite(float(x0.u)) and float(x0.u) > 0
    tau = float(vessel.length) / float(x0.u)
    turn = js.Turn(np.deg2rad(20.0), duration=20 * tau, dt=tau / 20)
    starboard = js.simulate(vessel, turn, x0, simulator=js.Simulator(substeps=2))
    port = js.simulate(
        vessel, js.Turn(np.deg2rad(-20.0), duration=20 * tau, dt=tau / 20), x0,
        simulator=js.Simulator(substeps=2),
    )
    assert bool(starboard.success) and bool(port.success)
    assert float(starboard.state.r[-1]) > 0 and float(starboard.state.psi[-1]) > 0
    assert float(port.state.r[-1]) < 0 and float(port.state.psi[-1]) < 0


def test_unknown_vessel_names_the_choices():
    with pytest.raises(ValueError, match="mariner"):
        js.get_vessel("titanic")


def test_vessel_and_get_vessel_give_fresh_equal_presets():
    a, b = js.get_vessel("Mariner"), js.get_vessel("mariner")
    assert a is not b and type(a) is type(b) is Mariner
    assert float(a.length) == float(b.length)
