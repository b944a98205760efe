#!/usr/bin/env python3
"""The house in layers, checked: each crate's lines and the crates it depends on, and any
import circle between the top-level modules of a crate (`crate::a` used in `b` and
`crate::b` in `a`, tests excluded). Exits 1 when a circle is found, when a library crate
is over 12 000 lines or the CLI over 1 500, or when a function outside tests and SIMD
kernels is over 80 lines.

    python3 tools/layers.py            # from the repository root
"""
import collections
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
CRATES = os.path.join(ROOT, "crates")
LIMIT_LIB, LIMIT_CLI, LIMIT_FN = 12_000, 1_500, 80


def sources(folder):
    for r, _, fs in os.walk(folder):
        for f in sorted(fs):
            if f.endswith(".rs"):
                yield os.path.join(r, f)


def without_tests(text):
    """The text before a file's `#[cfg(test)] mod tests`, or all of it."""
    return re.split(r"#\[cfg\(test\)\]\s*mod tests", text)[0]


def is_test_file(path):
    return os.path.basename(path) == "tests.rs" or "/tests/" in path


def workspace_deps(crate):
    text = open(os.path.join(CRATES, crate, "Cargo.toml")).read()
    deps = text.split("[dependencies]", 1)[-1].split("\n[", 1)[0]
    return sorted(set(re.findall(r"^(neurotex[a-z-]*)", deps, re.M)) - {crate})


def module_graph(src):
    mods = [f[:-3] for f in os.listdir(src) if f.endswith(".rs") and f not in ("lib.rs", "main.rs")]
    mods += [d for d in os.listdir(src) if os.path.isdir(os.path.join(src, d))]
    graph = collections.defaultdict(set)
    for m in mods:
        files = [os.path.join(src, m + ".rs")] if os.path.isfile(os.path.join(src, m + ".rs")) else []
        if os.path.isdir(os.path.join(src, m)):
            files += [f for f in sources(os.path.join(src, m)) if not is_test_file(f)]
        for f in files:
            for line in without_tests(open(f).read()).splitlines():
                if line.strip().startswith("//"):
                    continue
                for d in re.findall(r"crate::([a-z_0-9]+)", line):
                    if d != m and d in mods:
                        graph[m].add(d)
    return mods, graph


def circles(mods, graph):
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in mods:
        if v not in index:
            visit(v)
    return found


def long_functions(path):
    """(name, first line, length) of each `fn` over the limit, outside tests and SIMD."""
    lines = without_tests(open(path).read()).splitlines()
    out = []
    for i, line in enumerate(lines):
        m = re.match(r"\s*(pub(\([a-z]+\))? )?(const )?(unsafe )?fn ([a-z_0-9]+)", line)
        if not m or line.rstrip().endswith(";"):
            continue
        indent = len(line) - len(line.lstrip())
        for j in range(i + 1, len(lines)):
            if lines[j].startswith(" " * indent + "}") and len(lines[j]) - len(lines[j].lstrip()) == indent:
                break
        else:
            continue
        kernel = any("target_feature" in lines[k] for k in range(max(0, i - 3), i))
        if j - i + 1 > LIMIT_FN and not kernel:
            out.append((m.group(5), i + 1, j - i + 1))
    return out


def main():
    failed = False
    # Crates with sources of their own (the benchmarks' crate has benches and examples only).
    crates = sorted(c for c in os.listdir(CRATES) if os.path.isdir(os.path.join(CRATES, c, "src")))
    print(f"{'crate':<22} {'lines':>6}  depends on")
    for c in crates:
        src = os.path.join(CRATES, c, "src")
        n = sum(len(open(f).read().splitlines()) for f in sources(src))
        print(f"{c:<22} {n:>6}  {', '.join(workspace_deps(c)) or '-'}")
        limit = LIMIT_CLI if c == "neurotex-cli" else LIMIT_LIB
        if n > limit:
            print(f"  over the limit of {limit} lines")
            failed = True
        for comp in circles(*module_graph(src)):
            print(f"  import circle between modules: {' <-> '.join(comp)}")
            failed = True
        for f in sources(src):
            if is_test_file(f):
                continue
            for name, line, length in long_functions(f):
                print(f"  {os.path.relpath(f, ROOT)}:{line}: fn {name} is {length} lines")
                failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
