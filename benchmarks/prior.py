"""Does a Gaussian prior help where the truth lies away from it? (issue 69, point 4)

A Monte Carlo on records of a second-order Nomoto model with known coefficients
(K = 0.06 1/s, T1 = 25 s, T2 = 3 s, T3 = 5 s; delta0 = 0 held), the four of them
estimated by output error (psi and r; the start's r and psi estimated too,
`EstimatedStarts`, as `identify` does for output error) from one record of rudder steps
of +-10 deg (random holds, a steering gear's 2.32 deg/s rate) with white noise on psi and
a tenth of it (in deg/s) on r: "short", 120 s with 0.5 deg, the issue's case of few data
for the coefficients, and "long", 300 s with 0.2 deg, which determine them well.

The prior, stated before any result: its mean is the truth with K, T1 and T3 moved by
30 % each (the sign drawn per seed), T2 left at the truth; its standard deviation is
30 % of each mean (`Prior(scale=0.3)`, relative), the size of the offsets it has to
absorb: the three moved coefficients lie one prior standard deviation (of the mean's
size, i.e. 0.23 to 0.43 of the truth) from the mean. Both fits start from the prior
mean, as `identify --prior` starts from the preset: the unregularised fit (least
squares) and the MAP fit.

Per seed: the relative error of each fit, $\\sqrt{\\sum_i ((\\hat\\theta_i -
\\theta_i) / \\theta_i)^2}$; whether the MAP's is no larger; and per coefficient
whether the truth lies in the 90 % interval (estimate +- 1.645 std, the posterior std for
the MAP, the least-squares std for the unregularised fit).

Two generators of the records:

- `jaxship`: `jaxship.simulate` of `Nomoto2` (RK4, rudder sampled at 0.5 s and replayed
  linearly between samples);
- `scipy`: an independent few-line implementation, `scipy.integrate.solve_ivp` (RK45,
  rtol 1e-10) of the transfer function in its own states (psi, r, r dot),
  $T_1T_2\\ddot r + (T_1 + T_2)\\dot r + r = K\\delta + KT_3\\dot\\delta$ (Nomoto 1957;
  Astrom & Kallstrom 1979, eq. 4) with the exact rudder and rudder rate of the
  steering-gear program, sampled at 0.5 s.

With `--exact-start` the first sample of each record is exact (a record that starts from
a known rest): the single output-error window then starts from the true state, which
isolates what a noisy start sample does to the intervals (see
benchmarks/results/prior.md).

    python benchmarks/prior.py [--seeds 40] [--scale 0.3] [--exact-start]
"""

import argparse
import math
import time

import jax


jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import jaxship as js  # noqa: E402


DEG = math.pi / 180
DT, RATE = 0.5, 2.32 * DEG  # sample interval [s], steering gear [rad/s]
# the records: (duration [s], psi noise [deg]; r's is a tenth of it in deg/s): "short", the
# issue's case of few data for the coefficients (least squares determines T2 and T3 to
# about 50-100 %, worse than the prior's 30 %), and "long", data that determine them well
REGIMES = {"short": (120.0, 0.5), "long": (300.0, 0.2)}
TRUTH = dict(K=0.06, T1=25.0, T2=3.0, T3=5.0)
MOVED, OFFSET = ("K", "T1", "T3"), 0.3  # the prior mean's offsets from the truth
FREE = tuple(TRUTH)
Z90 = 1.6448536269514722  # the standard normal's 95 % quantile


def rudder_program(rng, duration):
    """`(delta(t), delta_dot(t))` of steps between +-10 deg held 20-60 s, each moved at the
    gear's rate: exact functions of time."""
    switches, targets, t, sign = [], [], 5.0, 1.0
    while t < duration:
        switches.append(t)
        targets.append(sign * 10 * DEG)
        t, sign = t + rng.uniform(20.0, 60.0), -sign if rng.random() < 0.8 else sign

    def delta_and_rate(time):
        value, rate = 0.0, 0.0
        for start, target in zip(switches, targets):
            if time < start:
                break
            ramp = abs(target - value) / RATE
            if time < start + ramp:
                rate = math.copysign(RATE, target - value)
                return value + rate * (time - start), rate
            value, rate = target, 0.0
        return value, 0.0

    return delta_and_rate


def scipy_record(truth, program, duration):
    """The independent generator: solve_ivp of the transfer function (module text)."""
    k, t1, t2, t3 = (truth[n] for n in FREE)

    def field(t, x):
        delta, rate = program(t)
        return [x[1], x[2], (k * delta + k * t3 * rate - x[1] - (t1 + t2) * x[2]) / (t1 * t2)]

    times = np.arange(0.0, duration + DT / 2, DT)
    sol = solve_ivp(field, (0.0, times[-1]), [0.1, 0.0, 0.0], t_eval=times, rtol=1e-10,
                    atol=1e-12, max_step=DT / 4)
    return times, sol.y[0], sol.y[1]


