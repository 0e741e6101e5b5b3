#!/usr/bin/env python3
"""Independent check of gaitfit's coefficient exports with Python's own readers (optional;
`cargo test` never needs Python).

1. Every fits/<id>.json and fits/<id>.toml hold the same record: `json.load` and `tomllib.load`
   give equal dictionaries once JSON's nulls are dropped (TOML has no null: a missing number,
   e.g. an open interval end, is an absent key), with every float bit-identical.
2. With --rust FILE (`gaitfit export --format rust -o FILE`): every `pub const` in module
   `<relation>` has the bits of the JSON coefficient it comes from.

    /work/venv/bin/python tools/export/check_toml_json.py fits
    gaitfit export --format rust -o /tmp/c.rs && \
        /work/venv/bin/python tools/export/check_toml_json.py fits --rust /tmp/c.rs

Prints one line per file and exits 1 on the first difference (Python >= 3.11 for tomllib).
"""
import argparse
import json
import math
import pathlib
import re
import struct
import sys
import tomllib


def drop_nulls(x):
    if isinstance(x, dict):
        return {k: drop_nulls(v) for k, v in x.items() if v is not None}
    if isinstance(x, list):
        if any(v is None for v in x):
            raise ValueError(f"array with null: {x}")
        return [drop_nulls(v) for v in x]
    return x


def bits(v):
    return struct.pack("<d", float(v))


def same(a, b, where):
    """Equal structure; numbers equal bit for bit (TOML writes 255.0 where JSON may write 255.0
    too, but an integer-valued float read as int by one reader is compared as float)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return f"{where}: keys differ: {sorted(a.keys() ^ b.keys())}"
        for k in a:
            d = same(a[k], b[k], f"{where}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{where}: lengths {len(a)} vs {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            d = same(x, y, f"{where}[{i}]")
            if d:
                return d
        return None
    if isinstance(a, bool) or isinstance(b, bool):
        return None if a is b else f"{where}: {a!r} vs {b!r}"
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if isinstance(a, int) and isinstance(b, int):
            return None if a == b else f"{where}: {a} vs {b}"
        if math.isnan(float(a)) or bits(a) != bits(b):
            return f"{where}: {a!r} vs {b!r} (not bit-identical)"
        return None
    return None if a == b else f"{where}: {a!r} vs {b!r}"


def ident(name, upper):
    s = ""
    for ch in name:
        if ch.isascii() and ch.isalnum():
            s += ch.upper() if upper else ch.lower()
        elif s and not s.endswith("_"):
            s += "_"
    s = s.rstrip("_")
    return "_" + s if (not s or s[0].isdigit()) else s


def check_rust(path, records):
    src = pathlib.Path(path).read_text()
    consts = {}
    module = None
    for line in src.splitlines():
        m = re.match(r"pub mod (\w+) \{", line)
        if m:
            module = m.group(1)
        m = re.match(r"\s+pub const (\w+): f64 = ([^;]+);", line)
        if m:
            consts[(module, m.group(1))] = float(m.group(2).replace("_", ""))
    n = 0
    for rec in records:
        for c in rec["coefficients"]:
            key = (ident(rec["relation"], False), ident(c["name"], True))
            if key not in consts:
                return f"{path}: no constant {key[0]}::{key[1]}"
            if bits(consts[key]) != bits(c["value"]):
                return f"{path}: {key[0]}::{key[1]} = {consts[key]!r}, JSON {c['value']!r}"
            n += 1
    print(f"{path}: {n} constants bit-identical to the JSON")
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fits", nargs="?", default="fits")
    ap.add_argument("--rust", help="a `gaitfit export --format rust` file to check too")
    a = ap.parse_args()
    records = []
    for pj in sorted(pathlib.Path(a.fits).glob("*.json")):
        pt = pj.with_suffix(".toml")
        j = json.loads(pj.read_text())
        with open(pt, "rb") as f:
            t = tomllib.load(f)
        try:
            d = same(drop_nulls(j), t, pj.stem)
        except ValueError as e:
            d = f"the JSON has {e} (TOML cannot hold it)"
        if d:
            print(f"DIFFERENT {pj} vs {pt}: {d}")
            return 1
        print(f"{pj.stem}: JSON (nulls dropped) == TOML, floats bit-identical")
        records.append(j)
    if not records:
        print(f"{a.fits}: no *.json")
        return 1
    if a.rust:
        d = check_rust(a.rust, records)
        if d:
            print(f"DIFFERENT {d}")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
