"""Plots of ``pipeline run`` (matplotlib, Agg backend, no display needed).

Figures are rendered to PNG bytes (so a worker on another machine can make them and the main process
writes them atomically) with no software-version or time metadata, so re-runs give identical files.
"""
from __future__ import annotations

import math
import struct
import threading
import zlib
from typing import ClassVar

import matplotlib as mpl
import numpy as np

# imported here, not on first use: ``pipeline run`` preloads this module in the fork server (its
# workers then start with matplotlib loaded) and in a thread of the main process (for the summary)
from matplotlib import cbook
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import (
    FigureCanvasAgg,
    RendererAgg,
    get_hinting_flag,
)
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.ft2font import RenderMode
from matplotlib.lines import Line2D
from matplotlib.markers import TICKDOWN, TICKLEFT
from matplotlib.patches import FancyBboxPatch
from matplotlib.ticker import AutoLocator, NullFormatter, NullLocator, ScalarFormatter
from matplotlib.transforms import IdentityTransform

#: at most this many points per curve (long records are thinned for drawing only)
MAX_POINTS = 20000
#: resolution of the PNGs (8 in wide: 640 px)
DPI = 80


class _TextRenderer(RendererAgg):
    """Agg renderer with cached text: the same pixels for the same string, a process draws it once.

    matplotlib (3.11) shapes every string with HarfBuzz and renders every glyph with FreeType's
    autohinter on each draw, twice per string (metrics, then drawing): ~0.6 ms a string of 40
    characters, and half the cost of a record figure.  Here a string is laid out from per-character
    advances (hinted, whole pixels, as matplotlib's) plus per-pair kerning (what matplotlib's layout
    gives for the pair), and drawn as one bitmap composed from glyph bitmaps rendered once per
    glyph, size, angle and quarter-pixel position (matplotlib: 1/64 px; a quarter pixel is
    invisible at 80 dpi).  Every cached value is a pure function of its key, so a figure's pixels
    do not depend on what the process drew before.  Math text, font fallback (a character the font
    lacks), font features or languages, and blank strings go through matplotlib's own path.

    Fonts are keyed by their properties (family, style, ..., size), not by the font file they
    resolve to: the rcParams that resolve them are not changed while ``pipeline`` runs.
    """

    #: (font key, char) -> (glyph index, advance, inked, ink x0, x1, y0, y1) in pixels
    _chars: ClassVar[dict] = {}
    #: (font key, char pair) -> kerning in pixels
    _kerns: ClassVar[dict] = {}
    #: (font key, string) -> (glyphs [(glyph index, x)], width, height, descent), None: fallback
    _strings: ClassVar[dict] = {}
    #: (font key, glyph, angle, x quarter, y quarter, antialiased) -> bitmap, left, top
    _glyphs: ClassVar[dict] = {}
    #: (font key, string, angle, x quarter, y quarter, antialiased) -> bitmap, left, top
    _bitmaps: ClassVar[dict] = {}
    #: font key -> (ascent, descent, line gap) in pixels
    _heights: ClassVar[dict] = {}
    #: caches are cleared past this many entries (bounded memory in long runs)
    MAX_ENTRIES = 20000

    def _key(self, prop):
        return (tuple(prop.get_family()), prop.get_style(), prop.get_variant(), prop.get_weight(),
                prop.get_stretch(), prop.get_file(), prop.get_size_in_points(), self.dpi,
                mpl.rcParams["text.hinting"])

    def _font(self, prop):
        """The FT2Font of ``prop`` at its size and the hinting flags."""
        return self._prepare_font(prop), get_hinting_flag()

    @classmethod
    def _store(cls, cache, key, value):
        if len(cache) > cls.MAX_ENTRIES:
            cache.clear()
        cache[key] = value
        return value

    def _layout(self, s, prop, mtext=None):
        """(font key, (glyphs, width, height, descent)) for ``s``, or None for matplotlib's path."""
        if mtext is not None and (mtext.get_fontfeatures() is not None or mtext.get_language() is not None):
            return None
        key = self._key(prop)
        lay = self._strings.get((key, s), False)
        if lay is False:
            lay = self._store(self._strings, (key, s), self._new_layout(key, prop, s))
        return None if lay is None else (key, lay)

    def _new_layout(self, key, prop, s):
        if not s.strip():
            return None
        font, flags = self._font(prop)
        chars = []
        for c in s:
            info = self._chars.get((key, c))
            if info is None:
                gi = font.get_char_index(ord(c))
                if gi == 0:
                    return None  # not in this font: matplotlib's fallback fonts
                g = font.load_glyph(gi, flags)
                x0 = g.horiBearingX / 64
                y1 = g.horiBearingY / 64
                info = self._store(self._chars, (key, c), (
                    gi, g.horiAdvance / 64, g.width > 0 and g.height > 0, x0, x0 + g.width / 64,
                    y1 - g.height / 64, y1))
            chars.append(info)
        glyphs, x = [], 0.0
        xmin = ymin = math.inf
        xmax = ymax = -math.inf
        for i, (gi, adv, ink, x0, x1, y0, y1) in enumerate(chars):
            if i:
                kern = self._kerns.get((key, s[i - 1:i + 1]))
                if kern is None:
                    items = font._layout(s[i - 1:i + 1], flags=flags)
                    kern = self._store(self._kerns, (key, s[i - 1:i + 1]), (
                        items[1].x - items[0].x - chars[i - 1][1] if len(items) == 2 else 0.0))
                x += kern
            if ink:
                glyphs.append((gi, x))
                xmin, xmax = min(xmin, x + x0), max(xmax, x + x1)
                ymin, ymax = min(ymin, y0), max(ymax, y1)
            x += adv
        if not glyphs:
            return None
        return glyphs, xmax - xmin, ymax - ymin, -ymin

    def get_text_width_height_descent(self, s, prop, ismath):
        if not ismath:
            found = self._layout(s, prop)
            if found is not None:
                return found[1][1:]
        return super().get_text_width_height_descent(s, prop, ismath)

    def _glyph(self, key, prop, gi, angle, fx, fy, aa):
        """(coverage bitmap, left, top) of a glyph with its pen at (fx, fy) quarter pixels, y up."""
        bitmap = self._glyphs.get((key, gi, angle, fx, fy, aa))
        if bitmap is None:
            font, flags = self._font(prop)
            cos, sin = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            font._set_transform((0x10000 * np.array([[cos, -sin], [sin, cos]])).round().astype(int),
                                [16 * fx, 16 * fy])
            g = font._render_glyph(gi, flags, RenderMode.NORMAL if aa else RenderMode.MONO)
            buf = np.array(g.buffer, dtype=np.uint8)
            if not aa:
                buf *= 0xff
            bitmap = self._store(self._glyphs, (key, gi, angle, fx, fy, aa), (buf, g.left, g.top))
        return bitmap

    def _string_bitmap(self, key, prop, s, glyphs, angle, fx, fy, aa):
        """(coverage bitmap, left, top) of a string with its origin at (fx, fy) quarter pixels."""
        found = self._bitmaps.get((key, s, angle, fx, fy, aa))
        if found is not None:
            return found
        cos, sin = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        placed = []
        for gi, dx in glyphs:
            ix, gx = divmod(fx + round(4 * dx * cos), 4)
            iy, gy = divmod(fy + round(4 * dx * sin), 4)
            buf, left, top = self._glyph(key, prop, gi, angle, gx, gy, aa)
            if buf.size:
                placed.append((buf, ix + left, iy + top))  # columns right, rows up
        if not placed:
            found = (np.zeros((0, 0), np.uint8), 0, 0)
        else:
            x0 = min(p[1] for p in placed)
            x1 = max(p[1] + p[0].shape[1] for p in placed)
            top = max(p[2] for p in placed)
            bottom = min(p[2] - p[0].shape[0] for p in placed)
            out = np.zeros((top - bottom, x1 - x0), np.uint16)
            for buf, left, gtop in placed:
                r, c = top - gtop, left - x0
                sub = out[r:r + buf.shape[0], c:c + buf.shape[1]]
                # coverage of two glyphs on a pixel as Agg blends them: a + b - a b
                sub += buf - (sub * buf + 127) // 255
            found = (out.astype(np.uint8), x0, top)
        return self._store(self._bitmaps, (key, s, angle, fx, fy, aa), found)

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        found = None if ismath else self._layout(s, prop, mtext)
        if found is None:
            return super().draw_text(gc, x, y, s, prop, angle, ismath, mtext)
        key, (glyphs, *_) = found
        # origin in quarter pixels, y upwards (FreeType's)
        ix, fx = divmod(round(4 * x), 4)
        iy, fy = divmod(round(4 * (self.height - y)), 4)
        buf, left, top = self._string_bitmap(key, prop, s, glyphs, angle, fx, fy,
                                             bool(gc.get_antialiased()))
        if buf.size:
            self._renderer.draw_text_image(buf, ix + left, int(self.height) - (iy + top) + buf.shape[0],
                                           0, gc)

    def _get_font_height_metrics(self, prop):
        """Ascent, descent and line gap of the font (what ``Text._get_layout`` reads from the font's
        tables on every draw), cached."""
        key = self._key(prop)
        found = self._heights.get(key)
        if found is None:
            from matplotlib.font_manager import fontManager, get_font

            found = (None, None, None)
            font = get_font(fontManager._find_fonts_by_props(prop))
            for table, gap, ascent, descent in [("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
                                                ("hhea", "lineGap", "ascent", "descent")]:
                t = font.get_sfnt_table(table)
                if t is not None:
                    scale = key[6] * self.dpi / 72 / font.get_sfnt_table("head")["unitsPerEm"]
                    found = (t[ascent] * scale, -t[descent] * scale, t[gap] * scale)
                    break
            self._store(self._heights, key, found)
        return found


class _Canvas(FigureCanvasAgg):
    """Agg canvas drawing with :class:`_TextRenderer`."""

    def get_renderer(self):
        w, h = self.get_width_height(physical=True)
        key = w, h, self.figure.dpi
        if self._lastKey != key:
            self.renderer = _TextRenderer(w, h, self.figure.dpi)
            self._lastKey = key
        return self.renderer


def _figure(figsize):
    """A new figure on the Agg canvas (no pyplot: nothing global to register or close)."""
    fig = Figure(figsize=figsize, dpi=DPI)
    _Canvas(fig)
    return fig


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _png(fig) -> bytes:
    """PNG bytes of the figure drawn on its Agg canvas: 8-bit RGB (RGBA if any pixel is not
    opaque), no metadata (re-runs give the same bytes), rows unfiltered, zlib level 1.

    Written here rather than by ``savefig`` (Pillow, adaptive row filters): 4 ms instead of 10
    for a record figure, files as large (these plots are mostly flat colour)."""
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    h, w = rgba.shape[:2]
    opaque = bool((rgba[:, :, 3] == 255).all())
    pixels = rgba[:, :, :3] if opaque else rgba
    rows = np.empty((h, 1 + pixels.shape[2] * w), np.uint8)
    rows[:, 0] = 0  # filter type None
    rows[:, 1:].reshape(pixels.shape)[...] = pixels
    header = struct.pack(">IIBBBBB", w, h, 8, 2 if opaque else 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", header)
            + _png_chunk(b"IDAT", zlib.compress(rows, 1)) + _png_chunk(b"IEND", b""))


def _thin(t, y):
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size > MAX_POINTS:
        step = int(math.ceil(t.size / MAX_POINTS))
        t, y = t[::step], y[::step]
    return t, y


#: most fitted pulses drawn on a record (``pipeline run`` keeps the shapes within FIT_TOLERANCE of
#: the best: at most one per shape, four shapes)
MAX_PULSES = 4
#: most curves per rotation-history panel (the column as it stands and the Eq. 31 design)
MAX_CURVES = 2
_PULSE_STYLES = ["-", "--", "-.", ":"]


class _Labels(Artist):
    """Strings drawn straight by the renderer at positions given in pixels (one artist for all the
    tick labels of an axes, or all the texts of a legend): what a ``Text`` per string costs is
    its layout machinery (~0.2 ms), here positions are computed once by :meth:`place`."""

    def __init__(self, size, zorder):
        super().__init__()
        self.prop = FontProperties(size=size)
        self.items = []  # (x, y of the baseline, from the bottom, in pixels; string; math)
        self.set_zorder(zorder)

    def metrics(self, renderer, s):
        """(width, ascent, descent) as matplotlib's ``Text`` lays out one line ('normal' spacing)."""
        math_ = cbook.is_math_text(s)
        w, h, d = renderer.get_text_width_height_descent(s, self.prop, math_)
        ascent, descent, _ = renderer._get_font_height_metrics(self.prop)
        if ascent is None:
            return w, h - d, d
        return w, max(h - d, ascent), max(d, descent)

    def place(self, renderer, items):
        """``items``: ``[(x, y, string, ha, va)]`` in pixels; ha left/center/right, va
        top/baseline/center_baseline (matplotlib's meanings)."""
        self.items = []
        for x, y, s, ha, va in items:
            w, a, _ = self.metrics(renderer, s)
            x -= {"left": 0.0, "center": w / 2, "right": w}[ha]
            y -= {"top": a, "baseline": 0.0, "center_baseline": a / 2}[va]
            self.items.append((x, y, s, cbook.is_math_text(s)))
        self.stale = True

    def draw(self, renderer):
        if not self.get_visible() or not self.items:
            return
        gc = renderer.new_gc()
        gc.set_foreground(mpl.rcParams["text.color"])
        gc.set_antialiased(mpl.rcParams["text.antialiased"])
        for x, y, s, math_ in self.items:
            renderer.draw_text(gc, x, renderer.height - y, s, self.prop, 0.0, ismath=math_)
        gc.restore()
        self.stale = False


class _Legend:
    """A legend (upper right of an axes) laid out as matplotlib's with its default settings, from
    a frame, one handle line per entry and one :class:`_Labels`: a ``Legend`` lays out through
    nested packers on every draw (~2 ms)."""

    FONTSIZE = 7
    #: matplotlib's legend defaults, in font sizes
    BORDERPAD, LABELSPACING, HANDLELENGTH, HANDLETEXTPAD, BORDERAXESPAD = 0.4, 0.5, 2.0, 0.8, 0.5

    def __init__(self, ax, lines):
        self.ax = ax
        self.frame = FancyBboxPatch((0, 0), 1, 1, boxstyle="round,pad=0,rounding_size=0.2",
                                    facecolor=mpl.rcParams["axes.facecolor"],
                                    edgecolor=mpl.rcParams["legend.edgecolor"], alpha=0.8, snap=True,
                                    transform=IdentityTransform(), zorder=5)
        self.handles = []
        for line in lines:
            h = Line2D([], [], zorder=5.01)
            h.update_from(line)  # copies transform, clipping and visibility too: set below
            h.set_transform(IdentityTransform())
            h.set_visible(True)
            self.handles.append(h)
        self.labels = _Labels(self.FONTSIZE, zorder=5.02)
        for a in (self.frame, *self.handles, self.labels):
            ax.add_artist(a)
            a.set_clip_on(False)

    def show(self, renderer, texts):
        self.frame.set_visible(bool(texts))
        if not texts:  # no entry: no legend
            for h in self.handles:
                h.set_visible(False)
            self.labels.place(renderer, [])
            return
        fs = renderer.points_to_pixels(self.FONTSIZE)
        metrics = [self.labels.metrics(renderer, s) for s in texts]
        row = max(a for _, a, _ in metrics) + max(d for *_, d in metrics)
        width = ((2 * self.BORDERPAD + self.HANDLELENGTH + self.HANDLETEXTPAD) * fs
                 + max(w for w, *_ in metrics))
        height = 2 * self.BORDERPAD * fs + len(texts) * row + (len(texts) - 1) * self.LABELSPACING * fs
        bbox = self.ax.bbox
        x1, y1 = bbox.x1 - self.BORDERAXESPAD * fs, bbox.y1 - self.BORDERAXESPAD * fs
        x0 = x1 - width
        self.frame.set_bounds(x0, y1 - height, width, height)
        self.frame.set_mutation_scale(fs)
        items = []
        for i, h in enumerate(self.handles):
            h.set_visible(i < len(texts))
            if i < len(texts):
                base = y1 - self.BORDERPAD * fs - i * (row + self.LABELSPACING * fs) - metrics[i][1]
                hx = x0 + self.BORDERPAD * fs
                h.set_data([hx, hx + self.HANDLELENGTH * fs], [base + 0.35 * fs] * 2)
                items.append((hx + (self.HANDLELENGTH + self.HANDLETEXTPAD) * fs, base, texts[i],
                              "left", "baseline"))
        self.labels.place(renderer, items)


class _RecordFigure:
    """One reusable record figure with ``n_hist`` history panels (a process draws many records).

    Building a figure (axes, their ticks and text) cost as much as drawing it; here every artist is
    made once and each record only updates data, texts, visibility and limits.  Every property
    that differs between records is set on every draw (nothing is inherited from the previous
    record: explicit colours, no colour cycle, no ``ax.plot``), so a record's PNG bytes do not
    depend on what the figure drew before (``tests/test_pipeline_run.py`` checks it).

    Drawing costs per artist, so the figure has few: matplotlib's axes draw two lines and a text
    per tick (~120 lines a figure, each with its machinery), here the grid, the tick marks and the
    tick labels of an axes are one artist each, placed as matplotlib's (its locators and
    formatters give the ticks and their labels); legends are :class:`_Legend`; y limits are
    computed here (no ``relim``); the axis labels sit at fixed places.
    """

    TICK_LABEL_SIZE = 10

    def __init__(self, n_hist):
        height = 2.4 + 2.0 * n_hist
        fig = _figure((8.0, height))
        axes = fig.subplots(1 + n_hist, 1, squeeze=False)[:, 0]
        # fixed margins (in inches) rather than tight_layout, which draws the figure twice
        fig.subplots_adjust(left=0.09, right=0.98, top=1.0 - 0.35 / height, bottom=0.5 / height,
                            hspace=0.75 / 2.0)
        self.fig, self.axes = fig, axes
        ax = axes[0]
        self.record_line, = ax.plot([], [], color="0.55", lw=0.6)
        self.pulse_lines = [ax.plot([], [], color=f"C{i}", lw=1.6 if i == 0 else 1.1,
                                    ls=_PULSE_STYLES[i])[0] for i in range(MAX_PULSES)]
        ax.set_ylabel("ground acc. (g)")
        self.hist_lines = []
        for ax in axes[1:]:
            self.hist_lines.append([ax.plot([], [], color=f"C{j}", lw=1.0, ls="-" if j == 0 else "--")[0]
                                    for j in range(MAX_CURVES)])
            ax.axhline(1.0, color="k", lw=0.5, ls=":")
            ax.axhline(-1.0, color="k", lw=0.5, ls=":")
            ax.set_ylabel("theta / alpha")
        axes[-1].set_xlabel("time (s)")
        renderer = fig.canvas.get_renderer()
        pt = renderer.points_to_pixels(1.0)
        # tick labels: (tick size + pad) from the axes, as matplotlib's
        self.tick_pad = (mpl.rcParams["xtick.major.size"] + mpl.rcParams["xtick.major.pad"]) * pt
        self.decor, self.locators, self.legends = [], [], []
        grid = {"color": mpl.rcParams["grid.color"], "lw": mpl.rcParams["grid.linewidth"], "alpha": 0.3,
                "zorder": 1.5}
        tick = {"ls": "none", "color": mpl.rcParams["xtick.color"], "ms": mpl.rcParams["xtick.major.size"],
                "mew": mpl.rcParams["xtick.major.width"], "clip_on": False, "zorder": 2.6}
        for k, (ax, lines) in enumerate(zip(axes, [[self.record_line] + self.pulse_lines] + self.hist_lines)):
            # ticks chosen by matplotlib's own locators and formatters, drawn here
            locators = []
            for axis in (ax.xaxis, ax.yaxis):
                loc, fmt = AutoLocator(), ScalarFormatter()
                loc.set_axis(axis)
                fmt.set_axis(axis)
                locators.append((loc, fmt))
                axis.set_major_locator(NullLocator())
                axis.set_minor_locator(NullLocator())
                axis.set_major_formatter(NullFormatter())
            self.locators.append(locators)
            artists = (Line2D([], [], transform=ax.get_xaxis_transform(), **grid),
                       Line2D([], [], transform=ax.get_yaxis_transform(), **grid),
                       Line2D([], [], transform=ax.get_xaxis_transform(), marker=TICKDOWN, **tick),
                       Line2D([], [], transform=ax.get_yaxis_transform(), marker=TICKLEFT, **tick),
                       _Labels(self.TICK_LABEL_SIZE, zorder=2.6))
            for a in artists:
                ax.add_artist(a)
            artists[-1].set_clip_on(False)
            self.decor.append(artists)
            self.legends.append(_Legend(ax, lines))
            # left of the widest usual tick labels ("-0.75"), the same place on every panel
            ax.yaxis.set_label_coords(-0.078, 0.5)
        # x label below the tick labels (matplotlib: tick labels' extent + labelpad)
        _, a, d = self.decor[-1][-1].metrics(renderer, "0123456789")
        below = self.tick_pad + a + d + mpl.rcParams["axes.labelpad"] * pt
        axes[-1].xaxis.set_label_coords(0.5, -below / axes[-1].bbox.height)

    def _show(self, k, lines, data, xlim, ylim_with=()):
        """Panel ``k``'s lines get ``data`` (``[(t, y, label), ...]``, the rest hidden), legend,
        limits (y: the data and ``ylim_with``, 5 % margins as matplotlib's autoscale), ticks."""
        ax = self.axes[k]
        if len(data) > len(lines):
            raise ValueError(f"at most {len(lines)} curves per panel, got {len(data)}")
        lo, hi = math.inf, -math.inf
        for line, d in zip(lines, data + [None] * (len(lines) - len(data))):
            if d is None:
                line.set_visible(False)
                line.set_data([], [])
            else:
                line.set_visible(True)
                line.set_data(d[0], d[1])
                if np.isfinite(d[1]).any():
                    lo, hi = min(lo, np.nanmin(d[1])), max(hi, np.nanmax(d[1]))
        for v in ylim_with:
            lo, hi = min(lo, v), max(hi, v)
        if not math.isfinite(lo):
            lo, hi = -1.0, 1.0
        yloc = self.locators[k][1][0]
        lo, hi = yloc.nonsingular(float(lo), float(hi))
        margin = ax.margins()[1] * (hi - lo)
        ax.set_ylim(lo - margin, hi + margin)
        ax.set_xlim(*xlim)
        renderer = self.fig.canvas.get_renderer()
        self.legends[k].show(renderer, [d[2] for d in data])
        self._ticks(k, renderer, bottom_labels=k == len(self.axes) - 1)

    def _ticks(self, k, renderer, bottom_labels):
        ax = self.axes[k]
        xgrid, ygrid, xtick, ytick, labels = self.decor[k]
        (xloc, xfmt), (yloc, yfmt) = self.locators[k]
        ticks = []
        for axis, loc, fmt in ((ax.xaxis, xloc, xfmt), (ax.yaxis, yloc, yfmt)):
            lo, hi = sorted(axis.get_view_interval())
            locs = np.asarray(loc())
            texts = fmt.format_ticks(locs)  # all the locator's ticks, as matplotlib's axis does
            tol = 1e-9 * (hi - lo)
            keep = (locs >= lo - tol) & (locs <= hi + tol)
            ticks.append((locs[keep], [t for t, kp in zip(texts, keep) if kp], fmt.get_offset()))
        (xs, xtexts, xoff), (ys, ytexts, yoff) = ticks
        nan = np.full(len(xs), np.nan)
        xgrid.set_data(np.column_stack([xs, xs, nan]).ravel(), np.tile([0.0, 1.0, np.nan], len(xs)))
        nan = np.full(len(ys), np.nan)
        ygrid.set_data(np.tile([0.0, 1.0, np.nan], len(ys)), np.column_stack([ys, ys, nan]).ravel())
        xtick.set_data(xs, np.zeros(len(xs)))
        ytick.set_data(np.zeros(len(ys)), ys)
        bbox = ax.bbox
        items = []
        if bottom_labels:
            px = ax.transData.transform(np.column_stack([xs, np.zeros(len(xs))]))[:, 0]
            items += [(x, bbox.y0 - self.tick_pad, s, "center", "top") for x, s in zip(px, xtexts)]
            if xoff:  # matplotlib: at the right end, below the tick labels
                _, a, d = labels.metrics(renderer, "0")
                items.append((bbox.x1, bbox.y0 - self.tick_pad - a - d, xoff, "right", "top"))
        py = ax.transData.transform(np.column_stack([np.zeros(len(ys)), ys]))[:, 1]
        items += [(bbox.x0 - self.tick_pad, y, s, "right", "center_baseline") for y, s in zip(py, ytexts)]
        if yoff:  # matplotlib: above the top left corner
            items.append((bbox.x0, bbox.y1 + self.tick_pad, yoff, "left", "baseline"))
        labels.place(renderer, items)

    def draw(self, record_id, record, fitting, histories) -> bytes:
        from pulses import G

        xlim = (record.t_start, record.t_start + record.duration)
        t = record.time
        pulses = [(*_thin(t, c.pulse(t) / G),
                   f"{c.shape}: ap {c.ap / G:+.3g} g, Tp {c.tp:.3g} s, score {c.score:.2f}")
                  for c in fitting]
        self._show(0, [self.record_line] + self.pulse_lines,
                   [(*_thin(t, record.acc / G), "record")] + pulses, xlim)
        self.axes[0].set_title(f"{record_id}: record and fitted pulse{'s' if len(fitting) > 1 else ''}",
                               fontsize=10, y=1.0)
        for k, (lines, (label, curves)) in enumerate(zip(self.hist_lines, histories), start=1):
            data = []
            for curve_label, block, res in curves:
                th = np.asarray(res.theta, dtype=float) / block.alpha
                verdict = "overturns" if res.overturned else f"max {res.max_rotation_ratio:.3g} alpha"
                data.append((*_thin(res.t, th), f"{curve_label}: {verdict}"))
            self._show(k, lines, data, xlim, ylim_with=(-1.0, 1.0))
            self.axes[k].set_title(f"column {label} m under the full record", fontsize=9, y=1.0)
        return _png(self.fig)


#: one record figure per number of history panels, per process (see :class:`_RecordFigure`)
_RECORD_FIGURES: dict = {}
#: matplotlib figures are not thread-safe (dask may run tasks in threads)
_LOCK = threading.Lock()


def record_figure_png(record_id, record, fit, fitting, histories) -> bytes:
    """The record with its fitted pulses (paper's Fig. 4) and rotation histories (Figs. 9, 11).

    ``histories`` is a list of ``(column label, [(curve label, block, simulate result), ...])``.
    Drawn for speed (it was the costliest stage of ``pipeline run`` per record): one figure per
    process reused for every record (:class:`_RecordFigure`), fixed margins and title positions
    (no layout pass), :data:`DPI`.
    """
    n = len(histories)
    with _LOCK:
        fig = _RECORD_FIGURES.get(n)
        if fig is None:
            fig = _RECORD_FIGURES[n] = _RecordFigure(n)
        try:
            return fig.draw(record_id, record, list(fitting), histories)
        except BaseException:
            _RECORD_FIGURES.pop(n, None)  # never reuse a figure left half-updated
            raise


def _num(row, key):
    v = row.get(key)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.nan
    return v


def summary_figure_png(rows) -> bytes:
    """Required against actual tan(alpha), across records and columns."""
    fig = _figure((10.0, 4.6))
    ax1, ax2 = fig.subplots(1, 2)
    # fixed margins (what tight_layout gives for these labels) rather than a second layout draw
    fig.subplots_adjust(left=0.067, right=0.974, top=0.929, bottom=0.127, wspace=0.187)
    blocks = [r for r in rows if r.get("column_kind") == "block"]
    hi = 0.0
    if blocks:
        x = np.array([_num(r, "tan_alpha") for r in blocks])
        y31 = np.array([_num(r, "governing_eq31_tan_alpha") for r in blocks])
        yv = np.array([_num(r, "verified_tan_alpha") for r in blocks])
        over = np.array([bool(r.get("overturns")) for r in blocks])
        ax1.scatter(x, y31, marker="o", facecolors="none", edgecolors="C0", label="Eq. 31 (governing pulse)")
        ax1.scatter(x[~over], yv[~over], marker="x", color="C2", label="verified, column survives")
        ax1.scatter(x[over], yv[over], marker="x", color="C3", label="verified, column overturns")
        hi = np.nanmax(np.concatenate([x, y31, yv, [0.0]]))
    hi = 1.1 * hi if hi > 0 else 1.0
    ax1.plot([0, hi], [0, hi], "k-", lw=0.6)
    ax1.set_xlim(0, hi)
    ax1.set_ylim(0, hi)
    ax1.set_xlabel("actual tan(alpha) of the column")
    ax1.set_ylabel("required tan(alpha)")
    ax1.set_title("columns as they stand (above the line: too slender)", fontsize=9)
    ax1.grid(alpha=0.3)
    if blocks:
        ax1.legend(fontsize=7)
    else:
        ax1.text(0.5, 0.5, "no column as it stands (--block) in this run", ha="center", va="center",
                 transform=ax1.transAxes, fontsize=9, color="0.4")
    x = np.array([_num(r, "eq31_width_tan_alpha") for r in rows])
    y = np.array([_num(r, "verified_tan_alpha") for r in rows])
    bad = np.array([bool(r.get("eq31_width_overturns")) for r in rows], dtype=bool)
    hi2 = np.nanmax(np.concatenate([x, y, [0.0]])) if rows else 0.0
    hi2 = 1.1 * hi2 if hi2 > 0 else 1.0
    if rows:
        ax2.scatter(x[~bad], y[~bad], marker="o", color="C0", label="Eq. 31 design survives the record")
        ax2.scatter(x[bad], y[bad], marker="o", color="C3", label="Eq. 31 design overturns")
        ax2.legend(fontsize=7)
    ax2.plot([0, hi2], [0, hi2], "k-", lw=0.6)
    ax2.set_xlim(0, hi2)
    ax2.set_ylim(0, hi2)
    ax2.set_xlabel("Eq. 31 design tan(alpha)")
    ax2.set_ylabel("verified tan(alpha) (full record)")
    ax2.set_title("Eq. 31 against verification (below the line: Eq. 31 conservative)", fontsize=9)
    ax2.grid(alpha=0.3)
    return _png(fig)
