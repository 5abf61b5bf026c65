"""The README's `identify` example as a competent SciPy user would write it, without
jaxship: the yardstick of `benchmarks/latency.py` (issue 70).

First-order Nomoto model $T\\dot r + r = K\\delta$, $\\dot\\psi = r$ (Nomoto et al. 1957),
fitted to the Esso Osaka zig-zags by prediction error over 10 s windows (each window
restarts from the measured psi, r; the rudder linearly interpolated between samples,
one RK4 step per sample, all windows integrated at once with NumPy), the residuals of
psi and r weighted by 1/std of each channel (pooled within-record standard deviation),
`scipy.optimize.least_squares(method="lm")` from the equation-error least-squares start;
then output-error simulation of the training and held-out records, fit % (NRMSE),
standard errors $\\hat\\sigma_c^2$ per channel in $(J^TJ)^{-1}$, the residuals' whiteness
test (Ljung-Box portmanteau of 25 lags against the chi-square 99 % quantile), a JSON file,
and with `--figures` the same eight figures as `jaxship identify` (matplotlib).

Run: `python benchmarks/scipy_identify.py TRAIN... --validate TEST... --out DIR
[--figures] [--check result.json]` (`--check`: print K, T against jaxship's estimates).
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy import optimize, stats


HORIZON = 10.0  # [s] prediction window
LAGS = 25  # whiteness test lags


def read(path):
    """(t, delta, psi unwrapped, r) of an Esso Osaka CSV (SI units, radians)."""
    data = np.genfromtxt(path, delimiter=",", names=True)
    names = data.dtype.names
    col = lambda prefix: data[next(n for n in names if n.startswith(prefix))]
    return dict(name=Path(path).stem, t=col("t"), delta=col("delta_rudder"),
                psi=np.unwrap(col("psi_hat")), r=col("r_angvelo"))


def rk4(p, psi, r, d0, d1, dt):
    """One RK4 step of Nomoto 1 for arrays of states; rudder linear from d0 to d1."""
    K, T = p
    f = lambda r_, d: (K * d - r_) / T
    dm = 0.5 * (d0 + d1)
    k1p, k1r = r, f(r, d0)
    k2p, k2r = r + 0.5 * dt * k1r, f(r + 0.5 * dt * k1r, dm)
    k3p, k3r = r + 0.5 * dt * k2r, f(r + 0.5 * dt * k2r, dm)
    k4p, k4r = r + dt * k3r, f(r + dt * k3r, d1)
    return (psi + dt / 6 * (k1p + 2 * k2p + 2 * k3p + k4p),
            r + dt / 6 * (k1r + 2 * k2r + 2 * k3r + k4r))


def windows(records):
    """Window index arrays of all records: starts (M,), steps (M, L) and mask (M, L)."""
    starts, idx, mask, offset = [], [], [], 0
    for rec in records:
        n = len(rec["t"])
        L = int(round(HORIZON / (rec["t"][1] - rec["t"][0])))
        for s in range(0, n - 1, L):
            steps = s + np.arange(1, L + 1)
            starts.append(offset + s)
            mask.append(steps <= n - 1)
            idx.append(offset + np.minimum(steps, n - 1))
        offset += n
    return np.array(starts), np.array(idx), np.array(mask)


def predict(p, y, starts, idx, dt):
    """psi, r predicted at idx (M, L) from the measured states at starts."""
    psi, r = y["psi"][starts], y["r"][starts]
    prev = starts
    out = np.empty((2,) + idx.shape)
    for j in range(idx.shape[1]):
        psi, r = rk4(p, psi, r, y["delta"][prev], y["delta"][idx[:, j]], dt[prev])
        out[0, :, j], out[1, :, j] = psi, r
        prev = idx[:, j]
    return out


def simulate(p, rec):
    """Output error: psi, r simulated over the whole record from its first sample."""
    dt = np.diff(rec["t"])
    psi, r = [rec["psi"][0]], [rec["r"][0]]
    for k in range(len(dt)):
        a, b = rk4(p, psi[-1], r[-1], rec["delta"][k], rec["delta"][k + 1], dt[k])
        psi.append(a)
        r.append(b)
    return np.array(psi), np.array(r)


def fit_percent(measured, simulated):
    """100 (1 - |y - yhat| / |y - mean y|), pooled over records (each its own mean)."""
    err = sum(np.sum((m - s) ** 2) for m, s in zip(measured, simulated))
    spread = sum(np.sum((m - m.mean()) ** 2) for m in measured)
    return 100 * (1 - np.sqrt(err / spread))


def whiteness(e):
    """Ljung-Box statistic of 25 lags against chi2(25)'s 99 % quantile."""
    e = e - e.mean()
    n = len(e)
    acf = np.array([e[:n - k] @ e[k:] for k in range(1, LAGS + 1)]) / (e @ e)
    q = n * (n + 2) * np.sum(acf**2 / (n - np.arange(1, LAGS + 1)))
    limit = stats.chi2.ppf(0.99, LAGS)
    return dict(statistic=float(q), threshold_99=float(limit), passed=bool(q < limit))


