"""The one model contract: what `fit`, `predict` and `discover` ask of a vessel
(`AbstractVessel`) and of a steering model (`AbstractSteeringModel`) alike.

A model is replayed against a measured record: every prediction window starts from a
state built from the record (`replay_state`) and runs the model's field with the
record's inputs replayed (`replay_field`); `channel_index` and `measure` say where an
output sits in the state and what its sensor reports. Its parameters are its `param`
fields, with their units and whether `fit` estimates them by default
(`parameter_fields`, below), addressed by name (`lookup`, `get_path`); a
model with effects (`AbstractComposite`) adds each effect's as `"<effect id>.<field>"`.
"""

import abc
import dataclasses
from typing import ClassVar

import equinox as eqx


PARAMETER_KEY = "jaxship_parameter"  # the field metadata `_params.param` writes


class AbstractModel(eqx.Module):
    """The contract of every model `jaxship.fit` estimates and `jaxship.discover` extends.

    Class variables: `default_channels` (outputs fitted by default), `start_channels`
    (measured channels every window starts from), `wind_loads` (feels the replayed
    wind), `has_servo` (a rudder servo that can replay the command) and
    `built_in_effects` (ids of catalogue effects its own equations carry).
    """

    default_channels: eqx.AbstractClassVar[tuple[str, ...]]
    start_channels: eqx.AbstractClassVar[tuple[str, ...]]
    wind_loads: eqx.AbstractClassVar[bool]
    has_servo: eqx.AbstractClassVar[bool]
    built_in_effects: ClassVar[tuple[str, ...]] = ()

    @abc.abstractmethod
    def channel_index(self, channel: str) -> int:
        """Where output `channel` sits in the replayed state vector."""

    @abc.abstractmethod
    def replay_state(self, start, servo: bool = False):
        """The state vector at a window start (`WindowStart`) of a measured record."""

    @abc.abstractmethod
    def replay_field(self, servo: bool = False):
        """`f(t, y, inputs)`: the state derivative with the record's inputs replayed."""

    def measure(self, channel: str, value):
        """What the sensor of `channel` reports for the true `value` (exact here;
        sensor effects change it)."""
        return value

    def with_current(self, y, scale):
        """The replayed state `y` with `scale` times the current's body components
        added to its u, v: through the water to over ground (`scale` 1), back (-1),
        unchanged (0: a record logged through the water). No current here."""
        return y

    def lookup(self, name: str):
        """The parameter (or part) called `name`: a field here."""
        return getattr(self, name)

    def parameter_names(self) -> tuple[str, ...]:
        """Every estimable parameter, in field order: the `param` fields, and with
        effects each effect's as `"<effect id>.<field>"` (`fit`'s `free=` takes them)."""
        return tuple(parameter_fields(self))

    def get_parameter(self, name: str):
        """The value of the parameter `name` (one of `parameter_names()`)."""
        return get_path(self, name)

    def with_parameters(self, values):
        """This model with the parameters of `values` (`{name: value}`, names of
        `parameter_names()`) replaced; the model itself is unchanged."""
        values = dict(values)
        return rebuild(self, tuple(values), tuple(values.values())) if values else self


class AbstractComposite(AbstractModel):
    """A model with effects (`jaxship.effects.AugmentedSteering`,
    `jaxship.effects.AugmentedVessel`):
    the `base` model's parameters and each effect's as `"<effect id>.<field>"`."""

    base: eqx.AbstractVar[AbstractModel]
    effects: eqx.AbstractVar[tuple]

    def lookup(self, name: str):
        """The base's field `name`, or the effect with the id `name`."""
        # `eqx.tree_at` wraps an empty `effects` tuple while it looks paths up
        for effect in self.effects if isinstance(self.effects, tuple) else ():
            if effect.id == name:
                return effect
        return getattr(self.base, name)


# the parameters of a model by name (`_params` maps them to the optimiser's space)
def parameter_fields(model) -> dict:
    """The estimable fields of `model` with their metadata (`_params.ParameterInfo`), in
    field order: the fields declared with `param` (vessels, steering models and effects
    alike); for a model with effects, the base's and each effect's as
    `"<effect id>.<field>"`."""
    if isinstance(model, AbstractComposite):  # the base's and "<id>.<field>"
        out = dict(parameter_fields(model.base))
        for effect in model.effects:
            out.update({f"{effect.id}.{k}": v for k, v in parameter_fields(effect).items()})
        return out
    return {f.name: f.metadata[PARAMETER_KEY] for f in dataclasses.fields(model)
            if PARAMETER_KEY in f.metadata}


def get_path(model, name: str):
    """The parameter `name` of `model`: a field, or `"<effect id>.<field>"`."""
    for part in name.split("."):
        model = model.lookup(part) if isinstance(model, AbstractModel) else getattr(model, part)
    return model


def rebuild(model, names, values):
    """`model` with the parameters `names` replaced by the entries of `values` (traced)."""
    return eqx.tree_at(
        lambda m: tuple(get_path(m, n) for n in names), model,
        tuple(values[i] for i in range(len(names))),
    )
