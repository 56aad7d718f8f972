#!/usr/bin/env python3
"""Refits the calibration of the diagnosis's confidence (crates/diagnose/src/confidence.rs,
CALIBRATION) from `subfric selfcheck --sets DIR --json FILE` outputs, and checks it.

    python3 scripts/calibrate_confidence.py PREFIX 1001,1002,1003 [RIDGE]
        fits the logistic regression of "the verdict is exactly right" on the verdict's features
        over PREFIX-1001.json, PREFIX-1002.json, ... and prints the coefficients and the
        reliability of the fitted confidence (in-sample: check it on other seeds).
    python3 scripts/calibrate_confidence.py PREFIX 2001,2002 --coef c0,c1,...
        prints the reliability of given coefficients on other files.

The features are computed from each case's `weighed` stages, `verdict` and
`without_first_loadings` exactly as VerdictFeatures::of does. Standard library only.
"""
import json, sys, math

prefix=sys.argv[1]; seeds=sys.argv[2].split(',')
T=1.0; MAXM=8.0
def same(a,b): return sorted(a)==sorted(b)
def feats(c):
    path=1.0
    for st in c['weighed']:
        ch=[o for o in st['options'] if o['chosen']]
        path*= ch[0]['probability'] if ch else 1.0
    margin=max(-MAXM,min(MAXM, math.log(max(path,1e-300))-math.log(max(1-path,1e-300))))
    last=c['weighed'][-1] if c['weighed'] else None
    remaining=math.log(max(1,last['dispersion'])) if last else 0
    rej=0.0
    if last:
        best=max([o['evidence'] for o in last['options'] if not o['chosen'] and math.isfinite(o['evidence'])]+[0.0])
        rej=math.log(1+best/max(1,last['dispersion']))
    v=c['verdict']; w=c.get('without_first_loadings')
    return [1.0, float(len(v)==0), float(v==['unexplained']), float(len(v)>=2), margin, remaining, rej, float(w is not None and not same(w,v))]
X=[];Y=[];names=[]
for s in seeds:
    try: d=json.load(open(f'{prefix}-{s}.json'))
    except Exception as e: print('skip',s,e); continue
    for c in d['cases']:
        if c['confidence'] is None: continue
        X.append(feats(c)); Y.append(1.0 if same(c['truth'],c['verdict']) else 0.0); names.append((s,c['name'],c['confidence']))
n=len(X); k=len(X[0]); print(n,'sets', sum(Y),'right')
def sig(z): return 1/(1+math.exp(-max(-50,min(50,z))))
def evaluate(b, label):
    ps=[sig(sum(x*bb for x,bb in zip(xi,b))) for xi in X]
    brier=sum((p-y)**2 for p,y in zip(ps,Y))/n
    ll=-sum(math.log(max(1e-9,p if y else 1-p)) for p,y in zip(ps,Y))/n
    c9=[(p,y) for p,y in zip(ps,Y) if p>=0.9]
    print(f'{label}: brier {brier:.3f} logloss {ll:.3f}; >=0.9: {int(sum(y for _,y in c9))}/{len(c9)}')
    for lo,hi in [(0,.5),(.5,.7),(.7,.9),(.9,1.01)]:
        b_=[(p,y) for p,y in zip(ps,Y) if lo<=p<hi]
        if b_: print(f'   {lo:.1f}-{min(hi,1):.1f}: {len(b_)} sets, mean p {sum(p for p,_ in b_)/len(b_):.2f}, right {sum(y for _,y in b_)/len(b_):.2f}')
    return ps
if '--coef' in sys.argv:
    b=[float(v) for v in sys.argv[sys.argv.index('--coef')+1].split(',')]
    evaluate(b,'given'); sys.exit()
lam=float(sys.argv[3]) if len(sys.argv)>3 else 1.0
b=[0.0]*k
for it in range(200):
    ps=[sig(sum(x*bb for x,bb in zip(xi,b))) for xi in X]
    g=[sum((p-y)*xi[j] for p,y,xi in zip(ps,Y,X)) + (lam*b[j] if j>0 else 0) for j in range(k)]
    H=[[sum(p*(1-p)*xi[a]*xi[c] for p,xi in zip(ps,X)) + (lam if a==c and a>0 else 0) + (1e-9 if a==c else 0) for c in range(k)] for a in range(k)]
    # solve H d = g
    M=[row[:]+[g[i]] for i,row in enumerate(H)]
    for i in range(k):
        piv=max(range(i,k),key=lambda r:abs(M[r][i])); M[i],M[piv]=M[piv],M[i]
        for r in range(k):
            if r!=i:
                f=M[r][i]/M[i][i]
                for cc in range(i,k+1): M[r][cc]-=f*M[i][cc]
    d=[M[i][k]/M[i][i] for i in range(k)]
    b=[bb-dd for bb,dd in zip(b,d)]
    if max(abs(x) for x in d)<1e-10: break
print('coef', ','.join(f'{v:.4f}' for v in b))
evaluate(b,'fitted')
evaluate([0,0,0,0,1,0,0,0],'margin only')
