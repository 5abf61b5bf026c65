"""Response (autopilot) models: the interface and their simulation.

A steering model maps the rudder angle to the yaw rate with a few states; the heading
is the integral of the yaw rate. Unlike a vessel (`jaxship.AbstractVessel`) it has no
sway or surge dynamics of its own: measured speeds, when a model needs them, come in
as the auxiliary inputs `AuxInputs(u, v, n)` of the current sample.

The models never integrate themselves: `jaxship.simulate` (a `Replay` of recorded
inputs, or any other manoeuvre closed on the model's heading) and `fit` run them
through the simulator's one time loop.
"""

import abc
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ..._foundation._contract import AbstractModel


class AuxInputs(eqx.Module):
    """Measured quantities a response model may use besides the rudder, at the time the
    model is evaluated: surge `u` and sway `v` velocity [m/s] at midship (through the
    water), the propeller rate `n` [rev/s] and, where wind is logged, the apparent
    wind `wind_u`, `wind_v` [m/s]: the ship's velocity through the air in body axes,
    so that the wind comes from $\\gamma =$ atan2(`wind_v`, `wind_u`) off the bow,
    positive from starboard (`jaxship.Wind`'s convention). Unused by the Nomoto models;
    effects use them (`jaxship.effects.ApparentWind`)."""

    u: ArrayLike = 0.0
    v: ArrayLike = 0.0
    n: ArrayLike = 0.0
    wind_u: ArrayLike | None = None  # None: not logged (no wind)
    wind_v: ArrayLike | None = None


class WindowStart(eqx.Module):
    """What a record says at the first sample $t_s$ of a prediction window, for
    `AbstractSteeringModel.window_state`: the measured yaw rate `r` [rad/s] and
    heading `psi` [rad] there, the rudder `delta` [rad] held over the next
    interval, the auxiliary inputs `aux` there, and, from the start $t_0$ of the
    experiment, `r_first`, `psi_first`, the rudder integral
    `delta_integral` $= \\int_{t_0}^{t_s}\\delta\\,dt$ [rad s] (exact for the
    replayed rudder, held or interpolated) and `elapsed` $= t_s - t_0$ [s];
    `rudder_angle`: the measured rudder angle at $t_s$ (where a servo replays the
    command); `x`, `y`: the measured position at $t_s$ (None: not given); `ground`: 1
    where the record's u, v are over ground, 0 or None through the water
    (`with_current`)."""

    r: ArrayLike
    psi: ArrayLike
    delta: ArrayLike
    r_first: ArrayLike
    psi_first: ArrayLike
    delta_integral: ArrayLike
    elapsed: ArrayLike
    aux: AuxInputs
    rudder_angle: ArrayLike | None = None  # the measured rudder angle there [rad]
    x: ArrayLike | None = None  # the measured earth-fixed position there [m], if any
    y: ArrayLike | None = None
    ground: ArrayLike | None = None  # None (or 0): u, v through the water

    @property
    def ground_scale(self) -> ArrayLike:
        """`ground` with None read as 0 (the scale of `with_current`)."""
        return 0.0 if self.ground is None else self.ground


class AbstractSteeringModel(AbstractModel):
    """A response model $\\dot x = f(x, \\delta, a)$, $r = h(x)$, $\\dot\\psi = r$.

    Subclasses (final) declare their coefficients as fields with
    `jaxship.param` metadata (free/frozen default, bounds, scale, unit) and provide:

    - `state_names`: class variable, the names of the state entries; the first is
      always `"r"`;
    - `rhs(state, delta, aux)`: the continuous-time derivative of the state (1-D
      array) at rudder angle `delta` [rad] (positive turns to starboard) and the
      auxiliary inputs `aux` (`AuxInputs`);
    - `output(state)`: the yaw rate r [rad/s];
    - `initial_state(r)`: the state of a steady turn (or straight run, r = 0) at
      yaw rate `r`; simulations start from `initial_state(0.0)` by default;
    - `window_state(start)`: the state at the first sample of a prediction window,
      reconstructed from the record (`WindowStart`): the measured r for
      first-order models; hidden states from measured signals as each model
      documents.

    The model never integrates itself: `simulate` and `fit` own the numerics.
    """

    state_names: eqx.AbstractClassVar[tuple[str, ...]]
    # the model contract (`AbstractModel`): psi and r fitted by default, no measured
    # channel needed at a window start, no wind loads, no rudder servo
    default_channels: ClassVar[tuple[str, ...]] = ("psi", "r")
    start_channels: ClassVar[tuple[str, ...]] = ()
    wind_loads: ClassVar[bool] = False
    has_servo: ClassVar[bool] = False
    # the unit of a term f an effect adds to the yaw equation (`yaw_term`): [rad/s^2]
    # for models written as r' = ... + f; Nomoto models (T r' + r = K delta + f) say rad/s
    yaw_term_unit: ClassVar[str] = "rad/s^2"

    @abc.abstractmethod
    def rhs(self, state: Array, delta: ArrayLike, aux: AuxInputs) -> Array:
        """Time derivative of `state` (same shape) at rudder `delta` [rad]."""

    @abc.abstractmethod
    def output(self, state: Array) -> Array:
        """Yaw rate r [rad/s] of `state`."""

    @abc.abstractmethod
    def initial_state(self, r: ArrayLike) -> Array:
        """The state of a steady turn at yaw rate `r` [rad/s]."""

    @abc.abstractmethod
    def window_state(self, start: WindowStart) -> Array:
        """The state at a window start, reconstructed from the record."""

    def forcing(self, state: Array) -> Array:
        """$b(x) = \\partial\\dot x/\\partial f$: how a term $f$ added to the right-hand
        side of the yaw equation, where the rudder's moment enters, moves the state
        (effects use it, `jaxship.effects.YawMomentBias`). Here the yaw equation is
        $\\dot r = \\dots$, so $b = e_r$; Nomoto models override it."""
        return jnp.zeros_like(state).at[0].set(1.0)

    # -- the model contract shared with vessels: the simulated state is y = (x, psi) --

    def channel_index(self, channel: str) -> int:
        """Where an output channel sits in $y = (x, \\psi)$: r is the first state, psi
        the last entry, `"u"`/`"v"` a state of that name."""
        if channel == "psi":
            return len(self.state_names)
        if channel in self.state_names:
            return self.state_names.index(channel)
        raise ValueError(f"{type(self).__name__} has no output {channel!r}; its outputs are "
                         f"psi and its states {self.state_names}.")

    def replay_state(self, start: WindowStart, servo: bool = False) -> Array:
        """$y = (x, \\psi)$ at a window start, `x` from `window_state`."""
        return jnp.concatenate([self.window_state(start), jnp.reshape(start.psi, (1,))])

    def replay_field(self, servo: bool = False):
        """`f(t, y, inputs)` $= (f(x, \\delta, a), h(x))$ with the replayed rudder
        `inputs["delta"]` (a command, with `servo`, is taken as the angle: a response
        model has no servo) and the measured `inputs["u"]`, `["v"]`, `["n"]` (and the
        apparent wind `["wind_u"]`, `["wind_v"]` where it is replayed)."""

        def field(t, y, inputs):
            x = y[:-1]
            aux = AuxInputs(inputs["u"], inputs["v"], inputs["n"], inputs.get("wind_u"),
                            inputs.get("wind_v"))
            return jnp.concatenate([self.rhs(x, inputs["delta"], aux),
                                    jnp.reshape(self.output(x), (1,))])

        return field
