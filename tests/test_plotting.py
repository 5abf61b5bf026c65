"""The figures a naval architect expects (issue 13): quantities on axes of their own,
legends off the data, ship outlines and the turning indices on tracks, overshoots on
zig-zags, correlation lags in seconds, spiral branches, IMO tables, reference values."""

from types import SimpleNamespace

import matplotlib


matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

import jaxship as js  # noqa: E402
from jaxship._analysis._indices import SpiralCurve, StoppingIndices  # noqa: E402
from jaxship.cli._trial_files import simulate_to_folder  # noqa: E402
from jaxship.plotting import (  # noqa: E402
    plot_comparison,
    plot_imo_criteria,
    plot_parameter_correlation,
    plot_residuals,
    plot_spiral,
    plot_trajectory,
)


DEG = np.pi / 180
L = 160.0


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def run(t, x, y, psi, r, delta, u=None, order=None, n=None):
    """A trajectory-like record (what `plot_trajectory` reads)."""
    u = np.full_like(t, 7.0) if u is None else u
    state = SimpleNamespace(x=x, y=y, psi=psi, u=u, v=np.zeros_like(t), r=r, delta=delta,
                            n=np.full_like(t, 1.5) if n is None else n)
    return SimpleNamespace(t=t, state=state, valid=np.ones_like(t, dtype=bool),
                           command=SimpleNamespace(delta=delta if order is None else order),
                           success=True)


def turning_run(side=1):
    """A straight approach of 100 s at 7 m/s, then a circle of radius 2 L at 7 m/s."""
    t = np.arange(0.0, 700.0, 1.0)
    radius, speed, t_e = 2 * L, 7.0, 100.0
    angle = np.where(t > t_e, speed * (t - t_e) / radius, 0.0)
    x = np.where(t > t_e, speed * t_e + radius * np.sin(angle), speed * t)
    y = np.where(t > t_e, side * radius * (1 - np.cos(angle)), 0.0)
    r = np.where(t > t_e, side * speed / radius, 0.0)
    delta = np.where(t >= t_e, side * 35 * DEG, 0.0)
    return run(t, x, y, side * angle, r, delta)


def zigzag_run():
    """A heading oscillation with the rudder reversed at +-10 deg (overshoots 5 deg)."""
    t = np.arange(0.0, 600.0, 0.5)
    psi = 15 * DEG * np.sin(2 * np.pi * t / 200.0)
    r = np.gradient(psi, t)
    side, order = 1.0, []
    for p in psi:
        if side > 0 and p >= 10 * DEG:
            side = -1.0
        elif side < 0 and p <= -10 * DEG:
            side = 1.0
        order.append(side * 10 * DEG)
    order = np.array(order)
    heading = np.cumsum(7.0 * 0.5 * np.cos(psi))
    return run(t, heading, np.cumsum(7.0 * 0.5 * np.sin(psi)), psi, r, order)


def data_boxes(ax):
    """Display-space points of every line drawn with data in `ax`."""
    points = []
    for line in ax.get_lines():
        xy = np.column_stack([np.asarray(line.get_xdata(), float),
                              np.asarray(line.get_ydata(), float)])
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        if xy.size:
            points.append(ax.transData.transform(xy))
    return np.concatenate(points) if points else np.zeros((0, 2))


