#!/usr/bin/env python3
"""Module import graph of a Rust crate: cycles and imports against the layering.

Usage: python3 tools/modgraph.py [src]   (DEPTH=2 default: crate::a::b granularity)
Collects `crate::…`, `super::…` and `self::…` paths from every file (use lines and inline paths),
maps each to a module at DEPTH levels, and prints strongly connected components > 1.
"""
import os, re, sys
from collections import defaultdict

SRC = sys.argv[1] if len(sys.argv) > 1 else "src"
DEPTH = int(os.environ.get("DEPTH", "2"))
LAYERS = ["gait", "units", "fsio", "shared_data", "ingest", "events", "relations", "fit",
          "generator", "export", "report", "calibrate", "studio", "error", "cli", "main", "lib"]

def mod_path(path):
    rel = os.path.relpath(path, SRC)[:-3].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    if rel in (["lib"], ["main"]):
        return []
    return rel

files = []
for root, _, names in os.walk(SRC):
    for n in names:
        if n.endswith(".rs"):
            files.append(os.path.join(root, n))

known = set()
for f in files:
    m = mod_path(f)
    for i in range(1, len(m) + 1):
        known.add(tuple(m[:i]))

def trunc(m):
    m = list(m)
    # stop at the deepest known module
    while m and tuple(m) not in known:
        m.pop()
    return tuple(m[:DEPTH])

edges = defaultdict(set)
pat = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
for f in files:
    me = mod_path(f)
    is_mod = os.path.basename(f) in ("mod.rs",)
    text = open(f).read()
    # drop #[cfg(test)] mod tests { … } blocks roughly: everything after "#[cfg(test)]\nmod tests"
    cut = re.search(r"#\[cfg\(test\)\]\s*mod tests", text)
    if cut:
        text = text[:cut.start()]
    text = re.sub(r"//[^\n]*", "", text)
    for m in pat.finditer(text):
        head, rest = m.group(1), m.group(2).split("::")[1:]
        if head == "crate":
            target = rest
        elif head == "self":
            target = me + rest
        else:
            base = me[:] if is_mod else me[:-1]
            segs = rest
            base = base[:-1]
            while segs and segs[0] == "super":
                base = base[:-1]
                segs = segs[1:]
            target = base + segs
        a, b = trunc(me), trunc(target)
        if a and b and a != b and not (a[:len(b)] == b or b[:len(a)] == a):
            edges[a].add(b)

# Tarjan
index, low, st, on, comps, idx = {}, {}, [], set(), [], [0]
def sc(v):
    index[v] = low[v] = idx[0]; idx[0] += 1; st.append(v); on.add(v)
    for w in edges.get(v, ()):
        if w not in index:
            sc(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        c = []
        while True:
            w = st.pop(); on.discard(w); c.append(w)
            if w == v: break
        if len(c) > 1: comps.append(c)
sys.setrecursionlimit(10000)
for v in list(edges):
    if v not in index:
        sc(v)
print(f"cycles (depth {DEPTH}): {len(comps)}")
for c in comps:
    names = sorted("::".join(x) for x in c)
    print("  ", " <-> ".join(names))
    for a in c:
        for b in edges[a]:
            if b in c:
                print("      ", "::".join(a), "->", "::".join(b))
bad = []
for a, bs in edges.items():
    for b in bs:
        if a[0] in LAYERS and b[0] in LAYERS and LAYERS.index(b[0]) > LAYERS.index(a[0]):
            bad.append(("::".join(a), "::".join(b)))
print(f"imports against the layering: {len(bad)}")
for a, b in sorted(bad):
    print("  ", a, "->", b)
