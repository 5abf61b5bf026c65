"""A second independent generator: KVLCC2 records simulated by shipmmg (Mitsuyuki's
Python MMG package, MIT licence, on the package index; `pip install --no-deps shipmmg`),
for testing `jaxship.discover` on records jaxship did not simulate (issue 71).

shipmmg integrates the MMG standard method (Yasukawa & Yoshimura 2015) with SciPy's
`solve_ivp` (RK45; here at relative and absolute tolerances of 1e-9, as the Mariner
generator: at shipmmg's default 1e-3 the 20/20 zig-zag's heading is 7 deg off the
converged one after 150 s, an error of the generator, not of the ship) and differs from
jaxship's `kvlcc2` preset as a second implementation of the same paper does:

- its wake fraction is $w_P = w_{P0}\\exp(-4\\beta_P^2)$ with $x'_P = -0.690$ (its tests'
  KVLCC2 set), not the paper's $C_1, C_2$ form with $x'_P = -0.48$;
- its U and drift angle use $v - x_G r$ where the paper uses the midship sway velocity v;
- it has no steering gear: the rudder angle is a prescribed series, interpolated by a
  natural cubic spline whose derivative is integrated.

This module adds only what a trial and a logger add: the rudder series of a helm that
moves the rudder at 15.8 deg/s (the SIMMAN model's rate) towards its order and reverses a
zig-zag at the first logged sample past the heading limit (as shipmmg's own zig-zag
helper does), and the logs (`jaxship.studies.generators.logged`). The coefficients
are the paper's KVLCC2 L7 model (`../shared/reference/vessel-models.md`, sec. 2), passed
to shipmmg's own equations; nothing of jaxship's model code runs here.

Hidden effects as in `jaxship.studies.generators`: a rudder `offset` felt and not
logged, a `current` drifting the track and in the over-ground u, v, a `gyro_bias` in
the logged r, an `added_mass` error $s_r$ scaling $I_{zG} + x_G^2 m + J_z$ by $1 + s_r$.
The noise is a model basin's (`NOISE`: heading 0.1 deg, yaw rate 0.05 deg/s, u and v
0.003 m/s, positions 0.02 m).
"""

import dataclasses

import numpy as np

from jaxship.studies.generators import DEG, TurnPilot, ZigZagPilot, logged


LENGTH = 7.0  # L_pp [m], KVLCC2 L7 model (Yasukawa & Yoshimura 2015, Table 1)
U0 = 1.179  # approach speed [m/s], Fn 0.142 (paper; SIMMAN 2008)
N_P = 11.85159  # propeller rate [rev/s] of self-propulsion at U0 (straight run: w_P = w_P0)
RUDDER_RATE = 15.8 * DEG  # [rad/s], model helm rate (SIMMAN 2008 test report, HSVA)
NOISE = (0.1, 0.05, 0.003, 0.003, 0.02)  # psi [deg], r [deg/s], u, v [m/s], x, y [m]
TRAIN = tuple((a, s) for a in (10, 20) for s in (1, -1))  # zig-zag angle [deg], side
RHO = 1025.0  # [kg/m^3]
MASS = RHO * 3.27  # m = rho nabla [kg], Table 1


