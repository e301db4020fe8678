#!/usr/bin/env python3
"""The import graph of src/ and its circles, at two levels: files, and top-level modules of a
layer (`physics/bladder/*` is one node, `physics/gaylord.rs` another). An edge is a path through
`crate::`, `super::` or `self::` in code that is not a test (`*tests.rs` and inline
`#[cfg(test)] mod` blocks are left out: a test may use any module); a module's own children
(`mod x;`) are parts of it, not edges. Prints the circles and exits 1 if any.

    python3 tools/import_graph.py [--edges]
"""
import re
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"


def module_of(path):
    """`src/physics/bladder/mod.rs` -> ('physics', 'bladder'); `src/lib.rs` -> ()."""
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts.pop()
    return tuple(parts)


def production_code(path):
    text = path.read_text()
    # An inline test module runs to the end of the file (the project's convention).
    cut = re.search(r"#\[cfg\(test\)\]\s*mod \w+\s*\{", text)
    text = text if cut is None else text[: cut.start()]
    # Comments name modules too; they are not imports.
    return re.sub(r"//[^\n]*", "", text)


def resolve(path, modules):
    """The longest prefix of `path` that is a module (file) of the crate."""
    for n in range(len(path), 0, -1):
        if tuple(path[:n]) in modules:
            return tuple(path[:n])
    return None


def edges():
    files = [p for p in SRC.rglob("*.rs") if not p.name.endswith("tests.rs")]
    modules = {module_of(p): p for p in files}
    out = {}
    for module, path in modules.items():
        code = production_code(path)
        targets = set()
        for m in re.finditer(r"\b((?:crate|super|self)(?:::\w+)+|(?:crate|super)::\{[^}]*\})", code):
            text = m.group(1)
            heads = [text]
            if "{" in text:
                base, inner = text.split("::{", 1)
                heads = [f"{base}::{item.strip().split('::')[0]}" for item in inner.rstrip("}").split(",")]
            for head in heads:
                segs = head.split("::")
                if segs[0] == "crate":
                    full = segs[1:]
                else:
                    base = list(module)
                    while segs and segs[0] in ("super", "self"):
                        if segs[0] == "super":
                            base = base[:-1]
                        segs = segs[1:]
                    full = base + segs
                target = resolve(full, modules)
                if target is not None and target != module and target != ():
                    targets.add(target)
        out[module] = targets
    return out


def circles(graph):
    """The strongly connected components with more than one node (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in list(graph):
        if v not in index:
            visit(v)
    return found


def collapse(graph):
    """Top-level modules of each layer: `physics/bladder/x` -> `physics/bladder`. A module's own
    children are inside it, so edges within one node vanish."""
    def node(m):
        return m[:2]
    out = {}
    for v, ws in graph.items():
        out.setdefault(node(v), set()).update(node(w) for w in ws if node(w) != node(v))
    return out


def main():
    graph = edges()
    if "--edges" in sys.argv:
        for v in sorted(graph):
            print("/".join(v), "->", ", ".join("/".join(w) for w in sorted(graph[v])))
    failed = False
    for level, g in (("files", graph), ("modules", collapse(graph))):
        found = circles(g)
        print(f"{level}: {len(g)} nodes, {sum(len(w) for w in g.values())} edges, "
              f"{len(found)} circles")
        for c in found:
            failed = True
            print("  circle:", " <-> ".join("/".join(m) for m in c))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