def fit(train):
    """`(report, (e, jac))`: the LM fit on `train`, its standard errors and the training
    residuals' whiteness (what `jaxship.fit` returns, without the simulations)."""
    y = {c: np.concatenate([rec[c] for rec in train]) for c in ("psi", "r", "delta")}
    dt = np.concatenate([np.append(np.diff(rec["t"]), np.nan) for rec in train])
    starts, idx, mask = windows(train)
    std = [np.sqrt(sum(np.sum((rec[c] - rec[c].mean()) ** 2) for rec in train)
                   / sum(len(rec[c]) for rec in train)) for c in ("psi", "r")]
    weights = 1.0 / np.array(std)
    targets = np.stack([y["psi"][idx], y["r"][idx]])

    def residuals(p):
        e = weights[:, None, None] * (targets - predict(p, y, starts, idx, dt))
        return e[:, mask].ravel()

    # start: equation error, r[k+1] - r[k] = dt/T (K delta[k] - r[k]) by linear least squares
    a = np.concatenate([np.stack([rec["delta"][:-1], -rec["r"][:-1]], 1)
                        * np.diff(rec["t"])[:, None] for rec in train])
    b = np.concatenate([np.diff(rec["r"]) for rec in train])
    (k_over_t, one_over_t), *_ = np.linalg.lstsq(a, b, rcond=None)
    start = np.array([k_over_t / one_over_t, 1 / one_over_t])
    sol = optimize.least_squares(residuals, start, method="lm")
    # per-channel noise variances in the covariance: sigma_c^2 (J^T J)^-1, J weighted by 1/sigma_c
    e = sol.fun.reshape(2, -1) / weights[:, None]
    var = np.mean(e**2, axis=1)
    jac = sol.jac.reshape(2, -1, 2) / weights[:, None, None]
    info = sum(jac[c].T @ jac[c] / var[c] for c in range(2))
    std_err = np.sqrt(np.diag(np.linalg.inv(info)))
    report = dict(K=sol.x[0], T=sol.x[1], std=dict(K=std_err[0], T=std_err[1]),
                  cost=sol.cost, nfev=sol.nfev, status=sol.status, start=start.tolist(),
                  weights=weights.tolist(),
                  whiteness_train={c: whiteness(e[i]) for i, c in enumerate(("psi", "r"))})
    return report, (e, jac)


def identify(train, held_out):
    report, errors = fit(train)
    sol_x = np.array([report["K"], report["T"]])
    sims = {}
    for label, records in (("train_simulation", train), ("validation", held_out)):
        sims[label] = [simulate(sol_x, rec) for rec in records]
        report[label] = {c: dict(
            fit_percent=fit_percent([rec[c] for rec in records], [s[i] for s in sims[label]]),
            whiteness=whiteness(np.concatenate([rec[c] - s[i] for rec, s
                                                in zip(records, sims[label])])))
            for i, c in enumerate(("psi", "r"))}
    return report, sims, errors


def figures(folder, train, held_out, sims, errors):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    for label, records in (("train", train), ("validation", held_out)):
        key = "train_simulation" if label == "train" else "validation"
        for i, (rec, (psi, r)) in enumerate(zip(records, sims[key])):
            fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7), layout="constrained")
            axes[0].plot(rec["t"], np.rad2deg(rec["psi"]), label="measured")
            axes[0].plot(rec["t"], np.rad2deg(psi), label="Nomoto1")
            axes[1].plot(rec["t"], np.rad2deg(rec["r"]))
            axes[1].plot(rec["t"], np.rad2deg(r))
            axes[2].plot(rec["t"], np.rad2deg(rec["delta"]))
            for ax, name in zip(axes, ("psi [deg]", "r [deg/s]", "delta [deg]")):
                ax.set_ylabel(name)
            axes[0].legend()
            fig.savefig(folder / f"fit_{label}_{i:02d}_{rec['name']}.png", dpi=100)
            plt.close(fig)
    e, jac = errors
    for label, series in (("train", e), ("validation", [
            np.concatenate([rec[c] - s[i] for rec, s in zip(held_out, sims["validation"])])
            for i, c in enumerate(("psi", "r"))])):
        fig, axes = plt.subplots(2, 2, figsize=(10, 6), layout="constrained")
        for i, c in enumerate(("psi", "r")):
            x = series[i] - series[i].mean()
            acf = [x[:len(x) - k] @ x[k:] / (x @ x) for k in range(LAGS + 1)]
            axes[i, 0].plot(series[i])
            axes[i, 0].set_ylabel(f"error {c}")
            axes[i, 1].stem(range(LAGS + 1), acf)
            axes[i, 1].axhline(2.58 / np.sqrt(len(x)), ls="--")
            axes[i, 1].axhline(-2.58 / np.sqrt(len(x)), ls="--")
        fig.savefig(folder / f"residuals_{label}.png", dpi=100)
        plt.close(fig)
    cov = np.linalg.inv(sum(jac[c].T @ jac[c] for c in range(2)))
    corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    fig, ax = plt.subplots(figsize=(4, 4), layout="constrained")
    ax.imshow(corr, vmin=-1, vmax=1, cmap="RdBu_r")
    fig.savefig(folder / "correlation.png", dpi=100)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("train", nargs="+")
    parser.add_argument("--validate", nargs="+", required=True)
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--figures", action="store_true")
    parser.add_argument("--check", type=Path, help="jaxship's result.json to compare with")
    args = parser.parse_args()
    train, held_out = [read(p) for p in args.train], [read(p) for p in args.validate]
    report, sims, errors = identify(train, held_out)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "result.json").write_text(json.dumps(report, indent=2, default=float))
    if args.figures:
        figures(args.out / "figures", train, held_out, sims, errors)
    print(f"K = {report['K']:.8g}, T = {report['T']:.8g}, cost {report['cost']:.10g}")
    if args.check:
        theirs = json.loads(args.check.read_text())
        for name in ("K", "T"):
            value = theirs["parameters"][name]["value"]
            print(f"{name}: jaxship {value:.8g}, SciPy {report[name]:.8g}, relative difference "
                  f"{abs(report[name] / value - 1):.1e}")
        print(f"cost: jaxship {theirs['fit']['cost']:.10g}, SciPy {report['cost']:.10g}")


if __name__ == "__main__":
    sys.exit(main())
