"""How a sampled signal is held between its samples (MATLAB's `InterSample`): the
strategies `ZeroOrderHold` and `FirstOrderHold` of `Replay`, the estimators and `ekf`."""

import equinox as eqx
import jax.numpy as jnp


def _sample_at(record, dt, tau):
    """`(record, k)`: the record as an array and the index of its sample at or before
    `tau` seconds after its first sample (the last beyond the end)."""
    record = jnp.asarray(record)
    position = tau / dt
    return record, jnp.clip(jnp.floor(position + 1e-9).astype(int), 0, record.shape[0] - 1)


class ZeroOrderHold(eqx.Module):
    """A recorded signal held from each sample to the next (MATLAB's `InterSample='zoh'`):
    right for a commanded, piecewise-constant signal."""

    def interpolate(self, record, dt, tau):
        """Value and slope (zero) of `record`, sampled every `dt`, at `tau` seconds after
        its first sample; the last sample holds beyond the end."""
        record, k = _sample_at(record, dt, tau)
        return record[k], jnp.zeros_like(record[k])

    def slope(self, first, second, dt):
        """The slope over one sample interval from `first` to `second`: zero."""
        return 0.0 * first

    def interval_mean(self, first, second):
        """The signal's mean over the interval from sample `first` to `second`."""
        return first

    def interval_samples(self, first, second) -> list:
        """The samples the signal over the interval depends on."""
        return [first]


class FirstOrderHold(eqx.Module):
    """A recorded signal interpolated linearly between samples (MATLAB's
    `InterSample='foh'`): right for a measured, continuous signal such as a logged rudder
    angle or shaft speed."""

    def interpolate(self, record, dt, tau):
        """Value and slope of `record`, sampled every `dt`, at `tau` seconds after its first
        sample, linear between samples; the last sample holds beyond the end."""
        record, k = _sample_at(record, dt, tau)
        k1 = jnp.minimum(k + 1, record.shape[0] - 1)
        slope = (record[k1] - record[k]) / dt
        return record[k] + slope * jnp.clip(tau - k * dt, 0.0, None), slope

    def slope(self, first, second, dt):
        """The slope over one sample interval from `first` to `second`."""
        return (second - first) / dt

    def interval_mean(self, first, second):
        """The signal's mean over the interval from sample `first` to `second`."""
        return 0.5 * (first + second)

    def interval_samples(self, first, second) -> list:
        """The samples the signal over the interval depends on."""
        return [first, second]


HOLDS = (ZeroOrderHold, FirstOrderHold)


def check_hold(hold, name: str):
    """`hold` if it is a `ZeroOrderHold()` or `FirstOrderHold()`; `ValueError` naming
    `name` otherwise."""
    if not isinstance(hold, HOLDS):
        raise ValueError(f"`{name}` must be ZeroOrderHold() or FirstOrderHold(), got "
                         f"{hold!r}.")
    return hold
