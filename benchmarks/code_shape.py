"""The shape of the source tree, measured the same way every time.

Prints the figures that a consolidation round is judged by: lines and modules in
``src/softbend``, library parameters that exist only to name a command-line option
in a message (``owner``, ``field``, ``option``, ``*_field``, ``*_option``; the CLI
package itself is not counted), parameters annotated with a bare ``Any``, and the
modules that parse CSV text (``pandas.read_csv``, ``csv.reader``/``csv.DictReader``)::

    python benchmarks/code_shape.py            # the table
    python benchmarks/code_shape.py --json     # the same figures as JSON
    python benchmarks/code_shape.py --list     # every counted parameter, for review
"""

from __future__ import annotations

import argparse
import ast
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "softbend"
MESSAGE_ONLY = {"owner", "field", "option"}
CSV_CALLS = {"read_csv", "reader", "DictReader"}


def _is_message_only(name: str) -> bool:
    return name in MESSAGE_ONLY or name.endswith(("_field", "_option"))


def _parameters(function: ast.FunctionDef | ast.AsyncFunctionDef) -> list[ast.arg]:
    a = function.args
    extra = [x for x in (a.vararg, a.kwarg) if x is not None]
    return [*a.posonlyargs, *a.args, *a.kwonlyargs, *extra]


def _is_bare_any(annotation: ast.expr | None) -> bool:
    if annotation is None:
        return False
    if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
        return annotation.value.strip() in {"Any", "typing.Any"}
    if isinstance(annotation, ast.Name):
        return annotation.id == "Any"
    return isinstance(annotation, ast.Attribute) and annotation.attr == "Any"


def measure() -> dict[str, object]:
    """Count the figures over ``src/softbend``."""
    lines = modules = 0
    message_only: list[str] = []
    functions_with_message_only: set[str] = set()
    bare_any: list[str] = []
    csv_modules: list[str] = []
    for path in sorted(SRC.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        lines += len(text.splitlines())
        modules += 1
        rel = path.relative_to(SRC).as_posix()
        tree = ast.parse(text)
        library = not rel.startswith("cli/")
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                for arg in _parameters(node):
                    where = f"{rel}:{node.lineno} {node.name}({arg.arg})"
                    if library and _is_message_only(arg.arg):
                        message_only.append(where)
                        functions_with_message_only.add(f"{rel}:{node.name}")
                    if _is_bare_any(arg.annotation):
                        bare_any.append(where)
            if isinstance(node, ast.Call):
                func = node.func
                name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
                if name in CSV_CALLS and rel not in csv_modules:
                    csv_modules.append(rel)
    return {
        "lines": lines,
        "modules": modules,
        "message_only_parameters": len(message_only),
        "functions_with_message_only_parameters": len(functions_with_message_only),
        "bare_any_parameters": len(bare_any),
        "csv_parsing_modules": csv_modules,
        "_message_only": message_only,
        "_bare_any": bare_any,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.add_argument("--list", action="store_true", help="list every counted parameter")
    args = parser.parse_args()
    figures = measure()
    if args.list:
        for key in ("_message_only", "_bare_any"):
            print(f"# {key.strip('_')}")
            print("\n".join(figures[key]))  # type: ignore[arg-type]
        return
    public = {k: v for k, v in figures.items() if not k.startswith("_")}
    if args.json:
        print(json.dumps(public, indent=2))
        return
    for key, value in public.items():
        shown = ", ".join(value) if isinstance(value, list) else value
        print(f"{key:42s} {shown}")


if __name__ == "__main__":
    main()
