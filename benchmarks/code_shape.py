"""The shape of the source tree, measured the same way every time.

Prints the figures that a consolidation round is judged by: lines in ``src/softbend``
(all; code, neither blank, comment nor docstring; docstrings) and its modules, library
parameters that exist only to name a command-line option in a message (``owner``,
``field``, ``option``, ``*_field``, ``*_option``; the CLI package itself is not counted),
parameters annotated with a bare ``Any``, and the
modules that parse CSV text (``pandas.read_csv``, ``csv.reader``/``csv.DictReader``),
and the figures of "one road for every actuator": tests that name paper B's actuator
outside its own modules (an ``if``/``elif``/``while``/``assert``, a conditional
expression or a comprehension filter whose test names ``SFRBA``, ``paper_b`` in any
case, ``is_paper_b``, ``"sfrba"`` or ``DEFAULT_FAMILY``), the classes that stand for one
design (a class whose name ends in ``Design``), ``ContextVar``s that hold actuator
state (any but the progress listener and the CLI's command and argument records),
and command functions of the CLI longer than 60 lines::

    python benchmarks/code_shape.py            # the table
    python benchmarks/code_shape.py --json     # the same figures as JSON
    python benchmarks/code_shape.py --list     # every counted parameter, for review
"""

from __future__ import annotations

import argparse
import ast
import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "softbend"
MESSAGE_ONLY = {"owner", "field", "option"}
CSV_CALLS = {"read_csv", "reader", "DictReader"}
#: A test names paper B's actuator when its source text matches this.
PAPER_B = re.compile(r"SFRBA|(?i:paper_b)|[\"']sfrba[\"']|DEFAULT_FAMILY")
#: Paper B's own modules: its analytical model, its FEM family, its reproduction and report.
PAPER_B_OWN = re.compile(r"(^|/)(paper_b[^/]*\.py|analytical\.py|fem/sfrba/.*)$")
#: ContextVars that hold no actuator state: the progress listener, the running command
#: and its arguments (for the output-folder rule).
CONTEXT_OK = {"softbend_progress", "command", "arguments"}
CLI_FUNCTION_LINES = 60


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


def _tests(node: ast.AST) -> list[ast.expr]:
    """The conditional tests ``node`` holds itself (not those of nested nodes)."""
    if isinstance(node, ast.If | ast.While | ast.IfExp | ast.Assert):
        return [node.test]
    if isinstance(node, ast.comprehension):
        return list(node.ifs)
    if isinstance(node, ast.match_case) and node.guard is not None:
        return [node.guard]
    return []


def _docstring_lines(tree: ast.Module) -> set[int]:
    """Line numbers of the module's, classes' and functions' docstrings."""
    found: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            first = node.body[0] if node.body else None
            if (
                isinstance(first, ast.Expr)
                and isinstance(first.value, ast.Constant)
                and isinstance(first.value.value, str)
            ):
                found.update(range(first.lineno, (first.end_lineno or first.lineno) + 1))
    return found


def _is_command(node: ast.expr) -> bool:
    """Whether ``node`` is a typer ``app.command(...)`` call (a decorator or a registration)."""
    return (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "command"
    )


def _context_var_name(node: ast.Call) -> str | None:
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
    if name != "ContextVar" or not node.args:
        return None
    first = node.args[0]
    return first.value if isinstance(first, ast.Constant) else "?"


def measure() -> dict[str, object]:
    """Count the figures over ``src/softbend``."""
    lines = modules = 0
    message_only: list[str] = []
    functions_with_message_only: set[str] = set()
    bare_any: list[str] = []
    csv_modules: list[str] = []
    paper_b_tests: list[str] = []
    design_classes: list[str] = []
    actuator_context: list[str] = []
    long_commands: list[str] = []
    module_lines: dict[str, int] = {}
    docstring_lines = code_lines = 0
    functions: dict[str, tuple[str, ast.FunctionDef]] = {}
    commands: set[str] = set()
    for path in sorted(SRC.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        lines += len(text.splitlines())
        modules += 1
        rel = path.relative_to(SRC).as_posix()
        module_lines[rel] = len(text.splitlines())
        tree = ast.parse(text)
        documented = _docstring_lines(tree)
        docstring_lines += len(documented)
        code_lines += sum(
            1
            for number, line in enumerate(text.splitlines(), 1)
            if number not in documented and line.strip() and not line.strip().startswith("#")
        )
        library = not rel.startswith("cli/")
        own = PAPER_B_OWN.search(rel) is not None
        for node in ast.walk(tree):
            for test in _tests(node):
                if not own and PAPER_B.search(ast.get_source_segment(text, test) or ""):
                    paper_b_tests.append(f"{rel}:{test.lineno}")
            if isinstance(node, ast.ClassDef) and node.name.endswith("Design"):
                design_classes.append(f"{rel}:{node.lineno} {node.name}")
            if isinstance(node, ast.Call):
                var = _context_var_name(node)
                if var is not None and var not in CONTEXT_OK:
                    actuator_context.append(f"{rel}:{node.lineno} {var}")
            if rel.startswith("cli/") and isinstance(node, ast.FunctionDef):
                functions[node.name] = (rel, node)
                if any(_is_command(d) for d in node.decorator_list):
                    commands.add(node.name)
            if isinstance(node, ast.Call) and _is_command(node.func):  # app.command("x")(f)
                commands.update(a.id for a in node.args if isinstance(a, ast.Name))
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
    for name in sorted(commands & set(functions)):
        rel, node = functions[name]
        length = (node.end_lineno or node.lineno) - node.lineno + 1
        if length > CLI_FUNCTION_LINES:
            long_commands.append(f"{rel}:{node.lineno} {name} ({length} lines)")
    return {
        "lines": lines,
        "code_lines": code_lines,
        "docstring_lines": docstring_lines,
        "modules": modules,
        "message_only_parameters": len(message_only),
        "functions_with_message_only_parameters": len(functions_with_message_only),
        "bare_any_parameters": len(bare_any),
        "csv_parsing_modules": csv_modules,
        "paper_b_tests_outside_its_modules": len(paper_b_tests),
        "modules_with_paper_b_tests": len({w.split(":")[0] for w in paper_b_tests}),
        "design_classes": len(design_classes),
        "actuator_context_vars": len(actuator_context),
        "cli_commands_over_60_lines": len(long_commands),
        "modules_over_700_lines": sum(n > 700 for n in module_lines.values()),
        "_message_only": message_only,
        "_bare_any": bare_any,
        "_paper_b_tests": paper_b_tests,
        "_design_classes": design_classes,
        "_actuator_context_vars": actuator_context,
        "_cli_commands_over_60_lines": long_commands,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.add_argument("--list", action="store_true", help="list every counted parameter")
    args = parser.parse_args()
    figures = measure()
    if args.list:
        for key in (k for k in figures if k.startswith("_")):
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
