import sys, glob, json; sys.path.insert(0,'tmp'); from check import *
def overrides_of(run):
    c = animat.load_config(run + "/config.toml")
    return c
for run in sys.argv[1:]:
    best = sorted(glob.glob(run+"/best/gen_*.json"))[-1]
    g = genome(best)
    c0 = overrides_of(run)
    fits=[]
    for s in (1,2,4,16):
        c = animat.load_config(run + "/config.toml"); c["physics.substeps"]=s
        r = animat.evaluate(g, c); fits.append(r.fitness)
        if s==1: info=(r.collisions, round(r.min_area_ratio,3), r.valid)
    ov = {"scene.drag_normal": c0["scene.drag_normal"], "development.frequency_max": c0["development.frequency_max"], "development.max_cells": c0["development.max_cells"]}
    base, ch = chaos(g, ov, subs=1)
    err = [abs(f-fits[-1])/max(fits[-1],1e-9)*100 for f in fits[:-1]]
    print(run, best[-16:], "fits", ['%.3f'%f for f in fits], "err%", ['%.2f'%e for e in err], "coll,minS,valid", info, "chaos", ['%.3f'%f for f in ch], flush=True)
