#!/usr/bin/env python3
"""Counts the public functions and methods of topomech that have a runnable rustdoc example.

Reads the HTML that `cargo doc --no-deps` writes (so only items reachable from the public API are
counted, each once at its canonical path): free functions (`fn.*.html`) and inherent methods
(sections `method.*` inside a type's `implementations-list`; trait-impl methods such as `fmt` are
not counted). An item "has an example" when its own doc block holds a rendered Rust code block
(rustdoc renders ```text blocks differently, so they do not count).

Usage: cargo doc --no-deps && python3 scripts/doc_examples.py [--missing] [doc dir]
"""
import os
import re
import sys
from collections import defaultdict

EXAMPLE = "rust-example-rendered"
END_MARKERS = ('id="trait-implementations', 'id="synthetic-implementations', 'id="blanket-implementations')


def inherent_methods(html):
    start = html.find('id="implementations-list"')
    if start < 0:
        return []
    ends = [html.find(m, start) for m in END_MARKERS]
    end = min([e for e in ends if e >= 0], default=len(html))
    region = html[start:end]
    hits = list(re.finditer(r'<section id="method\.([A-Za-z0-9_]+)" class="method"', region))
    out = []
    for k, m in enumerate(hits):
        chunk = region[m.end() : hits[k + 1].start() if k + 1 < len(hits) else len(region)]
        out.append((m.group(1), EXAMPLE in chunk))
    return out


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    show_missing = "--missing" in sys.argv
    root = args[0] if args else os.path.join(os.environ.get("CARGO_TARGET_DIR", "target"), "doc", "topomech")
    stats = defaultdict(lambda: [0, 0])  # module -> [items, with example]
    missing = defaultdict(list)
    for dirpath, _, files in os.walk(root):
        module = os.path.relpath(dirpath, root).replace(os.sep, "::")
        module = "(crate root)" if module == "." else module
        for name in sorted(files):
            if not name.endswith(".html") or not re.match(r"(fn|struct|enum|trait|type)\.", name):
                continue
            html = open(os.path.join(dirpath, name), encoding="utf-8").read()
            if 'http-equiv="refresh"' in html or "<title>Redirection</title>" in html:
                continue
            kind, item = name[:-5].split(".", 1)
            if kind == "fn":
                entries = [(item, EXAMPLE in html)]
            else:
                entries = [(f"{item}::{m}", ok) for m, ok in inherent_methods(html)]
            for label, ok in entries:
                stats[module][0] += 1
                stats[module][1] += ok
                if not ok:
                    missing[module].append(label)
    total = [0, 0]
    print(f"{'module':<28} {'fns+methods':>11} {'with example':>12}")
    for module in sorted(stats):
        n, ok = stats[module]
        total[0] += n
        total[1] += ok
        print(f"{module:<28} {n:>11} {ok:>12}")
        if show_missing and missing[module]:
            print("    missing: " + ", ".join(missing[module]))
    print(f"{'total':<28} {total[0]:>11} {total[1]:>12}")


if __name__ == "__main__":
    main()
