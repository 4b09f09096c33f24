"""Rendering a swim to a GIF (Pillow) or an MP4 (ffmpeg, where available): :func:`animate`."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["animate", "frame_figure", "default_frames", "mp4_available"]


def mp4_available() -> bool:
    """True if MP4 can be written: the ``imageio_ffmpeg`` package or an ``ffmpeg`` on PATH."""
    return _ffmpeg_exe() is not None


def _ffmpeg_exe() -> Optional[str]:
    try:
        import imageio_ffmpeg  # type: ignore

        return imageio_ffmpeg.get_ffmpeg_exe()
    except Exception:
        return shutil.which("ffmpeg")


def default_frames(trajectory, max_frames: int = 240, per_cycle: int = 8, start: Optional[int] = None) -> list:
    """Frame indices an animation shows by default: at most ``max_frames`` frames.

    The stride between frames is the smaller of (a) the stride that spreads ``max_frames`` over the
    whole trajectory and (b) the stride that gives one dominant oscillation period
    (``trajectory.period()``) ``per_cycle`` frames. So short swims are shown whole, and long swims
    show a window of smooth motion (no stroboscopic aliasing) as long as ``max_frames`` allows:
    the window starts at frame ``start``, or by default ends at the last frame (the settled swim).
    """
    F = trajectory.frame_count
    if F == 0 or max_frames < 1:
        return []
    whole = max(1, math.ceil(F / max_frames))
    period = trajectory.period()
    frame_dt = trajectory.dt * trajectory.every
    smooth = max(1, int(period / frame_dt / per_cycle)) if math.isfinite(period) else whole
    stride = min(whole, smooth)
    if start is None:
        return list(range(F - 1, -1, -stride))[:max_frames][::-1]
    return list(range(int(start) % F, F, stride))[:max_frames]


def animate(
    trajectory: Any,
    path: Union[str, os.PathLike],
    *,
    fps: float = 25.0,
    frames: Optional[Sequence[int]] = None,
    max_frames: int = 240,
    start: Optional[int] = None,
    size: Tuple[int, int] = (560, 360),
    follow: Optional[bool] = None,
    align: Optional[bool] = None,
    trail: bool = True,
    color_springs: bool = False,
    title: Optional[str] = None,
    progress: Optional[bool] = None,
    config: Optional[Any] = None,
    colors: int = 64,
) -> Path:
    """Render a trajectory to an animated GIF, or to MP4 where ffmpeg is available.

    Each frame shows the body (region fill, springs, thick skin, nodes red expanding / blue
    contracting / green neutral as in :func:`animat.plot.motion_cycle`), a background grid fixed in
    the world (so the motion shows even when the camera follows the body), the centre-of-mass
    trail, the world (:func:`animat.plot.draw_world`: the floor at ``scene.ground_height`` with
    effect ``ground``; the chemical source as a star, and an arrow toward it, when the swim has one),
    the time, the control step and the swim's progress by the run's objective so far (progress
    toward the source for ``chemotaxis``, the horizontal distance for ``distance_x``, the signed
    distance along ``evaluation.direction`` for ``speed_toward``, else the distance travelled), and
    a banner naming the world as it is (:func:`animat.plot.world_text`). The texts take a band at the
    top of the frame that the view keeps clear: the body, its track and the source are drawn below
    it. :func:`frame_figure` draws one such frame as a matplotlib Figure. A chemotaxis swim is one
    of its evaluation's swims (:func:`animat.replay`: by default the first), drawn with that swim's
    source; a swim in which nothing moves is drawn with a warning (:func:`animat.plot.motionless`).

    Args:
        trajectory: an :class:`animat.Trajectory`; anything else accepted by
            :func:`animat.replay` (Genome, LineageEntry, Body) is replayed first with ``config``.
        path: output file; ``.gif`` (Pillow) or ``.mp4`` (needs ``imageio-ffmpeg`` or ``ffmpeg`` on
            PATH, else RuntimeError).
        fps: frames per second of the output (GIF delays are rounded to 1/100 s).
        frames: trajectory frame indices to render (default :func:`default_frames` with
            ``max_frames`` and ``start``: the whole swim if it fits in ``max_frames`` frames with
            at least 8 frames per oscillation period, else the last such window, or the window
            from frame ``start``).
        size: (width, height) in pixels (MP4 rounds them up to even numbers).
        follow: keep the body centred (the camera follows the centre of mass). Default: follow
            only when the rendered path would not fit in a view about twice the body's size; a
            fixed view makes much smaller GIFs.
        align: rotate the world so the overall direction of motion points right. Default: True,
            but False in a world with gravity or a floor (down stays down, the floor level).
        trail: draw the centre-of-mass track.
        color_springs: colour springs by their actuation state too.
        title: caption at the bottom right (default: the colour legend).
        progress: show a tqdm progress bar (default: when stderr is a terminal and there are at
            least 60 frames).
        config: config for replaying a non-Trajectory (and for naming the world of a Trajectory
            recorded without one).
        colors: GIF palette size (one palette for all frames; <= 256, fewer = smaller file).
    Returns:
        The path written: ``len(frames)`` frames of ``size`` pixels.
    """
    from .trajectory import Trajectory, replay

    tr = trajectory if isinstance(trajectory, Trajectory) else replay(trajectory, config)
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"animate: {path}: unsupported format {suffix or '(none)'}; use .gif or .mp4")
    ffmpeg = None
    if suffix == ".mp4":
        ffmpeg = _ffmpeg_exe()
        if ffmpeg is None:
            raise RuntimeError(
                f"animate: cannot write {path}: MP4 needs ffmpeg (pip install imageio-ffmpeg, or "
                "install ffmpeg); write a .gif instead"
            )
    idx = _frame_indices(tr, frames, max_frames, start)
    width, height = int(size[0]), int(size[1])
    if ffmpeg:
        width += width % 2
        height += height % 2
    overlay = _TextOverlay(width, height)
    stage = _Stage(
        tr,
        idx,
        (width, height),
        follow=follow,
        align=align,
        trail=trail,
        color_springs=color_springs,
        title=title,
        config=config,
        overlay=overlay,
    )

    show_bar = progress if progress is not None else (len(idx) >= 60 and _stderr_is_tty())
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        tqdm = None
    iterator = tqdm(idx, desc=f"rendering {path.name}", unit="frame", disable=not show_bar) if tqdm else idx

    images = []
    proc = None
    if ffmpeg:
        path.parent.mkdir(parents=True, exist_ok=True)
        proc = subprocess.Popen(
            [
                ffmpeg,
                "-y",
                "-loglevel",
                "error",
                "-f",
                "rawvideo",
                "-pix_fmt",
                "rgb24",
                "-s",
                f"{width}x{height}",
                "-r",
                f"{fps}",
                "-i",
                "-",
                "-an",
                "-vcodec",
                "libx264",
                "-pix_fmt",
                "yuv420p",
                "-crf",
                "23",
                str(path),
            ],
            stdin=subprocess.PIPE,
        )
    try:
        for f in iterator:
            stage.update(f)
            stage.canvas.draw()
            rgb = np.asarray(stage.canvas.buffer_rgba())[:height, :width, :3]
            text = stage.texts(f)
            image = overlay.apply(rgb, text)
            if proc is not None and proc.stdin is not None:
                proc.stdin.write(np.asarray(image).tobytes())
            else:
                images.append(image)
    finally:
        if proc is not None and proc.stdin is not None:
            proc.stdin.close()
            proc.wait()
    if proc is not None:
        if proc.returncode != 0:
            raise RuntimeError(f"animate: ffmpeg failed writing {path} (exit code {proc.returncode})")
        return path
    _write_gif(path, images, fps, colors)
    return path


def frame_figure(
    trajectory: Any,
    frame: int = -1,
    *,
    frames: Optional[Sequence[int]] = None,
    max_frames: int = 240,
    start: Optional[int] = None,
    size: Tuple[int, int] = (560, 360),
    follow: Optional[bool] = None,
    align: Optional[bool] = None,
    trail: bool = True,
    color_springs: bool = False,
    title: Optional[str] = None,
    config: Optional[Any] = None,
):
    """One frame of :func:`animate` as a matplotlib Figure (a still, or a look at what the GIF draws).

    Same arguments as :func:`animate`; ``frame`` is the trajectory frame shown (default the last),
    ``frames`` the frames the view is fitted to (default those :func:`animate` renders, plus
    ``frame``). The texts the GIF writes with Pillow are matplotlib texts here, labelled ``"clock"``
    (time, step, progress), ``"world"`` (:func:`animat.plot.world_text`), ``"caption"`` and
    ``"motion"``. Artists are labelled as :func:`animat.plot.draw_body` and
    :func:`animat.plot.draw_world` label them (``"nodes"``, ``"floor"``, ``"ground"``, ``"chemical
    source"``), plus ``"toward source"`` (the arrow) and ``"trail"``.
    """
    from .trajectory import Trajectory, replay

    tr = trajectory if isinstance(trajectory, Trajectory) else replay(trajectory, config)
    if not -tr.frame_count <= frame < tr.frame_count:
        raise ValueError(f"frame_figure: frame {frame} out of range (trajectory has {tr.frame_count} frames)")
    frame %= tr.frame_count
    idx = _frame_indices(tr, frames, max_frames, start)
    if frame not in idx:
        idx = sorted(set(idx) | {frame})
    width, height = int(size[0]), int(size[1])
    overlay = _TextOverlay(width, height)
    stage = _Stage(
        tr,
        idx,
        (width, height),
        follow=follow,
        align=align,
        trail=trail,
        color_springs=color_springs,
        title=title,
        config=config,
        overlay=overlay,
    )
    stage.update(frame)
    fig = stage.fig
    # where the GIF's overlay writes them, in the same fonts and sizes (pixels at 100 dpi -> points)
    for t in overlay.layout(stage.texts(frame)):
        (x, y), (ha, va) = t["xy"], _ANCHORS[t["anchor"]]
        fig.text(
            x / width,
            1.0 - y / height,
            t["text"],
            ha=ha,
            va=va,
            family=t["family"],
            fontsize=t["size"] * 72.0 / 100.0,
            color=t["color"],
            linespacing=1.0 + t["spacing"] / t["size"],
            label=t["label"],
        )
    return fig


#: Pillow's text anchors (the overlay's) as matplotlib's (ha, va) (frame_figure).
_ANCHORS = {"la": ("left", "top"), "rd": ("right", "bottom"), "md": ("center", "bottom")}
#: Pixels kept between the texts and what the view draws.
_TEXT_GAP = 4.0
#: The chemical source's star (plot.draw_world: 16 points) as a radius in pixels at 100 dpi, plus its edge.
_SOURCE_RADIUS_PX = 16 * 100 / 72 / 2 + 2


def _frame_indices(tr, frames, max_frames, start) -> list:
    idx = list(default_frames(tr, max_frames=max_frames, start=start) if frames is None else frames)
    if not idx:
        raise ValueError("animate: no frames to render")
    bad = [f for f in idx if not -tr.frame_count <= f < tr.frame_count]
    if bad:
        raise ValueError(f"animate: frames {bad[:5]} out of range (trajectory has {tr.frame_count} frames)")
    return [f % tr.frame_count for f in idx]


class _Stage:
    """The matplotlib scene of :func:`animate`: built once, updated per frame (``update``), with the
    texts of each frame (``texts``)."""

    def __init__(self, tr, idx, size, *, follow, align, trail, color_springs, title, overlay, config=None):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.collections import LineCollection
        from matplotlib.figure import Figure
        from matplotlib.patches import FancyArrowPatch

        from . import _core
        from . import plot as aplot

        width, height = size
        if width < 32 or height < 32:
            raise ValueError(f"animate: size {size} too small (at least 32 x 32 pixels)")
        aplot._warn_if_motionless(tr, "animate")
        self.tr, self.idx, self.trail, self.color_springs = tr, list(idx), trail, color_springs
        self.config = tr.config if tr.config is not None else (config if config is not None else _core.Config())
        self.scene = tr.meta.get("scene")
        if align is None:
            effects = list(aplot._scene_of(self.config, self.scene).effects)
            align = "gravity" not in effects and "ground" not in effects
        self.align = align
        self.source_rel = aplot.chemical_source_of(self.config, self.scene)
        self.caption = title if title is not None else "red: expanding   blue: contracting   green: neutral"
        self.banner = aplot.world_text(self.config, self.scene, source_trial=tr.meta.get("source_trial"))
        self.objective = str(self.config["evaluation.objective"])
        # the bands of the texts at the top and the bottom, as fractions of the height: kept clear of
        # the body, its track and the source
        top_px, bottom_px = overlay.bands(self.texts(idx[0]))
        top, bottom = top_px / height, bottom_px / height
        if top + bottom > 0.6:  # a frame too small for its texts: the texts give way
            top, bottom = 0.6 * top / (top + bottom), 0.6 * bottom / (top + bottom)
        rot = aplot.rotation_to(tr.direction) if align else np.eye(2)
        origin = tr.com[idx[0]] if align else np.zeros(2)  # unrotated: world coordinates (the floor's height)
        self.to_view = lambda p: (np.asarray(p, dtype=float) - origin) @ rot.T
        self.world = self.to_view(tr.positions)  # (F, n, 2)
        self.com = self.to_view(tr.com)  # (F, 2)
        r = aplot._node_radius(tr.body)
        aspect = width / height

        # View: the body's largest extent (relative to its centre of mass) plus a margin, between the
        # bands of the texts (the view's height minus the bands holds what is drawn).
        below = 1.0 - top - bottom
        sel = self.world[idx]
        rel = sel - self.com[idx][:, None, :]
        half = np.abs(rel).max(axis=(0, 1)) + r + 0.5
        view_w = max(2 * half[0], 2 * half[1] * aspect / below) * 1.3
        lo, hi = sel.reshape(-1, 2).min(axis=0) - r - 0.5, sel.reshape(-1, 2).max(axis=0) + r + 0.5

        def fitted(lo, hi):  # the width of a fixed view showing [lo, hi] between the bands
            return max((hi - lo)[0], (hi - lo)[1] * aspect / below) * 1.1

        fixed_w = fitted(lo, hi)
        if follow is None:
            follow = fixed_w > 2.0 * view_w
        source = self.source_rel
        if source is not None and not follow:  # a source near enough is kept in the fixed view, star whole
            s_xy = self.to_view((tr.com[0] + source)[None, :])[0]
            margin = 1.0
            for _ in range(3):  # the star's radius in world units depends on the view it widens
                lo2, hi2 = np.minimum(lo, s_xy - margin), np.maximum(hi, s_xy + margin)
                wide = fitted(lo2, hi2)
                margin = max(margin, 1.2 * _SOURCE_RADIUS_PX * wide / width)
            lo2, hi2 = np.minimum(lo, s_xy - margin), np.maximum(hi, s_xy + margin)
            wide = fitted(lo2, hi2)
            if wide <= 2.5 * fixed_w:
                lo, hi, fixed_w = lo2, hi2, wide
        self.follow = follow
        if not follow:
            view_w = fixed_w
        self.view_w, self.view_h = view_w, view_w / aspect
        # the centre of the view sits above the centre of what is drawn by half the bands' difference
        self.lift = np.array([0.0, (top - bottom) * self.view_h / 2])
        self.fixed_centre = (lo + hi) / 2 + self.lift

        dpi = 100
        self.fig = fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
        fig.patch.set_facecolor("white")
        self.canvas = FigureCanvasAgg(fig)
        self.ax = ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_aspect("auto")
        ax.set_axis_off()
        # world-fixed grid, about 7 lines across the view
        spacing = _nice_spacing(view_w, 7)
        allc = sel.reshape(-1, 2)
        reach = max(view_w, self.view_h)
        g_lo = np.floor((allc.min(axis=0) - reach) / spacing) * spacing
        g_hi = np.ceil((allc.max(axis=0) + reach) / spacing) * spacing
        xs = np.arange(g_lo[0], g_hi[0] + spacing / 2, spacing)
        ys = np.arange(g_lo[1], g_hi[1] + spacing / 2, spacing)
        if len(xs) + len(ys) < 4000:
            lines = [((x, g_lo[1]), (x, g_hi[1])) for x in xs] + [((g_lo[0], y), (g_hi[0], y)) for y in ys]
            ax.add_collection(LineCollection(lines, colors="#e3e7ec", linewidths=0.8, zorder=0))
        # the world: floor and chemical source (in view coordinates)
        self.world_artists = aplot.draw_world(
            ax,
            self.config,
            scene=self.scene,
            start=tr.com[0],
            transform=self.to_view,
            extent=float(np.max(np.abs(g_hi - g_lo))) + reach,
        )
        self.arrow = None
        if self.world_artists["source_xy"] is not None:
            self.arrow = FancyArrowPatch(
                (0, 0),
                (0, 0),
                arrowstyle="-|>",
                mutation_scale=12,
                color=aplot.SOURCE_COLOR,
                lw=1.6,
                zorder=5,
                label="toward source",
            )
            ax.add_patch(self.arrow)

        f0 = idx[0]
        self.artists = aplot.draw_body(
            ax,
            tr.body,
            self.world[f0],
            [aplot.STATE_COLORS[int(s)] for s in tr.node_state[f0]],
            node_radius=r,
            spring_colors=aplot.SPRING_COLOR,
        )
        (self.trail_line,) = ax.plot([], [], color="#7f7f7f", lw=1.0, ls="--", zorder=1, label="trail")
        (self.com_dot,) = ax.plot([], [], "+", color="#444444", ms=7, zorder=5)
        if align:
            ax.add_patch(
                FancyArrowPatch(
                    (0.9, 0.915),
                    (0.975, 0.915),
                    transform=ax.transAxes,
                    arrowstyle="-|>",
                    mutation_scale=10,
                    color="#777777",
                    lw=1.2,
                    zorder=6,
                )
            )
        self.springs = np.asarray(tr.body.springs)
        self.aplot = aplot

    def update(self, f: int) -> None:
        """Move every artist to frame ``f`` and set the view."""
        tr, aplot, artists = self.tr, self.aplot, self.artists
        pos = self.world[f]
        if artists["fill"] is not None:
            artists["fill"].set_verts([pos[reg] for reg in tr.body.regions])
        if len(self.springs):
            artists["springs"].set_segments(pos[self.springs])
        if self.color_springs:
            artists["springs"].set_color([aplot.STATE_COLORS[int(s)] for s in tr.spring_state[f]])
        artists["skin"].set_segments(aplot._loops_closed(pos, tr.body.skin_loops))
        artists["nodes"].set_offsets(pos)
        artists["nodes"].set_facecolor([aplot.STATE_COLORS[int(s)] for s in tr.node_state[f]])
        c = self.com[f]
        if self.trail:
            upto = [k for k in self.idx if k <= f]
            self.trail_line.set_data(self.com[upto, 0], self.com[upto, 1])
        self.com_dot.set_data([c[0]], [c[1]])
        if self.arrow is not None:  # from the centre of mass toward the source, at most a third of the view long
            to = self.world_artists["source_xy"] - c
            dist = float(np.linalg.norm(to))
            length = min(dist, 0.3 * min(self.view_w, self.view_h))
            tip = c + (to / dist * length if dist > 0 else 0.0)
            self.arrow.set_positions(tuple(c), tuple(tip))
        centre = c + self.lift if self.follow else self.fixed_centre
        self.ax.set_xlim(centre[0] - self.view_w / 2, centre[0] + self.view_w / 2)
        self.ax.set_ylim(centre[1] - self.view_h / 2, centre[1] + self.view_h / 2)

    def progress(self, f: int) -> Tuple[str, float]:
        """(label, value) of the swim so far by the objective (see :func:`animate`)."""
        d = self.tr.com[f] - self.tr.com[0]
        if self.source_rel is not None and self.objective == "chemotaxis":
            s = self.source_rel
            return "to source", float(np.linalg.norm(s) - np.linalg.norm(s - d))
        if self.objective == "distance_x":
            return "x distance", float(abs(d[0]))
        if self.objective == "speed_toward":
            u = np.asarray(self.config["evaluation.direction"], dtype=float)
            u = u / (np.linalg.norm(u) or 1.0)
            return "along dir.", float(d @ u)
        return "distance", float(np.linalg.norm(d))

    def texts(self, f: int) -> dict:
        """The texts of frame ``f``: ``clock`` (time, step, progress), ``world``, ``caption``, ``motion``."""
        label, value = self.progress(f)
        clock = f"t = {self.tr.times[f]:6.2f}   step {int(self.tr.steps[f]):5d}\n{label:<10s}{value:8.3f}"
        return {"clock": clock, "world": self.banner, "caption": self.caption, "motion": "motion" if self.align else ""}


class _TextOverlay:
    """Text drawn with Pillow (much faster than matplotlib text), in matplotlib's DejaVu fonts: the
    clock at the top left, the world below it (wrapped at its "; " to the frame's width), the
    caption at the bottom right, "motion" at the top right. :meth:`layout` says where;
    :func:`frame_figure` writes the same texts there with matplotlib."""

    def __init__(self, width: int, height: int):
        from matplotlib import font_manager
        from PIL import ImageFont

        scale = max(0.7, min(width, 1.6 * height) / 560)
        self.mono_size, self.sans_size = int(round(12 * scale)), int(round(10 * scale))
        try:
            self.mono = ImageFont.truetype(font_manager.findfont("DejaVu Sans Mono"), self.mono_size)
            self.sans = ImageFont.truetype(font_manager.findfont("DejaVu Sans"), self.sans_size)
        except Exception:  # pragma: no cover - no FreeType
            self.mono = self.sans = ImageFont.load_default()
        self.width, self.height = width, height
        self.margin = int(round(6 * scale))

    def _wrap(self, text: str) -> str:
        """``text`` broken after its "; " where a line would pass the frame's right margin."""
        lines: list = []
        for part in text.split("; "):
            joined = f"{lines[-1]}; {part}" if lines else part
            if lines and self.sans.getlength(joined) > self.width - 2 * self.margin:
                lines[-1] += ";"
                lines.append(part)
            elif lines:
                lines[-1] = joined
            else:
                lines.append(part)
        return "\n".join(lines)

    def layout(self, texts: dict) -> list:
        """The texts of one frame (:meth:`_Stage.texts`) as dicts: ``text``, ``xy`` (pixels),
        ``anchor`` (Pillow's), ``family``, ``size`` (pixels), ``spacing`` (pixels between lines),
        ``color``, ``label`` and ``box`` (left, top, right, bottom in pixels)."""
        from PIL import Image, ImageDraw

        draw = ImageDraw.Draw(Image.new("RGB", (1, 1)))
        m = self.margin
        out = []

        def add(label, text, xy, anchor, mono, color):
            font = self.mono if mono else self.sans
            box = draw.multiline_textbbox(xy, text, font=font, anchor=anchor, spacing=2)
            out.append(
                dict(
                    label=label,
                    text=text,
                    xy=xy,
                    anchor=anchor,
                    family="monospace" if mono else "sans-serif",
                    size=self.mono_size if mono else self.sans_size,
                    spacing=2,
                    color=color,
                    box=box,
                )
            )
            return box

        clock = add("clock", texts["clock"], (m, m), "la", True, "#222222")
        if texts.get("world"):
            add("world", self._wrap(texts["world"]), (m, clock[3] + m // 2), "la", False, "#555555")
        if texts.get("caption"):
            add("caption", texts["caption"], (self.width - m, self.height - m), "rd", False, "#555555")
        if texts.get("motion"):
            add(
                "motion",
                texts["motion"],
                (int(0.9375 * self.width), int(0.085 * self.height) - 2),
                "md",
                False,
                "#777777",
            )
        return out

    def bands(self, texts: dict) -> Tuple[float, float]:
        """Pixels at the top (clock, world, motion) and at the bottom (caption) that the texts of
        :meth:`layout` take, each with a gap."""
        boxes = {t["label"]: t["box"] for t in self.layout(texts)}
        top = max(boxes[k][3] for k in ("clock", "world", "motion") if k in boxes) + _TEXT_GAP
        bottom = self.height - boxes["caption"][1] + _TEXT_GAP if "caption" in boxes else 0.0
        return float(top), float(bottom)

    def apply(self, rgb: np.ndarray, texts: dict):
        from PIL import Image, ImageDraw

        image = Image.fromarray(np.ascontiguousarray(rgb))
        draw = ImageDraw.Draw(image)
        for t in self.layout(texts):
            font = self.mono if t["family"] == "monospace" else self.sans
            draw.multiline_text(
                t["xy"], t["text"], font=font, fill=t["color"], anchor=t["anchor"], spacing=t["spacing"]
            )
        return image


def _nice_spacing(span: float, target: int) -> float:
    """1, 2 or 5 times a power of ten, about span / target."""
    raw = max(span / target, 1e-9)
    base = 10.0 ** math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if base * m >= raw:
            return base * m
    return base * 10


def _stderr_is_tty() -> bool:
    import sys

    try:
        return sys.stderr.isatty()
    except Exception:
        return False


#: Colours every GIF palette keeps exactly (background, skin, springs, fill, grid, text, node states, floor,
#: ground, chemical source).
_KEY_COLORS = [
    "#ffffff",
    "#111111",
    "#222222",
    "#8c8c8c",
    "#e9eef3",
    "#e3e7ec",
    "#555555",
    "#777777",
    "#7f7f7f",
    "#444444",
    "#d62728",
    "#1f77b4",
    "#2ca02c",
    "#8c564b",
    "#eee4da",
    "#ff7f0e",
]


def _write_gif(path: Path, images, fps: float, colors: int) -> None:
    """One palette for all frames: the key colours exactly, the rest median-cut from a sample of
    frames; no dithering. Small files, no flicker, and the state colours stay true."""
    from matplotlib.colors import to_rgb
    from PIL import Image

    colors = int(min(max(colors, len(_KEY_COLORS) + 2), 256))
    sample = images[:: max(1, len(images) // 12)][:12]
    w, h = sample[0].size
    mosaic = Image.new("RGB", (w, h * len(sample)))
    for k, im in enumerate(sample):
        mosaic.paste(im, (0, k * h))
    rest = mosaic.quantize(colors=colors - len(_KEY_COLORS), method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    extra = (rest.getpalette() or [])[: 3 * (colors - len(_KEY_COLORS))]
    keys = [int(round(255 * v)) for c in _KEY_COLORS for v in to_rgb(c)]
    palette = Image.new("P", (1, 1))
    palette.putpalette(keys + extra)
    frames = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    path.parent.mkdir(parents=True, exist_ok=True)
    duration = max(20, int(round(100.0 / fps)) * 10)  # GIF delays are whole 1/100 s
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=duration, loop=0, optimize=False, disposal=1)
