import sys, glob; sys.path.insert(0,'tmp'); from check import *
import numpy as np
run=sys.argv[1]
g = genome(sorted(glob.glob(run+"/best/gen_*.json"))[-1])
c = animat.load_config(run+"/config.toml")
e = animat.develop(g, c); b = animat.build_body(e, c)
sim = animat.Simulation(b, config=c)
sim.monitor_embedding(b)
prev = np.asarray(sim.positions).copy(); prevc = dict(sim.counters)
for k in range(4000):
    sim.step(1)
    em = sim.embedding
    if not em["intact"]:
        P = np.asarray(sim.positions)
        print("broken at step", k, em, sim.counters, "prev counters", prevc)
        for r, loop in enumerate(b.regions):
            a = 0.5*sum(P[loop[i],0]*P[loop[(i+1)%len(loop)],1]-P[loop[(i+1)%len(loop)],0]*P[loop[i],1] for i in range(len(loop)))
            a0 = 0.5*sum(prev[loop[i],0]*prev[loop[(i+1)%len(loop)],1]-prev[loop[(i+1)%len(loop)],0]*prev[loop[i],1] for i in range(len(loop)))
            if a/b.rest_areas[r] <= 0.05: print("region", r, loop, "S/S0", a/b.rest_areas[r], "prev", a0/b.rest_areas[r])
            if a/b.rest_areas[r] <= 0:
                for v in loop: print("  node", v, prev[v], "->", P[v], "moved", P[v]-prev[v])
        break
    prev = np.asarray(sim.positions).copy(); prevc = dict(sim.counters)
