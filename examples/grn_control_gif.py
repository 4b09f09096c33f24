"""Active control (docs/control.md): a GRN-controlled swimmer turning toward a chemical source, as a GIF.

Swims the best of the amplitude-mode chemotaxis run (data/control/chemotaxis_amplitude_seed2_*)
toward sources in several directions with ``animat.grn_swim`` and writes one panel per source into
docs/images/control_chemotaxis_amplitude_seed2.gif: the body (springs, skin), the source (star),
the direction of the source (red arrow; the source itself is 20 length units away, off the
panel) and the centre-of-mass path so far (blue). The panels are centred on the start.

    PYTHONPATH=build/python .venv/bin/python examples/grn_control_gif.py
"""

import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from PIL import Image  # noqa: E402

import animat  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
RUN = "chemotaxis_amplitude_seed2"
ANGLES = (90.0, 45.0, 0.0, -45.0)  # source directions (degrees from +x) seen from the start


def main() -> None:
    cfg = animat.load_config(str(ROOT / "data" / "control" / f"{RUN}_config.toml"))
    genome = animat.Genome.load(str(ROOT / "data" / "control" / f"{RUN}_best_genome.json"))
    r = float(np.hypot(*cfg["scene.chemical_source"]))
    steps = int(cfg["evaluation.steps"])
    swims = []
    for a in ANGLES:
        src = [r * math.cos(math.radians(a)), r * math.sin(math.radians(a))]
        t = animat.grn_swim(genome, cfg, steps=steps, every=25, source=src)
        start = t["com"][0]
        swims.append((np.asarray(src) + start, t))
    body = animat.build_body(animat.develop(genome, cfg), config=cfg)
    springs = np.asarray(body.springs)
    skin = np.asarray(body.skin)
    frames = len(swims[0][1]["times"])
    images = []
    for k in range(0, frames, 2):
        fig = plt.figure(figsize=(9.0, 2.7), dpi=64)
        canvas = FigureCanvasAgg(fig)
        for j, (src, t) in enumerate(swims):
            ax = fig.add_subplot(1, len(swims), j + 1)
            p = t["positions"][k]
            c0 = t["com"][0]
            u = (src - t["com"][0]) / np.linalg.norm(src - t["com"][0])
            ax.annotate(
                "",
                xy=t["com"][0] + 5.0 * u,
                xytext=t["com"][0] + 3.0 * u,
                arrowprops=dict(arrowstyle="->", color="#d62728", lw=1.5),
            )
            ax.plot(t["com"][: k + 1, 0], t["com"][: k + 1, 1], color="#1f77b4", lw=1)
            for s in springs:
                ax.plot(p[s, 0], p[s, 1], color="#999999", lw=0.4)
            for s in skin:
                ax.plot(p[s, 0], p[s, 1], color="black", lw=1.0)
            half = 5.5
            mid = c0
            ax.set_xlim(mid[0] - half, mid[0] + half)
            ax.set_ylim(mid[1] - half, mid[1] + half)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"source at {ANGLES[j]:+.0f}°", fontsize=8)
        fig.suptitle(f"GRN control (amplitude mode), t = {swims[0][1]['times'][k]:.1f}", fontsize=9)
        canvas.draw()
        images.append(Image.fromarray(np.asarray(canvas.buffer_rgba())[:, :, :3]).quantize(colors=16))
        plt.close(fig)
    out = ROOT / "docs" / "images" / f"control_{RUN}.gif"
    images[0].save(out, save_all=True, append_images=images[1:], duration=80, loop=0, optimize=True)
    print(out, len(images), "frames", out.stat().st_size, "bytes")
    for (src, t), a in zip(swims, ANGLES):
        d = t["com"][-1] - t["com"][0]
        u = (src - t["com"][0]) / np.linalg.norm(src - t["com"][0])
        print(f"source at {a:+.0f} deg: moved {np.linalg.norm(d):.2f}, progress toward it {d @ u:.2f}")


if __name__ == "__main__":
    main()
