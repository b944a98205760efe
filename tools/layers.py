#!/usr/bin/env python3
"""The house in layers, checked: each crate's lines and the crates it depends on, and any
import circle between the files of a crate. Exits 1 when a circle is found, when a library
crate is over 12 000 lines or the CLI over 1 500, when a function outside tests and SIMD
kernels is over 80 lines, or when ARCHITECTURE.md names in backticks a path (`tools/x.py`)
or a module path (`recording::read_recording`, `Dataset::open`, a bold **`module`**) that
is not in the tree.

    python3 tools/layers.py              # from the repository root
    python3 tools/layers.py --self-test  # the circle finder on a small tree of its own

The graph is over files (each module and submodule is one file: `lib.rs`, `a.rs`,
`a/mod.rs`, `a/b.rs`), tests excluded. A file's edges are the names it uses from other
files, resolved to the file that defines them:

- a path in code or in a private `use` (`crate::a::b::f`, `super::b::f`, `self::c::f`, or
  `c::f` for a submodule `c` the file declares) is followed module by module to the first
  name that is not a module, and the edge goes to the file that defines that name (or to
  the module's own file, when the path ends on a module);
- a name a module re-exports (`pub use c::X`, `pub use c::*`) resolves to the file it
  comes from, so `super::X` in `a/b.rs` points at `a/c.rs` when `a/mod.rs` only
  re-exports it; a name a module imports from another crate is no edge;
- `mod c;` declarations and `pub use` re-exports are not uses;
- a file's uses of its own submodules are not edges: the module tree already orders them
  top-down. A folder's `mod.rs` is its front door, which declares, re-exports and walks
  its children (`run_all` over the analyses), and the home of what they share (a
  `Context`, a `Candidate`); a child may use what its parents define. So the circles
  found are between files of which neither contains the other: siblings (`a/b.rs` and
  `a/c.rs`) or cousins, whose shared piece belongs in a common parent or a file of its
  own.

A circle is a strongly connected set of two or more files, or of two or more submodules
of one module, each taken with everything under it (`a/` and `b/` when a file under `a/`
uses one under `b/` and another file under `b/` one under `a/`).
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


ITEM = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:(?:unsafe|async|const|extern\s+\S+)\s+)*"
                  r"(?:fn|struct|enum|trait|type|const|static|union|mod)\s+([A-Za-z_][A-Za-z_0-9]*)"
                  r"|^\s*macro_rules!\s*([A-Za-z_][A-Za-z_0-9]*)", re.M)
MOD_DECL = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z_0-9]+)\s*;", re.M)
USE = re.compile(r"^\s*(pub(?:\([^)]*\))?\s+)?use\s+([^;]*);", re.M)
PATH = re.compile(r"\b((?:crate|super|self)(?:\s*::\s*[A-Za-z_][A-Za-z_0-9]*)+)")


LEXEME = re.compile(r"""//[^\n]*|/\*.*?\*/|r(\#*)"[\s\S]*?"\1|"(?:[^"\\]|\\.)*"|'(?:[^'\\\n]|\\[^\n]{1,9})'""",
                    re.S)


def code_of(path):
    """A file's text without its tests and comments, and with its string and character
    literals emptied (one pass, so that `"//"` is a string and `'"'` a character)."""
    def blank(m):
        token = m.group(0)
        return "" if token.startswith("/") else ("' '" if token.startswith("'") else '""')
    return LEXEME.sub(blank, without_tests(open(path).read()))


def use_paths(tree):
    """The paths of a `use` tree, each as (segments, alias): `a::{b, c::d as e, *}`."""
    tree = re.sub(r"\s+", " ", tree).strip()
    split = lambda text: [t.strip() for t in text.split("::") if t.strip()]  # noqa: E731
    if "{" not in tree:
        alias = None
        if " as " in tree:
            tree, alias = (t.strip() for t in tree.split(" as ", 1))
        segs = split(tree)
        return [(segs, alias or segs[-1])]
    start = tree.index("{")
    prefix, inner = split(tree[:start]), tree[start + 1:tree.rindex("}")]
    parts, depth, last = [], 0, 0
    for i, ch in enumerate(inner + ","):
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            parts.append(inner[last:i].strip())
            last = i + 1
    out = []
    for part in filter(None, parts):
        for segs, alias in use_paths(part):
            if segs == ["self"]:  # `a::{self, b}` imports `a` itself
                out.append((prefix, prefix[-1] if alias == "self" else alias))
            else:
                out.append((prefix + segs, alias))
    return out


def crate_files(src):
    """Each module's path (a tuple of names; the root is ()) and its file."""
    files = {}
    for f in sources(src):
        if is_test_file(f):
            continue
        rel = os.path.relpath(f, src)[:-3].split(os.sep)
        if rel[-1] == "mod" or (len(rel) == 1 and rel[0] in ("lib", "main")):
            rel = rel[:-1]
        files[tuple(rel)] = f
    return files


