"""Paper Figs. 8-9: best fitness over the generations of a fresh run, generations where the best's
morphology changed marked, with thumbnails of those bodies (coloured by phase shift).

    PYTHONPATH=build/python .venv/bin/python examples/fig8_fitness_history.py [--run DIR] [--out PNG]
"""

import animat

from _common import fresh_run, parser, save_png

p = parser(__doc__, "fitness_history.png")
p.set_defaults(generations=20)
args = p.parse_args()
run = fresh_run(args)
print(run.summary())
changes = run.morphology_changes()
print("morphology changed at generations", [e.generation for e in changes])
save_png(animat.plot.fitness_history(run, max_thumbnails=6), args.out)
