"""The import direction of design.md §2 and docs/architecture.md, and no import cycles.

Every module of app/, engine/ and db/ is parsed (not imported); each import (module level or
inside a function) must go to the same or a lower layer, and the module-level imports must
not form a cycle.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (prefix, rank): a module may import modules of its own rank or lower. Longest prefix wins.
LAYERS = [
    ("engine", 0),
    ("db", 0),
    ("app.machine", 1),
    ("app.config", 2), ("app.gud", 2), ("app.records", 2), ("app.errors", 2), ("app.http_limits", 2),
    ("app.checks", 2),            # the strict number checks of every client input (issue 25)
    ("app.i18n", 2),              # operator languages: catalogues and formats, used by the screens
    ("app.access", 2),            # levels, identity, errors, service, checks: below the services
    ("app.workflow", 3), ("app.nc", 3),
    ("app.services", 4),
    ("app.ports", 2), ("app.openapi_doc", 2),
    ("app.deps", 5), ("app.opcua", 5), ("app.mtconnect", 5), ("app.access.deps", 5), ("app.access.middleware", 5),
    ("app.api", 6), ("app.web", 6),
    ("app.main", 7), ("app.access.handlers", 7),
    ("app.__main__", 8),
    ("app", 8),
]
# the simulator never imports the engine's evaluation (design.md §2): only these engine modules
MACHINE_MAY_USE = ("engine.alarms", "engine.checks", "engine.coords", "engine.frames", "engine.planes")
SEPARATE = {("engine", "db"), ("db", "engine")}     # the two bottom packages know nothing of each other


def _modules() -> dict[str, Path]:
    mods = {}
    for top in ("app", "engine", "db"):
        for path in (ROOT / top).rglob("*.py"):
            if "migrations" in path.parts:
                continue
            name = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            mods[name.removesuffix(".__init__")] = path
    return mods


MODULES = _modules()


def _rank(module: str) -> int:
    best = max((p for p, _ in LAYERS if module == p or module.startswith(p + ".")), key=len)
    return dict(LAYERS)[best]


def _imports(name: str, path: Path) -> list[tuple[str, bool, int]]:
    """(imported module, at module level, line) for the project's own modules."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            targets = [f"{module}.{a.name}" for a in node.names] + [module]
        else:
            continue
        for target in targets:
            while target and target not in MODULES:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.append((target, node.col_offset == 0, node.lineno))
                break
    return found


def test_imports_follow_the_layers():
    wrong = []
    for name, path in MODULES.items():
        for target, _top, line in _imports(name, path):
            top_a, top_b = name.split(".")[0], target.split(".")[0]
            if (top_a, top_b) in SEPARATE:
                wrong.append(f"{name}:{line} imports {target} ({top_a} knows nothing of {top_b})")
            elif _rank(target) > _rank(name):
                wrong.append(f"{name}:{line} imports {target}, a higher layer")
            elif name.startswith("app.machine") and target.startswith("engine") \
                    and not target.startswith(MACHINE_MAY_USE):
                wrong.append(f"{name}:{line} imports {target}: the simulator must not use the engine's evaluation")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles():
    graph = {name: sorted({t for t, top, _ in _imports(name, path) if top}) for name, path in MODULES.items()}
    cycles, state = [], {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = "open"
        for nxt in graph.get(node, []):
            if state.get(nxt) == "open":
                cycles.append(" -> ".join(stack[stack.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])
    assert not cycles, "\n".join(cycles)