def assert_legends_clear(fig):
    """No legend of `fig` covers a data point of any axes, nor lies inside an axes."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    assert legends
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            points = data_boxes(ax)
            inside = ((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                      & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))
            assert not np.any(inside), (legend, ax.get_ylabel())
            assert not box.overlaps(ax.get_window_extent(renderer)), ax.get_ylabel()


def axes_by_label(fig, label):
    return next(ax for ax in fig.axes if ax.get_ylabel() == label)


def texts(ax, gid):
    return [t for t in ax.texts if t.get_gid() == gid]


# --------------------------------------------------------------------------- trials


def test_trajectory_heading_and_rudder_on_axes_of_their_own():
    traj = turning_run()
    fig = plot_trajectory(traj, length=L, title="turn:35", labels=["turn"])
    heading = axes_by_label(fig, "heading [deg]")
    rudder = axes_by_label(fig, "rudder angle [deg]")
    assert heading is not rudder
    # the heading (to 750 deg) is not on the rudder's axes, which span the rudder
    low, high = rudder.get_ylim()
    assert high - low < 60 and high >= 35
    assert max(np.max(np.abs(line.get_ydata())) for line in rudder.get_lines()) <= 35 + 1e-9
    assert max(np.max(line.get_ydata()) for line in heading.get_lines()) > 700
    assert {"yaw rate [deg/s]", "speed U [m/s]"} <= {ax.get_ylabel() for ax in fig.axes}
    assert_legends_clear(fig)


def test_track_has_outlines_and_the_turning_indices_in_lengths_and_metres():
    traj = turning_run()
    ind = js.indices.turning_indices(t=traj.t, x=traj.state.x, y=traj.state.y, psi=traj.state.psi,
                             u=traj.state.u, v=traj.state.v, r=traj.state.r,
                             delta=traj.state.delta)
    np.testing.assert_allclose([ind.advance, ind.transfer, ind.tactical_diameter],
                               [2 * L, 2 * L, 4 * L], rtol=1e-3)
    fig = plot_trajectory(traj, length=L, indices=ind, outlines=6, labels=["turn"])
    track = axes_by_label(fig, "north [L]")
    outlines = [p for p in track.patches if isinstance(p, Polygon)
                and p.get_gid() == "ship-outline"]
    assert 4 <= len(outlines) <= 6
    # each outline is one ship length long (in ship lengths on these axes)
    xy = outlines[0].get_xy()
    assert np.ptp(xy[:, 1]) == pytest.approx(1.0, rel=1e-6)  # heading north at the start
    for gid, value in (("advance", 2.0), ("transfer", 2.0), ("tactical_diameter", 4.0)):
        (text,) = texts(track, gid)
        assert f"{value:.2f} L" in text.get_text() and " m)" in text.get_text()
    # both units: ship lengths on the axes, metres on the secondary axes
    assert track.get_xlabel() == "east [L]"
    labels = {a.get_ylabel() for a in track.child_axes} | {a.get_xlabel()
                                                          for a in track.child_axes}
    assert {"north [m]", "east [m]"} <= labels
    assert_legends_clear(fig)


def test_reference_values_are_drawn_and_named():
    traj = turning_run()
    ind = js.indices.turning_indices(t=traj.t, x=traj.state.x, y=traj.state.y, psi=traj.state.psi,
                             u=traj.state.u, v=traj.state.v, r=traj.state.r,
                             delta=traj.state.delta)
    fig = plot_trajectory(traj, length=L, indices=ind, reference_label="thesis",
                          reference={"tactical_diameter": (3.5 * L, 4.5 * L),
                                     "advance": 2.1 * L, "yaw_rate": (1.0 * DEG, 1.4 * DEG)})
    labels = [h for h in fig.legends[0].get_texts()]
    names = " | ".join(t.get_text() for t in labels)
    assert "thesis: tactical diameter 3.50 L" in names and "thesis: advance 2.10 L" in names
    assert "thesis: yaw rate 1 deg/s to 1.4 deg/s" in names
    rate = axes_by_label(fig, "yaw rate [deg/s]")
    assert any(p.get_label().startswith("thesis") for p in rate.patches)
    with pytest.raises(ValueError, match="unknown reference"):
        plot_trajectory(traj, reference={"overshoot": 1.0})
    with pytest.raises(ValueError, match="TurningIndices"):
        plot_trajectory(traj, reference={"advance": 1.0})


def test_zigzag_overshoots_annotated_on_the_heading_axes():
    traj = zigzag_run()
    ind = js.indices.zigzag_indices(t=traj.t, psi=traj.state.psi, delta=traj.state.delta,
                            heading_switch=10 * DEG)
    fig = plot_trajectory(traj, length=L, indices=ind, labels=["zig-zag"],
                          reference={"overshoot_1": (4 * DEG, 6 * DEG)},
                          reference_label="thesis")
    heading = axes_by_label(fig, "heading [deg]")
    (first,) = texts(heading, "overshoot_1")
    (second,) = texts(heading, "overshoot_2")
    assert f"{np.rad2deg(ind.overshoots[0]):.1f} deg" in first.get_text()
    assert "2nd overshoot" in second.get_text()
    switch = [line for line in heading.get_lines() if line.get_label() == "switch heading"]
    assert switch and switch[0].get_ydata()[0] == pytest.approx(10.0)
    assert any("thesis: 1st overshoot" in c.get_label() for c in heading.collections)
    assert_legends_clear(fig)


def test_stop_marks_head_reach_and_the_propeller():
    t = np.arange(0.0, 300.0, 1.0)
    u = np.maximum(7.0 - 0.03 * t, 0.0)
    x = np.cumsum(u)
    n = np.where(t < 5, 1.5, np.where(u > 0, -1.5, 0.0))
    traj = run(t, x, np.zeros_like(t), np.zeros_like(t), np.zeros_like(t), np.zeros_like(t),
               u=u, n=n)
    ind = js.indices.stopping_indices(t=t, x=x, y=np.zeros_like(t), psi=np.zeros_like(t), u=u, n=n)
    fig = plot_trajectory(traj, length=L, indices=ind, labels=["stop"])
    track = axes_by_label(fig, "north [L]")
    (text,) = texts(track, "head_reach")
    assert "head reach" in text.get_text() and "track reach" in text.get_text()
    assert any(ax.get_ylabel() == "propeller [rpm]" for ax in fig.axes)
    # constant signals are not drawn as rounding noise
    low, high = axes_by_label(fig, "heading [deg]").get_ylim()
    assert high - low >= 2.0
    assert_legends_clear(fig)


def test_simulate_writes_the_trial_figures(tmp_path):
    vessel = js.get_vessel("mariner")
    indices = simulate_to_folder(vessel, "zigzag:10/10", tmp_path, title="mariner 10/10")
    assert (tmp_path / "trial.png").is_file() and (tmp_path / "imo_criteria.png").is_file()
    assert [row["criterion"] for row in indices["imo_criteria"]] == [
        "yaw checking: 1st overshoot, 10/10 zig-zag",
        "course keeping: 2nd overshoot, 10/10 zig-zag"]


# --------------------------------------------------------------------------- spirals and IMO


def test_spiral_draws_both_branches_and_the_loop():
    levels = np.concatenate([np.arange(25, -26, -5), np.arange(-20, 26, 5)]) * DEG
    r = np.array([2.935, 2.748, 2.507, 2.180, 1.676, 0.094, -2.095, -2.478, -2.741, -2.939,
                  -3.091, -2.939, -2.741, -2.478, -2.094, -1.158, 1.678, 2.182, 2.508,
                  2.749, 2.935]) * DEG
    curve = SpiralCurve(delta=levels, r=r, kind="direct")
    reverse = SpiralCurve(delta=np.array([5.0, 0.4, 0.1, 0.3, -1.0]) * DEG,
                          r=np.array([1.6, 0.6, 0.0, -0.6, -1.6]) * DEG, kind="reverse")
    fig = plot_spiral(curve, reverse=reverse, ordered=reverse.r, title="KVLCC2 spiral",
                      reference=curve, reference_label="thesis")
    ax = fig.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert "direct spiral: to port (from starboard)" in labels
    assert "direct spiral: back to starboard" in labels
    assert "reverse spiral" in labels and "thesis: to port (from starboard)" in labels
    (loop,) = [line for line in ax.get_lines() if line.get_gid() == "loop"]
    assert "loop width 5.00 deg" in loop.get_label()
    assert any(p.get_label().startswith("loop") for p in ax.patches)
    assert ax.get_xlabel().startswith("rudder angle [deg]")
    assert ax.get_ylabel().startswith("steady yaw rate [deg/s]")
    assert_legends_clear(fig)


def test_imo_criteria_table():
    rows = js.indices.imo_criteria(L, 7.7, stopping=StoppingIndices(2800.0, 3100.0, 50.0, 400.0,
                                                               0.0))
    fig = plot_imo_criteria(rows)
    table = fig.axes[0].tables[0]
    cells = table.get_celld()
    assert cells[(1, 0)].get_text().get_text() == "stopping: track reach, full astern"
    assert cells[(0, 3)].get_text().get_text() == "margin"
    assert cells[(1, 3)].get_text().get_text() == "-4.38"  # 15 L - 19.4 L: missed
    assert cells[(1, 4)].get_text().get_text() == "FAIL"  # 19.4 L > 15 L


# --------------------------------------------------------------------------- identification


def correlation(lags, values):
    return SimpleNamespace(lags=np.asarray(lags), values=np.asarray(values), band=0.2,
                           passed=True, statistic=1.0, threshold=2.0)


def assessment(title_name="record with a long name"):
    """An identification assessment of two records sampled every 0.5 s."""
    t = np.tile(np.arange(0.0, 100.0, 0.5), (2, 1))
    r = 0.01 * np.sin(t / 10.0)
    psi = np.cumsum(r, axis=1) * 0.5
    delta = 0.1 * np.sign(np.sin(t / 10.0))
    data = SimpleNamespace(t=t, lengths=[200, 200], names=[title_name, "second"], r=r,
                           psi=psi, delta=delta)
    lags = np.arange(0, 26)
    report = SimpleNamespace(autocorrelation=correlation(lags, np.exp(-lags / 5.0)),
                             cross_correlation=correlation(lags - 12, 0.05 * np.ones(26)),
                             fit_per_experiment=np.array([91.2, 88.0]))
    return SimpleNamespace(data=data, rudder="delta", kind="simulation",
                           predictions={"psi": psi * 1.01, "r": r * 0.99},
                           mask=np.ones_like(t, dtype=bool),
                           metrics={"psi": report, "r": report})


def test_residual_correlation_lags_in_seconds():
    fig = plot_residuals(assessment())
    acf = [ax for ax in fig.axes if "autocorrelation" in ax.get_title()]
    assert acf and all(ax.get_xlabel() == "lag [s]" for ax in acf)
    stems = acf[0].collections[-1]  # the vlines at each lag
    x = np.concatenate([seg[:, 0] for seg in stems.get_segments()])
    np.testing.assert_allclose(np.unique(x), np.arange(0, 26) * 0.5)  # 0.5 s samples
    band = [p for p in acf[0].patches if p.get_label() == "99 % band"]
    assert band
    assert_legends_clear(fig)


def test_comparison_fit_in_the_legend_and_a_title_that_fits():
    long = ("MMGVessel on train record kvlcc2_turn35_starboard_500rpm_measured "
            "(simulation from the measured start)")
    fig = plot_comparison(assessment(), 0, title=long, reference={"r": (85.0, 93.1)},
                          reference_label="thesis")
    r_axes = axes_by_label(fig, "yaw rate [deg/s]")
    legend = [t.get_text() for t in r_axes.get_legend().get_texts()]
    assert "model, fit 91.2 %" in legend and "thesis: fit 85.0 % to 93.1 %" in legend
    assert_legends_clear(fig)
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert box.x0 >= 0 and box.x1 <= fig.bbox.x1  # not clipped


def assert_inside(fig):
    """Every legend and title of `fig` lies inside the figure (its fixed layout leaves room
    for them)."""
    fig.canvas.draw()
    texts = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend()),
             *(ax.title for ax in fig.axes), fig._suptitle]
    for artist in texts:
        box = artist.get_window_extent()
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.x1, artist
        assert box.y1 <= fig.bbox.y1, artist
    for ax in fig.axes:  # the y axes' labels, of any width, not cut off
        assert ax.yaxis.get_tightbbox().x0 >= 0, ax.get_ylabel()


def test_identification_figures_leave_room_for_their_legends_and_titles():
    small = assessment("a record with a name of sixty characters, 012345678")
    small.data.r, small.predictions["r"] = small.data.r / 80, small.predictions["r"] / 80
    fig = plot_comparison(small, 0, title="x " * 120, reference={"r": (85.0, 93.1)},
                          reference_label="a reference of a long name")
    assert_legends_clear(fig)
    assert_inside(fig)
    fig = plot_residuals(small, title="x " * 120)
    assert_legends_clear(fig)
    assert_inside(fig)
    fig = plot_parameter_correlation(["K", "a parameter of a long name"], np.eye(2),
                                     title="x " * 40)
    assert_inside(fig)
    labels = [t.get_window_extent() for t in fig.axes[0].get_yticklabels()]
    assert min(box.x0 for box in labels) >= 0  # the names are not cut off


def pixels(fig):
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba()).copy()


def test_a_figure_drawn_again_is_a_new_figure():
    """`save_identification_figures` draws the figures of one shape into one figure object,
    emptied each time (issue 70): the pixels are a new figure's."""
    from jaxship.plotting._common import _emptied
    from jaxship.plotting._fits import (
        _comparison_figure,
        _draw_comparison,
        _draw_residuals,
        _residual_figure,
    )

    first, second = assessment(), assessment()
    first.metrics["r"] = SimpleNamespace(**{**vars(first.metrics["r"]),
                                            "cross_correlation": None})
    # a shorter record of smaller values: the axes' limits shrink
    second.kind, second.data.names, second.data.t = "prediction", ["c", "d"], second.data.t / 2
    second.data.r, second.data.psi = second.data.r / 10, second.data.psi / 10
    second.predictions = {c: p / 10 for c, p in second.predictions.items()}
    fig = _comparison_figure(2)
    _draw_comparison(fig, first, 0, title="first")
    pixels(fig)
    _draw_comparison(_emptied(fig), second, 1, title="second")
    new = plot_comparison(second, 1, title="second")
    np.testing.assert_array_equal(pixels(fig), pixels(new))
    fig = _residual_figure(2)
    _draw_residuals(fig, first, title="first")
    pixels(fig)
    _draw_residuals(_emptied(fig), second, title="second")
    np.testing.assert_array_equal(pixels(fig), pixels(plot_residuals(second, title="second")))


