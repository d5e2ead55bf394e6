"""The package's import graph: no cycle, and no stage imports a later one.

Every ``import softbend…`` in the source is read (including imports inside
functions, which still tie the modules together), and each module is placed in
the stage of the pipeline its package belongs to. A module may import its own
stage and earlier ones only.
"""

from __future__ import annotations

import ast
from pathlib import Path

import softbend

PACKAGE = Path(softbend.__file__).parent

#: The pipeline, earliest first; a module's stage is that of its first name
#: after ``softbend.`` (private helper modules sit at the bottom).
STAGES: tuple[tuple[str, ...], ...] = (
    (
        "__init__",
        "_extras",
        "_interrupts",
        "_io",
        "_outdir",
        "_jsontext",
        "_lazy",
        "_names",
        "_progress",
        "_tomltext",
        "_torch",
        "_validation",
        "errors",
        "limits",
        "units",
    ),
    ("registry", "references", "parameters"),
    ("plausibility", "column_values", "table_rows", "tables"),
    ("metrics", "kinematics"),
    ("actuators", "design"),
    ("materials",),
    ("models",),
    ("analytical", "fem"),
    ("campaign",),
    ("datasets", "dataset_writing", "analysis"),
    ("surrogates",),
    ("identification",),
    ("transfer", "control", "design_search"),
    ("pipeline",),
    ("reports",),
    ("cli",),
)
STAGE = {name: i for i, names in enumerate(STAGES) for name in names}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, module: str) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_package = path.name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")
                base = base if is_package else base[:-1]
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            found.add(target)
            found.update(f"{target}.{a.name}" for a in node.names)
    return {name for name in found if name == "softbend" or name.startswith("softbend.")}


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph = {}
    for module, path in files.items():
        # Keep the names that are modules (``from softbend.x import y`` may name a function).
        graph[module] = {name for name in _imports(path, module) if name in files} - {module}
    return graph


def _stage(module: str) -> int:
    parts = module.split(".")
    return STAGE["__init__"] if len(parts) == 1 else STAGE[parts[1]]


def test_every_module_has_a_stage():
    unknown = sorted(m for m in _graph() if len(m.split(".")) > 1 and m.split(".")[1] not in STAGE)
    assert not unknown, f"place these modules in STAGES: {unknown}"


def test_no_stage_imports_a_later_one():
    upward = sorted(
        f"{module} (stage {_stage(module)}) imports {target} (stage {_stage(target)})"
        for module, targets in _graph().items()
        for target in targets
        if _stage(target) > _stage(module)
    )
    assert not upward, "\n".join(upward)


def test_the_import_graph_has_no_cycle():
    graph = _graph()
    # The package's __init__ files import their submodules; a submodule importing
    # its own package's __init__ is not a cycle of logic, so those edges go.
    edges = {
        m: {t for t in targets if not m.startswith(t + ".") and not t.startswith(m + ".")}
        for m, targets in graph.items()
    }
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(edges[node]):
            if state.get(target) == 1:
                return [*path[path.index(target) :], target]
            if target not in state and (cycle := visit(target)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(edges):
        if node not in state and (cycle := visit(node)):
            raise AssertionError("import cycle: " + " -> ".join(cycle))
