"""The records of `jaxship reproduce`'s discovery case: a truth model run through 10/10
and 20/20 zig-zags to both sides (training) and +-20 deg turning circles (held out), with
a rudder rate limit of 2.3 deg/s, integrated more finely than any fit (0.02 s control
steps against one RK4 step per 0.5 s sample), the rudder logged at the sample rate.
Measurement noise: heading 0.1 deg, yaw rate 0.05 deg/s.

The same records as the discovery tests' generator (`jaxship/studies/discovery.py`,
`hidden_effect_records` without a disturbance), which lives outside the package;
tests/test_reproduce.py checks that the two agree sample for sample.
"""

import dataclasses

import numpy as np

import jaxship as js


DEG = np.pi / 180
FINE = js.Simulator(max_step=0.02)
TRAIN = tuple((a, s) for a in (10, 20) for s in (1, -1))  # zig-zag angle [deg], side
HOLDOUT = (20, -20)  # turning-circle rudder angles [deg]
NOISE = (0.1, 0.05)  # heading [deg], yaw rate [deg/s]


def _record(truth, manoeuvre, name, rng):
    out = js.simulate(truth, dataclasses.replace(manoeuvre, rudder_rate=2.3 * DEG),
                      simulator=FINE)
    t, delta = np.asarray(out.t), np.asarray(out.state.delta)
    psi = np.asarray(truth.measure("psi", np.asarray(out.state.psi)))  # sensors
    r = np.asarray(truth.measure("r", np.asarray(out.state.r)))
    return js.Experiment(t, delta, psi=psi + rng.normal(0, NOISE[0] * DEG, t.size),
                         r=r + rng.normal(0, NOISE[1] * DEG, t.size), name=name)


def hidden_effect_records(truth, seed):
    """`(train, holdout)` records of `truth` (see the module text), noise drawn from
    `numpy.random.default_rng(seed)`."""
    rng = np.random.default_rng(seed)
    train = [_record(truth, js.ZigZag(a * DEG, s * a * DEG, duration=400.0, dt=0.5),
                     f"zigzag {a}/{a} {'starboard' if s > 0 else 'port'}", rng)
             for a, s in TRAIN]
    holdout = [_record(truth, js.Turn(a * DEG, duration=300.0, dt=0.5), f"turn {a:+d}", rng)
               for a in HOLDOUT]
    return train, holdout