class Crate:
    """One crate's modules: what each defines, declares, imports and re-exports."""

    def __init__(self, src):
        self.files = crate_files(src)
        self.code = {m: code_of(f) for m, f in self.files.items()}
        self.defined, self.children, self.uses = {}, {}, {}
        for m, text in self.code.items():
            self.defined[m] = {a or b for a, b in ITEM.findall(text)}
            declared = set(MOD_DECL.findall(text))
            self.children[m] = {c for c in declared if m + (c,) in self.files}
            # name -> (segments, public) of each `use`, globs under "*" as a list.
            uses = collections.defaultdict(list)
            for public, tree in USE.findall(text):
                for segs, alias in use_paths(tree):
                    uses[alias].append((segs, bool(public)))
            self.uses[m] = uses

    def resolve(self, module, segs, depth=0):
        """The file defining the name `segs` names from `module`, or None (another crate)."""
        if depth > 20 or not segs:
            return None
        head, rest = segs[0], segs[1:]
        if head == "crate":
            return self.walk((), rest, depth)
        if head == "super":
            return self.walk(module[:-1], rest, depth)
        if head == "self":
            return self.walk(module, rest, depth)
        if head in self.children[module]:
            return self.walk(module + (head,), rest, depth)
        return None

    def walk(self, module, segs, depth):
        """`segs` followed from inside `module` (after `crate::`, `super::` or `self::`)."""
        if not segs:
            return self.files[module]
        head = segs[0]
        if head in ("super", "self", "crate"):
            return self.resolve(module, segs, depth + 1)
        if head in self.children[module]:
            return self.walk(module + (head,), segs[1:], depth)
        if head in self.defined[module]:
            return self.files[module]
        for target, _ in self.uses[module].get(head, []):
            return self.resolve(module, target + segs[1:], depth + 1)
        for target, _ in self.uses[module].get("*", []):
            found = self.resolve(module, target[:-1] + segs, depth + 1)
            if found is not None:
                return found
        return self.files[module]

    def edges(self, module):
        """The files whose names `module`'s file uses."""
        text = self.code[module]
        found = set()
        for public, tree in USE.findall(text):
            if not public:
                found |= {self.resolve(module, segs) for segs, alias in use_paths(tree)
                          if alias != "*" or segs[0] in ("crate", "super", "self")}
        body = USE.sub("", MOD_DECL.sub("", text))
        for path in PATH.findall(body):
            found.add(self.resolve(module, [t.strip() for t in path.split("::")]))
        for child in self.children[module]:
            for name in re.findall(r"(?<![A-Za-z_0-9:])" + child + r"\s*::\s*([A-Za-z_][A-Za-z_0-9]*)",
                                   body):
                found.add(self.resolve(module, [child, name]))
        found.discard(None)
        # A module's own submodules are below it: that edge is the tree's top-down order.
        below = {f for m, f in self.files.items() if m[:len(module)] == module}
        return found - below


def file_graph(src):
    """The crate's files and, for each, the files it uses."""
    crate = Crate(src)
    rel = {f: os.path.relpath(f, src) for f in crate.files.values()}
    graph = {rel[f]: {rel[t] for t in crate.edges(m)} for m, f in crate.files.items()}
    return sorted(graph), collections.defaultdict(set, graph)


def all_circles(src):
    """The circles between files, then those between the submodules of any one module
    (a submodule with submodules of its own is one node, `a/`: it uses `b/` when a file
    under `a/` uses one under `b/`) that the files' circles do not already show."""
    files, graph = file_graph(src)
    found = circles(files, graph)
    module_of = {os.path.relpath(p, src): m for m, p in crate_files(src).items()}
    modules = set(module_of.values())

    def label(module):
        if any(m[:len(module)] == module and m != module for m in modules):
            return "/".join(module) + "/"
        return next(f for f, m in module_of.items() if m == module)

    for parent in modules:
        depth = len(parent) + 1
        level = collections.defaultdict(set)
        for f, targets in graph.items():
            a = module_of[f]
            for b in map(module_of.get, targets):
                if len(a) >= depth and len(b) >= depth and a[:depth - 1] == parent \
                        and b[:depth - 1] == parent and a[:depth] != b[:depth]:
                    level[label(a[:depth])].add(label(b[:depth]))
        for comp in circles(sorted(level), level):
            if comp not in found:
                found.append(comp)
    return found


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


