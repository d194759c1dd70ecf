"""Plots of ``pipeline run`` compared by content: the data on each panel, labels, size, metadata."""
from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from pipeline.reports.figures import record as plots
from pipeline.batch.record import _process
from pipeline.batch.tasks import Column, Options
from pipeline.batch.runner import make_tasks
from pulses import G

from .test_pipeline_run import write_good


def _png_info(png: bytes):
    with Image.open(io.BytesIO(png)) as im:
        return im.format, im.size, dict(im.info)


@pytest.mark.slow
def test_record_figure_draws_the_record_its_pulses_and_rotations(tmp_path):
    """Each panel holds what the run computed: the record and the fitted pulses in g, theta / alpha
    of each column with the alpha lines, the verdicts in the legends, one time axis."""
    path = write_good(tmp_path, 4)
    task, = make_tasks([str(path)], [Column(7.5, 1.8), Column(6.0, 1.2)], Options())
    record, fit, fitting, histories, _velocity = _process(task)[1]
    assert fitting and len(histories) == 2
    fig = plots.record_figure(task.record_id, record, fit, fitting, histories)
    top, *panels = fig.axes
    assert len(panels) == 2
    # record panel: the record (fewer samples than MAX_POINTS: drawn unthinned, so exactly equal)
    # and every fitted pulse evaluated on the record's time base
    assert record.time.size < plots.MAX_POINTS
    lines = top.get_lines()
    assert len(lines) == 1 + len(fitting)
    np.testing.assert_array_equal(lines[0].get_xdata(), record.time)
    np.testing.assert_array_equal(lines[0].get_ydata(), record.acc / G)
    for line, c in zip(lines[1:], fitting):
        np.testing.assert_array_equal(line.get_ydata(), c.pulse(record.time) / G)
    legend = [t.get_text() for t in top.get_legend().get_texts()]
    assert legend[0] == "record"
    for text, c in zip(legend[1:], fitting):
        assert text.startswith(f"{c.shape}: ap {c.ap / G:+.3g} g, Tp {c.tp:.3g} s")
    assert top.get_title().startswith(task.record_id)
    # rotation panels: theta / alpha of each curve, the +-1 lines, the verdict in the legend
    for ax, (label, curves) in zip(panels, histories):
        assert label in ax.get_title()
        drawn = ax.get_lines()
        for line, (_, block, res) in zip(drawn, curves):
            np.testing.assert_array_equal(line.get_ydata(), np.asarray(res.theta) / block.alpha)
        assert sorted(tuple(line.get_ydata()) for line in drawn[len(curves):]) == [(-1.0, -1.0), (1.0, 1.0)]
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        for text, (_, _, res) in zip(texts, curves):
            r = res.max_rotation_ratio
            # a curve that passes its slenderness angle (and comes back) says so
            assert text.endswith("overturns" if res.overturned else
                                 f"passes alpha, max {r:.4g} alpha" if r >= 1 else f"max {r:.3g} alpha")
    # one time axis: the record's span on every panel, tick labels on the bottom one only
    for ax in fig.axes:
        assert ax.get_xlim() == (record.t_start, record.t_start + record.duration)
    assert fig.axes[-1].get_xlabel() == "time (s)"
    # the PNG: readable size, no software metadata (matplotlib writes no date into a PNG)
    png = plots.record_figure_png(task.record_id, record, fit, fitting, histories)
    fmt, (width, _), info = _png_info(png)
    assert fmt == "PNG" and width >= 1000
    assert not {k for k in info if k.lower() in ("software", "creation time", "date")}


def _text_boxes(fig):
    """Window extents (pixels) of the figure's visible, non-empty texts, by kind."""
    fig.draw_without_rendering()
    boxes = {"title": [], "ylabel": [], "yticks": [], "other": []}
    for ax in fig.axes:
        boxes["title"].append(ax.title.get_window_extent())
        boxes["ylabel"].append(ax.yaxis.label.get_window_extent())
        boxes["yticks"] += [t.get_window_extent() for t in ax.get_yticklabels() if t.get_text()]
        boxes["other"] += [t.get_window_extent() for t in [*ax.get_xticklabels(), ax.xaxis.label,
                                                           ax.yaxis.get_offset_text()]
                           if t.get_visible() and t.get_text()]
    return boxes


@pytest.mark.slow
def test_record_figure_labels_inside_and_apart(tmp_path):
    """The record figure's margins are fixed in inches: every label stays inside the figure and off
    the others, also with wide tick labels (a weak record: ticks like -0.010) and one column."""
    path = write_good(tmp_path, 4)
    task, = make_tasks([str(path)], [Column(7.5, 1.8), Column(6.0, 1.2)], Options())
    record, fit, fitting, histories, _velocity = _process(task)[1]
    figures = [plots.record_figure(task.record_id, record, fit, fitting, histories),
               plots.record_figure(task.record_id, record.scaled(0.02), fit, [], histories[:1])]
    assert [t.get_text() for t in figures[1].axes[0].get_yticklabels()][1].startswith("\N{MINUS SIGN}0.0")
    for fig in figures:
        boxes = _text_boxes(fig)
        inside = fig.bbox
        every = [b for kind in boxes.values() for b in kind]
        for b in every:
            assert inside.x0 <= b.x0 and b.x1 <= inside.x1 and inside.y0 <= b.y0 and b.y1 <= inside.y1
        for label in boxes["ylabel"]:
            assert not any(label.overlaps(b) for b in boxes["yticks"])
        for i, title in enumerate(boxes["title"]):
            assert not any(title.overlaps(ax.bbox) for ax in fig.axes)
            assert not any(title.overlaps(b) for b in every if b is not title)
        # y labels aligned (placed by the widest tick labels)
        assert len({round(b.x0, 6) for b in boxes["ylabel"]}) == 1


