import sys; sys.path.insert(0,'tmp'); from check import *
g=genome(sys.argv[1]); dn=float(sys.argv[2])
variants = {
 "base": {},
 "cp300": {"scene.pressure":300.0},
 "cp1000": {"scene.pressure":1000.0},
 "damp10": {"scene.spring_damping":10.0},
 "f6": {"development.frequency_max":6.0},
}
for name, o in variants.items():
    o=dict(o); o["scene.drag_normal"]=dn
    fits=[]
    for s in (1,4,16):
        c=animat.Config()
        for k,v in o.items(): c[k]=v
        c["physics.substeps"]=s
        r=animat.evaluate(g,c); fits.append(r.fitness)
        if s==1: coll=r.collisions; ms=r.min_area_ratio; val=r.valid
    base, ch = chaos(g, o, subs=1)
    print(f"{name:8s} fits={['%.3f'%f for f in fits]} coll={coll} minS={ms:.3f} valid={val} chaos={['%.3f'%f for f in ch]}", flush=True)
