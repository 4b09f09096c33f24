import animat, time
c = animat.Config()
rng_seed = 0
t0=time.time(); n=0; tries=0; cells=[]
dev=0
while n < 100:
    g = animat.Genome.random(seed=1000+tries) if False else animat.Genome.random(1000+tries)
    tries+=1
    t=time.time(); e = animat.develop(g, c); dev+=time.time()-t
    if e.cell_count >= 4:
        n+=1; cells.append(e.cell_count)
print("tries", tries, "dev s", dev, "total", time.time()-t0, "mean cells", sum(cells)/len(cells))