def test_long_records_are_thinned_for_drawing_only():
    """A record longer than MAX_POINTS samples is drawn with every k-th sample (k the smallest step
    that fits), first sample kept."""
    t = np.arange(2 * plots.MAX_POINTS + 3) * 0.01
    tt, yy = plots._thin(t, np.sin(t))
    assert tt.size <= plots.MAX_POINTS and tt.size == t[::3].size
    np.testing.assert_array_equal(yy, np.sin(t)[::3])


@pytest.mark.slow
def test_summary_figure_plots_the_rows():
    """The summary's points are the rows' numbers: required against actual tan(alpha) for columns as
    they stand, split by verdict, and the design width's against Eq. 31's for every row."""
    rows = [
        {"column_kind": "block", "tan_alpha": 0.24, "governing_eq31_tan_alpha": 0.2, "design_tan_alpha": 0.18,
         "overturns": False, "eq31_width_tan_alpha": 0.2, "eq31_width_overturns": False},
        {"column_kind": "block", "tan_alpha": "0.15", "governing_eq31_tan_alpha": "0.3",
         "design_tan_alpha": "0.33", "overturns": True, "eq31_width_tan_alpha": "0.3",
         "eq31_width_overturns": True},
        {"column_kind": "height", "tan_alpha": "", "eq31_width_tan_alpha": 0.25, "design_tan_alpha": 0.21,
         "eq31_width_overturns": False},
    ]
    fig = plots.summary_figure(rows)
    ax1, ax2 = fig.axes
    eq31, survives, overturns = (c.get_offsets() for c in ax1.collections)
    np.testing.assert_array_equal(eq31, [[0.24, 0.2], [0.15, 0.3]])
    np.testing.assert_array_equal(survives, [[0.24, 0.18]])
    np.testing.assert_array_equal(overturns, [[0.15, 0.33]])
    ok, bad = (c.get_offsets() for c in ax2.collections)
    np.testing.assert_array_equal(ok, [[0.2, 0.18], [0.25, 0.21]])
    np.testing.assert_array_equal(bad, [[0.3, 0.33]])
    # 10 % above the largest value on both axes, so the 1:1 line spans the panel
    assert np.isclose(ax1.get_xlim()[1], 1.1 * 0.33) and np.isclose(ax2.get_ylim()[1], 1.1 * 0.33)
    png = plots.summary_figure_png(rows)
    fmt, (width, _), info = _png_info(png)
    assert fmt == "PNG" and width >= 1000 and "Software" not in info
    assert plots.summary_figure_png(rows) == png  # a re-run: the same bytes


def test_summary_figure_without_columns_says_so():
    fig = plots.summary_figure([])
    assert [t.get_text() for t in fig.axes[0].texts] == ["no column as it stands (--block) in this run"]
    assert fig.axes[0].get_legend() is None and fig.axes[1].get_legend() is None


@pytest.mark.slow
def test_record_figure_velocity_pulse_and_design_width(tmp_path):
    """The run's figure adds the record's velocity with the extracted velocity pulse (the
    classification's own arrays), the column at its design width (the row's width) and, under
    the default level, at the verge beside it (the row's overturning width)."""
    import pulses

    path = write_good(tmp_path, 4)
    task, = make_tasks([str(path)], [Column(7.5, 1.8)], Options())
    rows, (record, fit, fitting, histories, _velocity), _designs, _friction = _process(task)
    (label, curves), = histories
    assert [c[0].split(",")[0] for c in curves] == ["as it stands", "Eq. 31 design", "design width", "verge"]
    _, block_v, res_v = curves[2]
    assert block_v.width == pytest.approx(rows[0]["design_width_m"], rel=1e-12)
    assert not res_v.overturned and res_v.max_rotation_ratio <= 0.5  # the design width keeps the level
    assert curves[3][1].width == pytest.approx(rows[0]["overturning_width_m"], rel=1e-12)
    cls = pulses.classify_pulse(record)
    fig = plots.record_figure(task.record_id, record, fit, fitting, histories, velocity=cls)
    top, vel, rot = fig.axes
    ground, pulse = vel.get_lines()[:2]
    np.testing.assert_array_equal(ground.get_ydata(), cls.velocity)
    np.testing.assert_array_equal(pulse.get_ydata(), cls.pulse)
    assert f"Tp {cls.tp:.3g} s" in vel.get_legend().get_texts()[1].get_text()
    assert len(rot.get_legend().get_texts()) == 4
    # the run's figure is this one, drawn the same way every time
    png = plots.run_figure_png(task.record_id, record, fit, fitting, histories)
    assert png == plots.record_figure_png(task.record_id, record, fit, fitting, histories, velocity=cls)
    assert _png_info(png)[1][1] > _png_info(plots.record_figure_png(task.record_id, record, fit, fitting,
                                                                     histories))[1][1]
