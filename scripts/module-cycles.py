#!/usr/bin/env python3
"""Fails if two modules of one crate import each other, directly or through others.

For every crate of the workspace (and the firmware), each source file is a module; its references
are the `crate::a::b` and `super::x` paths in its code (comments and `#[cfg(test)]` modules left
out), resolved to the longest module they name. A parent's `mod child;` is not a reference, so a
child may use its parent, but then the parent must not use the child's items. Prints every cycle.

    python3 scripts/module-cycles.py
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def crate_roots() -> list[Path]:
    roots = [ROOT / "src"]
    roots += sorted(p.parent for p in ROOT.glob("crates/*/src/lib.rs"))
    roots += [ROOT / "experiments" / "src", ROOT / "embedded" / "src"]
    return [r for r in roots if r.is_dir()]


def module_path(src: Path, file: Path) -> tuple[str, ...]:
    parts = list(file.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def code_of(text: str) -> str:
    # Test modules use their parent freely; they are not part of the module graph.
    cut = re.search(r"#\[cfg\(test\)\]\s*(pub(\(crate\))?\s+)?mod\s+\w+\s*\{", text)
    if cut:
        text = text[: cut.start()]
    lines = [line.split("//", 1)[0] for line in text.splitlines()]
    return "\n".join(lines)


def root_exports(root_code: str, modules: set[tuple[str, ...]]) -> dict[str, tuple[str, ...]]:
    """Items the crate root re-exports (`pub use a::b::{C, D}`), by name, with their module."""
    exports: dict[str, tuple[str, ...]] = {}
    for path, group in re.findall(r"pub use (?:crate::)?([\w:]+?)(?:::\{([^}]*)\})?;", root_code):
        parts = path.split("::")
        names = [g.strip().split(" as ")[-1] for g in group.split(",") if g.strip()] if group else [parts.pop()]
        target = tuple(parts)
        while target and target not in modules:
            target = target[:-1]
        for name in names:
            if target:
                exports[name] = target
    return exports


EXPORTS: dict[str, tuple[str, ...]] = {}


def references(module: tuple[str, ...], code: str, modules: set[tuple[str, ...]]) -> set[tuple[str, ...]]:
    found: set[tuple[str, ...]] = set()
    paths = re.findall(r"\b((?:crate|super)(?:::\w+)+)", code)
    # `use crate::{a, b::c}` groups
    for group_root, inner in re.findall(r"\b(crate|super)::\{([^}]*)\}", code):
        paths += [f"{group_root}::{item.strip()}" for item in inner.split(",") if item.strip()]
    for path in paths:
        parts = path.split("::")
        if parts[0] == "crate":
            base: list[str] = []
            rest = parts[1:]
        else:
            base = list(module[:-1])
            rest = parts[1:]
            while rest and rest[0] == "super":
                base = base[:-1]
                rest = rest[1:]
        target = tuple(base)
        best = target if target in modules else None
        if not base and rest and rest[0] in EXPORTS:
            best = EXPORTS[rest[0]]
        for part in rest:
            target = target + (part,)
            if target in modules:
                best = target
        # The crate root only declares modules and re-exports their items: `crate::Item` names the
        # module that defines it, which the root's `pub use` says; not a reference to the root.
        if best is not None and best != () and best != module:
            found.add(best)
    return found


def cycles(graph: dict[tuple[str, ...], set[tuple[str, ...]]]) -> list[list[tuple[str, ...]]]:
    index: dict[tuple[str, ...], int] = {}
    low: dict[tuple[str, ...], int] = {}
    stack: list[tuple[str, ...]] = []
    on_stack: set[tuple[str, ...]] = set()
    result: list[list[tuple[str, ...]]] = []

    def visit(v: tuple[str, ...]) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                result.append(component)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return result


def main() -> int:
    sys.setrecursionlimit(10000)
    failed = False
    for src in crate_roots():
        files = sorted(src.rglob("*.rs"))
        modules = {module_path(src, f) for f in files}
        root = next((src / n for n in ("lib.rs", "main.rs") if (src / n).exists()), None)
        EXPORTS.clear()
        if root is not None:
            EXPORTS.update(root_exports(code_of(root.read_text()), modules))
        graph = {module_path(src, f): references(module_path(src, f), code_of(f.read_text()), modules) for f in files}
        # A parent uses a child's items only through `child::`; `mod child;` alone is no reference.
        for module, text in ((module_path(src, f), code_of(f.read_text())) for f in files):
            for child in {m for m in modules if len(m) == len(module) + 1 and m[: len(module)] == module}:
                if re.search(rf"\b{child[-1]}::", text):
                    graph[module].add(child)
        for component in cycles(graph):
            failed = True
            names = ", ".join("::".join(m) or "(root)" for m in sorted(component))
            print(f"{src.relative_to(ROOT)}: modules import each other: {names}")
    if failed:
        return 1
    print(f"no import circles in {len(crate_roots())} crates")
    return 0


if __name__ == "__main__":
    sys.exit(main())