def test_parameter_correlation_heat_map():
    corr = np.array([[1.0, 0.9, np.nan], [0.9, 1.0, -0.2], [np.nan, -0.2, 1.0]])
    fig = plot_parameter_correlation(["a", "b", "c"], corr, title="correlation")
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.texts][:3] == ["+1.00", "+0.90", "n/a"]
    assert len(fig.axes) == 2  # the heat map and its colour bar


def test_the_trial_figure_gives_the_rudder_its_own_axis_and_keeps_thesis_ranges_off_the_data():
    """`reproduce`'s trial figures: the heading ran to 1600 deg on the axis of a +-40 deg
    rudder, which drew the rudder flat; the thesis figures' axis ranges were hatched over
    the data and read as tolerance bands. Now the rudder has its own axis, and a range is
    a bar beside the axes."""
    from jaxship.plotting._report import plot_trial_vs_thesis

    vessel = js.get_vessel("thesis")
    traj = js.simulate(vessel, js.Turn(np.deg2rad(40.0), duration=60.0),
                       js.straight_run(vessel, n=500.0 / 60))
    fig = plot_trial_vs_thesis(traj, bands={"yaw_rate": [(0.0, 6.0, "axis 0-6 deg/s")]})
    labels = {ax.get_ylabel() for ax in fig.axes}
    assert {"heading [deg]", "rudder [deg]", "yaw rate [deg/s]"} <= labels
    rudder = next(ax for ax in fig.axes if ax.get_ylabel() == "rudder [deg]")
    assert rudder.get_ylim()[1] < 60.0  # scaled to the rudder, not to the heading
    rate = next(ax for ax in fig.axes if ax.get_ylabel() == "yaw rate [deg/s]")
    assert not rate.patches  # no shaded span over the data
    bar = next(line for line in rate.lines if line.get_label() == "axis 0-6 deg/s")
    assert not bar.get_clip_on() and min(bar.get_xdata()) > 1.0  # outside the axes
    plt.close(fig)
