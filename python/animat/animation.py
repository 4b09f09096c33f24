"""Rendering a swim to a GIF (Pillow) or an MP4 (ffmpeg, where available): :func:`animate`."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["animate", "default_frames", "mp4_available"]


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
    align: bool = True,
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
    trail, and the time, control step and distance travelled so far.

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
        align: rotate the world so the overall direction of motion points right.
        trail: draw the centre-of-mass track.
        color_springs: colour springs by their actuation state too.
        title: caption at the bottom right (default: the colour legend).
        progress: show a tqdm progress bar (default: when stderr is a terminal and there are at
            least 60 frames).
        config: config for replaying a non-Trajectory.
        colors: GIF palette size (one palette for all frames; <= 256, fewer = smaller file).
    Returns:
        The path written: ``len(frames)`` frames of ``size`` pixels.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import FancyArrowPatch

    from . import plot as aplot
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
    idx = list(default_frames(tr, max_frames=max_frames, start=start) if frames is None else frames)
    if not idx:
        raise ValueError("animate: no frames to render")
    bad = [f for f in idx if not -tr.frame_count <= f < tr.frame_count]
    if bad:
        raise ValueError(f"animate: frames {bad[:5]} out of range (trajectory has {tr.frame_count} frames)")
    idx = [f % tr.frame_count for f in idx]
    width, height = int(size[0]), int(size[1])
    if ffmpeg:
        width += width % 2
        height += height % 2
    if width < 32 or height < 32:
        raise ValueError(f"animate: size {size} too small (at least 32 x 32 pixels)")

    rot = aplot.rotation_to(tr.direction) if align else np.eye(2)
    origin = tr.com[idx[0]]
    world = (tr.positions - origin) @ rot.T  # (F, n, 2)
    com = (tr.com - origin) @ rot.T  # (F, 2)
    r = aplot._node_radius(tr.body)
    aspect = width / height

    # View: the body's largest extent (relative to its centre of mass) plus a margin.
    sel = world[idx]
    rel = sel - com[idx][:, None, :]
    half = np.abs(rel).max(axis=(0, 1)) + r + 0.5
    view_w = max(2 * half[0], 2 * half[1] * aspect) * 1.3
    lo, hi = sel.reshape(-1, 2).min(axis=0) - r - 0.5, sel.reshape(-1, 2).max(axis=0) + r + 0.5
    span = hi - lo
    fixed_w = max(span[0], span[1] * aspect) * 1.1
    if follow is None:
        follow = fixed_w > 2.0 * view_w
    fixed_centre = (lo + hi) / 2
    if not follow:
        view_w = fixed_w
    view_h = view_w / aspect

    dpi = 100
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    fig.patch.set_facecolor("white")
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_aspect("auto")
    ax.set_axis_off()
    # world-fixed grid, about 7 lines across the view
    spacing = _nice_spacing(view_w, 7)
    allc = sel.reshape(-1, 2)
    g_lo = np.floor((allc.min(axis=0) - max(view_w, view_h)) / spacing) * spacing
    g_hi = np.ceil((allc.max(axis=0) + max(view_w, view_h)) / spacing) * spacing
    xs = np.arange(g_lo[0], g_hi[0] + spacing / 2, spacing)
    ys = np.arange(g_lo[1], g_hi[1] + spacing / 2, spacing)
    if len(xs) + len(ys) < 4000:
        lines = [((x, g_lo[1]), (x, g_hi[1])) for x in xs] + [((g_lo[0], y), (g_hi[0], y)) for y in ys]
        ax.add_collection(LineCollection(lines, colors="#e3e7ec", linewidths=0.8, zorder=0))

    f0 = idx[0]
    artists = aplot.draw_body(
        ax,
        tr.body,
        world[f0],
        [aplot.STATE_COLORS[int(s)] for s in tr.node_state[f0]],
        node_radius=r,
        spring_colors=aplot.SPRING_COLOR,
    )
    (trail_line,) = ax.plot([], [], color="#7f7f7f", lw=1.0, ls="--", zorder=1)
    (com_dot,) = ax.plot([], [], "+", color="#444444", ms=7, zorder=5)
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
    caption = title if title is not None else "red: expanding   blue: contracting   green: neutral"
    overlay = _TextOverlay(width, height)

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
    springs = np.asarray(tr.body.springs)
    regions = tr.body.regions
    loops = tr.body.skin_loops
    try:
        for f in iterator:
            pos = world[f]
            if artists["fill"] is not None:
                artists["fill"].set_verts([pos[reg] for reg in regions])
            if len(springs):
                artists["springs"].set_segments(pos[springs])
            if color_springs:
                artists["springs"].set_color([aplot.STATE_COLORS[int(s)] for s in tr.spring_state[f]])
            artists["skin"].set_segments(aplot._loops_closed(pos, loops))
            artists["nodes"].set_offsets(pos)
            artists["nodes"].set_facecolor([aplot.STATE_COLORS[int(s)] for s in tr.node_state[f]])
            c = com[f]
            if trail:
                upto = [k for k in idx if k <= f]
                trail_line.set_data(com[upto, 0], com[upto, 1])
            com_dot.set_data([c[0]], [c[1]])
            centre = c if follow else fixed_centre
            ax.set_xlim(centre[0] - view_w / 2, centre[0] + view_w / 2)
            ax.set_ylim(centre[1] - view_h / 2, centre[1] + view_h / 2)
            canvas.draw()
            rgb = np.asarray(canvas.buffer_rgba())[:height, :width, :3]
            travelled = float(np.linalg.norm(tr.com[f] - tr.com[0]))
            image = overlay.apply(
                rgb,
                f"t = {tr.times[f]:6.2f}   step {int(tr.steps[f]):5d}\ndistance {travelled:8.3f}",
                caption,
                "motion" if align else "",
            )
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


class _TextOverlay:
    """Text drawn with Pillow (much faster than matplotlib text), in matplotlib's DejaVu fonts."""

    def __init__(self, width: int, height: int):
        from matplotlib import font_manager
        from PIL import ImageFont

        scale = max(0.7, min(width, 1.6 * height) / 560)
        try:
            self.mono = ImageFont.truetype(font_manager.findfont("DejaVu Sans Mono"), int(round(12 * scale)))
            self.sans = ImageFont.truetype(font_manager.findfont("DejaVu Sans"), int(round(10 * scale)))
        except Exception:  # pragma: no cover - no FreeType
            self.mono = self.sans = ImageFont.load_default()
        self.width, self.height = width, height
        self.margin = int(round(6 * scale))

    def apply(self, rgb: np.ndarray, top_left: str, bottom_right: str, top_right: str):
        from PIL import Image, ImageDraw

        image = Image.fromarray(np.ascontiguousarray(rgb))
        draw = ImageDraw.Draw(image)
        m = self.margin
        draw.multiline_text((m, m), top_left, font=self.mono, fill=(34, 34, 34), spacing=2)
        if bottom_right:
            draw.text((self.width - m, self.height - m), bottom_right, font=self.sans, fill=(85, 85, 85), anchor="rd")
        if top_right:
            draw.text(
                (int(0.9375 * self.width), int(0.085 * self.height) - 2),
                top_right,
                font=self.sans,
                fill=(119, 119, 119),
                anchor="md",
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


#: Colours every GIF palette keeps exactly (background, skin, springs, fill, grid, text, node states).
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