def jaxship_record(truth, program, duration):
    times = np.arange(0.0, duration + DT / 2, DT)
    delta = np.array([program(t)[0] for t in times])
    tr = js.simulate(js.Nomoto2(**truth), js.Replay(delta, dt=DT,
                                                    delta_hold=js.strategies.FirstOrderHold()),
                     js.straight_state(0.0, psi=0.1),
                     simulator=js.Simulator(max_step=math.inf, substeps=1))
    return times, np.asarray(tr.state.psi), np.asarray(tr.state.r)


def one_seed(seed, generator, scale, regime, exact_start=False):
    """`[(error, covered (4,), code)]` of the unregularised and the MAP fit of one seed."""
    duration, noise = REGIMES[regime]
    rng = np.random.default_rng(seed)
    program = rudder_program(rng, duration)
    mean = {n: (v * (1 + OFFSET * rng.choice([-1.0, 1.0])) if n in MOVED else v)
            for n, v in TRUTH.items()}
    generate = scipy_record if generator == "scipy" else jaxship_record
    times, psi, r = generate(TRUTH, program, duration)
    delta = np.array([program(t)[0] for t in times])
    noise_psi = noise * DEG * rng.standard_normal(times.size)
    noise_r = 0.1 * noise * DEG * rng.standard_normal(times.size)
    if exact_start:  # the first sample exact: a record that starts from a known rest
        noise_psi[0] = noise_r[0] = 0.0
    data = js.Experiment(times, delta, psi=psi + noise_psi, r=r + noise_r, name=f"seed{seed}")
    start, truth = js.Nomoto2(**mean), np.array([TRUTH[n] for n in FREE])
    out = []
    for prior in (None, js.strategies.Prior(scale=scale)):
        fit = js.fit(start, data, free=FREE, estimator=js.PredictionError(
            prior=prior, initial=js.EstimatedStarts()))
        error = float(np.sqrt(np.sum(((fit.values - truth) / truth) ** 2)))
        lo, hi = fit.values - Z90 * fit.std, fit.values + Z90 * fit.std
        out.append((error if np.isfinite(error) else math.inf, (lo <= truth) & (truth <= hi),
                    fit.code_name))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40)
    parser.add_argument("--scale", type=float, default=OFFSET)
    parser.add_argument("--exact-start", action="store_true",
                        help="the first sample without noise (isolates the bias of a noisy "
                        "start sample of the one output-error window)")
    parser.add_argument("--regimes", nargs="+", default=list(REGIMES), choices=list(REGIMES))
    args = parser.parse_args()
    print(f"Nomoto2 truth {TRUTH}; prior mean: {', '.join(MOVED)} moved by "
          f"+-{100 * OFFSET:.0f} %; prior sd {100 * args.scale:.0f} % of the mean; "
          f"{args.seeds} seeds per generator\n")
    print("| record | generator | seeds | MAP error <= LS error | median error LS "
          "| median error MAP | LS converged | MAP converged | LS 90 % coverage "
          "| MAP 90 % coverage | MAP coverage per coefficient (K, T1, T2, T3) | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for regime, generator in [(r, g) for r in args.regimes for g in ("jaxship", "scipy")]:
        begun = time.perf_counter()
        rows = [one_seed(seed, generator, args.scale, regime, args.exact_start)
                for seed in range(args.seeds)]
        ls = np.array([row[0][0] for row in rows])
        mp = np.array([row[1][0] for row in rows])
        cov_ls = np.array([row[0][1] for row in rows])
        cov_map = np.array([row[1][1] for row in rows])
        ok = [sum(row[i][2] == "successful" for row in rows) for i in (0, 1)]
        per = ", ".join(f"{100 * c:.0f}" for c in cov_map.mean(axis=0))
        duration, noise = REGIMES[regime]
        print(f"| {regime} ({duration:.0f} s, {noise} deg) | {generator} | {args.seeds} "
              f"| {100 * np.mean(mp <= ls):.1f} % "
              f"| {np.median(ls):.4f} | {np.median(mp):.4f} | {ok[0]} | {ok[1]} "
              f"| {100 * cov_ls.mean():.1f} % | {100 * cov_map.mean():.1f} % | {per} % "
              f"| {time.perf_counter() - begun:.0f} |", flush=True)


if __name__ == "__main__":
    main()
