"""Other body graphs (docs/model.md): one embryo's centres turned into a body by each body.graph
(Gabriel, distance, alpha shape at two radii). Regions are filled; holes of the alpha shape are left
white and their boundary is drawn as skin (thick).

    PYTHONPATH=build/python .venv/bin/python examples/body_graphs.py [--run DIR] [--out PNG]
"""

import matplotlib.pyplot as plt

import animat

from _common import fresh_run, parser, save_png

args = parser(__doc__, "body_graphs.png").parse_args()
run = fresh_run(args)
embryo = animat.develop(run.best().genome, run.config)
panels = [
    ("gabriel", {}, "gabriel (paper)"),
    ("distance", {"body.distance_threshold": 1.5}, "distance, threshold 1.5"),
    ("alpha_shape", {"body.alpha": 1.0}, "alpha_shape, alpha 1.0"),
    ("alpha_shape", {"body.alpha": 0.6}, "alpha_shape, alpha 0.6"),
]
fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.4))
for ax, (graph, extra, title) in zip(axes, panels):
    c = animat.Config()
    c["body.graph"] = graph
    for key, value in extra.items():
        c[key] = value
    body = animat.build_body(embryo.positions, config=c)
    animat.plot.draw_body(ax, body)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_axis_off()
    holes = len(body.skin_loops) - 1
    ax.set_title(f"{title}\n{body.spring_count} springs, {body.region_count} regions, {holes} holes", fontsize=8)
    print(title, body)
fig.tight_layout()
save_png(fig, args.out)
