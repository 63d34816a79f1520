#!/usr/bin/env python3
"""Counts the public types (struct, enum, trait, type alias) of topomech whose own doc block holds a
runnable Rust example, from the HTML of `cargo doc --no-deps` (redirect pages of re-exports skipped).

Usage: cargo doc --no-deps && python3 scripts/doc_type_examples.py [doc dir]
"""
import os, re, sys
root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.environ.get("CARGO_TARGET_DIR", "target"), "doc", "topomech")
seen = {}
for dp, dn, fn in os.walk(root):
    for f in fn:
        m = re.match(r'(struct|enum|trait|type)\.(.*)\.html$', f)
        if not m:
            continue
        h = open(os.path.join(dp, f), errors="ignore").read()
        if "<title>Redirection</title>" in h or len(h) < 600:
            continue
        i = h.find('<details class="toggle top-doc"')
        if i < 0:
            i = h.find('class="docblock"')
        j = min([x for x in (h.find('id="implementations"'), h.find('id="fields"'), h.find('id="variants"'), h.find('id="required-methods"'), h.find('id="aliased-type"')) if x >= 0] or [len(h)])
        block = h[i:j] if i >= 0 and j > i else ''
        rel = os.path.relpath(os.path.join(dp, f), root)
        key = (rel.split("/")[0], m.group(2))
        # keep the deepest path (canonical definition module)
        ok = 'rust-example-rendered' in block
        if key not in seen or rel.count('/') > seen[key][0].count('/'):
            seen[key] = (rel, ok)
tot = len(seen); ex = sum(1 for v in seen.values() if v[1])
print(f"types {tot}, with example {ex}")
for k, (rel, ok) in sorted(seen.items(), key=lambda kv: kv[1][0]):
    if not ok:
        print("missing", rel)