@dataclasses.dataclass(frozen=True)
class KVLCC2Shipmmg:
    """The KVLCC2 L7 model in shipmmg with hidden effects (module text): `offset` [rad],
    `current` `(north, east)` [m/s], `gyro_bias` [rad/s], `added_mass` $s_r$ [-]."""

    offset: float = 0.0
    current: tuple = (0.0, 0.0)
    gyro_bias: float = 0.0
    added_mass: float = 0.0

    def params(self):
        """shipmmg's `(basic, manoeuvring)` parameters: the paper's Tables 1-4 as shipmmg's
        tests set them (SI: rho 1025 kg/m^3, masses in kg)."""
        from shipmmg.mmg_3dof import Mmg3DofBasicParams, Mmg3DofManeuveringParams

        half = 0.5 * RHO * LENGTH**2 * 0.46  # rho L^2 d / 2
        x_g, i_zg, j_z = 0.25, MASS * (0.25 * LENGTH) ** 2, 0.011 * half * LENGTH**2
        yaw = (i_zg + j_z + x_g**2 * MASS) * (1.0 + self.added_mass)  # shipmmg's yaw inertia
        basic = Mmg3DofBasicParams(
            L_pp=LENGTH, B=1.27, d=0.46, x_G=x_g, D_p=0.216, m=MASS,
            I_zG=yaw - j_z - x_g**2 * MASS, A_R=0.0539, η=0.216 / 0.345,
            m_x=0.022 * half, m_y=0.223 * half, J_z=j_z, f_α=2.747, ϵ=1.09, t_R=0.387,
            x_R=-0.500 * LENGTH, a_H=0.312, x_H=-0.464 * LENGTH, γ_R_minus=0.395,
            γ_R_plus=0.640, l_R=-0.710, κ=0.50, t_P=0.220, w_P0=0.40, x_P=-0.690)
        manoeuvring = Mmg3DofManeuveringParams(
            k_0=0.2931, k_1=-0.2753, k_2=-0.1385, R_0_dash=0.022, X_vv_dash=-0.040,
            X_vr_dash=0.002, X_rr_dash=0.011, X_vvvv_dash=0.771, Y_v_dash=-0.315,
            Y_r_dash=0.083, Y_vvv_dash=-1.607, Y_vvr_dash=0.379, Y_vrr_dash=-0.391,
            Y_rrr_dash=0.008, N_v_dash=-0.137, N_r_dash=-0.049, N_vvv_dash=-0.030,
            N_vvr_dash=-0.294, N_vrr_dash=0.055, N_rrr_dash=-0.013)
        return basic, manoeuvring

    def run(self, pilot, duration, dt=0.2):
        """The clean trajectory at `t = 0, dt, ..., duration` from the straight run at U0
        under `pilot` (`ZigZagPilot` or `TurnPilot` of `jaxship.studies.generators`): the
        rudder ramps at `RUDDER_RATE` to the order, held; a zig-zag's order reverses at
        the first sample whose heading is past the limit. Each leg is one shipmmg run
        from the state where the last one was cut. Returns `{t, u, v, r, x, y, psi,
        delta}` (u, v through the water, x, y over ground, delta as the helm sets it,
        without the offset)."""
        from shipmmg.mmg_3dof import simulate_mmg_3dof

        basic, manoeuvring = self.params()
        t = np.round(np.arange(0.0, duration + dt / 2, dt), 9)
        out = np.zeros((7, t.size))
        state, delta, start = (U0, 0.0, 0.0, 0.0, 0.0, 0.0), 0.0, 0
        order = pilot(0.0, None)
        while start < t.size - 1:
            legs = t[start:] - t[start]
            ramp = delta + np.clip(order - delta, -RUDDER_RATE * legs, RUDDER_RATE * legs)
            sol = simulate_mmg_3dof(basic, manoeuvring, t[start:], ramp + self.offset,
                                    np.full(legs.size, N_P), u0=state[0], v0=state[1],
                                    r0=state[2], x0=state[3], y0=state[4], ψ0=state[5],
                                    ρ=RHO, rtol=1e-9, atol=1e-9)
            leg = np.vstack([sol.sol(t[start:])[:6], ramp])
            psi = leg[5]
            limit = getattr(pilot, "limit", lambda held: None)(order)
            past = (np.flatnonzero(np.sign(order) * (psi - limit) >= 0) if limit is not None
                    else np.array([], int))
            past = past[past > 0]
            end = start + (past[0] if past.size else legs.size - 1)
            out[:, start:end + 1] = leg[:, :end + 1 - start]
            if not past.size:
                break
            state, delta, start = tuple(out[:6, end]), out[6, end], end
            order = pilot(out[5, end], order)
        north, east = self.current  # a uniform current drifts the track: shipmmg's own
        out[3] += north * t  # x, y are through the water (Fossen 2021, Property 10.1)
        out[4] += east * t
        names = ("u", "v", "r", "x", "y", "psi", "delta")
        return dict(t=t, **dict(zip(names, out)))


def kvlcc2_shipmmg_records(generator: KVLCC2Shipmmg, seed, *, duration=150.0, dt=0.2,
                           noise=NOISE):
    """`(train, holdout)` of `generator`: 10/10 and 20/20 zig-zags to both sides and +-35
    deg turning circles to train; +-25 deg turns and a 15/15 zig-zag held out; `duration` s
    at `1/dt` Hz, logged as `jaxship.studies.generators.logged` does (u, v over ground, n
    at N_P). The turns train because zig-zags alone leave the preset's free N_rrr' to go
    positive on these records, and the fitted base model then blows up in the held-out
    35 deg turns (measured, seed 1000, with and without a 30 % prior)."""
    rng = np.random.default_rng(seed)

    def one(pilot, name):
        return logged(generator, generator.run(pilot, duration, dt), rng, noise=noise,
                      name=name, n=N_P)

    train = [one(ZigZagPilot(a * DEG, a * DEG, s),
                 f"zigzag {a}/{a} {'starboard' if s > 0 else 'port'}") for a, s in TRAIN]
    train += [one(TurnPilot(a * DEG), f"turn {a:+d}") for a in (35, -35)]
    holdout = [one(TurnPilot(a * DEG), f"turn {a:+d}") for a in (25, -25)]
    holdout.append(one(ZigZagPilot(15 * DEG, 15 * DEG), "zigzag 15/15"))
    return train, holdout
