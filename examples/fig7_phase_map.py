"""Paper Fig. 7: the best swimmer of a fresh run at rest, nodes coloured by their oscillation phase
shift (colour range normalised to the body, maximum indicated).

    PYTHONPATH=build/python .venv/bin/python examples/fig7_phase_map.py [--run DIR] [--out PNG]
"""

import animat

from _common import fresh_run, parser, save_png

args = parser(__doc__, "phase_map.png").parse_args()
run = fresh_run(args)
body = animat.build_body(animat.develop(run.best().genome, run.config), run.config)
print(body, "phases", body.phase.min(), "..", body.phase.max())
save_png(animat.plot.phase_map(body), args.out)
