import sys, json, time, animat
def genome(path):
    return animat.Genome.from_json(json.dumps(json.load(open(path))["genome"]))
def run(g, overrides, subs=(1,2,4,16), label="", stop=True):
    out=[]
    for s in subs:
        c = animat.Config()
        for k,v in overrides.items(): c[k]=v
        c["physics.substeps"]=s
        t=time.time(); r = animat.evaluate(g, c); dt=time.time()-t
        out.append(r)
        print(f"{label} sub={s:2d} fit={r.fitness:8.4f} valid={int(r.valid)} st={int(r.stable)} coll={r.collisions} inel={r.collisions_inelastic} unres={r.collisions_unresolved} minS={r.min_area_ratio:.3f} inv={r.inverted_region_steps} skinx={r.skin_crossing_steps} first={r.first_invalid_step} dl={r.drag_limited} t={dt*1000:.0f}ms", flush=True)
    return out
OLD = {"scene.effects": ["springs","actuation","pressure","drag","skin_collision"], "physics.drag_scheme":"stable", "evaluation.check_embedding": True}
if __name__=="__main__":
    g = genome(sys.argv[1]); dn=float(sys.argv[2])
    subs = tuple(int(x) for x in sys.argv[3].split(",")) if len(sys.argv)>3 else (1,2,4,16)
    o = dict(OLD); o["scene.drag_normal"]=dn
    run(g, o, subs, "old")
    run(g, {"scene.drag_normal":dn}, subs, "new")

import numpy as np
def chaos(g, overrides, eps=1e-6, k=4, subs=1):
    c = animat.Config()
    for kk,v in overrides.items(): c[kk]=v
    c["physics.substeps"]=subs
    e = animat.develop(g, c); b = animat.build_body(e, c)
    base = animat.swim(b, config=c)
    rng = np.random.default_rng(0)
    fits=[]
    for j in range(k):
        p = np.asarray(b.positions) + eps*rng.standard_normal(np.asarray(b.positions).shape)
        bj = animat.build_body(p, e.amplitude, e.frequency, e.phase, c)
        r = animat.swim(bj, config=c)
        fits.append(r.distance)
    return base.distance, fits
