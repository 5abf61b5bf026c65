"""Froude scaling of vessels, trajectories and records (issue 34, point 2)."""

import json

import jax
import numpy as np
import pytest
from helpers import tree_allclose

import jaxship as js
from jaxship._simulation._froude import froude_exponent


jax.config.update("jax_enable_x64", True)
LAMBDA = 320.0 / 7.0  # the KVLCC2 ship over the 7 m model (SIMMAN 2008)


def test_the_exponents_follow_the_dimensions():
    """kg^3 m^1 s^(1/2): a mass by lambda^3, a moment of inertia by lambda^5, a rate by
    lambda^(-1/2); angles and primed coefficients stay."""
    for unit, power in (("m", 1), ("m/s", 0.5), ("s", 0.5), ("rev/s", -0.5), ("rad/s", -0.5),
                        ("kg", 3), ("kg m^2", 5), ("N m", 4), ("kg s/m^2", 1.5), ("-", 0),
                        ("kg/m^3", 0), ("rad", 0), ("m^2", 2), ("m^3", 3)):
        assert froude_exponent(unit) == power, unit
    with pytest.raises(ValueError, match="cannot Froude-scale 'furlong'"):
        froude_exponent("furlong/s")


@pytest.mark.parametrize("name", sorted(js.VESSELS))
def test_scaling_a_vessel_and_back_is_the_identity(name):
    vessel = js.get_vessel(name)
    there = js.froude_scale(vessel, 12.5)
    assert float(there.length) == pytest.approx(12.5 * float(vessel.length))
    assert float(there.nominal_speed) == pytest.approx(np.sqrt(12.5) * float(vessel.nominal_speed))
    assert tree_allclose(js.froude_scale(there, 1 / 12.5), vessel, rtol=1e-12, atol=0)


def test_a_scaled_vessel_with_effects_and_its_records_scale_back():
    vessel = js.augment(js.get_vessel("kvlcc2"), js.effects.YawMomentBias(n0=2.0),
                        js.effects.RudderOffset(0.01))
    there = js.froude_scale(vessel, LAMBDA)
    assert float(there.effects[0].n0) == pytest.approx(2.0 * LAMBDA**4)  # N m
    assert float(there.effects[1].delta0) == 0.01  # an angle
    assert tree_allclose(js.froude_scale(there, 1 / LAMBDA), vessel, rtol=1e-12, atol=0)
    t = np.linspace(0.0, 10.0, 11)
    record = js.Experiment(t, 0.1 * np.sin(t), r=0.01 * t, u=np.ones(11), x=t, n=np.full(11, 10.0),
                           metadata={"lpp": 7.0}, extra={"roll": 0.01 * t})
    with pytest.raises(ValueError, match="roll have no unit"):
        js.froude_scale(record, LAMBDA)
    big = js.froude_scale(record, LAMBDA, extra_units={"roll": "rad"})
    assert big.meta["lpp"] == pytest.approx(320.0) and big.t[-1] == pytest.approx(10 * LAMBDA**0.5)
    np.testing.assert_allclose(big.u, LAMBDA**0.5)
    np.testing.assert_allclose(big.n, 10 / LAMBDA**0.5)
    back = js.froude_scale(big, 1 / LAMBDA, extra_units={"roll": "rad"})
    for c in ("t", "delta", "r", "u", "x", "n"):
        np.testing.assert_allclose(getattr(back, c), getattr(record, c), rtol=1e-12, atol=1e-15)


def test_the_scaled_kvlcc2_model_turns_as_the_ship():
    """The 7 m KVLCC2 model's 35 deg turning circle and the 320 m ship's (the model
    Froude-scaled), each at its own scaled speed and time step: advance and tactical
    diameter over the length agree to 1e-6, and the ship's trajectory scaled down is the
    model's."""
    model = js.get_vessel("kvlcc2")
    ship = js.froude_scale(model, LAMBDA)
    runs = {}
    for name, vessel, scale in (("model", model, 1.0), ("ship", ship, LAMBDA)):
        turn = js.Turn(np.deg2rad(35.0), duration=250.0 * scale**0.5, dt=0.2 * scale**0.5)
        x0 = js.straight_state(vessel.nominal_speed, vessel.nominal_n)
        # one RK4 step per control step, each the same fraction of the time scale L/U
        traj = js.simulate(vessel, turn, x0, simulator=js.Simulator(max_step=np.inf, substeps=2))
        runs[name] = (traj, js.indices.turning_indices(traj), float(vessel.length))
    (small, a, la), (large, b, lb) = runs["model"], runs["ship"]
    assert a.advance / la == pytest.approx(b.advance / lb, rel=1e-6)
    assert a.tactical_diameter / la == pytest.approx(b.tactical_diameter / lb, rel=1e-6)
    down = js.froude_scale(large, 1 / LAMBDA)
    np.testing.assert_allclose(down.state.x, small.state.x, rtol=1e-6, atol=1e-6 * la)
    np.testing.assert_allclose(down.state.r, small.state.r, rtol=1e-6, atol=1e-9)


def test_simulate_scales_a_preset_to_the_length_given(tmp_path, capsys):
    """`jaxship simulate --length 320`: the KVLCC2 preset as the 320 m ship; its turning
    indices over its length are the 7 m model's (to the control step, which is the same
    in seconds at both sizes)."""
    from jaxship.cli import main

    found = {}
    for length in (None, 320.0):
        out = tmp_path / f"{length}"
        extra = [] if length is None else ["--length", f"{length:g}"]
        assert main(["simulate", "--vessel", "kvlcc2", "--manoeuvre", "turn:35", "--out",
                     str(out), *extra]) == 0
        indices = json.loads((out / "indices.json").read_text())
        found[length] = indices["advance_m"] / (length or 7.0)
    capsys.readouterr()
    assert found[320.0] == pytest.approx(found[None], rel=1e-3)
    assert main(["simulate", "--vessel", "kvlcc2", "--manoeuvre", "turn:35", "--out",
                 str(tmp_path / "bad"), "--length", "-3"]) == 2
    assert "--length -3: must be a positive number" in capsys.readouterr().err
