"""One home for what every figure of the package does before it is saved.

Each figure (the paper's Figures 1 and 2, the deciphering-time curves, the attacker comparisons,
the identification strategies, the learning curves) is drawn by its own module; this module holds
the two things they share:

- :func:`layout_problems` measures a drawn figure: tick labels of one axis that overlap each other,
  text that falls outside the saved canvas, legends drawn over the data points of their axes, and
  curves cut away entirely by the axis limits.
- :func:`plain_log_ticks` labels a log axis spanning less than two decades with plain numbers at
  1, 2 and 5 per decade (``1 2 5 10 20``) instead of matplotlib's lone ``10^1``.
- :func:`save_figure` applies it, thins tick labels that would overlap (on a log axis spanning less than a
  decade matplotlib labels every minor tick: ``2x10^1 3x10^1 4x10^1 ...``), saves the PNG and
  warns with :class:`FigureLayoutWarning` for every problem that is left, so a figure that a
  reader cannot read is never saved silently. The test suite turns that warning into an error.

Nothing here depends on the paper's equations; it is presentation only.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

__all__ = ["FigureLayoutWarning", "layout_problems", "legend_below", "plain_log_ticks", "save_figure", "thin_tick_labels"]

#: A log axis spanning fewer decades than this (and within :data:`_PLAIN_RANGE`) gets plain labels.
_PLAIN_DECADES = 2.0
#: The values whose plain spelling (``{v:g}``) is short.
_PLAIN_RANGE = (1e-2, 1e5)

#: Overlaps or overhangs smaller than this many pixels are rounding, not a problem.
_SLACK_PX = 1.0


class FigureLayoutWarning(UserWarning):
    """A saved figure has overlapping tick labels, text outside its canvas or a legend over data."""


def _visible_tick_labels(axis: Any, which: str) -> list[Any]:
    """The tick labels of ``axis`` ("major" or "minor") that are drawn: visible, non-empty and at
    a tick inside the view interval."""
    lo, hi = sorted(axis.get_view_interval())
    ticks = axis.get_major_ticks() if which == "major" else axis.get_minor_ticks()
    locs = axis.get_majorticklocs() if which == "major" else axis.get_minorticklocs()
    out = []
    for tick, loc in zip(ticks, locs):
        if not (lo <= loc <= hi) and not _close(loc, lo, hi):
            continue
        for label in (tick.label1, tick.label2):
            if label.get_visible() and label.get_text().strip():
                out.append(label)
    return out


def _close(loc: float, lo: float, hi: float) -> bool:
    span = abs(hi - lo) or 1.0
    return abs(loc - lo) <= 1e-9 * span or abs(loc - hi) <= 1e-9 * span


def _overlap(a: Any, b: Any) -> bool:
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > _SLACK_PX) and (min(a.y1, b.y1) - max(a.y0, b.y0) > _SLACK_PX)


def _overlapping_pairs(labels: list[Any], renderer: Any) -> list[tuple[Any, Any]]:
    boxes = [t.get_window_extent(renderer) for t in labels]
    return [(labels[i], labels[j]) for i in range(len(labels)) for j in range(i + 1, len(labels)) if _overlap(boxes[i], boxes[j])]


def _renderer(fig: Any) -> Any:
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def plain_log_ticks(fig: Any) -> None:
    """Label every log axis of ``fig`` that spans less than :data:`_PLAIN_DECADES` decades within
    :data:`_PLAIN_RANGE` at 1, 2 and 5 per decade with plain numbers (``5 10 20 50``); over such a
    range matplotlib shows one power of ten or none (``10^1`` alone under a curve from 5 to 40).
    Axes with a formatter of their own are left alone."""
    import math

    from matplotlib.ticker import FuncFormatter, LogFormatterSciNotation, LogLocator, NullFormatter

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() != "log" or type(axis.get_major_formatter()) is not LogFormatterSciNotation:
                continue
            lo, hi = sorted(axis.get_view_interval())
            if not (_PLAIN_RANGE[0] <= lo and hi <= _PLAIN_RANGE[1] and math.log10(hi / lo) < _PLAIN_DECADES):
                continue
            axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
            axis.set_minor_formatter(NullFormatter())


def thin_tick_labels(fig: Any) -> None:
    """Hide tick labels that would overlap: first every minor label of an axis whose labels collide,
    then every other major label until none does (the ticks themselves stay)."""
    from matplotlib.ticker import NullFormatter

    renderer = _renderer(fig)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            labels = _visible_tick_labels(axis, "major") + _visible_tick_labels(axis, "minor")
            if not _overlapping_pairs(labels, renderer):
                continue
            axis.set_minor_formatter(NullFormatter())
            renderer = _renderer(fig)
            for _ in range(8):  # each pass halves the labels: 2^8 labels is far beyond any axis
                labels = _visible_tick_labels(axis, "major")
                if not _overlapping_pairs(labels, renderer):
                    break
                for label in labels[1::2]:
                    label.set_visible(False)
                renderer = _renderer(fig)


def layout_problems(fig: Any, *, tight: bool = False) -> list[str]:
    """What a reader of the drawn ``fig`` could not read, one line each (empty: none).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, complete (it is drawn here).
    tight : bool
        The figure is saved with ``bbox_inches="tight"``: the canvas is the tight box of its
        artists, so only text outside that box (none, by construction) would be cut.

    Returns
    -------
    list of str
        Overlapping tick labels (per axis), text outside the canvas, legends over data points, and
        labelled lines none of whose points lies inside their axes.
    """
    import numpy as np
    from matplotlib.lines import Line2D
    from matplotlib.text import Text

    renderer = _renderer(fig)
    problems: list[str] = []
    for k, ax in enumerate(fig.axes):
        if not ax.get_visible() or not ax.axison:
            continue
        name = ax.get_title() or f"axes {k}"
        for axis_name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            labels = _visible_tick_labels(axis, "major") + _visible_tick_labels(axis, "minor")
            for a, b in _overlapping_pairs(labels, renderer):
                problems.append(f"{name!r}: {axis_name} tick labels {a.get_text()!r} and {b.get_text()!r} overlap")
        for line in ax.get_lines():
            if not line.get_visible() or str(line.get_label()).startswith("_"):
                continue
            xy = np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])
            xy = xy[np.isfinite(xy).all(axis=1)]
            if xy.size and not _in_bbox(line.get_transform().transform(xy), ax.bbox).any():
                problems.append(f"{name!r}: no point of {line.get_label()!r} lies inside the axes")
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            box = legend.get_window_extent(renderer)
            for line in ax.get_lines():
                if not isinstance(line, Line2D) or not line.get_visible() or str(line.get_label()).startswith("_"):
                    continue
                xy = np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])
                xy = xy[np.isfinite(xy).all(axis=1)]
                if xy.size == 0:
                    continue
                pts = line.get_transform().transform(xy)
                inside = (pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)
                # only data inside the axes counts (points cut by the limits are not drawn)
                inside &= _in_bbox(pts, ax.bbox)
                if inside.any():
                    problems.append(f"{name!r}: the legend covers {int(inside.sum())} point(s) of {line.get_label()!r}")
                    break
    if not tight:
        canvas = fig.bbox
        # tick labels exist for ticks outside the view too; only the drawn ones count
        all_ticks: set[int] = set()
        drawn: set[int] = set()
        for ax in fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                    all_ticks.update((id(tick.label1), id(tick.label2)))
                for which in ("major", "minor"):
                    drawn.update(id(t) for t in _visible_tick_labels(axis, which))
        for text in fig.findobj(Text):
            if not text.get_visible() or not text.get_text().strip() or text.figure is None:
                continue
            if id(text) in all_ticks and id(text) not in drawn:
                continue
            tb = text.get_window_extent(renderer)
            if text.get_clip_on() and text.axes is not None and not _overlap(tb, text.axes.bbox):
                continue  # a clipped text outside its axes is not drawn at all
            if (
                tb.x0 < canvas.x0 - _SLACK_PX
                or tb.y0 < canvas.y0 - _SLACK_PX
                or tb.x1 > canvas.x1 + _SLACK_PX
                or tb.y1 > canvas.y1 + _SLACK_PX
            ):
                problems.append(f"text {text.get_text()[:40]!r} lies outside the canvas")
    return problems


def _in_bbox(pts: Any, bbox: Any) -> Any:
    return (pts[:, 0] >= bbox.x0) & (pts[:, 0] <= bbox.x1) & (pts[:, 1] >= bbox.y0) & (pts[:, 1] <= bbox.y1)


def save_figure(fig: Any, path: str | Path, *, dpi: int = 110, tight: bool = False) -> Path:
    """Thin overlapping tick labels, save ``fig`` as ``path`` and warn (:class:`FigureLayoutWarning`)
    for each layout problem left (:func:`layout_problems`), short log axes labelled with plain
    numbers first (:func:`plain_log_ticks`). Returns the path."""
    plain_log_ticks(fig)
    thin_tick_labels(fig)
    problems = layout_problems(fig, tight=tight)
    path = Path(path)
    fig.savefig(path, dpi=dpi, **({"bbox_inches": "tight"} if tight else {}))
    for problem in problems:
        warnings.warn(f"{path.name}: {problem}", FigureLayoutWarning, stacklevel=2)
    return path


def legend_below(fig: Any, axes: Any, *, fontsize: float = 8, ncol: int | None = None) -> float:
    """One legend for the whole figure, below its axes, with every distinct label of ``axes``
    (an array or list of axes) once, in ``ncol`` columns or as many fewer as the figure's width
    holds; returns the fraction of the figure height it needs, for
    ``fig.tight_layout(rect=(0, that, 1, top))``."""
    import numpy as np

    handles: dict[str, Any] = {}
    for ax in np.ravel(axes):
        for h, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, h)
    if not handles:
        return 0.0
    ncol = ncol or min(len(handles), 6)
    renderer = _renderer(fig)
    while True:  # as many columns as fit the figure's width
        legend = fig.legend(
            list(handles.values()), list(handles), loc="lower center", ncol=ncol, fontsize=fontsize, frameon=False
        )
        if ncol == 1 or legend.get_window_extent(renderer).width <= 0.98 * fig.bbox.width:
            break
        legend.remove()
        ncol -= 1
    rows = -(-len(handles) // ncol)
    return min(0.45, (rows * fontsize * 1.9 + 6) / 72.0 / fig.get_figheight())
