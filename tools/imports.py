import os,re,collections,sys
root=sys.argv[1]
os.chdir(root)
mods={}
for f in os.listdir('.'):
    if f.endswith('.rs') and f!='lib.rs': mods[f[:-3]]=None
    elif os.path.isdir(f): mods[f]=None
g=collections.defaultdict(lambda: collections.defaultdict(list))
for m in mods:
    files=[]
    if os.path.isfile(m+'.rs'): files.append(m+'.rs')
    if os.path.isdir(m):
        for r,_,fs in os.walk(m):
            files+=[os.path.join(r,x) for x in fs if x.endswith('.rs') and 'tests' not in x]
    for f in files:
        txt=open(f).read()
        txt=re.split(r'#\[cfg\(test\)\]\s*mod tests', txt)[0]
        for ln,line in enumerate(txt.splitlines(),1):
            s=line.strip()
            if s.startswith('//'): continue
            for d in re.findall(r'crate::([a-z_0-9]+)', s):
                if d!=m and d in mods: g[m][d].append(f"{f}:{ln}")
idx={};low={};st=[];on=set();sccs=[];i=[0]
sys.setrecursionlimit(10000)
def sc(v):
    idx[v]=low[v]=i[0];i[0]+=1;st.append(v);on.add(v)
    for w in g[v]:
        if w not in idx: sc(w);low[v]=min(low[v],low[w])
        elif w in on: low[v]=min(low[v],idx[w])
    if low[v]==idx[v]:
        c=[]
        while True:
            w=st.pop();on.discard(w);c.append(w)
            if w==v:break
        sccs.append(c)
for v in list(mods):
    if v not in idx: sc(v)
for c in sccs:
    if len(c)>1:
        print("cycle:",c)
        for a in c:
            for b in c:
                if b in g[a]: print(f"  {a} -> {b}: {g[a][b][:3]}")