SELF_TEST = {
    # Siblings using each other: a circle.
    "lib.rs": "mod a;\nmod b;\nmod c;\nmod d;\nmod e;\nmod f;\nmod g;\nmod h;\nmod i;\npub use c::Top;\n",
    "a.rs": "use crate::b::f;\npub fn g() { f() }\n",
    "b.rs": "pub fn f() { super::a::g() }\n",
    # A mod.rs that defines what its children share and calls into them: no circle. A name
    # the parent re-exports resolves to the child defining it, so x and y form a circle.
    "c/mod.rs": "mod x;\nmod y;\npub use x::{go, X};\npub struct Top;\npub fn run() { x::go(); }\n",
    "c/x.rs": "use super::Top;\npub struct X;\npub fn go() { crate::c::y::h(); }\n",
    "c/y.rs": "use super::X;\npub fn h() {}\n",
    # Comments, strings and tests are no uses: no circle between d and e.
    "d.rs": "// crate::e::k\npub fn k() { let _ = \"crate::e::k\"; }\n"
            "#[cfg(test)]\nmod tests {\n    use crate::e::k;\n}\n",
    "e.rs": "pub fn k() { crate::d::k() }\n",
    # A use group with `self` and a rename, and a name from another crate: f and g circle.
    "f.rs": "use crate::{g::{self, G as H}, d::k};\nuse std::fmt;\npub struct F;\n",
    "g.rs": "use super::f::F;\npub struct G;\n",
    # Two folders using each other through different files: a circle between modules.
    "h/mod.rs": "mod p;\nmod s;\n",
    "h/p.rs": "pub fn p() { crate::i::q::q() }\n",
    "h/s.rs": "pub fn s() {}\n",
    "i/mod.rs": "pub mod q;\nmod r;\n",
    "i/q.rs": "pub fn q() {}\n",
    "i/r.rs": "pub fn r() { crate::h::s::s() }\n",
}


def self_test():
    """The circle finder on `SELF_TEST`'s tree: 0 when it finds exactly the circles there."""
    import tempfile
    with tempfile.TemporaryDirectory() as src:
        for name, text in SELF_TEST.items():
            os.makedirs(os.path.dirname(os.path.join(src, name)), exist_ok=True)
            with open(os.path.join(src, name), "w") as f:
                f.write(text)
        found = all_circles(src)
    expected = [["a.rs", "b.rs"], ["c/x.rs", "c/y.rs"], ["f.rs", "g.rs"], ["h/", "i/"]]
    if sorted(found) != expected:
        print(f"self-test failed: found {sorted(found)}, expected {expected}")
        return 1
    print("self-test passed")
    return 0


# Crates the facade re-exports under another name (`neurotex::stream` is `neurotex-stream`).
ALIASES = {"stream": ("neurotex-stream", ())}


def module_index():
    """(crate, module path) -> file, over every crate's sources."""
    index = {}
    for c in sorted(os.listdir(CRATES)):
        src = os.path.join(CRATES, c, "src")
        if os.path.isdir(src):
            index.update({(c, m): f for m, f in crate_files(src).items()})
    return index


def names_module_path(segs, index):
    """Whether `a::b::f` names a module of some crate and an item of it (a name its file
    defines or re-exports), or `Type::item` a type with that item in an `impl` of it."""
    segs = [s for s in segs if not s.startswith("neurotex")]
    if not segs or segs[0] in ("crate", "self", "super", "std"):
        return True
    if segs[0][0].isupper():
        impl = re.compile(r"impl\b[^{;]*\b" + segs[0] + r"\b")
        item = re.compile(r"\b(?:fn|const|type)\s+" + segs[1] + r"\b")
        return any(impl.search(t) and item.search(t) for t in map(code_of, index.values()))
    starts = [(c, m) for c, m in index if m and m[-1] == segs[0]]
    starts += [ALIASES[segs[0]]] if segs[0] in ALIASES else []
    for crate, module in starts:
        found = True
        for seg in segs[1:]:
            if (crate, module + (seg,)) in index:
                module += (seg,)
                continue
            # An item of this module (what comes after it, `Type::method`, is not checked).
            found = re.search(r"\b" + seg + r"\b", code_of(index[(crate, module)])) is not None
            break
        if found:
            return True
    return False


def document_names(path):
    """What `path` (a Markdown file) names in backticks that does not exist: a path with a
    `/` (from the repository's root, a crate's folder or its `src/`) or a module path
    (`recording::read_recording`, and each bold **`module`** of the code map)."""
    text = open(path).read()
    index = module_index()
    missing = []
    for name in sorted(set(re.findall(r"`([^`\s]*/[^`\s]*)`", text))):
        bases = [ROOT] + [os.path.join(CRATES, c, sub) for c in os.listdir(CRATES)
                          for sub in ("", "src")]
        if not any(os.path.exists(os.path.join(b, name)) for b in bases):
            missing.append(name)
    paths = re.findall(r"`([A-Za-z_][A-Za-z_0-9]*(?:::[A-Za-z_][A-Za-z_0-9]*)+)`", text)
    paths += re.findall(r"\*\*`([a-z_][a-z_0-9]*)`\*\*", text)
    for name in sorted(set(paths)):
        if not names_module_path(name.split("::"), index):
            missing.append(name)
    return missing


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
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
        for comp in all_circles(src):
            print(f"  import circle: {' <-> '.join(comp)}")
            failed = True
        for f in sources(src):
            if is_test_file(f):
                continue
            for name, line, length in long_functions(f):
                print(f"  {os.path.relpath(f, ROOT)}:{line}: fn {name} is {length} lines")
                failed = True
    for name in document_names(os.path.join(ROOT, "ARCHITECTURE.md")):
        print(f"  ARCHITECTURE.md names `{name}`, which is not in the tree")
        failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
