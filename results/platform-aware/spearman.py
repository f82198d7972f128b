import json, sys, glob, os
def ranks(xs):
    order = sorted(range(len(xs)), key=lambda i: xs[i])
    r = [0.0]*len(xs); i = 0
    while i < len(xs):
        j = i
        while j+1 < len(xs) and xs[order[j+1]] == xs[order[i]]: j += 1
        for k in range(i, j+1): r[order[k]] = (i+j)/2
        i = j+1
    return r
def spearman(a, b):
    ra, rb = ranks(a), ranks(b); n = len(a)
    ma, mb = sum(ra)/n, sum(rb)/n
    cov = sum((x-ma)*(y-mb) for x, y in zip(ra, rb))
    va = sum((x-ma)**2 for x in ra); vb = sum((y-mb)**2 for y in rb)
    return cov/(va*vb)**0.5 if va > 0 and vb > 0 else float('nan')
out = sys.argv[1]
for name in sorted({os.path.basename(p).rsplit('-', 1)[0] for p in glob.glob(out+'/*-policy.jsonl')}):
    load = lambda who: {d['level']: d['success_ratio'] for d in map(json.loads, open(f'{out}/{name}-{who}.jsonl'))}
    p, e = load('policy'), load('expert')
    levels = sorted(set(p) & set(e))
    rules = [l for l in levels if '-rules/' in l]; gen = [l for l in levels if '-gen/' in l]
    mean = lambda d, ls: sum(d[l] for l in ls)/max(len(ls), 1)
    print(f"{name}: {len(rules)} rule + {len(gen)} Generator levels; Solver {mean(p, rules):.3f} / {mean(p, gen):.3f}, expert {mean(e, rules):.3f} / {mean(e, gen):.3f} (rule / Generator); Spearman over all {spearman([p[l] for l in levels], [e[l] for l in levels]):.2f}")
