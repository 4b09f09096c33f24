"""Evolvable stiffness (docs/model.md): the best swimmer of a run with evolvable stiffness
(genome.extra_outputs = "stiffness"), phase map beside stiffness map (nodes and springs coloured by
their factors).

    PYTHONPATH=build/python .venv/bin/python examples/stiffness_map.py --run DIR [--out PNG]
"""

import matplotlib.pyplot as plt

import animat

from _common import fresh_run, parser, save_png

args = parser(__doc__, "stiffness_map.png").parse_args()
run = fresh_run(args)
body = animat.build_body(animat.develop(run.best().genome, run.config), config=run.config)
print(
    body,
    "stiffness",
    body.stiffness.min() if len(body.stiffness) else None,
    "..",
    body.stiffness.max() if len(body.stiffness) else None,
)
fig, (a, b) = plt.subplots(1, 2, figsize=(9, 4))
animat.plot.phase_map(body, ax=a)
animat.plot.stiffness_map(body, ax=b)
fig.tight_layout()
save_png(fig, args.out)
